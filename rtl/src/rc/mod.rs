//! The Reconfigurable Cell, held lane-wise for `N` RCs at once.
//!
//! `RcArray<64>` is the datapath of the whole 8x8 array; `RcArray<1>` is a
//! single RC for testbenches. Each cycle one decoded [`Context`] drives every
//! lane: the operation is matched once, and the lanes are a loop inside it.
//!
//! Units, one file each: [`alu`], [`shifter`], [`multiplier`] (with the
//! accumulator), [`register_file`], [`ram`], [`flags`], plus the output
//! register `out` that the interconnect and the frame-buffer write path read.

pub mod alu;
pub mod context;
pub mod flags;
pub mod isa_vh;
pub mod lanes;
pub mod multiplier;
pub mod ram;
pub mod register_file;
pub mod shifter;
mod waves;
pub mod word;

use std::fmt;

use crate::kernel::{Clocked, Fault};
use context::{ASrc, BSrc, Cond, Context, Guard, Op};
use flags::Flags;
use lanes::{full, Mask, SignBits};
use ram::Ram;
use register_file::RegisterFile;
pub(crate) use waves::{CTX_FILTER, OP_FILTER};
use word::{blend, expand, select_word};
pub use word::{Datapath, Word};

/// How lanes are named in waveforms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LaneNames {
    /// One RC, scope `rc`.
    Single,
    /// Row-major 8-wide grid: `rc_r{row}_c{col}`.
    Grid,
}

impl LaneNames {
    /// The scope name of lane `i` (in waveforms and fault messages).
    pub fn name(self, i: usize) -> String {
        match self {
            LaneNames::Single => "rc".to_string(),
            LaneNames::Grid => format!("rc_r{}_c{}", i / 8, i % 8),
        }
    }
}

/// Which pending updates the clock edge applies.
#[derive(Clone, Copy, Default)]
struct Pending {
    result: bool,
    cv: bool,
    f: bool,
    acc: bool,
    store: bool,
}

/// The lane arrays come first and the whole is 64-byte aligned, so that
/// with 64 lanes every lane array starts on a cache line: a 64-byte
/// vector load never spans two lines, wherever the chip is placed (left
/// to the compiler, the placement moved with unrelated changes and the
/// speed with it, by up to 8%).
#[repr(C, align(64))]
pub struct RcArray<const N: usize, W: Word = i16> {
    // ---- registered state (q) ----
    pub regs: RegisterFile<N, W>,
    pub acc: [W::Acc; N],
    pub out: [W; N],
    // ---- input for this cycle ----
    /// Operand A for the interconnect and frame-buffer sources, driven by
    /// the array around the RCs.
    pub ext: [W; N],
    // ---- next state (d), computed by eval ----
    res: [W; N],
    acc_d: [W::Acc; N],
    addr: [u16; N],
    // ---- the rest of the registered state and inputs ----
    pub ram: Ram<N, W>,
    pub flags: Flags,
    ctx: Context,
    ctx_word: u32,
    /// Lanes allowed to execute this cycle (all by default). Row and column
    /// broadcast modes run one context per row/column by restricting this.
    pub lane_enable: Mask,
    en: Mask,
    /// The RAM access of this cycle has one address in every lane,
    /// `addr0` (`addr` is then not written).
    uniform: bool,
    addr0: u16,
    d_c: Mask,
    d_v: Mask,
    d_f: Mask,
    pend: Pending,
    names: LaneNames,
}

impl<const N: usize, W: Word> RcArray<N, W> {
    pub const FULL: Mask = full(N);

    pub fn new(names: LaneNames) -> Self {
        assert!(N >= 1 && N <= 64, "1 to 64 lanes");
        RcArray {
            regs: RegisterFile::default(),
            ram: Ram::default(),
            acc: [W::Acc::default(); N],
            out: [W::ZERO; N],
            flags: Flags::default(),
            ctx: Context::NOP,
            ctx_word: Context::NOP.encode(),
            ext: [W::ZERO; N],
            lane_enable: full(N),
            en: 0,
            res: [W::ZERO; N],
            acc_d: [W::Acc::default(); N],
            addr: [0; N],
            uniform: false,
            addr0: 0,
            d_c: 0,
            d_v: 0,
            d_f: 0,
            pend: Pending::default(),
            names,
        }
    }

