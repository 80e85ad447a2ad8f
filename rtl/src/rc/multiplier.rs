//! The RC's multiplier with its accumulator: 16x16 into 32 bits ([`w16`],
//! the paper's chip) or 32x32 into 64 bits ([`w32`], the wide variant).
//!
//! * `MUL`: `acc = a * b` (the full product; `MIN^2` fits).
//! * `MAC` / `MSU`: `acc = acc ± a * b`, saturating at the accumulator's bounds.
//! * Every multiplier operation also yields a word-sized result
//!   `sat(acc >> sh)`, rounded to nearest (ties towards +inf: `+2^(sh-1)`
//!   before the arithmetic shift) or truncated towards -inf, so with `sh = n`
//!   two Qm.n operands give a Qm.n result in one word. The shift is 0..=31
//!   (16-bit) or 0..=63 (32-bit).
//!
//! `V` is set when the accumulator or the result saturated.

/// `$t` the word, `$acc` the accumulator (twice as wide) and `$uacc` its
/// unsigned pattern, `$w` wider still (exact sums and shifts), `$smask` the
/// shift field mask.
macro_rules! multiplier_unit {
    ($m:ident, $t:ty, $acc:ty, $uacc:ty, $w:ty, $smask:expr, $accumulate:ident, $doc:literal) => {
        #[doc = $doc]
        pub mod $m {
            /// The full product of two words.
            #[inline(always)]
            pub fn product(a: $t, b: $t) -> $acc {
                a as $acc * b as $acc
            }

            /// `acc + p` (or `acc - p` when `sub`), saturating at the
            /// accumulator's bounds.
            #[inline(always)]
            pub fn accumulate(acc: $acc, p: $acc, sub: bool) -> ($acc, bool) {
                super::$accumulate(acc, p, sub)
            }

            /// Scale the accumulator to one word: shift right by `sh`, rounding
            /// to nearest unless `trunc`, then saturate.
            ///
            /// Rounding adds `2^(sh-1)` before the shift; without overflow that
            /// is `floor(acc / 2^sh)` plus bit `sh-1` of `acc`.
            #[inline(always)]
            pub fn scale(acc: $acc, sh: u32, trunc: bool) -> ($t, bool) {
                let sh = sh & $smask;
                let mut w = acc >> sh;
                if !trunc && sh > 0 {
                    w += (acc >> (sh - 1)) & 1;
                }
                // Saturated where `w` lies outside the word's range: one
                // unsigned comparison of `w - MIN` (vectorised: an add and
                // a compare, where `clamp(w) != w` took three operations).
                let out = (w as $uacc).wrapping_sub(<$t>::MIN as $acc as $uacc)
                    > (<$t>::MAX as $acc).wrapping_sub(<$t>::MIN as $acc) as $uacc;
                (w.clamp(<$t>::MIN as $acc, <$t>::MAX as $acc) as $t, out)
            }

            /// `ldacc`: `acc = sat(a * 2^sh)`.
            #[inline(always)]
            pub fn load(a: $t, sh: u32) -> $acc {
                ((a as $w) << (sh & $smask)).clamp(<$acc>::MIN as $w, <$acc>::MAX as $w) as $acc
            }

            /// [`load`] for `sh` below the word's width: `A 2^sh` always
            /// fits the accumulator (at most 2^(2 bits - 2) in magnitude),
            /// so no clamp and no wider type.
            #[inline(always)]
            pub fn load_narrow(a: $t, sh: u32) -> $acc {
                (a as $acc) << sh
            }

            /// `acch`: the accumulator's upper word.
            #[inline(always)]
            pub fn high(acc: $acc) -> $t {
                (acc >> <$t>::BITS) as $t
            }

            /// `accl`: the accumulator's lower word.
            #[inline(always)]
            pub fn low(acc: $acc) -> $t {
                acc as $t
            }
        }
    };
}

/// 32-bit accumulator: `acc +- p` saturated to 32 bits. In 32-bit arithmetic: a 16x16 product
/// is at most 2^30 in magnitude, so `-p` fits, and an overflow's true sum
/// lies beyond the limit on `acc`'s side (same as the 64-bit sum clamped,
/// which the property tests check; without 64-bit lanes it vectorises
/// twice as wide).
#[inline(always)]
fn accumulate32(acc: i32, p: i32, sub: bool) -> (i32, bool) {
    let q = if sub { p.wrapping_neg() } else { p };
    let r = acc.wrapping_add(q);
    // Overflow: both addends of one sign, the sum of the other.
    let o = ((acc ^ r) & (q ^ r)) < 0;
    ((if o { (acc >> 31) ^ i32::MAX } else { r }), o)
}

/// 64-bit accumulator: a wrapping sum and its overflow flag (i128 sums do
/// not vectorise). A product of two 32-bit words is at most 2^62 in
/// magnitude, so `-p` never overflows, and an overflowing sum saturates
/// towards the sign of `acc`.
#[inline(always)]
fn accumulate64(acc: i64, p: i64, sub: bool) -> (i64, bool) {
    let (r, o) = if sub {
        acc.overflowing_sub(p)
    } else {
        acc.overflowing_add(p)
    };
    if o {
        (if acc < 0 { i64::MIN } else { i64::MAX }, true)
    } else {
        (r, false)
    }
}

multiplier_unit!(
    w16,
    i16,
    i32,
    u32,
    i64,
    31,
    accumulate32,
    "16x16 multiplier, 32-bit accumulator."
);
multiplier_unit!(
    w32,
    i32,
    i64,
    u64,
    i128,
    63,
    accumulate64,
    "32x32 multiplier, 64-bit accumulator."
);

pub use w16::*;
