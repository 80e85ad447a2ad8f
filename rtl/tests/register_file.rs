//! Register file (two reads, one write per cycle) and the output register,
//! against a plain array model.

mod common;
use common::*;
use proptest::prelude::*;
use rtl::rc::context::{Context, Op};

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Random `add rd, ra, rb` / `movb rd, #imm` sequences: both read ports
    /// see the registers as they were during the cycle, the write lands at
    /// the edge (so `add r1, r1, r1` doubles the old r1).
    #[test]
    fn read_after_write(init in proptest::collection::vec(lanes(), 16),
                        ops in proptest::collection::vec((0u8..16, 0u8..16, 0u8..16, -1024i16..1024, any::<bool>(), any::<bool>()), 1..40)) {
        let mut rc = rc();
        let mut model = [[0i64; L]; 16];
        for (k, v) in init.iter().enumerate() {
            load(&mut rc, k as u8, v);
            for i in 0..L { model[k][i] = v[i] as i64; }
        }
        for (rd, ra, rb, imm, use_imm, we) in ops {
            let mut ctx = if use_imm {
                Context::rri(Op::Movb, rd, ra, imm)
            } else {
                Context::rrr(Op::Add, rd, ra, rb)
            };
            ctx.we = we;
            exec(&mut rc, ctx).unwrap();
            let mut out = [0i64; L];
            for i in 0..L {
                out[i] = if use_imm {
                    imm as i64
                } else {
                    (model[ra as usize][i] + model[rb as usize][i]).rem_euclid(1 << 16) as u16 as i16 as i64
                };
                if we { model[rd as usize][i] = out[i]; }
            }
            for i in 0..L {
                prop_assert_eq!(rc.out[i] as i64, out[i], "out lane {}", i);
            }
            for k in 0..16u8 {
                for i in 0..L {
                    prop_assert_eq!(reg(&rc, k)[i] as i64, model[k as usize][i], "r{} lane {}", k, i);
                }
            }
        }
    }

    /// Operand A from the output register (`asrc = out`).
    #[test]
    fn output_register_feeds_back(a in lanes(), imm in -1024i16..1024) {
        let mut rc = rc();
        load(&mut rc, 1, &a);
        exec(&mut rc, Context::rrr(Op::Mov, 0, 1, 0)).unwrap(); // out = r1 (and r0)
        let ctx = Context { asrc: rtl::rc::context::ASrc::Out, we: false, ..Context::rri(Op::Add, 0, 0, imm) };
        exec(&mut rc, ctx).unwrap();
        for i in 0..L {
            prop_assert_eq!(rc.out[i] as i64, (a[i] as i64 + imm as i64).rem_euclid(1 << 16) as u16 as i16 as i64);
        }
    }
}
