//! ALU operations against wide (i64) integer arithmetic, lane-wise.

mod common;
use common::*;
use proptest::prelude::*;
use rtl::rc::context::{Cond, Context, Guard, Op, ALL_CONDS};

fn wrap16(x: i64) -> i16 {
    x.rem_euclid(1 << 16) as u16 as i16
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn add_sub_with_carry_and_overflow(a in lanes(), b in lanes(), cin in any::<u64>()) {
        for (op, sub, use_c) in [(Op::Add, false, false), (Op::Adc, false, true),
                                 (Op::Sub, true, false), (Op::Sbc, true, true)] {
            let mut rc = rc();
            rc.flags.c = cin;
            let r = binop(&mut rc, op, &a, &b);
            for i in 0..L {
                let c = if use_c { bit(cin, i) as i64 } else { 0 };
                let (x, y) = (a[i] as i64, b[i] as i64);
                let (ux, uy) = (a[i] as u16 as i64, b[i] as u16 as i64);
                let exact = if sub { x - y - c } else { x + y + c };
                prop_assert_eq!(r[i], wrap16(exact), "{:?} lane {}", op, i);
                let carry = if sub { ux < uy + c } else { ux + uy + c > 0xFFFF };
                prop_assert_eq!(bit(rc.flags.c, i), carry, "{:?} C lane {}", op, i);
                prop_assert_eq!(bit(rc.flags.v, i), clamp16(exact) != exact, "{:?} V lane {}", op, i);
            }
        }
    }

    #[test]
    fn rsb_and_neg(a in lanes(), b in lanes()) {
        let mut rc = rc();
        let r = binop(&mut rc, Op::Rsb, &a, &b);
        for i in 0..L {
            prop_assert_eq!(r[i], wrap16(b[i] as i64 - a[i] as i64));
        }
        load(&mut rc, 1, &a);
        exec(&mut rc, Context::rrr(Op::Neg, 4, 1, 0)).unwrap();
        for i in 0..L {
            let exact = -(a[i] as i64);
            prop_assert_eq!(reg(&rc, 4)[i], wrap16(exact));
            prop_assert_eq!(bit(rc.flags.v, i), exact != clamp16(exact));
            prop_assert_eq!(bit(rc.flags.c, i), a[i] != 0, "borrow of 0 - a");
        }
    }

    /// 32-bit arithmetic from two 16-bit halves: add/adc and sub/sbc chains.
    #[test]
    fn multiword_add_and_sub(x in any::<i32>(), y in any::<i32>()) {
        let lo = |v: i32| [v as i16; L];
        let hi = |v: i32| [(v >> 16) as i16; L];
        for (op_lo, op_hi, expect) in [(Op::Add, Op::Adc, x.wrapping_add(y)),
                                       (Op::Sub, Op::Sbc, x.wrapping_sub(y))] {
            let mut rc = rc();
            let l = binop(&mut rc, op_lo, &lo(x), &lo(y));
            let h = binop(&mut rc, op_hi, &hi(x), &hi(y));
            let got = ((h[0] as u16 as u32) << 16 | l[0] as u16 as u32) as i32;
            prop_assert_eq!(got, expect);
            // V of the high half is the signed overflow of the 32-bit operation.
            let wide = if op_lo == Op::Add { x as i64 + y as i64 } else { x as i64 - y as i64 };
            prop_assert_eq!(bit(rc.flags.v, 0), wide != expect as i64);
        }
    }

    #[test]
    fn saturating_ops(a in lanes(), b in lanes()) {
        let mut rc = rc();
        let r = binop(&mut rc, Op::Adds, &a, &b);
        for i in 0..L {
            let e = a[i] as i64 + b[i] as i64;
            prop_assert_eq!(r[i] as i64, clamp16(e));
            prop_assert_eq!(bit(rc.flags.v, i), clamp16(e) != e);
        }
        let r = binop(&mut rc, Op::Subs, &a, &b);
        for i in 0..L {
            let e = a[i] as i64 - b[i] as i64;
            prop_assert_eq!(r[i] as i64, clamp16(e));
            prop_assert_eq!(bit(rc.flags.v, i), clamp16(e) != e);
        }
        let r = binop(&mut rc, Op::Absd, &a, &b);
        for i in 0..L {
            let e = (a[i] as i64 - b[i] as i64).abs();
            prop_assert_eq!(r[i] as i64, clamp16(e));
        }
        let r = binop(&mut rc, Op::Abs, &a, &b);
        for i in 0..L {
            let e = (a[i] as i64).abs();
            prop_assert_eq!(r[i] as i64, clamp16(e));
            prop_assert_eq!(bit(rc.flags.v, i), e > i16::MAX as i64);
        }
    }

    #[test]
    fn logic_min_max_clz(a in lanes(), b in lanes()) {
        let mut rc = rc();
        let cases: [(Op, fn(i64, i64) -> i64); 6] = [
            (Op::And, |x, y| x & y),
            (Op::Or, |x, y| x | y),
            (Op::Xor, |x, y| x ^ y),
            (Op::Not, |x, _| !x),
            (Op::Min, |x, y| if x < y { x } else { y }),
            (Op::Max, |x, y| if x > y { x } else { y }),
        ];
        for (op, f) in cases {
            let r = binop(&mut rc, op, &a, &b);
            for i in 0..L {
                prop_assert_eq!(r[i] as i64, f(a[i] as i64, b[i] as i64), "{:?}", op);
            }
        }
        let r = binop(&mut rc, Op::Clz, &a, &b);
        for i in 0..L {
            // Reference: position of the highest set bit, counted by hand.
            let u = a[i] as u16 as i64;
            let mut n = 16;
            for k in 0..16 {
                if u >> k & 1 == 1 { n = 15 - k; }
            }
            prop_assert_eq!(r[i] as i64, n);
        }
    }

    #[test]
    fn compare_sets_the_flag(a in lanes(), b in lanes(), c in any::<u64>(), v in any::<u64>()) {
        for cond in ALL_CONDS {
            let mut rc = rc();
            rc.flags.c = c;
            rc.flags.v = v;
            load(&mut rc, 1, &a);
            load(&mut rc, 2, &b);
            let ctx = Context { rd: cond as u8, ..Context::rrr(Op::Cmp, 0, 1, 2) };
            exec(&mut rc, ctx).unwrap();
            for i in 0..L {
                let (x, y) = (a[i] as i64, b[i] as i64);
                let (ux, uy) = (x.rem_euclid(1 << 16), y.rem_euclid(1 << 16));
                let want = match cond {
                    Cond::Eq => x == y, Cond::Ne => x != y,
                    Cond::Lt => x < y, Cond::Ge => x >= y,
                    Cond::Le => x <= y, Cond::Gt => x > y,
                    Cond::Ltu => ux < uy, Cond::Geu => ux >= uy,
                    Cond::Leu => ux <= uy, Cond::Gtu => ux > uy,
                    Cond::Cs => bit(c, i), Cond::Vs => bit(v, i),
                    Cond::True => true, Cond::False => false,
                    Cond::Bit => ux & uy != 0, Cond::Nbit => ux & uy == 0,
                };
                prop_assert_eq!(bit(rc.flags.f, i), want, "{:?} lane {}", cond, i);
            }
            // cmp writes no register and leaves C and V alone.
            prop_assert_eq!(reg(&rc, 0), [0; L]);
            prop_assert_eq!((rc.flags.c, rc.flags.v), (c, v));
        }
    }

    /// Guarded execution: only lanes whose F matches the guard change.
    #[test]
    fn guards_select_lanes(a in lanes(), b in lanes(), f in any::<u64>(), old in lanes()) {
        for guard in [Guard::Always, Guard::IfF, Guard::IfNotF] {
            let mut rc = rc();
            rc.flags.f = f;
            load(&mut rc, 3, &old);
            load(&mut rc, 1, &a);
            load(&mut rc, 2, &b);
            exec(&mut rc, Context { guard, ..Context::rrr(Op::Add, 3, 1, 2) }).unwrap();
            for i in 0..L {
                let run = match guard { Guard::Always => true, Guard::IfF => bit(f, i), Guard::IfNotF => !bit(f, i) };
                let want = if run { wrap16(a[i] as i64 + b[i] as i64) } else { old[i] };
                prop_assert_eq!(reg(&rc, 3)[i], want);
            }
        }
    }

    /// `sel` is the pseudo branch: F ? A : B per lane.
    #[test]
    fn select_by_flag(a in lanes(), b in lanes(), f in any::<u64>()) {
        let mut rc = rc();
        rc.flags.f = f;
        let r = binop(&mut rc, Op::Sel, &a, &b);
        for i in 0..L {
            prop_assert_eq!(r[i], if bit(f, i) { a[i] } else { b[i] });
        }
    }

    /// Immediates are sign-extended 11-bit values.
    #[test]
    fn immediates(a in lanes(), imm in -1024i16..=1023) {
        let mut rc = rc();
        load(&mut rc, 1, &a);
        exec(&mut rc, Context::rri(Op::Add, 5, 1, imm)).unwrap();
        for i in 0..L {
            prop_assert_eq!(reg(&rc, 5)[i], wrap16(a[i] as i64 + imm as i64));
        }
    }
}

