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

/// A datapath word the property tests run on both chips with: the 16-bit
/// RC and the 32-bit variant, against i128 arithmetic.
pub trait TestWord: rtl::rc::Word + std::fmt::Debug + PartialEq + Copy + 'static {
    const MIN: i128;
    const MAX: i128;
    /// Values with the edge cases (MIN, -1, 0, 1, MAX) well represented.
    fn value() -> BoxedStrategy<Self>;
    /// `x` wrapped to the word (its low BITS bits).
    fn of(x: i128) -> Self;
    fn get(self) -> i128;
    /// The context decoder of this datapath.
    fn decode(w: u32) -> Context;
}

impl TestWord for i16 {
    const MIN: i128 = i16::MIN as i128;
    const MAX: i128 = i16::MAX as i128;
    fn value() -> BoxedStrategy<i16> {
        val().boxed()
    }
    fn of(x: i128) -> i16 {
        x as i16
    }
    fn get(self) -> i128 {
        self as i128
    }
    fn decode(w: u32) -> Context {
        Context::decode(w).expect("encoded context decodes")
    }
}

impl TestWord for i32 {
    const MIN: i128 = i32::MIN as i128;
    const MAX: i128 = i32::MAX as i128;
    fn value() -> BoxedStrategy<i32> {
        prop_oneof![
            1 => Just(i32::MIN),
            1 => Just(-1i32),
            1 => Just(0i32),
            1 => Just(1i32),
            1 => Just(i32::MAX),
            1 => -70000i32..70000,
            6 => any::<i32>(),
        ]
        .boxed()
    }
    fn of(x: i128) -> i32 {
        x as i32
    }
    fn get(self) -> i128 {
        self as i128
    }
    fn decode(w: u32) -> Context {
        Context::decode_wide(w).expect("encoded context decodes")
    }
}

pub type RcW<W> = RcArray<L, W>;

pub fn rc_w<W: TestWord>() -> Box<RcW<W>> {
    Box::new(RcArray::new(LaneNames::Grid))
}

pub fn lanes_w<W: TestWord>() -> impl Strategy<Value = [W; L]> {
    proptest::collection::vec(W::value(), L).prop_map(|v| v.try_into().unwrap())
}

/// Execute one context through the encoder, this datapath's decoder, eval
/// and commit.
pub fn exec_w<W: TestWord>(rc: &mut RcW<W>, ctx: Context) -> Result<(), rtl::Fault> {
    let w = ctx.encode();
    let d = W::decode(w);
    assert_eq!(d, ctx);
    rc.set_context(w, d);
    rc.eval()?;
    rc.commit();
    Ok(())
}

pub fn load_w<W: TestWord>(rc: &mut RcW<W>, r: u8, v: &[W; L]) {
    for (i, x) in v.iter().enumerate() {
        rc.regs.poke(i, r, *x);
    }
}

pub fn reg_w<W: TestWord>(rc: &RcW<W>, r: u8) -> [W; L] {
    *rc.regs.read(r)
}

/// `op r3, r1, r2` with A in r1 and B in r2; returns r3.
pub fn binop_w<W: TestWord>(rc: &mut RcW<W>, op: Op, a: &[W; L], b: &[W; L]) -> [W; L] {
    load_w(rc, 1, a);
    load_w(rc, 2, b);
    exec_w(rc, Context::rrr(op, 3, 1, 2)).unwrap();
    reg_w(rc, 3)
}

/// `x` saturated to the word's range.
pub fn clamp_w<W: TestWord>(x: i128) -> i128 {
    x.clamp(W::MIN, W::MAX)
}

/// `x`'s bit pattern as an unsigned number of the word's width.
pub fn unsigned_w<W: TestWord>(x: i128) -> i128 {
    x.rem_euclid(1 << W::BITS)
}
