//! The 32-bit datapath variant (`RcArray<64, i32>`), unit by unit, against
//! independent references: i128 integer arithmetic and the `fixed` crate
//! (I16F16, I8F24, I1F31 and I0F32 products; exact products in I64F64).

// Lanes are compared index by index across several arrays.
#![allow(clippy::needless_range_loop)]

use fixed::types::{I0F32, I16F16, I1F31, I64F64, I8F24};
use proptest::prelude::*;
use rtl::kernel::Clocked;
use rtl::rc::context::{BSrc, Cond, Context, Guard, Op, ALL_CONDS};
use rtl::rc::{LaneNames, RcArray};

const L: usize = 64;
type Rc = RcArray<L, i32>;

fn rc() -> Box<Rc> {
    Box::new(RcArray::new(LaneNames::Grid))
}

fn val() -> impl Strategy<Value = i32> {
    prop_oneof![
        1 => Just(i32::MIN),
        1 => Just(-1i32),
        1 => Just(0i32),
        1 => Just(1i32),
        1 => Just(i32::MAX),
        1 => -70000i32..70000,
        6 => any::<i32>(),
    ]
}

fn lanes() -> impl Strategy<Value = [i32; L]> {
    proptest::collection::vec(val(), L).prop_map(|v| v.try_into().unwrap())
}

/// Execute one context through the encoder, the 32-bit decoder, eval and commit.
fn exec(rc: &mut Rc, ctx: Context) -> Result<(), rtl::Fault> {
    let w = ctx.encode();
    let d = Context::decode_wide(w).expect("encoded context decodes");
    assert_eq!(d, ctx);
    rc.set_context(w, d);
    rc.eval()?;
    rc.commit();
    Ok(())
}

fn load(rc: &mut Rc, r: u8, v: &[i32; L]) {
    for (i, x) in v.iter().enumerate() {
        rc.regs.poke(i, r, *x);
    }
}

fn reg(rc: &Rc, r: u8) -> [i32; L] {
    *rc.regs.read(r)
}

fn binop(rc: &mut Rc, op: Op, a: &[i32; L], b: &[i32; L]) -> [i32; L] {
    load(rc, 1, a);
    load(rc, 2, b);
    exec(rc, Context::rrr(op, 3, 1, 2)).unwrap();
    reg(rc, 3)
}

fn mulctx(op: Op, rd: u8, ra: u8, rb: u8, sh: u8, trunc: bool) -> Context {
    Context {
        shift: sh,
        trunc,
        b: BSrc::Reg(rb),
        ..Context::rrr(op, rd, ra, rb)
    }
}

fn bit(m: u64, i: usize) -> bool {
    m >> i & 1 != 0
}

fn clamp32(x: i128) -> i128 {
    x.clamp(i32::MIN as i128, i32::MAX as i128)
}

fn clamp64(x: i128) -> i128 {
    x.clamp(i64::MIN as i128, i64::MAX as i128)
}

fn wrap32(x: i128) -> i32 {
    x.rem_euclid(1 << 32) as u32 as i32
}

