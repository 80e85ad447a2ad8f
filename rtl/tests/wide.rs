//! What only the 32-bit datapath variant (`RcArray<64, i32>`) has: the
//! 32x32 multiplier into a 64-bit accumulator against i128 arithmetic and
//! the `fixed` crate (I16F16, I8F24, I1F31 and I0F32 products; exact
//! products in I64F64), 32-bit RAM words, and the decoder's wide shifts.
//! The ALU and the shifter run generic over the word in `alu.rs` and
//! `shifter.rs`, on both datapaths.

// Lanes are compared index by index across several arrays.
#![allow(clippy::needless_range_loop)]

use fixed::types::{I0F32, I16F16, I1F31, I64F64, I8F24};
use proptest::prelude::*;
use rtl::rc::context::{BSrc, Context, Guard, Op};

mod common;
use common::*;

type Rc = RcW<i32>;

fn rc() -> Box<Rc> {
    rc_w::<i32>()
}

fn lanes() -> impl Strategy<Value = [i32; L]> {
    lanes_w::<i32>()
}

fn exec(rc: &mut Rc, ctx: Context) -> Result<(), rtl::Fault> {
    exec_w(rc, ctx)
}

fn load(rc: &mut Rc, r: u8, v: &[i32; L]) {
    load_w(rc, r, v)
}

fn reg(rc: &Rc, r: u8) -> [i32; L] {
    reg_w(rc, r)
}

fn clamp64(x: i128) -> i128 {
    x.clamp(i64::MIN as i128, i64::MAX as i128)
}

/// i128 reference of the 32-bit multiplier result.
fn scale_ref(acc: i128, sh: u32, trunc: bool) -> i128 {
    let add = if trunc || sh == 0 {
        0
    } else {
        1i128 << (sh - 1)
    };
    clamp_w::<i32>((acc + add).div_euclid(1i128 << sh))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Every multiplier shift 0..=63 (bit 5 in f[10]), both rounding modes.
    #[test]
    fn product_at_every_shift(a in lanes(), b in lanes(), sh in 0u8..64, trunc in any::<bool>()) {
        let mut rc = rc();
        load(&mut rc, 1, &a);
        load(&mut rc, 2, &b);
        exec(&mut rc, mulctx(Op::Mul, 3, 1, 2, sh, trunc)).unwrap();
        for i in 0..L {
            let p = a[i] as i128 * b[i] as i128;
            prop_assert_eq!(rc.acc[i] as i128, p);
            let want = scale_ref(p, sh as u32, trunc);
            prop_assert_eq!(reg(&rc, 3)[i] as i128, want);
            let unsat = (p + if trunc || sh == 0 { 0 } else { 1 << (sh - 1) }).div_euclid(1 << sh);
            prop_assert_eq!(bit(rc.flags.v, i), unsat != want);
        }
    }

    /// Multiply-accumulate sequences against an i128 sum saturated at the
    /// 64-bit bounds after each step; then `acc`, `acch`, `accl`.
    #[test]
    fn mac_sequences(terms in proptest::collection::vec((lanes(), lanes(), any::<bool>()), 1..10),
                     sh in 0u8..64) {
        let mut rc = rc();
        let mut acc = [0i128; L];
        for (k, (a, b, sub)) in terms.iter().enumerate() {
            load(&mut rc, 1, a);
            load(&mut rc, 2, b);
            let op = if k == 0 { Op::Mul } else if *sub { Op::Msu } else { Op::Mac };
            exec(&mut rc, mulctx(op, 5, 1, 2, sh, false)).unwrap();
            for i in 0..L {
                let p = a[i] as i128 * b[i] as i128;
                acc[i] = match op {
                    Op::Mul => p,
                    Op::Mac => clamp64(acc[i] + p),
                    _ => clamp64(acc[i] - p),
                };
                prop_assert_eq!(rc.acc[i] as i128, acc[i], "step {} lane {}", k, i);
                prop_assert_eq!(reg(&rc, 5)[i] as i128, scale_ref(acc[i], sh as u32, false));
            }
        }
        exec(&mut rc, mulctx(Op::Acc, 6, 0, 0, sh, true)).unwrap();
        exec(&mut rc, Context::rrr(Op::Acch, 7, 0, 0)).unwrap();
        exec(&mut rc, Context::rrr(Op::Accl, 8, 0, 0)).unwrap();
        for i in 0..L {
            prop_assert_eq!(reg(&rc, 6)[i] as i128, scale_ref(acc[i], sh as u32, true));
            let bits = acc[i].rem_euclid(1 << 64);
            prop_assert_eq!(reg(&rc, 7)[i] as u32 as i128, bits >> 32);
            prop_assert_eq!(reg(&rc, 8)[i] as u32 as i128, bits & 0xFFFF_FFFF);
        }
    }

    /// `ldacc` loads A * 2^sh, saturated to 64 bits, for every shift.
    #[test]
    fn load_accumulator(a in lanes(), sh in 0u8..64) {
        let mut rc = rc();
        load(&mut rc, 1, &a);
        exec(&mut rc, mulctx(Op::Ldacc, 0, 1, 0, sh, false)).unwrap();
        for i in 0..L {
            prop_assert_eq!(rc.acc[i] as i128, clamp64(a[i] as i128 * (1i128 << sh)));
        }
    }
}