    /// Drive this cycle's context (decoded once by the caller).
    #[inline]
    pub fn set_context(&mut self, word: u32, ctx: Context) {
        self.ctx_word = word;
        self.ctx = ctx;
    }

    pub fn context(&self) -> &Context {
        &self.ctx
    }

    /// Lanes that execute the current context: awake and passing the guard
    /// (`WAKE` also reaches sleeping lanes).
    #[inline(always)]
    pub fn enabled(&self) -> Mask {
        let g = match self.ctx.guard {
            Guard::Always => Self::FULL,
            Guard::IfF => self.flags.f,
            Guard::IfNotF => !self.flags.f & Self::FULL,
        };
        let g = g & self.lane_enable;
        if self.ctx.op == Op::Wake {
            g
        } else {
            g & !self.flags.sleep & Self::FULL
        }
    }

    /// Lanes that executed in the cycle just evaluated.
    pub fn executed(&self) -> Mask {
        self.en
    }

    /// Operand A of lane `i` (for waveforms and testbenches).
    pub fn operand_a(&self, i: usize) -> W {
        match self.ctx.asrc {
            ASrc::Reg => self.regs.read(self.ctx.ra)[i],
            ASrc::Out => self.out[i],
            _ => self.ext[i],
        }
    }

    /// Operand B of lane `i`.
    pub fn operand_b(&self, i: usize) -> W {
        match self.ctx.b {
            BSrc::Reg(r) => self.regs.read(r)[i],
            BSrc::Imm(v) => W::imm(v),
        }
    }

    /// The RAM address of lane `i` in the cycle just evaluated (a `ld` or
    /// `st`).
    pub fn ram_addr(&self, i: usize) -> u16 {
        if self.uniform {
            self.addr0
        } else {
            self.addr[i]
        }
    }

    fn lane_fault(&self, lane: usize, msg: String) -> Fault {
        Fault::new(
            self.names.name(lane),
            format!("{msg} (context `{}`)", self.ctx),
        )
    }
}

/// Apply a unary or binary lane function to every lane.
macro_rules! map {
    ($res:expr, |$i:ident| $e:expr) => {
        for $i in 0..N {
            $res[$i] = $e;
        }
    };
}

/// Run a flag-producing ALU function over every lane. The flags are
/// gathered as 0 / -1 lanes of the loop's own width and packed by their
/// sign bits ([`SignBits::sign_mask`]).
#[inline(always)]
fn cv<W: Word, const N: usize>(
    res: &mut [W; N],
    f: impl Fn(usize) -> alu::Flagged<W>,
) -> (Mask, Mask) {
    let mut c = [W::ZERO; N];
    let mut v = [W::ZERO; N];
    for i in 0..N {
        let r = f(i);
        res[i] = r.value;
        c[i] = W::flag(r.c);
        v[i] = W::flag(r.v);
    }
    (W::sign_mask(&c), W::sign_mask(&v))
}

/// Is every lane of `x` alike? (An OR of differences: it vectorises,
/// where a comparison that stops at the first difference did not.)
#[inline(always)]
fn same<W: Word, const N: usize>(x: &[W; N]) -> bool {
    let x0 = x[0];
    x.iter().fold(W::ZERO, |m, &v| m | (v ^ x0)) == W::ZERO
}

/// Run a multiplier lane function (lane `i`'s new accumulator, result and
/// saturation) over every lane; returns the saturation mask. 32 lanes at a
/// time, each chunk's flags gathered into the mask at once (one loop over
/// all the lanes with the flags stored as a lane array and gathered after
/// it: `mul` 13.3 ns a context in `rc_array_op`, this 10.0).
#[inline(always)]
fn mul_lanes<W: Word, const N: usize>(
    res: &mut [W; N],
    acc_d: &mut [W::Acc; N],
    f: impl Fn(usize) -> (W::Acc, W, bool),
) -> Mask {
    const C: usize = 32;
    if N.is_multiple_of(C) {
        let mut m = 0;
        for k in 0..N / C {
            let mut r = [W::ZERO; C];
            let mut s = [W::Acc::default(); C];
            for j in 0..C {
                let (n, x, v) = f(k * C + j);
                acc_d[k * C + j] = n;
                r[j] = x;
                s[j] = W::Acc::flag(v);
            }
            res[k * C..k * C + C].copy_from_slice(&r);
            m |= W::Acc::sign_mask(&s) << (k * C);
        }
        return m;
    }
    let mut s = [W::Acc::default(); N];
    for i in 0..N {
        let (n, x, v) = f(i);
        acc_d[i] = n;
        res[i] = x;
        s[i] = W::Acc::flag(v);
    }
    W::Acc::sign_mask(&s)
}

