//! Lane masks: one bit per RC, bit `i` for lane `i` (row-major in the 8x8
//! array). A `u64` holds every per-RC flag of the array, so "do all rays
//! agree?" is one comparison.

pub type Mask = u64;

/// The mask with the low `n` lanes set.
#[inline(always)]
pub const fn full(n: usize) -> Mask {
    if n >= 64 {
        u64::MAX
    } else {
        (1u64 << n) - 1
    }
}

/// `dst[i] = src[i]` for every lane `i` in `mask`.
#[inline(always)]
pub fn select<T: Copy + Default, const N: usize>(dst: &mut [T; N], mask: Mask, src: &[T; N]) {
    if mask == full(N) {
        *dst = *src;
    } else if mask != 0 {
        let m = unpack::<N>(mask);
        for i in 0..N {
            dst[i] = if m[i] { src[i] } else { dst[i] };
        }
    }
}

/// One bool per lane from a mask.
#[inline(always)]
pub fn unpack<const N: usize>(mask: Mask) -> [bool; N] {
    let mut m = [false; N];
    for (i, b) in m.iter_mut().enumerate() {
        *b = mask >> i & 1 != 0;
    }
    m
}

/// Pack one bool per lane into a mask. Eight lanes at a time: the eight
/// 0/1 bytes of a little-endian u64 gathered into one byte by a multiply.
#[inline(always)]
pub fn pack_bools<const N: usize>(b: &[bool; N]) -> Mask {
    let mut m = 0u64;
    let chunks = N / 8;
    for c in 0..chunks {
        let mut bytes = [0u8; 8];
        for k in 0..8 {
            bytes[k] = b[c * 8 + k] as u8;
        }
        let x = u64::from_le_bytes(bytes);
        m |= (x.wrapping_mul(0x0102_0408_1020_4080) >> 56) << (c * 8);
    }
    for i in chunks * 8..N {
        m |= (b[i] as u64) << i;
    }
    m
}

/// Pack one bool per lane, computed by `f`.
#[inline(always)]
pub fn pack<const N: usize>(f: impl Fn(usize) -> bool) -> Mask {
    let mut b = [false; N];
    for (i, x) in b.iter_mut().enumerate() {
        *x = f(i);
    }
    pack_bools(&b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pack_and_unpack_are_inverse() {
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..1000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let b = unpack::<64>(x);
            for i in 0..64 {
                assert_eq!(b[i], x >> i & 1 == 1);
            }
            assert_eq!(pack_bools(&b), x);
            let b5: [bool; 5] = std::array::from_fn(|i| b[i]);
            assert_eq!(pack_bools(&b5), x & 31);
            let b12: [bool; 12] = std::array::from_fn(|i| b[i]);
            assert_eq!(pack_bools(&b12), x & 0xFFF);
        }
    }
}
