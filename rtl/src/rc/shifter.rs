//! The RC's barrel shifter. The amount is operand B's low five bits, so
//! 0 to 31; shifts by 16 or more give 0 (logical) or the sign fill
//! (arithmetic right), as a 16-bit barrel shifter with a wide amount decode.

/// Amount field of operand B.
#[inline(always)]
pub fn amount(b: i16) -> u32 {
    (b as u16 & 31) as u32
}

/// Logical left shift.
#[inline(always)]
pub fn sll(a: i16, n: u32) -> i16 {
    if n >= 16 {
        0
    } else {
        ((a as u16) << n) as i16
    }
}

/// Logical right shift (zero fill).
#[inline(always)]
pub fn srl(a: i16, n: u32) -> i16 {
    if n >= 16 {
        0
    } else {
        ((a as u16) >> n) as i16
    }
}

/// Arithmetic right shift (sign fill): floor division by 2^n.
#[inline(always)]
pub fn sra(a: i16, n: u32) -> i16 {
    a >> n.min(15)
}

/// Arithmetic left shift, saturating: multiplies by 2^n and clamps to the
/// 16-bit range; the flag is `true` when it clamped.
#[inline(always)]
pub fn asl(a: i16, n: u32) -> (i16, bool) {
    if a == 0 {
        return (0, false);
    }
    let wide = (a as i64) << n.min(20);
    if wide > i16::MAX as i64 {
        (i16::MAX, true)
    } else if wide < i16::MIN as i64 {
        (i16::MIN, true)
    } else {
        (wide as i16, false)
    }
}
