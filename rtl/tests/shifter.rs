//! The barrel shifter for every amount, against i64 arithmetic and the
//! `fixed` crate's shifts.

mod common;
use common::*;
use fixed::types::{I4F12, I8F8};
use proptest::prelude::*;
use rtl::rc::context::Op;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn every_amount(a in lanes()) {
        let mut rc = rc();
        for n in 0..=31i16 {
            let amt = [n; L];
            let sll = binop(&mut rc, Op::Sll, &a, &amt);
            let srl = binop(&mut rc, Op::Srl, &a, &amt);
            let sra = binop(&mut rc, Op::Sra, &a, &amt);
            let asl = binop(&mut rc, Op::Asl, &a, &amt);
            for i in 0..L {
                let x = a[i] as i64;
                let u = x.rem_euclid(1 << 16);
                let n = n as i64;
                // Logical: the 16-bit pattern shifted in a 64-bit register.
                let want_sll = if n >= 16 { 0 } else { (u << n) & 0xFFFF };
                let want_srl = if n >= 16 { 0 } else { u >> n };
                prop_assert_eq!(sll[i] as u16 as i64, want_sll, "sll {} by {}", x, n);
                prop_assert_eq!(srl[i] as u16 as i64, want_srl, "srl {} by {}", x, n);
                // Arithmetic right: floor division by 2^n.
                prop_assert_eq!(sra[i] as i64, x.div_euclid(1i64 << n), "sra {} by {}", x, n);
                // Arithmetic left: the exact product, saturated.
                let exact = x * (1i64 << n);
                prop_assert_eq!(asl[i] as i64, clamp16(exact), "asl {} by {}", x, n);
                prop_assert_eq!(bit(rc.flags.v, i), clamp16(exact) != exact);
            }
        }
    }

    /// Only the low five bits of B are the amount.
    #[test]
    fn amount_is_b_mod_32(a in lanes(), b in lanes()) {
        let mut rc = rc();
        let r = binop(&mut rc, Op::Sra, &a, &b);
        for i in 0..L {
            let n = (b[i] as u16 & 31) as i64;
            prop_assert_eq!(r[i] as i64, (a[i] as i64).div_euclid(1i64 << n));
        }
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
