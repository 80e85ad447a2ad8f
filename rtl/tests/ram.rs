//! The 512 x 16 RC RAM: stores and loads against a model, and out-of-range
//! addresses as faults.

mod common;
use common::*;
use proptest::prelude::*;
use rtl::rc::context::{ASrc, Context, Op};

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random per-lane stores then loads (read after write) through
    /// `st A, [B]` and `ld rd, [A + B]`.
    #[test]
    fn store_then_load(steps in proptest::collection::vec((lanes(), proptest::collection::vec(0i16..512, L), any::<bool>()), 1..24)) {
        let mut rc = rc();
        let mut model = vec![[0i64; 512]; L];
        for (data, addr, is_store) in steps {
            let addr: [i16; L] = addr.try_into().unwrap();
            load(&mut rc, 1, &data);
            load(&mut rc, 2, &addr);
            if is_store {
                exec(&mut rc, Context::rrr(Op::St, 0, 1, 2)).unwrap();
                for i in 0..L { model[i][addr[i] as usize] = data[i] as i64; }
            } else {
                // Address = A + B with A = 0 in r0.
                load(&mut rc, 0, &[0; L]);
                exec(&mut rc, Context::rrr(Op::Ld, 3, 0, 2)).unwrap();
                for i in 0..L {
                    prop_assert_eq!(reg(&rc, 3)[i] as i64, model[i][addr[i] as usize], "lane {} addr {}", i, addr[i]);
                }
            }
        }
    }

    /// Table lookup form: `ld rd, [rA + #offset]`.
    #[test]
    fn indexed_loads(base in 0i16..256, idx in proptest::collection::vec(0i16..256, L)) {
        let mut rc = rc();
        for k in 0..512i16 {
            // table[k] = 3k + 1 (mod 2^16), written by stores of an immediate.
            load(&mut rc, 1, &[3 * k + 1; L]);
            exec(&mut rc, Context::rri(Op::St, 0, 1, 0).with_imm_addr(k)).unwrap();
        }
        let idx: [i16; L] = idx.try_into().unwrap();
        load(&mut rc, 5, &idx);
        exec(&mut rc, Context::rri(Op::Ld, 6, 5, base)).unwrap();
        for i in 0..L {
            prop_assert_eq!(reg(&rc, 6)[i] as i64, 3 * (idx[i] as i64 + base as i64) + 1);
        }
    }
}

trait ImmAddr {
    fn with_imm_addr(self, a: i16) -> Context;
}
impl ImmAddr for Context {
    /// `st r1, [#a]` for a in 0..512 (the 11-bit immediate reaches 1023).
    fn with_imm_addr(self, a: i16) -> Context {
        Context {
            asrc: ASrc::Reg,
            ra: 1,
            b: rtl::rc::context::BSrc::Imm(a),
            ..self
        }
    }
}

#[test]
fn out_of_range_addresses_fault_without_writing() {
    for bad in [-1i16, 512, 1000, i16::MIN] {
        let mut rc = rc();
        let mut addr = [0i16; L];
        addr[37] = bad; // one bad lane is enough
        load(&mut rc, 1, &[5; L]);
        load(&mut rc, 2, &addr);
        let err = exec(&mut rc, Context::rrr(Op::St, 0, 1, 2)).unwrap_err();
        assert_eq!(err.block, "rc_r4_c5");
        assert!(err.message.contains(&format!("RAM address {bad}")), "{err}");
        // Nothing was stored: the fault stopped the cycle before the edge.
        load(&mut rc, 0, &[0; L]);
        load(&mut rc, 2, &[0; L]);
        exec(&mut rc, Context::rrr(Op::Ld, 3, 0, 2)).unwrap();
        assert_eq!(reg(&rc, 3), [0; L]);
    }
}

#[test]
fn a_bad_address_in_a_guarded_off_lane_is_harmless() {
    let mut rc = rc();
    let mut addr = [0i16; L];
    addr[3] = -5;
    rc.flags.f = !(1u64 << 3);
    load(&mut rc, 2, &addr);
    let ctx = Context {
        guard: rtl::rc::context::Guard::IfF,
        ..Context::rrr(Op::Ld, 3, 0, 2)
    };
    exec(&mut rc, ctx).unwrap();
}
