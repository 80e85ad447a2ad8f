//! TinyRISC: the 32-bit control processor of MorphoSys, 16 registers.
//!
//! * [`decode`]: encoding, decoding, disassembly, the waveform filter.
//! * [`execute`]: the semantics and the [`Machine`] interface through which
//!   TinyRISC sees the array, the FB, the DMA and main memory.
//! * [`register_file`]: 16 x 32-bit, `r0` = 0, `r15` = link.
//!
//! Timing: an instruction issues in one cycle and then keeps TinyRISC busy
//! for its cost minus one cycles ([`RiscTiming`]); its effects land at the
//! clock edge of its issue cycle. An instruction that needs the array idle,
//! a free broadcast slot or a free DMA channel **stalls** (changes nothing
//! and is retried) until it gets it; stall cycles are counted by reason.

pub mod decode;
pub mod execute;
pub mod register_file;

pub(crate) use decode::INSTR_FILTER;
pub use decode::{Instr, Opcode};
pub use execute::{Command, Machine};
pub use register_file::RegisterFile;

use crate::trace::{Display, Field, LabelKind, Probe, Traced};

/// One instruction class's cycle count in [`RiscTiming`]: its key (the
/// field's name and its TOML key in `--timing` files), where its default
/// comes from (`morphosys timing` prints it), and the field.
#[derive(Clone, Copy)]
pub struct CycleField {
    pub key: &'static str,
    pub why: &'static str,
    pub get: fn(&RiscTiming) -> u32,
    pub set: fn(&mut RiscTiming, u32),
}

/// The instruction classes' cycle counts, declared once: the struct's
/// fields, their defaults and [`RiscTiming::CYCLES`] come from this list.
macro_rules! risc_timing {
    ($( $(#[doc = $doc:literal])* $name:ident = $default:literal, $why:literal; )*) => {
        /// Cycle cost of each instruction class (see `docs/isa.md`).
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub struct RiscTiming {
            $( $(#[doc = $doc])* pub $name: u32, )*
            /// How contexts reach the array (`docs/isa.md`, section 4).
            pub issue: IssueModel,
        }

        impl Default for RiscTiming {
            fn default() -> Self {
                RiscTiming {
                    $( $name: $default, )*
                    issue: IssueModel::Run,
                }
            }
        }

        impl RiscTiming {
            /// Every instruction class's cycle count, in the order
            /// `morphosys timing` prints them.
            pub const CYCLES: &'static [CycleField] = &[
                $( CycleField {
                    key: stringify!($name),
                    why: $why,
                    get: |t| t.$name,
                    set: |t, v| t.$name = v,
                }, )*
            ];
        }
    };
}

risc_timing! {
    alu = 1, "ours: a MIPS-like TinyRISC with a short pipeline (the M1 literature): one cycle for ALU, shift, lui, nop, rdcyc";
    mul = 2, "ours: a 32x32 multiply in two cycles";
    load = 2, "ours: main-memory loads (lw, lh, lhu, lb, lbu) with one load-use cycle";
    store = 1, "ours: stores (sw, sh, sb) retire into a write buffer";
    branch_taken = 2, "ours: one bubble for a taken branch (no delay slot, no prediction)";
    branch_not_taken = 1, "ours: a not-taken branch falls through";
    /// `j`, `jal`, `jr`, `jalr`.
    jump = 2, "ours: j, jal, jr, jalr, one bubble";
    fb_load = 2, "ours: lfb reads the frame buffer like a load";
    fb_store = 1, "ours: sfb writes the frame buffer like a store";
    /// `ldctxt`, `ldfb`, `stfb` (the transfer then runs on its own).
    dma_issue = 1, "ours: ldctxt, ldfb, stfb issue a transfer that then runs on its own";
    /// `dwait` once the channel is free.
    dwait = 1, "ours: dwait, once the channel is free";
    /// `cbcast`, `sbcb`, `dbcb`, `cbcr`, `cbcc` (the run then streams on its own).
    broadcast_issue = 1, "ours: cbcast, sbcb, dbcb, cbcr, cbcc issue a run (with issue = \"instruction\": at least this, and one cycle per context)";
    /// `wfb`: 64 words, one row of 8 per cycle.
    wfb = 8, "ours: 64 RC outputs into the FB, one row of 8 per cycle";
    rcrisc = 2, "ours: one RC's output into a TinyRISC register, like a load";
    /// `rcany`, `rcall`, `rcst`, `rcfl`, `rcfh`, `rcsl`, `rcsh`.
    status = 2, "ours: rcany, rcall, rcst, rcfl, rcfh, rcsl, rcsh: a 64-input reduction in two cycles (the paper: the status of all rays is sent to TinyRISC)";
    halt = 1, "ours";
}

/// How TinyRISC issues contexts to the array.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum IssueModel {
    /// This model's choice (the default): a run instruction (`cbcast`,
    /// `sbcb`, `dbcb`, `cbcr`, `cbcc`) takes `broadcast_issue` cycles and
    /// the broadcast unit streams its contexts, one per cycle, while
    /// TinyRISC goes on (one run in progress and one queued).
    #[default]
    Run,
    /// As in the M1 chip, where TinyRISC issues each context by an
    /// instruction: a run instruction keeps TinyRISC for one cycle per
    /// context (or row/column group) it issues (at least
    /// `broadcast_issue`), so the array waits whenever TinyRISC does
    /// anything else.
    Instruction,
}

impl IssueModel {
    pub const ALL: [IssueModel; 2] = [IssueModel::Run, IssueModel::Instruction];
    pub fn name(self) -> &'static str {
        match self {
            IssueModel::Run => "run",
            IssueModel::Instruction => "instruction",
        }
    }
}

impl std::str::FromStr for IssueModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        IssueModel::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("unknown issue model '{s}': expected run or instruction"))
    }
}

