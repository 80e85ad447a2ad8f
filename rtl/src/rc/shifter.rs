//! The RC's barrel shifter, 16-bit ([`w16`]) or 32-bit ([`w32`]).
//!
//! 16-bit: the amount is operand B's low five bits, so 0 to 31; shifts by
//! 16 or more give 0 (logical) or the sign fill (arithmetic right), as a
//! 16-bit barrel shifter with a wide amount decode. 32-bit: the low six
//! bits, 0 to 63, and shifts by 32 or more give 0 or the sign fill.

macro_rules! shifter_unit {
    ($m:ident, $t:ty, $u:ty, $sw:ty, $amask:expr, $doc:literal) => {
        #[doc = $doc]
        pub mod $m {
            const BITS: u32 = <$t>::BITS;

            /// Amount field of operand B.
            #[inline(always)]
            pub fn amount(b: $t) -> u32 {
                (b as $u & $amask) as u32
            }

            /// Logical left shift.
            #[inline(always)]
            pub fn sll(a: $t, n: u32) -> $t {
                if n >= BITS {
                    0
                } else {
                    ((a as $u) << n) as $t
                }
            }

            /// Logical right shift (zero fill).
            #[inline(always)]
            pub fn srl(a: $t, n: u32) -> $t {
                if n >= BITS {
                    0
                } else {
                    ((a as $u) >> n) as $t
                }
            }

            /// Arithmetic right shift (sign fill): floor division by 2^n.
            #[inline(always)]
            pub fn sra(a: $t, n: u32) -> $t {
                a >> n.min(BITS - 1)
            }

            /// Arithmetic left shift, saturating: multiplies by 2^n and clamps
            /// to the word's range; the flag is `true` when it clamped.
            #[inline(always)]
            pub fn asl(a: $t, n: u32) -> ($t, bool) {
                if a == 0 {
                    return (0, false);
                }
                let wide = (a as $sw) << n.min(BITS + 4);
                if wide > <$t>::MAX as $sw {
                    (<$t>::MAX, true)
                } else if wide < <$t>::MIN as $sw {
                    (<$t>::MIN, true)
                } else {
                    (wide as $t, false)
                }
            }
        }
    };
}

shifter_unit!(w16, i16, u16, i64, 31, "The 16-bit shifter.");
shifter_unit!(w32, i32, u32, i128, 63, "The 32-bit shifter.");

pub use w16::*;
