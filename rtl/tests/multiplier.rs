//! The multiplier and accumulator against the `fixed` crate (Qm.n products,
//! truncation, rounding, saturation) and i64 arithmetic (accumulation and
//! every shift amount).

mod common;
use common::*;
use fixed::types::{I0F16, I1F15, I32F32, I4F12, I8F8};
use proptest::prelude::*;
use rtl::rc::context::{Context, Op};

/// i64 reference of the 16-bit result: shift right by `sh` with round half
/// up (or floor), then saturate.
fn scale_ref(acc: i64, sh: u32, trunc: bool) -> i64 {
    let add = if trunc || sh == 0 {
        0
    } else {
        1i64 << (sh - 1)
    };
    clamp16((acc + add).div_euclid(1i64 << sh))
}

macro_rules! fixed_products {
    ($name:ident, $t:ty, $frac:expr) => {
        proptest! {
            #![proptest_config(ProptestConfig::with_cases(256))]
            #[test]
            fn $name(a in lanes(), b in lanes()) {
                let mut rc = rc();
                load(&mut rc, 1, &a);
                load(&mut rc, 2, &b);
                exec(&mut rc, mulctx(Op::Mul, 3, 1, 2, $frac, true)).unwrap();
                exec(&mut rc, mulctx(Op::Mul, 4, 1, 2, $frac, false)).unwrap();
                for i in 0..L {
                    let (x, y) = (<$t>::from_bits(a[i]), <$t>::from_bits(b[i]));
                    // Truncating: exactly the fixed crate's saturating multiply.
                    prop_assert_eq!(reg(&rc, 3)[i], x.saturating_mul(y).to_bits(),
                        "{} * {} truncated", x, y);
                    // Rounding: the exact product in I32F32, plus half an LSB,
                    // converted back (from_num rounds towards -inf).
                    let exact = I32F32::from_num(x) * I32F32::from_num(y);
                    let half = I32F32::from_bits(1i64 << (32 - $frac - 1));
                    prop_assert_eq!(reg(&rc, 4)[i], <$t>::saturating_from_num(exact + half).to_bits(),
                        "{} * {} rounded", x, y);
                }
            }
        }
    };
}

fixed_products!(q8_8_products, I8F8, 8);
fixed_products!(q4_12_products, I4F12, 12);
fixed_products!(q1_15_products, I1F15, 15);
fixed_products!(q0_16_products, I0F16, 16);

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Every shift amount of the full product, both rounding modes.
    #[test]
    fn product_at_every_shift(a in lanes(), b in lanes(), sh in 0u8..32, trunc in any::<bool>()) {
        let mut rc = rc();
        load(&mut rc, 1, &a);
        load(&mut rc, 2, &b);
        exec(&mut rc, mulctx(Op::Mul, 3, 1, 2, sh, trunc)).unwrap();
        for i in 0..L {
            let p = a[i] as i64 * b[i] as i64;
            prop_assert_eq!(rc.acc[i] as i64, p);
            let want = scale_ref(p, sh as u32, trunc);
            prop_assert_eq!(reg(&rc, 3)[i] as i64, want);
            let unsat = (p + if trunc || sh == 0 { 0 } else { 1 << (sh - 1) }).div_euclid(1 << sh);
            prop_assert_eq!(bit(rc.flags.v, i), unsat != want);
        }
    }

    /// Multiply-accumulate sequences against an i64 sum saturated at the
    /// 32-bit bounds after each step.
    #[test]
    fn mac_sequences(terms in proptest::collection::vec((lanes(), lanes(), any::<bool>()), 1..12),
                     sh in 0u8..32) {
        let mut rc = rc();
        let mut acc = [0i64; L];
        for (k, (a, b, sub)) in terms.iter().enumerate() {
            load(&mut rc, 1, a);
            load(&mut rc, 2, b);
            let op = if k == 0 { Op::Mul } else if *sub { Op::Msu } else { Op::Mac };
            exec(&mut rc, mulctx(op, 5, 1, 2, sh, false)).unwrap();
            for i in 0..L {
                let p = a[i] as i64 * b[i] as i64;
                acc[i] = match op {
                    Op::Mul => p,
                    Op::Mac => (acc[i] + p).clamp(i32::MIN as i64, i32::MAX as i64),
                    _ => (acc[i] - p).clamp(i32::MIN as i64, i32::MAX as i64),
                };
                prop_assert_eq!(rc.acc[i] as i64, acc[i], "step {} lane {}", k, i);
                prop_assert_eq!(reg(&rc, 5)[i] as i64, scale_ref(acc[i], sh as u32, false));
            }
        }
        // Reading the accumulator back: acc, acch, accl.
        exec(&mut rc, mulctx(Op::Acc, 6, 0, 0, sh, true)).unwrap();
        exec(&mut rc, Context::rrr(Op::Acch, 7, 0, 0)).unwrap();
        exec(&mut rc, Context::rrr(Op::Accl, 8, 0, 0)).unwrap();
        for i in 0..L {
            prop_assert_eq!(reg(&rc, 6)[i] as i64, scale_ref(acc[i], sh as u32, true));
            let bits = acc[i].rem_euclid(1 << 32);
            prop_assert_eq!(reg(&rc, 7)[i] as u16 as i64, bits >> 16);
            prop_assert_eq!(reg(&rc, 8)[i] as u16 as i64, bits & 0xFFFF);
        }
    }

    /// `ldacc` loads A * 2^sh, saturated to 32 bits.
    #[test]
    fn load_accumulator(a in lanes(), sh in 0u8..32) {
        let mut rc = rc();
        load(&mut rc, 1, &a);
        exec(&mut rc, mulctx(Op::Ldacc, 0, 1, 0, sh, false)).unwrap();
        for i in 0..L {
            let want = (a[i] as i64 * (1i64 << sh)).clamp(i32::MIN as i64, i32::MAX as i64);
            prop_assert_eq!(rc.acc[i] as i64, want);
        }
    }
}

#[test]
fn q8_8_by_hand() {
    // 1.5 * -2.25 = -3.375, exact in Q8.8 (0x0180 * -0x0240 = -0x0360).
    let mut rc = rc();
    load(&mut rc, 1, &[0x0180; L]);
    load(&mut rc, 2, &[-0x0240; L]);
    exec(&mut rc, mulctx(Op::Mul, 3, 1, 2, 8, false)).unwrap();
    assert_eq!(reg(&rc, 3)[0], -0x0360);
    // 100 * 100 = 10000 does not fit Q8.8 (max 127.996): saturates, V set.
    load(&mut rc, 1, &[100 << 8; L]);
    exec(&mut rc, mulctx(Op::Mul, 3, 1, 1, 8, false)).unwrap();
    assert_eq!(reg(&rc, 3)[0], i16::MAX);
    assert!(bit(rc.flags.v, 0));
    // Rounding: 0x0001 * 0x0080 = 0x80 >> 8 = 0.5 LSB: rounds up, truncates to 0.
    load(&mut rc, 1, &[1; L]);
    load(&mut rc, 2, &[0x80; L]);
    exec(&mut rc, mulctx(Op::Mul, 3, 1, 2, 8, false)).unwrap();
    exec(&mut rc, mulctx(Op::Mul, 4, 1, 2, 8, true)).unwrap();
    assert_eq!((reg(&rc, 3)[0], reg(&rc, 4)[0]), (1, 0));
}