/// Run a saturating function over every lane; returns the saturation mask.
#[inline(always)]
fn sat<W: Word, const N: usize>(res: &mut [W; N], f: impl Fn(usize) -> (W, bool)) -> Mask {
    let mut v = [W::ZERO; N];
    for i in 0..N {
        let (r, s) = f(i);
        res[i] = r;
        v[i] = W::flag(s);
    }
    W::sign_mask(&v)
}

/// The multiplier's output stage over every lane: the accumulator shifted
/// right by `sh` (rounded unless `trunc`) and saturated to the word;
/// returns the saturated lanes. The rounding choice is made once, outside
/// the lane loop (`sh = 0` has no rounding bit either way).
#[inline(always)]
fn scale_lanes<W: Word, const N: usize>(
    acc: &[W::Acc; N],
    sh: u32,
    trunc: bool,
    res: &mut [W; N],
) -> Mask {
    if trunc || sh & (2 * W::BITS - 1) == 0 {
        sat(res, |i| W::scale(acc[i], sh, true))
    } else {
        sat(res, |i| W::scale(acc[i], sh, false))
    }
}

/// The flag F of every lane for `cmp` (before the merge with the executing
/// lanes): the condition chosen once, each arm a loop over the lanes (the
/// condition inside the loop kept it from vectorising).
#[inline(always)]
fn cmp_mask<W: Word, const N: usize>(
    cond: Cond,
    a: &[W; N],
    b: &[W; N],
    cf: Mask,
    vf: Mask,
) -> Mask {
    macro_rules! by {
        ($k:expr) => {{
            let mut f = [W::ZERO; N];
            for i in 0..N {
                f[i] = W::flag(W::cond($k, a[i], b[i], false, false));
            }
            W::sign_mask(&f)
        }};
    }
    match cond {
        Cond::Eq => by!(Cond::Eq),
        Cond::Ne => by!(Cond::Ne),
        Cond::Lt => by!(Cond::Lt),
        Cond::Ge => by!(Cond::Ge),
        Cond::Le => by!(Cond::Le),
        Cond::Gt => by!(Cond::Gt),
        Cond::Ltu => by!(Cond::Ltu),
        Cond::Geu => by!(Cond::Geu),
        Cond::Leu => by!(Cond::Leu),
        Cond::Gtu => by!(Cond::Gtu),
        Cond::Bit => by!(Cond::Bit),
        Cond::Nbit => by!(Cond::Nbit),
        Cond::Cs => cf & full(N),
        Cond::Vs => vf & full(N),
        Cond::True => full(N),
        Cond::False => 0,
    }
}

impl<const N: usize, W: Word> Clocked for RcArray<N, W> {
    fn eval(&mut self) -> Result<(), Fault> {
        self.eval_lanes()
    }

    fn commit(&mut self) {
        if self.en != 0 {
            self.commit_lanes();
        }
    }
}

/// What the clock edge of each kind of operation writes.
const P_NONE: Pending = Pending {
    result: false,
    cv: false,
    f: false,
    acc: false,
    store: false,
};
const P_RES: Pending = Pending {
    result: true,
    ..P_NONE
};
const P_CV: Pending = Pending { cv: true, ..P_RES };
const P_MUL: Pending = Pending { acc: true, ..P_CV };
const P_F: Pending = Pending { f: true, ..P_NONE };
const P_ACC: Pending = Pending {
    acc: true,
    ..P_NONE
};
const P_ST: Pending = Pending {
    store: true,
    ..P_NONE
};

impl<const N: usize, W: Word> RcArray<N, W> {
    crate::simd::versions! {
        /// [`Clocked::eval`] and [`Clocked::commit`] in one call (nothing
        /// samples between the two): each operation's clock edge is written
        /// in its own arm, knowing what it writes (no branch on the pending
        /// updates).
        pub fn step(&mut self) -> Result<(), Fault>;
        versions step_portable step_avx2 step_avx512;
        { self.exec::<true>() }
    }

