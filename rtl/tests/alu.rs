//! ALU operations against wide (i128) integer arithmetic, lane-wise, on
//! both datapaths: every check is one function generic over the word
//! ([`TestWord`]), run on the 16-bit RC and on the 32-bit variant.

mod common;
use common::*;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use rtl::rc::context::{Cond, Context, Guard, Op, ALL_CONDS};

type Check = Result<(), TestCaseError>;

fn add_sub_with_carry_and_overflow<W: TestWord>(a: &[W; L], b: &[W; L], cin: u64) -> Check {
    for (op, sub, use_c) in [
        (Op::Add, false, false),
        (Op::Adc, false, true),
        (Op::Sub, true, false),
        (Op::Sbc, true, true),
    ] {
        let mut rc = rc_w::<W>();
        rc.flags.c = cin;
        let r = binop_w(&mut rc, op, a, b);
        for i in 0..L {
            let c = if use_c { bit(cin, i) as i128 } else { 0 };
            let (x, y) = (a[i].get(), b[i].get());
            let (ux, uy) = (unsigned_w::<W>(x), unsigned_w::<W>(y));
            let exact = if sub { x - y - c } else { x + y + c };
            prop_assert_eq!(r[i], W::of(exact), "{:?} lane {}", op, i);
            let carry = if sub {
                ux < uy + c
            } else {
                ux + uy + c >= 1 << W::BITS
            };
            prop_assert_eq!(bit(rc.flags.c, i), carry, "{:?} C lane {}", op, i);
            prop_assert_eq!(
                bit(rc.flags.v, i),
                clamp_w::<W>(exact) != exact,
                "{:?} V lane {}",
                op,
                i
            );
        }
    }
    Ok(())
}

fn rsb_and_neg<W: TestWord>(a: &[W; L], b: &[W; L]) -> Check {
    let mut rc = rc_w::<W>();
    let r = binop_w(&mut rc, Op::Rsb, a, b);
    for i in 0..L {
        prop_assert_eq!(r[i], W::of(b[i].get() - a[i].get()));
    }
    load_w(&mut rc, 1, a);
    exec_w(&mut rc, Context::rrr(Op::Neg, 4, 1, 0)).unwrap();
    for i in 0..L {
        let exact = -a[i].get();
        prop_assert_eq!(reg_w(&rc, 4)[i], W::of(exact));
        prop_assert_eq!(bit(rc.flags.v, i), exact != clamp_w::<W>(exact));
        prop_assert_eq!(bit(rc.flags.c, i), a[i].get() != 0, "borrow of 0 - a");
    }
    Ok(())
}

/// Twice-the-word arithmetic from two halves: add/adc and sub/sbc chains.
/// `x`, `y` are taken as numbers of twice the word's width.
fn multiword_add_and_sub<W: TestWord>(x: i128, y: i128) -> Check {
    let bits = 2 * W::BITS;
    let wide = |v: i128| (v << (128 - bits)) >> (128 - bits);
    let (x, y) = (wide(x), wide(y));
    let lo = |v: i128| [W::of(v); L];
    let hi = |v: i128| [W::of(v >> W::BITS); L];
    for (op_lo, op_hi, exact) in [(Op::Add, Op::Adc, x + y), (Op::Sub, Op::Sbc, x - y)] {
        let mut rc = rc_w::<W>();
        let l = binop_w(&mut rc, op_lo, &lo(x), &lo(y));
        let h = binop_w(&mut rc, op_hi, &hi(x), &hi(y));
        let got = wide(h[0].get() << W::BITS | unsigned_w::<W>(l[0].get()));
        prop_assert_eq!(got, wide(exact));
        // V of the high half is the signed overflow of the whole operation.
        prop_assert_eq!(bit(rc.flags.v, 0), wide(exact) != exact);
    }
    Ok(())
}