/// What a stalled instruction waits for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wait {
    #[default]
    None,
    /// The array idle (no run in progress or queued).
    ArrayIdle,
    /// A free broadcast slot.
    Issue,
    /// The DMA channel idle.
    Dma,
}

/// What TinyRISC did in the cycle just evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum State {
    /// An instruction issued.
    #[default]
    Issue = 0,
    /// A multi-cycle instruction is still busy.
    Busy = 1,
    /// Waiting for the array (idle or a free broadcast slot).
    StallArray = 2,
    /// Waiting for the DMA channel.
    StallDma = 3,
    Halted = 4,
}

/// Entries of the decoded-instruction cache.
pub(crate) const ICACHE: usize = 1024;

#[derive(Default)]
pub struct TinyRisc {
    pub pc: u32,
    pub regs: RegisterFile,
    pub timing: RiscTiming,
    busy: u32,
    halted: bool,
    /// Decoded-instruction cache, direct-mapped on the word address:
    /// (pc, word, decoded). Word 0 is never an instruction, so an empty
    /// entry never matches a real fetch.
    icache: Vec<(u32, u32, Instr)>,
    // ---- next state ----
    d_pc: u32,
    d_reg: Option<(u8, u32)>,
    d_busy: u32,
    d_halt: bool,
    /// The write of the instruction issued this cycle (applied by the chip).
    pub cmd: Command,
    /// What happened this cycle.
    pub state: State,
    /// What a stalled instruction waits for (with `state` StallArray or
    /// StallDma; `Wait::None` otherwise).
    pub wait: Wait,
    /// Instruction word of the last issue (waveforms).
    pub ir: u32,
    // ---- statistics ----
    pub issued: u64,
    pub stall_array: u64,
    pub stall_dma: u64,
    pub busy_cycles: u64,
    /// A simulator statistic, not a part of the chip: instruction
    /// addresses whose waits for the DMA are counted
    /// (`dma_waits_watched`: each time an instruction there starts to
    /// wait, however long it waits).
    pub dma_wait_watch: Vec<u32>,
    pub dma_waits_watched: u64,
    /// A simulator statistic, not a part of the chip: instruction
    /// addresses whose issues are counted (`issues_watched`), so that a
    /// program's statistics need not cost it cycles (the ray tracer: the
    /// leaves that look for their first piece in the leaf cache, and the
    /// misses).
    pub issue_watch: [Option<u32>; ISSUE_WATCH],
    pub issues_watched: [u64; ISSUE_WATCH],
}

