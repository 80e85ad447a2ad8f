//! Shared harness for the RC property tests: drive `RcArray<L>` lane-wise
//! through real context words and read the results back.
#![allow(dead_code)]

use proptest::prelude::*;
use rtl::kernel::Clocked;
use rtl::rc::context::{BSrc, Context, Op};
use rtl::rc::{LaneNames, RcArray};

/// Lanes used by the property tests: the full array width.
pub const L: usize = 64;
pub type Rc = RcArray<L>;

pub fn rc() -> Box<Rc> {
    Box::new(RcArray::new(LaneNames::Grid))
}

/// Values with the edge cases i16::MIN, -1, 0, 1, i16::MAX well represented.
pub fn val() -> impl Strategy<Value = i16> {
    prop_oneof![
        1 => Just(i16::MIN),
        1 => Just(-1i16),
        1 => Just(0i16),
        1 => Just(1i16),
        1 => Just(i16::MAX),
        6 => any::<i16>(),
    ]
}

pub fn lanes() -> impl Strategy<Value = [i16; L]> {
    proptest::collection::vec(val(), L).prop_map(|v| v.try_into().unwrap())
}

/// Execute one context through the encoder, decoder, eval and commit.
pub fn exec(rc: &mut Rc, ctx: Context) -> Result<(), rtl::Fault> {
    let w = ctx.encode();
    let d = Context::decode(w).expect("encoded context decodes");
    assert_eq!(d, ctx);
    rc.set_context(w, d);
    rc.eval()?;
    rc.commit();
    Ok(())
}

/// Load a register in every lane (a testbench poke, not a datapath op).
pub fn load(rc: &mut Rc, r: u8, v: &[i16; L]) {
    for (i, x) in v.iter().enumerate() {
        rc.regs.poke(i, r, *x);
    }
}

pub fn reg(rc: &Rc, r: u8) -> [i16; L] {
    *rc.regs.read(r)
}

/// `op r3, r1, r2` with A in r1 and B in r2; returns r3.
pub fn binop(rc: &mut Rc, op: Op, a: &[i16; L], b: &[i16; L]) -> [i16; L] {
    load(rc, 1, a);
    load(rc, 2, b);
    exec(rc, Context::rrr(op, 3, 1, 2)).unwrap();
    reg(rc, 3)
}

/// A multiplier context with shift `sh` and rounding mode.
pub fn mulctx(op: Op, rd: u8, ra: u8, rb: u8, sh: u8, trunc: bool) -> Context {
    Context {
        shift: sh,
        trunc,
        b: BSrc::Reg(rb),
        ..Context::rrr(op, rd, ra, rb)
    }
}

pub fn bit(m: u64, i: usize) -> bool {
    m >> i & 1 != 0
}

pub fn clamp16(x: i64) -> i64 {
    x.clamp(i16::MIN as i64, i16::MAX as i64)
}