fn saturating_ops<W: TestWord>(a: &[W; L], b: &[W; L]) -> Check {
    let mut rc = rc_w::<W>();
    for (op, f) in [
        (Op::Adds, (|x, y| x + y) as fn(i128, i128) -> i128),
        (Op::Subs, |x, y| x - y),
    ] {
        let r = binop_w(&mut rc, op, a, b);
        for i in 0..L {
            let e = f(a[i].get(), b[i].get());
            prop_assert_eq!(r[i].get(), clamp_w::<W>(e), "{:?}", op);
            prop_assert_eq!(bit(rc.flags.v, i), clamp_w::<W>(e) != e, "{:?} V", op);
        }
    }
    let r = binop_w(&mut rc, Op::Absd, a, b);
    for i in 0..L {
        let e = (a[i].get() - b[i].get()).abs();
        prop_assert_eq!(r[i].get(), clamp_w::<W>(e));
    }
    let r = binop_w(&mut rc, Op::Abs, a, b);
    for i in 0..L {
        let e = a[i].get().abs();
        prop_assert_eq!(r[i].get(), clamp_w::<W>(e));
        prop_assert_eq!(bit(rc.flags.v, i), e > W::MAX);
    }
    Ok(())
}

fn logic_min_max_clz_sel<W: TestWord>(a: &[W; L], b: &[W; L], f: u64) -> Check {
    let mut rc = rc_w::<W>();
    let cases: [(Op, fn(i128, i128) -> i128); 6] = [
        (Op::And, |x, y| x & y),
        (Op::Or, |x, y| x | y),
        (Op::Xor, |x, y| x ^ y),
        (Op::Not, |x, _| !x),
        (Op::Min, |x, y| if x < y { x } else { y }),
        (Op::Max, |x, y| if x > y { x } else { y }),
    ];
    for (op, g) in cases {
        let r = binop_w(&mut rc, op, a, b);
        for i in 0..L {
            prop_assert_eq!(r[i].get(), g(a[i].get(), b[i].get()), "{:?}", op);
        }
    }
    let r = binop_w(&mut rc, Op::Clz, a, b);
    for i in 0..L {
        // The position of the highest set bit, counted by hand.
        let u = unsigned_w::<W>(a[i].get());
        let mut n = W::BITS as i128;
        for k in 0..W::BITS {
            if u >> k & 1 == 1 {
                n = (W::BITS - 1 - k) as i128;
            }
        }
        prop_assert_eq!(r[i].get(), n);
    }
    // `sel` is the pseudo branch: F ? A : B per lane.
    rc.flags.f = f;
    let r = binop_w(&mut rc, Op::Sel, a, b);
    for i in 0..L {
        prop_assert_eq!(r[i], if bit(f, i) { a[i] } else { b[i] });
    }
    Ok(())
}

fn compare_sets_the_flag<W: TestWord>(a: &[W; L], b: &[W; L], c: u64, v: u64) -> Check {
    for cond in ALL_CONDS {
        let mut rc = rc_w::<W>();
        rc.flags.c = c;
        rc.flags.v = v;
        load_w(&mut rc, 1, a);
        load_w(&mut rc, 2, b);
        let ctx = Context {
            rd: cond as u8,
            ..Context::rrr(Op::Cmp, 0, 1, 2)
        };
        exec_w(&mut rc, ctx).unwrap();
        for i in 0..L {
            let (x, y) = (a[i].get(), b[i].get());
            let (ux, uy) = (unsigned_w::<W>(x), unsigned_w::<W>(y));
            let want = match cond {
                Cond::Eq => x == y,
                Cond::Ne => x != y,
                Cond::Lt => x < y,
                Cond::Ge => x >= y,
                Cond::Le => x <= y,
                Cond::Gt => x > y,
                Cond::Ltu => ux < uy,
                Cond::Geu => ux >= uy,
                Cond::Leu => ux <= uy,
                Cond::Gtu => ux > uy,
                Cond::Cs => bit(c, i),
                Cond::Vs => bit(v, i),
                Cond::True => true,
                Cond::False => false,
                Cond::Bit => ux & uy != 0,
                Cond::Nbit => ux & uy == 0,
            };
            prop_assert_eq!(bit(rc.flags.f, i), want, "{:?} lane {}", cond, i);
        }
        // cmp writes no register and leaves C and V alone.
        prop_assert_eq!(reg_w(&rc, 0), [W::of(0); L]);
        prop_assert_eq!((rc.flags.c, rc.flags.v), (c, v));
    }
    Ok(())
}

