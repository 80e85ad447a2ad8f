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
pub(crate) fn select<T: Copy + Default, const N: usize>(
    dst: &mut [T; N],
    mask: Mask,
    src: &[T; N],
) {
    if mask == full(N) {
        *dst = *src;
    } else if mask != 0 {
        let m = unpack::<N>(mask);
        for i in 0..N {
            dst[i] = if m[i] { src[i] } else { dst[i] };
        }
    }
}

/// A signed lane type whose sign bits can be gathered into a mask.
pub trait SignBits: Copy + Default {
    /// The mask of the lanes of `x` whose sign bit is set (bit `i`: lane
    /// `i`). On the AVX-512 path ([`crate::simd::avx512`]) one
    /// instruction per 512-bit register; otherwise through bools.
    fn sign_mask<const N: usize>(x: &[Self; N]) -> Mask;
    /// [`SignBits::sign_mask`] without AVX-512 (what other CPUs run).
    fn sign_mask_portable<const N: usize>(x: &[Self; N]) -> Mask;
    /// -1 if `b`, else 0 (a lane of a flag vector for [`SignBits::sign_mask`]).
    fn flag(b: bool) -> Self;
    /// The inverse of [`SignBits::sign_mask`]: lane `i` is -1 where bit
    /// `i` of `mask` is set, else 0. On the AVX-512 path one instruction
    /// per 512-bit register; otherwise `None` (the caller's table does it).
    fn from_mask<const N: usize>(mask: Mask) -> Option<[Self; N]>;
}

macro_rules! sign_bits {
    ($t:ty, $per:expr, $movemask:ident, $movm:ident) => {
        impl SignBits for $t {
            #[inline(always)]
            fn sign_mask<const N: usize>(x: &[$t; N]) -> Mask {
                #[cfg(target_arch = "x86_64")]
                if crate::simd::avx512() && N <= 64 && N % $per == 0 {
                    use std::arch::x86_64::{_mm512_loadu_si512, $movemask};
                    let mut m = 0u64;
                    for k in 0..N / $per {
                        // SAFETY: register k's lanes k * $per.. lie inside
                        // the N lanes of `x`; an unaligned load.
                        let bits = unsafe {
                            $movemask(_mm512_loadu_si512(x.as_ptr().add(k * $per).cast()))
                        };
                        m |= (bits as u64) << (k * $per);
                    }
                    return m;
                }
                Self::sign_mask_portable(x)
            }
            #[inline(always)]
            fn sign_mask_portable<const N: usize>(x: &[$t; N]) -> Mask {
                let mut b = [false; N];
                for i in 0..N {
                    b[i] = x[i] < 0;
                }
                pack_bools(&b)
            }
            #[inline(always)]
            fn flag(b: bool) -> $t {
                -(b as $t)
            }
            #[inline(always)]
            #[allow(unused_variables)]
            fn from_mask<const N: usize>(mask: Mask) -> Option<[$t; N]> {
                #[cfg(target_arch = "x86_64")]
                if crate::simd::avx512() && N == 64 {
                    use std::arch::x86_64::{_mm512_storeu_si512, $movm};
                    let mut x = [0 as $t; N];
                    for k in 0..64 / $per {
                        // SAFETY: register k's lanes k * $per.. lie inside
                        // the 64 lanes of `x`; an unaligned store.
                        unsafe {
                            let v = $movm((mask >> (k * $per)) as _);
                            _mm512_storeu_si512(x.as_mut_ptr().add(k * $per).cast(), v);
                        }
                    }
                    return Some(x);
                }
                None
            }
        }
    };
}

sign_bits!(i16, 32, _mm512_movepi16_mask, _mm512_movm_epi16);
sign_bits!(i32, 16, _mm512_movepi32_mask, _mm512_movm_epi32);
sign_bits!(i64, 8, _mm512_movepi64_mask, _mm512_movm_epi64);

/// One bool per lane from a mask.
#[inline(always)]
pub(crate) fn unpack<const N: usize>(mask: Mask) -> [bool; N] {
    let mut m = [false; N];
    for (i, b) in m.iter_mut().enumerate() {
        *b = mask >> i & 1 != 0;
    }
    m
}

/// Pack one bool per lane into a mask. Eight lanes at a time: the eight
/// 0/1 bytes of a little-endian u64 gathered into one byte by a multiply.
#[inline(always)]
pub(crate) fn pack_bools<const N: usize>(b: &[bool; N]) -> Mask {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Both ways of packing sign bits (AVX-512 on the AVX-512 path, and
    /// the portable one other CPUs run) against the bits one by one.
    #[test]
    fn sign_masks_of_every_lane_width() {
        fn check<T: SignBits + PartialOrd + From<i8> + std::fmt::Debug>(x: &[T; 64]) {
            let want = (0..64).fold(0u64, |m, i| m | ((x[i] < T::from(0)) as u64) << i);
            assert_eq!(T::sign_mask(x), want, "{x:?}");
            assert_eq!(T::sign_mask_portable(x), want);
            let x12: [T; 12] = std::array::from_fn(|i| x[i]);
            assert_eq!(T::sign_mask(&x12), want & 0xFFF);
            // 8, 16 and 32 lanes: whole registers of some widths
            let x8: [T; 8] = std::array::from_fn(|i| x[i]);
            assert_eq!(T::sign_mask(&x8), want & 0xFF);
            let x16: [T; 16] = std::array::from_fn(|i| x[i]);
            assert_eq!(T::sign_mask(&x16), want & 0xFFFF);
            let x32: [T; 32] = std::array::from_fn(|i| x[i + 32]);
            assert_eq!(T::sign_mask(&x32), want >> 32);
        }
        let mut r = 0x2545_F491_4F6C_DD1Du64;
        for _ in 0..500 {
            let mut next = || {
                r ^= r << 13;
                r ^= r >> 7;
                r ^= r << 17;
                r
            };
            check::<i16>(&std::array::from_fn(|_| next() as i16));
            check::<i32>(&std::array::from_fn(|_| next() as i32));
            check::<i64>(&std::array::from_fn(|_| next() as i64));
            check::<i16>(&std::array::from_fn(|i| {
                i16::flag(next() >> (i % 7) & 1 != 0)
            }));
        }
    }

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