macro_rules! fixed_products {
    ($name:ident, $t:ty, $frac:expr) => {
        proptest! {
            #![proptest_config(ProptestConfig::with_cases(128))]
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
                    // Rounding: the exact product in I64F64 plus half an LSB,
                    // converted back (from_num rounds towards -inf).
                    let exact = I64F64::from_num(x) * I64F64::from_num(y);
                    let half = I64F64::from_bits(1i128 << (64 - $frac - 1));
                    prop_assert_eq!(reg(&rc, 4)[i], <$t>::saturating_from_num(exact + half).to_bits(),
                        "{} * {} rounded", x, y);
                }
            }
        }
    };
}

fixed_products!(q16_16_products, I16F16, 16);
fixed_products!(q8_24_products, I8F24, 24);
fixed_products!(q1_31_products, I1F31, 31);
fixed_products!(q0_32_products, I0F32, 32);

#[test]
fn q16_16_by_hand() {
    // 1.5 * -2.25 = -3.375 in Q16.16; 300 * 300 = 90000 saturates (max 32767.99).
    let mut rc = rc();
    load(&mut rc, 1, &[0x0001_8000; L]);
    load(&mut rc, 2, &[-0x0002_4000; L]);
    exec(&mut rc, mulctx(Op::Mul, 3, 1, 2, 16, false)).unwrap();
    assert_eq!(reg(&rc, 3)[0], -0x0003_6000);
    load(&mut rc, 1, &[300 << 16; L]);
    exec(&mut rc, mulctx(Op::Mul, 3, 1, 1, 16, false)).unwrap();
    assert_eq!(reg(&rc, 3)[0], i32::MAX);
    assert!(bit(rc.flags.v, 0));
    // Immediates are 11-bit signed, sign-extended to 32 bits.
    load(&mut rc, 1, &[100_000; L]);
    exec(&mut rc, Context::rri(Op::Add, 4, 1, -1024)).unwrap();
    assert_eq!(reg(&rc, 4)[0], 98_976);
}

#[test]
fn ram_holds_32_bit_words_and_faults_outside_0_to_511() {
    let mut rc = rc();
    let data: [i32; L] = std::array::from_fn(|i| i32::MIN + 7 + i as i32 * 0x0123_4567);
    let addr: [i32; L] = std::array::from_fn(|i| (i * 7 % 512) as i32);
    load(&mut rc, 1, &data);
    load(&mut rc, 2, &addr);
    exec(&mut rc, Context::rrr(Op::St, 0, 1, 2)).unwrap();
    // read back at addr - 3 + 3
    let base: [i32; L] = std::array::from_fn(|i| addr[i] - 3);
    load(&mut rc, 5, &base);
    let ld = Context {
        b: BSrc::Imm(3),
        ..Context::rrr(Op::Ld, 6, 5, 0)
    };
    exec(&mut rc, ld).unwrap();
    assert_eq!(reg(&rc, 6), data);
    // a uniform store to word 511, read by every lane
    exec(&mut rc, Context::rri(Op::Movb, 7, 0, 511)).unwrap();
    exec(&mut rc, Context::rrr(Op::St, 0, 1, 7)).unwrap();
    exec(&mut rc, Context::rri(Op::Ld, 8, 7, 0)).unwrap();
    assert_eq!(reg(&rc, 8), data);
    // 512, and an address sum that would wrap in 32 bits, fault
    exec(&mut rc, Context::rri(Op::Ld, 8, 7, 1)).unwrap_err();
    load(&mut rc, 9, &[i32::MAX; L]);
    load(&mut rc, 10, &[i32::MAX; L]);
    exec(&mut rc, Context::rrr(Op::Ld, 8, 9, 10)).unwrap_err();
    // a guarded store leaves the lanes where F = 0
    rc.flags.f = 0xFFFF_0000_FFFF_0000;
    let st = Context {
        guard: Guard::IfF,
        ..Context::rrr(Op::St, 0, 2, 7)
    };
    exec(&mut rc, st).unwrap();
    exec(&mut rc, Context::rri(Op::Ld, 8, 7, 0)).unwrap();
    for i in 0..L {
        assert_eq!(
            reg(&rc, 8)[i],
            if bit(rc.flags.f, i) { addr[i] } else { data[i] }
        );
    }
}

#[test]
fn the_16_bit_decoder_refuses_wide_shifts() {
    let c = mulctx(Op::Mul, 3, 1, 2, 40, false);
    assert!(Context::decode(c.encode()).is_err());
    assert_eq!(Context::decode_wide(c.encode()), Ok(c));
}