/// i128 reference of the 32-bit multiplier result.
fn scale_ref(acc: i128, sh: u32, trunc: bool) -> i128 {
    let add = if trunc || sh == 0 {
        0
    } else {
        1i128 << (sh - 1)
    };
    clamp32((acc + add).div_euclid(1i128 << sh))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn add_sub_with_carry_and_overflow(a in lanes(), b in lanes(), cin in any::<u64>()) {
        for (op, sub, use_c) in [(Op::Add, false, false), (Op::Adc, false, true),
                                 (Op::Sub, true, false), (Op::Sbc, true, true)] {
            let mut rc = rc();
            rc.flags.c = cin;
            let r = binop(&mut rc, op, &a, &b);
            for i in 0..L {
                let c = if use_c { bit(cin, i) as i128 } else { 0 };
                let (x, y) = (a[i] as i128, b[i] as i128);
                let (ux, uy) = (a[i] as u32 as i128, b[i] as u32 as i128);
                let exact = if sub { x - y - c } else { x + y + c };
                prop_assert_eq!(r[i], wrap32(exact), "{:?} lane {}", op, i);
                let carry = if sub { ux < uy + c } else { ux + uy + c > 0xFFFF_FFFF };
                prop_assert_eq!(bit(rc.flags.c, i), carry, "{:?} C lane {}", op, i);
                prop_assert_eq!(bit(rc.flags.v, i), clamp32(exact) != exact, "{:?} V", op);
            }
        }
    }

    /// 64-bit arithmetic from two 32-bit halves: add/adc and sub/sbc chains.
    #[test]
    fn multiword_add_and_sub(x in any::<i64>(), y in any::<i64>()) {
        let lo = |v: i64| [v as i32; L];
        let hi = |v: i64| [(v >> 32) as i32; L];
        for (op_lo, op_hi, expect) in [(Op::Add, Op::Adc, x.wrapping_add(y)),
                                       (Op::Sub, Op::Sbc, x.wrapping_sub(y))] {
            let mut rc = rc();
            let l = binop(&mut rc, op_lo, &lo(x), &lo(y));
            let h = binop(&mut rc, op_hi, &hi(x), &hi(y));
            let got = ((h[0] as u32 as u64) << 32 | l[0] as u32 as u64) as i64;
            prop_assert_eq!(got, expect);
            let wide = if op_lo == Op::Add { x as i128 + y as i128 } else { x as i128 - y as i128 };
            prop_assert_eq!(bit(rc.flags.v, 0), wide != expect as i128);
        }
    }

    #[test]
    fn rsb_neg_and_saturating_ops(a in lanes(), b in lanes()) {
        let mut rc = rc();
        let r = binop(&mut rc, Op::Rsb, &a, &b);
        for i in 0..L {
            prop_assert_eq!(r[i], wrap32(b[i] as i128 - a[i] as i128));
        }
        load(&mut rc, 1, &a);
        exec(&mut rc, Context::rrr(Op::Neg, 4, 1, 0)).unwrap();
        for i in 0..L {
            let exact = -(a[i] as i128);
            prop_assert_eq!(reg(&rc, 4)[i], wrap32(exact));
            prop_assert_eq!(bit(rc.flags.c, i), a[i] != 0);
        }
        type F = fn(i128, i128) -> i128;
        let cases: [(Op, F); 4] = [
            (Op::Adds, |x, y| x + y),
            (Op::Subs, |x, y| x - y),
            (Op::Abs, |x, _| x.abs()),
            (Op::Absd, |x, y| (x - y).abs()),
        ];
        for (op, f) in cases {
            let r = binop(&mut rc, op, &a, &b);
            for i in 0..L {
                let e = f(a[i] as i128, b[i] as i128);
                prop_assert_eq!(r[i] as i128, clamp32(e), "{:?}", op);
                prop_assert_eq!(bit(rc.flags.v, i), clamp32(e) != e);
                prop_assert!(!bit(rc.flags.c, i));
            }
        }
    }

    #[test]
    fn logic_min_max_clz_sel(a in lanes(), b in lanes(), f in any::<u64>()) {
        let mut rc = rc();
        for (op, want) in [(Op::And, 0), (Op::Or, 1), (Op::Xor, 2), (Op::Min, 3), (Op::Max, 4)] {
            let r = binop(&mut rc, op, &a, &b);
            for i in 0..L {
                let w = match want {
                    0 => a[i] & b[i],
                    1 => a[i] | b[i],
                    2 => a[i] ^ b[i],
                    3 => (a[i] as i128).min(b[i] as i128) as i32,
                    _ => (a[i] as i128).max(b[i] as i128) as i32,
                };
                prop_assert_eq!(r[i], w, "{:?}", op);
            }
        }
        let r = binop(&mut rc, Op::Clz, &a, &b);
        for i in 0..L {
            // leading zeros of the 32-bit pattern, by counting
            let u = a[i] as u32 as u64;
            let n = (0..32).take_while(|k| u >> (31 - k) & 1 == 0).count();
            prop_assert_eq!(r[i], n as i32);
        }
        rc.flags.f = f;
        let r = binop(&mut rc, Op::Sel, &a, &b);
        for i in 0..L {
            prop_assert_eq!(r[i], if bit(f, i) { a[i] } else { b[i] });
        }
    }

    #[test]
    fn every_compare(a in lanes(), b in lanes()) {
        let mut rc = rc();
        load(&mut rc, 1, &a);
        load(&mut rc, 2, &b);
        for &cond in ALL_CONDS.iter() {
            let c = Context { we: false, rd: cond as u8, ..Context::rrr(Op::Cmp, 0, 1, 2) };
            rc.flags.c = 0x5555_0000_FFFF_0F0F;
            rc.flags.v = 0x0F0F_F0F0_1234_5678;
            exec(&mut rc, c).unwrap();
            for i in 0..L {
                let (x, y) = (a[i] as i128, b[i] as i128);
                let (ux, uy) = (a[i] as u32, b[i] as u32);
                let want = match cond {
                    Cond::Eq => x == y, Cond::Ne => x != y, Cond::Lt => x < y,
                    Cond::Ge => x >= y, Cond::Le => x <= y, Cond::Gt => x > y,
                    Cond::Ltu => ux < uy, Cond::Geu => ux >= uy, Cond::Leu => ux <= uy,
                    Cond::Gtu => ux > uy, Cond::Cs => bit(0x5555_0000_FFFF_0F0F, i),
                    Cond::Vs => bit(0x0F0F_F0F0_1234_5678, i), Cond::True => true,
                    Cond::False => false, Cond::Bit => ux & uy != 0, Cond::Nbit => ux & uy == 0,
                };
                prop_assert_eq!(bit(rc.flags.f, i), want, "{:?} {} {}", cond, x, y);
            }
        }
    }

    /// Every amount 0..=63 against i128 arithmetic: logical shifts by 32
    /// or more give 0, `sra` the sign fill, `asl` the saturated product.
    #[test]
    fn every_shift_amount(a in lanes()) {
        let mut rc = rc();
        for n in 0..=63i32 {
            let amt = [n; L];
            let sll = binop(&mut rc, Op::Sll, &a, &amt);
            let srl = binop(&mut rc, Op::Srl, &a, &amt);
            let sra = binop(&mut rc, Op::Sra, &a, &amt);
            let asl = binop(&mut rc, Op::Asl, &a, &amt);
            for i in 0..L {
                let x = a[i] as i128;
                let u = x.rem_euclid(1 << 32);
                let want_sll = if n >= 32 { 0 } else { (u << n) & 0xFFFF_FFFF };
                let want_srl = if n >= 32 { 0 } else { u >> n };
                prop_assert_eq!(sll[i] as u32 as i128, want_sll, "sll {} by {}", x, n);
                prop_assert_eq!(srl[i] as u32 as i128, want_srl, "srl {} by {}", x, n);
                prop_assert_eq!(sra[i] as i128, x.div_euclid(1i128 << n), "sra {} by {}", x, n);
                let exact = x * (1i128 << n);
                prop_assert_eq!(asl[i] as i128, clamp32(exact), "asl {} by {}", x, n);
                prop_assert_eq!(bit(rc.flags.v, i), clamp32(exact) != exact);
            }
        }
        // only the low six bits of B are the amount
        let b: [i32; L] = std::array::from_fn(|i| (i as i32) * 0x0101_0101 - 7);
        let r = binop(&mut rc, Op::Sra, &a, &b);
        for i in 0..L {
            let n = (b[i] as u32 & 63) as u32;
            prop_assert_eq!(r[i] as i128, (a[i] as i128).div_euclid(1i128 << n));
        }
    }

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