/// Guarded execution: only lanes whose F matches the guard change.
fn guards_select_lanes<W: TestWord>(a: &[W; L], b: &[W; L], f: u64, old: &[W; L]) -> Check {
    for guard in [Guard::Always, Guard::IfF, Guard::IfNotF] {
        let mut rc = rc_w::<W>();
        rc.flags.f = f;
        load_w(&mut rc, 3, old);
        load_w(&mut rc, 1, a);
        load_w(&mut rc, 2, b);
        exec_w(
            &mut rc,
            Context {
                guard,
                ..Context::rrr(Op::Add, 3, 1, 2)
            },
        )
        .unwrap();
        for i in 0..L {
            let run = match guard {
                Guard::Always => true,
                Guard::IfF => bit(f, i),
                Guard::IfNotF => !bit(f, i),
            };
            let want = if run {
                W::of(a[i].get() + b[i].get())
            } else {
                old[i]
            };
            prop_assert_eq!(reg_w(&rc, 3)[i], want);
        }
    }
    Ok(())
}

/// Immediates are sign-extended 11-bit values.
fn immediates<W: TestWord>(a: &[W; L], imm: i16) -> Check {
    let mut rc = rc_w::<W>();
    load_w(&mut rc, 1, a);
    exec_w(&mut rc, Context::rri(Op::Add, 5, 1, imm)).unwrap();
    for i in 0..L {
        prop_assert_eq!(reg_w(&rc, 5)[i], W::of(a[i].get() + imm as i128));
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(192))]

    #[test]
    fn add_sub_16(a in lanes_w::<i16>(), b in lanes_w::<i16>(), c in any::<u64>()) {
        add_sub_with_carry_and_overflow(&a, &b, c)?;
    }
    #[test]
    fn add_sub_32(a in lanes_w::<i32>(), b in lanes_w::<i32>(), c in any::<u64>()) {
        add_sub_with_carry_and_overflow(&a, &b, c)?;
    }
    #[test]
    fn rsb_neg_16(a in lanes_w::<i16>(), b in lanes_w::<i16>()) { rsb_and_neg(&a, &b)?; }
    #[test]
    fn rsb_neg_32(a in lanes_w::<i32>(), b in lanes_w::<i32>()) { rsb_and_neg(&a, &b)?; }
    #[test]
    fn multiword_16(x in any::<i128>(), y in any::<i128>()) { multiword_add_and_sub::<i16>(x, y)?; }
    #[test]
    fn multiword_32(x in any::<i128>(), y in any::<i128>()) { multiword_add_and_sub::<i32>(x, y)?; }
    #[test]
    fn saturating_16(a in lanes_w::<i16>(), b in lanes_w::<i16>()) { saturating_ops(&a, &b)?; }
    #[test]
    fn saturating_32(a in lanes_w::<i32>(), b in lanes_w::<i32>()) { saturating_ops(&a, &b)?; }
    #[test]
    fn logic_16(a in lanes_w::<i16>(), b in lanes_w::<i16>(), f in any::<u64>()) {
        logic_min_max_clz_sel(&a, &b, f)?;
    }
    #[test]
    fn logic_32(a in lanes_w::<i32>(), b in lanes_w::<i32>(), f in any::<u64>()) {
        logic_min_max_clz_sel(&a, &b, f)?;
    }
    #[test]
    fn compare_16(a in lanes_w::<i16>(), b in lanes_w::<i16>(), c in any::<u64>(), v in any::<u64>()) {
        compare_sets_the_flag(&a, &b, c, v)?;
    }
    #[test]
    fn compare_32(a in lanes_w::<i32>(), b in lanes_w::<i32>(), c in any::<u64>(), v in any::<u64>()) {
        compare_sets_the_flag(&a, &b, c, v)?;
    }
    #[test]
    fn guards_16(a in lanes_w::<i16>(), b in lanes_w::<i16>(), f in any::<u64>(), old in lanes_w::<i16>()) {
        guards_select_lanes(&a, &b, f, &old)?;
    }
    #[test]
    fn guards_32(a in lanes_w::<i32>(), b in lanes_w::<i32>(), f in any::<u64>(), old in lanes_w::<i32>()) {
        guards_select_lanes(&a, &b, f, &old)?;
    }
    #[test]
    fn immediates_16(a in lanes_w::<i16>(), imm in -1024i16..=1023) { immediates(&a, imm)?; }
    #[test]
    fn immediates_32(a in lanes_w::<i32>(), imm in -1024i16..=1023) { immediates(&a, imm)?; }
}

