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
pub fn select<T: Copy, const N: usize>(dst: &mut [T; N], mask: Mask, src: &[T; N]) {
    if mask == full(N) {
        *dst = *src;
    } else if mask != 0 {
        for i in 0..N {
            if mask >> i & 1 != 0 {
                dst[i] = src[i];
            }
        }
    }
}

/// Pack one bool per lane into a mask.
#[inline(always)]
pub fn pack<const N: usize>(f: impl Fn(usize) -> bool) -> Mask {
    let mut m = 0;
    for i in 0..N {
        m |= (f(i) as u64) << i;
    }
    m
}