/// Instruction addresses [`TinyRisc::issue_watch`] can count.
pub const ISSUE_WATCH: usize = 2;

impl TinyRisc {
    pub fn new(entry: u32, timing: RiscTiming) -> TinyRisc {
        TinyRisc {
            pc: entry,
            timing,
            icache: vec![(0, 0, Instr::new(decode::Opcode::Nop, 0, 0, 0, 0)); ICACHE],
            ..TinyRisc::default()
        }
    }

    pub fn halted(&self) -> bool {
        self.halted
    }

    /// Cycles left of the multi-cycle instruction in progress (0: the
    /// next cycle fetches).
    #[inline(always)]
    pub fn busy(&self) -> u32 {
        self.busy
    }

    /// `n` (at most [`TinyRisc::busy`]) busy cycles at once, exactly as
    /// `n` evaluations and clock edges would leave TinyRISC (the chip's
    /// fast path while nothing else on the chip is working).
    #[inline(always)]
    pub fn skip_busy(&mut self, n: u32) {
        debug_assert!(n <= self.busy && !self.halted);
        self.busy -= n;
        self.busy_cycles += n as u64;
        self.d_busy = self.busy;
        self.d_pc = self.pc;
        self.d_reg = None;
        self.d_halt = false;
        self.cmd = Command::None;
        self.state = State::Busy;
    }

    /// `n` more cycles of the stall evaluated last (the chip's fast path:
    /// a stalled instruction changes nothing but its counter).
    #[inline(always)]
    pub fn add_stalled(&mut self, n: u64) {
        match self.state {
            State::StallArray => self.stall_array += n,
            State::StallDma => self.stall_dma += n,
            _ => debug_assert!(n == 0, "add_stalled while {:?}", self.state),
        }
    }

    /// Clock edge.
    #[inline]
    pub fn commit(&mut self) {
        match self.state {
            State::Issue => {
                self.issued += 1;
                for (w, n) in self.issue_watch.iter().zip(&mut self.issues_watched) {
                    if *w == Some(self.pc) {
                        *n += 1;
                    }
                }
            }
            State::Busy => self.busy_cycles += 1,
            State::StallArray => self.stall_array += 1,
            State::StallDma => self.stall_dma += 1,
            State::Halted => return,
        }
        self.pc = self.d_pc;
        if let Some((k, v)) = self.d_reg {
            self.regs.write(k, v);
        }
        self.busy = self.d_busy;
        self.halted = self.d_halt;
    }
}

const REG_NAMES: [&str; 16] = [
    "r0", "r1", "r2", "r3", "r4", "r5", "r6", "r7", "r8", "r9", "r10", "r11", "r12", "r13", "r14",
    "r15",
];

fn state_text(v: u64) -> Option<String> {
    Some(
        ["issue", "busy", "stall_array", "stall_dma", "halted"]
            .get(v as usize)?
            .to_string(),
    )
}

pub(crate) static STATE_FILTER: crate::trace::Filter = crate::trace::Filter {
    name: "tinyrisc_state",
    text: state_text,
};

impl Traced for TinyRisc {
    fn trace<P: Probe>(&self, p: &mut P) {
        p.block_with(
            &|| {
                vec![
                    Field::new("", "pc", 32, Display::Label(LabelKind::Code)),
                    Field::new("", "ir", 32, Display::Translate(&INSTR_FILTER)),
                    Field::new("", "state", 3, Display::Translate(&STATE_FILTER)),
                ]
            },
            |v| *v = [self.pc as u64, self.ir as u64, self.state as u64],
        );
        // The register file, skipped by a waveform while no instruction
        // issues (only an issuing cycle writes a register, and `issued`
        // counts them; the register file keeps no counter of its own, which
        // would sit among the hot fields of the untraced path).
        p.block_versioned(
            self.issued,
            &|| {
                REG_NAMES
                    .map(|r| Field::new("regs", r, 32, Display::Hex))
                    .to_vec()
            },
            &mut |v| {
                for (k, v) in v.iter_mut().enumerate() {
                    *v = self.regs.read(k as u8) as u64;
                }
            },
        );
    }
}
