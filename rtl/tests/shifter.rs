//! The barrel shifter for every amount on both datapaths, against i128
//! arithmetic, and the `fixed` crate's shifts on the 16-bit RC.

mod common;
use common::*;
use fixed::types::{I4F12, I8F8};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use rtl::rc::context::Op;

/// Every amount 0 to twice the word's width less one: logical shifts by
/// the width or more give 0, `sra` the sign fill (floor division by 2^n),
/// `asl` the exact product saturated.
fn every_amount<W: TestWord>(a: &[W; L]) -> Result<(), TestCaseError> {
    let mut rc = rc_w::<W>();
    let bits = W::BITS as i128;
    for n in 0..2 * bits {
        let amt = [W::of(n); L];
        let sll = binop_w(&mut rc, Op::Sll, a, &amt);
        let srl = binop_w(&mut rc, Op::Srl, a, &amt);
        let sra = binop_w(&mut rc, Op::Sra, a, &amt);
        let asl = binop_w(&mut rc, Op::Asl, a, &amt);
        for i in 0..L {
            let x = a[i].get();
            let u = unsigned_w::<W>(x);
            let mask = (1i128 << bits) - 1;
            let want_sll = if n >= bits { 0 } else { (u << n) & mask };
            let want_srl = if n >= bits { 0 } else { u >> n };
            prop_assert_eq!(
                unsigned_w::<W>(sll[i].get()),
                want_sll,
                "sll {} by {}",
                x,
                n
            );
            prop_assert_eq!(
                unsigned_w::<W>(srl[i].get()),
                want_srl,
                "srl {} by {}",
                x,
                n
            );
            prop_assert_eq!(sra[i].get(), x.div_euclid(1i128 << n), "sra {} by {}", x, n);
            let exact = x * (1i128 << n);
            prop_assert_eq!(asl[i].get(), clamp_w::<W>(exact), "asl {} by {}", x, n);
            prop_assert_eq!(bit(rc.flags.v, i), clamp_w::<W>(exact) != exact);
        }
    }
    Ok(())
}

/// Only the low bits of B are the amount: five on the 16-bit RC, six on
/// the 32-bit one.
fn amount_is_b_mod_twice_the_width<W: TestWord>(
    a: &[W; L],
    b: &[W; L],
) -> Result<(), TestCaseError> {
    let mut rc = rc_w::<W>();
    let r = binop_w(&mut rc, Op::Sra, a, b);
    for i in 0..L {
        let n = unsigned_w::<W>(b[i].get()) & (2 * W::BITS as i128 - 1);
        prop_assert_eq!(r[i].get(), a[i].get().div_euclid(1i128 << n));
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn every_amount_16(a in lanes_w::<i16>()) { every_amount(&a)?; }

    #[test]
    fn every_amount_32(a in lanes_w::<i32>()) { every_amount(&a)?; }

    #[test]
    fn amount_is_b_mod_32_on_16_bits(a in lanes_w::<i16>(), b in lanes_w::<i16>()) {
        amount_is_b_mod_twice_the_width(&a, &b)?;
    }

    #[test]
    fn amount_is_b_mod_64_on_32_bits(a in lanes_w::<i32>(), b in lanes_w::<i32>()) {
        amount_is_b_mod_twice_the_width(&a, &b)?;
    }

    /// As fixed-point operations: `sra` is the `fixed` crate's `>>` and `asl`
    /// its saturating multiplication by a power of two.
    #[test]
    fn fixed_point_scaling(a in lanes(), n in 0u32..=14) {
        let mut rc = rc();
        let sra = binop(&mut rc, Op::Sra, &a, &[n as i16; L]);
        let asl = binop(&mut rc, Op::Asl, &a, &[n as i16; L]);
        for i in 0..L {
            let q = I8F8::from_bits(a[i]);
            prop_assert_eq!(sra[i], (q >> n).to_bits());
            prop_assert_eq!(asl[i], q.saturating_mul_int(1 << n).to_bits());
            let q = I4F12::from_bits(a[i]);
            prop_assert_eq!(asl[i], q.saturating_mul_int(1 << n).to_bits());
        }
    }
}