    crate::simd::versions! {
        /// [`Clocked::eval`]: the evaluation alone (the clock edge left
        /// pending for [`Clocked::commit`]).
        fn eval_lanes(&mut self) -> Result<(), Fault>;
        versions eval_portable eval_avx2 eval_avx512;
        { self.exec::<false>() }
    }

    crate::simd::versions! {
        /// [`Clocked::commit`] of the enabled lanes: the pending updates'
        /// clock edge.
        fn commit_lanes(&mut self) -> ();
        versions commit_portable commit_avx2 commit_avx512;
        {
            self.write_back(self.pend);
            self.sleep_wake();
        }
    }

    /// The evaluation; with `STEP` the clock edge too.
    #[inline(always)]
    fn exec<const STEP: bool>(&mut self) -> Result<(), Fault> {
        // What the clock edge writes: with `STEP` written now, each arm
        // knowing its kind, else left pending for `commit`.
        macro_rules! fin {
            ($p:expr) => {
                // The arms' kinds agree with the ISA's table of the
                // operations with a result (tests run with debug assertions).
                debug_assert_eq!($p.result, self.ctx.op.has_result(), "{:?}", self.ctx.op);
                if STEP {
                    self.write_back($p)
                } else {
                    self.pend = $p
                }
            };
        }
        // The fields one at a time (a copy of the whole context was one
        // wide load reaching past it into `lane_enable`, both just stored
        // by the array: the load could not be forwarded and stalled).
        let c = &self.ctx;
        let en = self.enabled();
        self.en = en;
        if !STEP {
            // (nothing pending if the evaluation faults)
            self.pend = P_NONE;
        }
        if en == 0 {
            return Ok(());
        }
        let imm;
        let a: &[W; N] = match c.asrc {
            ASrc::Reg => &self.regs.r[c.ra as usize],
            ASrc::Out => &self.out,
            _ => &self.ext,
        };
        let b: &[W; N] = match c.b {
            BSrc::Reg(r) => &self.regs.r[r as usize],
            BSrc::Imm(v) => {
                imm = [W::imm(v); N];
                &imm
            }
        };
        let res = &mut self.res;
        let (sh, trunc) = (c.shift as u32, c.trunc);
        let cin = self.flags.c;
        match c.op {
            Op::Nop | Op::Sleep | Op::Wake => {
                fin!(P_NONE);
                if STEP {
                    self.sleep_wake();
                }
            }
            Op::Add => {
                (self.d_c, self.d_v) = cv(res, |i| W::add(a[i], b[i], false));
                fin!(P_CV);
            }
            Op::Adc => {
                (self.d_c, self.d_v) = cv(res, |i| W::add(a[i], b[i], cin >> i & 1 != 0));
                fin!(P_CV);
            }
            Op::Sub => {
                (self.d_c, self.d_v) = cv(res, |i| W::sub(a[i], b[i], false));
                fin!(P_CV);
            }
            Op::Sbc => {
                (self.d_c, self.d_v) = cv(res, |i| W::sub(a[i], b[i], cin >> i & 1 != 0));
                fin!(P_CV);
            }
            Op::Rsb => {
                (self.d_c, self.d_v) = cv(res, |i| W::sub(b[i], a[i], false));
                fin!(P_CV);
            }
            Op::Neg => {
                (self.d_c, self.d_v) = cv(res, |i| W::sub(W::ZERO, a[i], false));
                fin!(P_CV);
            }
            Op::Adds => {
                self.d_v = sat(res, |i| W::adds(a[i], b[i]));
                self.d_c = 0;
                fin!(P_CV);
            }
            Op::Subs => {
                self.d_v = sat(res, |i| W::subs(a[i], b[i]));
                self.d_c = 0;
                fin!(P_CV);
            }
            Op::Abs => {
                self.d_v = sat(res, |i| W::abs(a[i]));
                self.d_c = 0;
                fin!(P_CV);
            }
            Op::Absd => {
                self.d_v = sat(res, |i| W::absd(a[i], b[i]));
                self.d_c = 0;
                fin!(P_CV);
            }
            Op::Asl => {
                self.d_v = sat(res, |i| W::asl(a[i], W::amount(b[i])));
                self.d_c = 0;
                fin!(P_CV);
            }
            Op::And => {
                map!(res, |i| a[i] & b[i]);
                fin!(P_RES);
            }
            Op::Or => {
                map!(res, |i| a[i] | b[i]);
                fin!(P_RES);
            }
            Op::Xor => {
                map!(res, |i| a[i] ^ b[i]);
                fin!(P_RES);
            }
            Op::Not => {
                map!(res, |i| !a[i]);
                fin!(P_RES);
            }
            Op::Mov => {
                *res = *a;
                fin!(P_RES);
            }
            Op::Movb => {
                *res = *b;
                fin!(P_RES);
            }
            Op::Min => {
                map!(res, |i| a[i].min(b[i]));
                fin!(P_RES);
            }
            Op::Max => {
                map!(res, |i| a[i].max(b[i]));
                fin!(P_RES);
            }
            Op::Clz => {
                map!(res, |i| W::clz(a[i]));
                fin!(P_RES);
            }
            Op::Sel => {
                let f = self.flags.f;
                if N.is_multiple_of(8) {
                    // F expanded to 0 / -1 lanes and blended (the bit
                    // tested lane by lane did not vectorise).
                    let m = expand::<W, N>(f);
                    map!(res, |i| (a[i] & m[i]) | (b[i] & !m[i]))
                } else {
                    map!(res, |i| if f >> i & 1 != 0 { a[i] } else { b[i] })
                }
                fin!(P_RES);
            }
            Op::Cmp => {
                self.d_f = cmp_mask(c.cond(), a, b, self.flags.c, self.flags.v);
                fin!(P_F);
            }
            Op::Sll => {
                map!(res, |i| W::sll(a[i], W::amount(b[i])));
                fin!(P_RES);
            }
            Op::Srl => {
                map!(res, |i| W::srl(a[i], W::amount(b[i])));
                fin!(P_RES);
            }
            Op::Sra => {
                map!(res, |i| W::sra(a[i], W::amount(b[i])));
                fin!(P_RES);
            }
            Op::Mul | Op::Mac | Op::Msu => {
                let acc = &self.acc;
                let acc_d = &mut self.acc_d;
                // One loop per operation and rounding choice (chosen once,
                // outside the lanes; `sh = 0` has no rounding bit either
                // way): the product is scaled while it is in a register,
                // not stored and loaded back.
                macro_rules! lanes {
                    ($trunc:expr) => {
                        match c.op {
                            Op::Mul => mul_lanes(res, acc_d, |i| {
                                let p = W::product(a[i], b[i]);
                                let (r, s2) = W::scale(p, sh, $trunc);
                                (p, r, s2)
                            }),
                            _ => {
                                let sub = c.op == Op::Msu;
                                mul_lanes(res, acc_d, |i| {
                                    let p = W::product(a[i], b[i]);
                                    let (n, s1) = W::accumulate(acc[i], p, sub);
                                    let (r, s2) = W::scale(n, sh, $trunc);
                                    (n, r, s1 | s2)
                                })
                            }
                        }
                    };
                }
                let v = if trunc || sh & (2 * W::BITS - 1) == 0 {
                    lanes!(true)
                } else {
                    lanes!(false)
                };
                (self.d_v, self.d_c) = (v, 0);
                fin!(P_MUL);
            }
            Op::Acc => {
                self.d_v = scale_lanes(&self.acc, sh, trunc, res);
                self.d_c = 0;
                fin!(P_CV);
            }
            Op::Acch => {
                map!(res, |i| W::acch(self.acc[i]));
                fin!(P_RES);
            }
            Op::Accl => {
                map!(res, |i| W::accl(self.acc[i]));
                fin!(P_RES);
            }
            Op::Ldacc => {
                let acc_d = &mut self.acc_d;
                // The shift the tracer uses (a Q.14 or Q.30 product's
                // scale) cannot saturate: no clamp in a wider type.
                let sh = sh & (2 * W::BITS - 1);
                if sh < W::BITS {
                    for i in 0..N {
                        acc_d[i] = W::ldacc_narrow(a[i], sh);
                    }
                } else {
                    for i in 0..N {
                        acc_d[i] = W::ldacc(a[i], sh);
                    }
                }
                fin!(P_ACC);
            }
            Op::Ld | Op::St => {
                let store = c.op == Op::St;
                // lane 0's address from its operands
                let a0 = if store {
                    W::addr1(b[0])
                } else {
                    W::addr(a[0], b[0])
                };
                // One address in every lane (constants, the stack, the hit
                // record): a whole RAM row, one address to check and keep;
                // otherwise one word per lane. Operands alike in every lane
                // (an immediate, one base) give one address without
                // computing 64; otherwise the addresses are compared.
                let b_same = matches!(c.b, BSrc::Imm(_)) || same(b);
                self.uniform = if b_same && (store || same(a)) {
                    true
                } else {
                    let mut addr = [0i32; N];
                    if store {
                        map!(addr, |i| W::addr1(b[i]));
                    } else {
                        map!(addr, |i| W::addr(a[i], b[i]));
                    }
                    let uniform = addr.iter().fold(true, |u, &x| u & (x == a0));
                    if !uniform {
                        let mut bad = [false; N];
                        for i in 0..N {
                            bad[i] = !Ram::<N, W>::valid(addr[i]);
                        }
                        let bad = lanes::pack_bools(&bad) & en;
                        if bad != 0 {
                            let i = bad.trailing_zeros() as usize;
                            let msg = format!("RAM address {} outside 0..=511", addr[i]);
                            return Err(self.lane_fault(i, msg));
                        }
                        for i in 0..N {
                            self.addr[i] = addr[i].clamp(0, 511) as u16;
                        }
                    }
                    uniform
                };
                if self.uniform {
                    if !Ram::<N, W>::valid(a0) {
                        let i = en.trailing_zeros() as usize;
                        let msg = format!("RAM address {a0} outside 0..=511");
                        return Err(self.lane_fault(i, msg));
                    }
                    self.addr0 = a0 as u16;
                }
                if store {
                    // A store has no result: `res` carries its data to the edge.
                    *res = *a;
                } else if self.uniform {
                    *res = *self.ram.row(self.addr0 as usize);
                } else {
                    for i in 0..N {
                        res[i] = self.ram.read(i, self.addr[i] as usize);
                    }
                }
                if store {
                    fin!(P_ST);
                } else {
                    fin!(P_RES);
                }
            }
        }
        Ok(())
    }