#[test]
fn sleeping_rcs_execute_nothing_but_wake() {
    let mut rc = rc();
    // Sleep the odd lanes: F = odd, then a guarded sleep.
    rc.flags.f = 0xAAAA_AAAA_AAAA_AAAA;
    exec(
        &mut rc,
        Context {
            guard: Guard::IfF,
            op: Op::Sleep,
            ..Context::NOP
        },
    )
    .unwrap();
    assert_eq!(rc.flags.sleep, 0xAAAA_AAAA_AAAA_AAAA);
    exec(&mut rc, Context::rri(Op::Movb, 1, 0, 7)).unwrap();
    for i in 0..L {
        assert_eq!(reg(&rc, 1)[i], if i % 2 == 1 { 0 } else { 7 }, "lane {i}");
    }
    exec(
        &mut rc,
        Context {
            op: Op::Wake,
            ..Context::NOP
        },
    )
    .unwrap();
    assert_eq!(rc.flags.sleep, 0);
    exec(&mut rc, Context::rri(Op::Movb, 1, 0, 9)).unwrap();
    assert_eq!(reg(&rc, 1), [9; L]);
}

#[test]
fn edge_values_by_hand() {
    // A few results worked out on paper, independent of any formula above.
    let mut rc = rc();
    let r = binop(&mut rc, Op::Add, &[i16::MAX; L], &[1; L]);
    assert_eq!(
        (r[0], bit(rc.flags.c, 0), bit(rc.flags.v, 0)),
        (i16::MIN, false, true)
    );
    let r = binop(&mut rc, Op::Add, &[-1; L], &[1; L]);
    assert_eq!(
        (r[0], bit(rc.flags.c, 0), bit(rc.flags.v, 0)),
        (0, true, false)
    );
    let r = binop(&mut rc, Op::Sub, &[0; L], &[1; L]);
    assert_eq!(
        (r[0], bit(rc.flags.c, 0), bit(rc.flags.v, 0)),
        (-1, true, false)
    );
    let r = binop(&mut rc, Op::Sub, &[i16::MIN; L], &[1; L]);
    assert_eq!(
        (r[0], bit(rc.flags.c, 0), bit(rc.flags.v, 0)),
        (i16::MAX, false, true)
    );
    let r = binop(&mut rc, Op::Abs, &[i16::MIN; L], &[0; L]);
    assert_eq!((r[0], bit(rc.flags.v, 0)), (i16::MAX, true));
    let r = binop(&mut rc, Op::Adds, &[i16::MAX; L], &[i16::MAX; L]);
    assert_eq!(r[0], i16::MAX);
    let r = binop(&mut rc, Op::Subs, &[i16::MIN; L], &[1; L]);
    assert_eq!(r[0], i16::MIN);
}