fn sleeping_rcs_execute_nothing_but_wake<W: TestWord>() {
    let mut rc = rc_w::<W>();
    // Sleep the odd lanes: F = odd, then a guarded sleep.
    rc.flags.f = 0xAAAA_AAAA_AAAA_AAAA;
    exec_w(
        &mut rc,
        Context {
            guard: Guard::IfF,
            op: Op::Sleep,
            ..Context::NOP
        },
    )
    .unwrap();
    assert_eq!(rc.flags.sleep, 0xAAAA_AAAA_AAAA_AAAA);
    exec_w(&mut rc, Context::rri(Op::Movb, 1, 0, 7)).unwrap();
    for i in 0..L {
        let want = if i % 2 == 1 { 0 } else { 7 };
        assert_eq!(reg_w(&rc, 1)[i], W::of(want), "lane {i}");
    }
    exec_w(
        &mut rc,
        Context {
            op: Op::Wake,
            ..Context::NOP
        },
    )
    .unwrap();
    assert_eq!(rc.flags.sleep, 0);
    exec_w(&mut rc, Context::rri(Op::Movb, 1, 0, 9)).unwrap();
    assert_eq!(reg_w(&rc, 1), [W::of(9); L]);
}

#[test]
fn sleeping_rcs_execute_nothing_but_wake_16_and_32() {
    sleeping_rcs_execute_nothing_but_wake::<i16>();
    sleeping_rcs_execute_nothing_but_wake::<i32>();
}

/// A few results worked out on paper, independent of any formula above.
fn edge_values_by_hand<W: TestWord>() {
    let (max, min) = (W::of(W::MAX), W::of(W::MIN));
    let k = |v: i128| [W::of(v); L];
    let mut rc = rc_w::<W>();
    let flags = |rc: &RcW<W>| (bit(rc.flags.c, 0), bit(rc.flags.v, 0));
    let r = binop_w(&mut rc, Op::Add, &[max; L], &k(1));
    assert_eq!((r[0], flags(&rc)), (min, (false, true)));
    let r = binop_w(&mut rc, Op::Add, &k(-1), &k(1));
    assert_eq!((r[0], flags(&rc)), (W::of(0), (true, false)));
    let r = binop_w(&mut rc, Op::Sub, &k(0), &k(1));
    assert_eq!((r[0], flags(&rc)), (W::of(-1), (true, false)));
    let r = binop_w(&mut rc, Op::Sub, &[min; L], &k(1));
    assert_eq!((r[0], flags(&rc)), (max, (false, true)));
    let r = binop_w(&mut rc, Op::Abs, &[min; L], &k(0));
    assert_eq!((r[0], bit(rc.flags.v, 0)), (max, true));
    let r = binop_w(&mut rc, Op::Adds, &[max; L], &[max; L]);
    assert_eq!(r[0], max);
    let r = binop_w(&mut rc, Op::Subs, &[min; L], &k(1));
    assert_eq!(r[0], min);
}

#[test]
fn edge_values_by_hand_16_and_32() {
    edge_values_by_hand::<i16>();
    edge_values_by_hand::<i32>();
}
