//! The Reconfigurable Cell, held lane-wise for `N` RCs at once.
//!
//! `RcArray<64>` is the datapath of the whole 8x8 array; `RcArray<1>` is a
//! single RC for testbenches. Each cycle one decoded [`Context`] drives every
//! lane: the operation is matched once, and the lanes are a loop inside it.
//!
//! Units, one file each: [`alu`], [`shifter`], [`multiplier`] (with the
//! accumulator), [`register_file`], [`ram`], [`flags`], plus the output
//! register `out` that the interconnect and the frame-buffer write path read.

/// Apply a unary or binary lane function to every lane.
macro_rules! map {
    ($res:expr, |$i:ident| $e:expr) => {
        for $i in 0..N {
            $res[$i] = $e;
        }
    };
}

pub mod alu;
pub mod context;
mod execute;
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
use context::{ASrc, BSrc, Context, Guard, Op};
use flags::Flags;
use lanes::{full, Mask};
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
        match c.op {
            Op::Nop | Op::Sleep | Op::Wake => {
                fin!(P_NONE);
                if STEP {
                    self.sleep_wake();
                }
            }
            Op::Add | Op::Adc | Op::Sub | Op::Sbc | Op::Rsb | Op::Neg => {
                (self.d_c, self.d_v) = execute::add_sub(c.op, a, b, self.flags.c, res);
                fin!(P_CV);
            }
            Op::Adds | Op::Subs | Op::Abs | Op::Absd | Op::Asl => {
                self.d_v = execute::saturating(c.op, a, b, res);
                self.d_c = 0;
                fin!(P_CV);
            }
            Op::And | Op::Or | Op::Xor | Op::Not | Op::Min | Op::Max | Op::Clz => {
                execute::logic(c.op, a, b, res);
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
            Op::Sel => {
                execute::select(self.flags.f, a, b, res);
                fin!(P_RES);
            }
            Op::Cmp => {
                self.d_f = execute::cmp_mask(c.cond(), a, b, self.flags.c, self.flags.v);
                fin!(P_F);
            }
            Op::Sll | Op::Srl | Op::Sra => {
                execute::shift(c.op, a, b, res);
                fin!(P_RES);
            }
            Op::Mul | Op::Mac | Op::Msu => {
                let (acc, acc_d) = (&self.acc, &mut self.acc_d);
                self.d_v = execute::multiply(c.op, a, b, acc, acc_d, res, (sh, trunc));
                self.d_c = 0;
                fin!(P_MUL);
            }
            Op::Acc => {
                self.d_v = execute::scale_lanes(&self.acc, sh, trunc, res);
                self.d_c = 0;
                fin!(P_CV);
            }
            Op::Acch | Op::Accl => {
                execute::acc_part(c.op, &self.acc, res);
                fin!(P_RES);
            }
            Op::Ldacc => {
                execute::load_acc(a, sh, &mut self.acc_d);
                fin!(P_ACC);
            }
            Op::Ld | Op::St => {
                let (store, at) = (c.op == Op::St, (&mut self.addr, &mut self.addr0));
                match execute::ram_address(c, a, b, en, store, at) {
                    Ok(uniform) => self.uniform = uniform,
                    Err((i, msg)) => return Err(self.lane_fault(i, msg)),
                }
                if store {
                    // A store has no result: `res` carries its data to the edge.
                    *res = *a;
                    fin!(P_ST);
                } else {
                    execute::load(&self.ram, self.uniform, self.addr0, &self.addr, res);
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