    /// The clock edge of the lanes that executed (not none): `p` says
    /// what it writes.
    #[inline(always)]
    fn write_back(&mut self, p: Pending) {
        let en = self.en;
        let c = self.ctx;
        if p.result {
            if en == Self::FULL || !N.is_multiple_of(8) {
                select_word(&mut self.out, en, &self.res);
                if c.we {
                    self.regs.write(c.rd, en, &self.res);
                }
            } else {
                // Some lanes: the mask expanded once for both writes.
                let m = expand::<W, N>(en);
                blend(&mut self.out, &m, &self.res);
                if c.we {
                    self.regs.write_lanes(c.rd, &m, &self.res);
                }
            }
        }
        if p.cv {
            // Two forms of the same merge: alike, the compiler did both
            // with one 16-byte load of `d_c` and `d_v`, which `eval` has
            // stored as two 8-byte words, and such a load waits until
            // both stores are written (no store forwarding).
            self.flags.c = Flags::merge(self.flags.c, en, self.d_c);
            self.flags.v = Flags::merge_xor(self.flags.v, en, self.d_v);
        }
        if p.f {
            self.flags.f = Flags::merge(self.flags.f, en, self.d_f);
        }
        if p.acc {
            W::select_acc(&mut self.acc, en, &self.acc_d);
        }
        if p.store {
            if self.uniform {
                select_word(self.ram.row_mut(self.addr0 as usize), en, &self.res);
            } else {
                for i in 0..N {
                    if en >> i & 1 != 0 {
                        self.ram.write(i, self.addr[i] as usize, self.res[i]);
                    }
                }
            }
        }
    }

    /// `sleep` and `wake` at the clock edge.
    #[inline(always)]
    fn sleep_wake(&mut self) {
        match self.ctx.op {
            Op::Sleep => self.flags.sleep |= self.en,
            Op::Wake => self.flags.sleep &= !self.en,
            _ => {}
        }
    }
}

impl<const N: usize, W: Word> fmt::Debug for RcArray<N, W> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "RcArray<{N}, {}> {{ ctx: {}, flags: {:?} }}",
            W::DATAPATH,
            self.ctx,
            self.flags
        )
    }
}
