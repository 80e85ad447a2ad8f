//! The RC's arithmetic-logic unit: 16-bit two's complement.
//!
//! These scalar functions are the definition of every ALU operation; the
//! lane-wise datapath in [`super::RcArray`] calls them once per active lane.
//! Flag conventions (see `docs/isa.md`):
//!
//! * carry `C`: carry out of bit 15 for additions; **borrow** for
//!   subtractions (`C = 1` when the unsigned subtrahend exceeds the minuend),
//!   so `SUB` then `SBC` subtracts 32-bit values.
//! * overflow `V`: signed overflow of the wrapped result; for the saturating
//!   operations, `V = 1` when the result saturated.

use super::context::Cond;

/// A result with its carry/borrow and overflow flags.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Flagged {
    pub value: i16,
    pub c: bool,
    pub v: bool,
}

#[inline(always)]
pub fn add(a: i16, b: i16, cin: bool) -> Flagged {
    let s = a as u16 as u32 + b as u16 as u32 + cin as u32;
    let value = s as u16 as i16;
    // Signed overflow: operands of equal sign, result of the other sign.
    let v = ((a ^ value) & (b ^ value)) < 0;
    Flagged {
        value,
        c: s > 0xFFFF,
        v,
    }
}

#[inline(always)]
pub fn sub(a: i16, b: i16, bin: bool) -> Flagged {
    let value = (a as u16).wrapping_sub(b as u16).wrapping_sub(bin as u16) as i16;
    let borrow = (a as u16 as u32) < (b as u16 as u32 + bin as u32);
    let v = ((a ^ b) & (a ^ value)) < 0;
    Flagged {
        value,
        c: borrow,
        v,
    }
}

#[inline(always)]
fn sat(x: i32) -> (i16, bool) {
    if x > i16::MAX as i32 {
        (i16::MAX, true)
    } else if x < i16::MIN as i32 {
        (i16::MIN, true)
    } else {
        (x as i16, false)
    }
}

/// Saturating addition; the flag is `true` when the result saturated.
#[inline(always)]
pub fn adds(a: i16, b: i16) -> (i16, bool) {
    sat(a as i32 + b as i32)
}

#[inline(always)]
pub fn subs(a: i16, b: i16) -> (i16, bool) {
    sat(a as i32 - b as i32)
}

/// `|a|`, saturating: `|-32768| = 32767` with the flag set.
#[inline(always)]
pub fn abs(a: i16) -> (i16, bool) {
    sat((a as i32).abs())
}

/// `|a - b|`, saturating.
#[inline(always)]
pub fn absd(a: i16, b: i16) -> (i16, bool) {
    sat((a as i32 - b as i32).abs())
}

#[inline(always)]
pub fn min(a: i16, b: i16) -> i16 {
    a.min(b)
}

#[inline(always)]
pub fn max(a: i16, b: i16) -> i16 {
    a.max(b)
}

/// Leading zeros of the 16-bit pattern (16 for zero).
#[inline(always)]
pub fn clz(a: i16) -> i16 {
    (a as u16).leading_zeros() as i16
}

/// Condition evaluation of `CMP` (`c`, `v` are the RC's current flags).
#[inline(always)]
pub fn cond(c: Cond, a: i16, b: i16, cf: bool, vf: bool) -> bool {
    let (ua, ub) = (a as u16, b as u16);
    match c {
        Cond::Eq => a == b,
        Cond::Ne => a != b,
        Cond::Lt => a < b,
        Cond::Ge => a >= b,
        Cond::Le => a <= b,
        Cond::Gt => a > b,
        Cond::Ltu => ua < ub,
        Cond::Geu => ua >= ub,
        Cond::Leu => ua <= ub,
        Cond::Gtu => ua > ub,
        Cond::Cs => cf,
        Cond::Vs => vf,
        Cond::True => true,
        Cond::False => false,
        Cond::Bit => a & b != 0,
        Cond::Nbit => a & b == 0,
    }
}
