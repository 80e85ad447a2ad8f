//! The RC's arithmetic-logic unit: 16-bit two's complement ([`w16`], the
//! paper's chip) or 32-bit ([`w32`], the wide variant); one source for both.
//!
//! These scalar functions are the definition of every ALU operation; the
//! lane-wise datapath in [`super::RcArray`] calls them once per active lane.
//! Flag conventions (see `docs/isa.md`):
//!
//! * carry `C`: carry out of the top bit (15 or 31) for additions; **borrow** for
//!   subtractions (`C = 1` when the unsigned subtrahend exceeds the minuend),
//!   so `SUB` then `SBC` subtracts double-width values.
//! * overflow `V`: signed overflow of the wrapped result; for the saturating
//!   operations, `V = 1` when the result saturated.

use super::context::Cond;

/// A result with its carry/borrow and overflow flags.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Flagged<T = i16> {
    pub value: T,
    pub c: bool,
    pub v: bool,
}

/// One source for both datapath widths: `$t` the word, `$u` its unsigned
/// pattern, `$uw` / `$sw` unsigned / signed types twice as wide.
macro_rules! alu_unit {
    ($m:ident, $t:ty, $u:ty, $uw:ty, $sw:ty, $doc:literal) => {
        #[doc = $doc]
        pub mod $m {
            use super::{Cond, Flagged};

            // Every operation below stays in the word's width (the flags
            // from the top bits): a loop over 16-bit lanes then runs 32
            // lanes to a 512-bit register and stores its results whole,
            // where widening to 32 bits halved both (and a result stored in
            // halves and loaded whole at the clock edge is not forwarded).
            // The property tests compare every one with wide arithmetic.

            /// `a + b + cin`; C the carry out of the top bit, V signed
            /// overflow.
            #[inline(always)]
            pub fn add(a: $t, b: $t, cin: bool) -> Flagged<$t> {
                let value = a.wrapping_add(b).wrapping_add(cin as $t);
                // Carry out of the top bit: both operand bits set, or one
                // set and no sum bit (a carry came in and went on).
                let c = ((a & b) | ((a | b) & !value)) < 0;
                // Signed overflow: operands of equal sign, result of the other sign.
                let v = ((a ^ value) & (b ^ value)) < 0;
                Flagged { value, c, v }
            }

            /// `a - b - bin`; C the borrow (the unsigned `b + bin` exceeds
            /// `a`), V signed overflow.
            #[inline(always)]
            pub fn sub(a: $t, b: $t, bin: bool) -> Flagged<$t> {
                let value = a.wrapping_sub(b).wrapping_sub(bin as $t);
                // Borrow out of the top bit: 0 - 1 there, or equal bits and
                // a borrow in (the difference bit set).
                let c = ((!a & b) | (!(a ^ b) & value)) < 0;
                let v = ((a ^ b) & (a ^ value)) < 0;
                Flagged { value, c, v }
            }

            /// Saturating addition; the flag is `true` when the result saturated.
            #[inline(always)]
            pub fn adds(a: $t, b: $t) -> ($t, bool) {
                let w = a.wrapping_add(b);
                (a.saturating_add(b), ((a ^ w) & (b ^ w)) < 0)
            }

            #[inline(always)]
            pub fn subs(a: $t, b: $t) -> ($t, bool) {
                let w = a.wrapping_sub(b);
                (a.saturating_sub(b), ((a ^ b) & (a ^ w)) < 0)
            }

            /// `|a|`, saturating: `|MIN| = MAX` with the flag set.
            #[inline(always)]
            pub fn abs(a: $t) -> ($t, bool) {
                (a.saturating_abs(), a == <$t>::MIN)
            }

            /// `|a - b|`, saturating: the larger minus the smaller is the
            /// exact distance as an unsigned word.
            #[inline(always)]
            pub fn absd(a: $t, b: $t) -> ($t, bool) {
                let d = (a.max(b) as $u).wrapping_sub(a.min(b) as $u);
                let max = <$t>::MAX as $u;
                (d.min(max) as $t, d > max)
            }

            #[inline(always)]
            pub fn min(a: $t, b: $t) -> $t {
                a.min(b)
            }

            #[inline(always)]
            pub fn max(a: $t, b: $t) -> $t {
                a.max(b)
            }

            /// Leading zeros of the word's bit pattern (the width for zero).
            #[inline(always)]
            pub fn clz(a: $t) -> $t {
                (a as $u).leading_zeros() as $t
            }

            /// Condition evaluation of `CMP` (`c`, `v` are the RC's current flags).
            #[inline(always)]
            pub fn cond(c: Cond, a: $t, b: $t, cf: bool, vf: bool) -> bool {
                let (ua, ub) = (a as $u, b as $u);
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
        }
    };
}

alu_unit!(
    w16,
    i16,
    u16,
    u32,
    i32,
    "The 16-bit ALU (the paper's chip)."
);
alu_unit!(
    w32,
    i32,
    u32,
    u64,
    i64,
    "The 32-bit ALU (the wide datapath variant)."
);

pub use w16::*;
