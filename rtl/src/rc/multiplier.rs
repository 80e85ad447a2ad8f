//! The RC's 16x16 multiplier with a 32-bit accumulator.
//!
//! * `MUL`: `acc = a * b` (the full 32-bit product; `(-32768)^2` fits).
//! * `MAC` / `MSU`: `acc = acc ± a * b`, saturating at the 32-bit bounds.
//! * Every multiplier operation also yields a 16-bit result
//!   `sat16(acc >> sh)`, rounded to nearest (ties towards +inf: `+2^(sh-1)`
//!   before the arithmetic shift) or truncated towards -inf, so with `sh = n`
//!   two Qm.n operands give a Qm.n result in 16 bits.
//!
//! `V` is set when the accumulator or the 16-bit result saturated.

/// The full product of two 16-bit values.
#[inline(always)]
pub fn product(a: i16, b: i16) -> i32 {
    a as i32 * b as i32
}

/// `acc + p` (or `acc - p` when `sub`), saturating at the 32-bit bounds.
#[inline(always)]
pub fn accumulate(acc: i32, p: i32, sub: bool) -> (i32, bool) {
    // In 64 bits the exact sum cannot overflow; clamp it (vectorises).
    let p = if sub { -(p as i64) } else { p as i64 };
    let w = acc as i64 + p;
    let r = w.clamp(i32::MIN as i64, i32::MAX as i64);
    (r as i32, r != w)
}

/// Scale the accumulator to 16 bits: shift right by `sh` (0..=31), rounding
/// to nearest unless `trunc`, then saturate.
///
/// Rounding adds `2^(sh-1)` before the shift; in 32 bits without overflow
/// that is `floor(acc / 2^sh)` plus bit `sh-1` of `acc`.
#[inline(always)]
pub fn scale(acc: i32, sh: u32, trunc: bool) -> (i16, bool) {
    let sh = sh & 31;
    let mut w = acc >> sh;
    if !trunc && sh > 0 {
        w += (acc >> (sh - 1)) & 1;
    }
    let r = w.clamp(i16::MIN as i32, i16::MAX as i32);
    (r as i16, r != w)
}
