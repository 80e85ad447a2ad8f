//! Image metrics for comparing a chip render against the reference: PSNR
//! over 8-bit RGB, per-pixel hit agreement, and the share of pixels off by
//! more than a threshold.

/// PSNR in dB over all channels of two 8-bit RGB images of equal size:
/// `10 log10(255^2 / MSE)`; infinite when identical.
pub fn psnr(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len(), "images differ in size");
    if a.is_empty() {
        return f64::INFINITY;
    }
    let se: u64 = a
        .iter()
        .zip(b)
        .map(|(&x, &y)| (x as i64 - y as i64).pow(2) as u64)
        .sum();
    if se == 0 {
        return f64::INFINITY;
    }
    let mse = se as f64 / a.len() as f64;
    10.0 * (255.0 * 255.0 / mse).log10()
}

/// Share (0..=1) of pixels whose largest channel difference exceeds
/// `threshold` (in 8-bit steps).
pub(crate) fn share_off(a: &[u8], b: &[u8], threshold: u8) -> f64 {
    assert_eq!(a.len(), b.len(), "images differ in size");
    let n = a.len() / 3;
    if n == 0 {
        return 0.0;
    }
    let off = a
        .chunks_exact(3)
        .zip(b.chunks_exact(3))
        .filter(|(p, q)| {
            p.iter()
                .zip(q.iter())
                .any(|(&x, &y)| x.abs_diff(y) > threshold)
        })
        .count();
    off as f64 / n as f64
}

/// Share (0..=1) of pixels whose eye rays hit the same object (or both
/// missed).
pub fn hit_agreement(a: &[u32], b: &[u32]) -> f64 {
    assert_eq!(a.len(), b.len(), "hit maps differ in size");
    if a.is_empty() {
        return 1.0;
    }
    a.iter().zip(b).filter(|(x, y)| x == y).count() as f64 / a.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn psnr_by_hand() {
        // One channel of four pixels off by 10: MSE = 100 / 12.
        let a = vec![0u8; 12];
        let mut b = a.clone();
        b[5] = 10;
        let expect = 10.0 * (65025.0f64 / (100.0 / 12.0)).log10(); // 38.92 dB
        assert!((psnr(&a, &b) - expect).abs() < 1e-12);
        assert!((psnr(&a, &b) - 38.9226).abs() < 1e-3);
        assert_eq!(psnr(&a, &a), f64::INFINITY);
        // Black against white: MSE = 255^2, PSNR 0 dB.
        assert_eq!(psnr(&[0, 0, 0], &[255, 255, 255]), 0.0);
    }

    #[test]
    fn share_and_agreement() {
        let a = [0u8, 0, 0, 10, 10, 10, 20, 20, 20, 30, 30, 30];
        let b = [0u8, 0, 5, 10, 10, 10, 20, 26, 20, 30, 30, 30];
        assert_eq!(share_off(&a, &b, 4), 0.5);
        assert_eq!(share_off(&a, &b, 5), 0.25);
        assert_eq!(share_off(&a, &b, 6), 0.0);
        assert_eq!(
            hit_agreement(&[1, 2, 3, u32::MAX], &[1, 2, 4, u32::MAX]),
            0.75
        );
    }
}
