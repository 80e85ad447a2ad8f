//! The MorphoSys chip: TinyRISC, the context broadcast unit, the 8x8 RC
//! array with its interconnect, the frame buffer, the context memory, the
//! DMA controller and main memory, wired together.
//!
//! ```text
//!               +-----------+   commands    +-------------------+
//!   main mem <->| TinyRISC  |-------------->| broadcast unit    |--contexts--+
//!      ^        +-----------+  (Machine)    +-------------------+            v
//!      |             | status, rcrisc            |  fb0/fb1 streams  +--------------+
//!      v             +------------------------------------------- ---| 8x8 RC array |
//!   +-----+   ldfb/stfb   +--------------+     broadcast            +--------------+
//!   | DMA |-------------->| frame buffer |------------------------------^     | wfb
//!   +-----+   ldctxt      +--------------+<------------------------------------+
//!      +----------------->| context memory (decoded) |
//! ```
//!
//! One [`Chip::eval`] + [`Chip::commit`] is one 300 MHz cycle. Every cycle
//! parameter is in [`Timing`]; [`Stats`] counts cycles, array busy cycles,
//! active RCs, stalls.

use crate::array::Array;
use crate::broadcast::Broadcast;
use crate::context_memory::ContextMemory;
use crate::dma::{Dma, DmaTiming};
use crate::fb::{self, FrameBuffer};
use crate::kernel::{Clocked, Fault, Sim, StepError};
use crate::memory::MainMemory;
use crate::rc::context::Context;
use crate::rc::{Datapath, Word};
use crate::tinyrisc::{decode, Command, Machine, RiscTiming, TinyRisc};
use crate::trace::{Display, Field, LabelKind, Probe, Traced};

mod fast;
pub(crate) use fast::{run_to_halt16, run_to_halt32};

/// Every cycle parameter of the chip.
///
/// Fixed by the architecture (not parameters): the array executes one
/// context (or one row/column group) per cycle; a run's first context
/// executes in the cycle after the issuing instruction; the FB supplies one
/// datum per set per cycle; `wfb` moves one row of 8 outputs per cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Timing {
    pub risc: RiscTiming,
    pub dma: DmaTiming,
    /// Clock for reporting (frames/s, waveform time): 300 MHz.
    pub clock_hz: u64,
}

impl Default for Timing {
    fn default() -> Self {
        Timing {
            risc: RiscTiming::default(),
            dma: DmaTiming::default(),
            clock_hz: 300_000_000,
        }
    }
}

/// Run statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    pub cycles: u64,
    /// Cycles in which the array executed a context.
    pub array_busy_cycles: u64,
    /// Sum over cycles of the RCs that executed.
    pub active_rc_cycles: u64,
    pub risc_instructions: u64,
    pub risc_busy_cycles: u64,
    /// TinyRISC cycles lost waiting for the array.
    pub array_stall_cycles: u64,
    /// TinyRISC cycles lost waiting for the DMA channel.
    pub dma_stall_cycles: u64,
    /// Cycles in which the array executed no context while TinyRISC was
    /// not waiting for the DMA: the array waits for control.
    pub array_idle_control_cycles: u64,
    pub dma_busy_cycles: u64,
    pub dma_words: u64,
    pub dma_transfers: u64,
    /// Waits for the DMA that started at the instructions TinyRISC
    /// watches (`TinyRisc::dma_wait_watch`; the ray tracer: a leaf piece's
    /// `dwait` before its tests).
    pub dma_waits_watched: u64,
    /// Issues of the instructions TinyRISC watches
    /// (`TinyRisc::issue_watch`), per watched address.
    pub issues_watched: [u64; crate::tinyrisc::ISSUE_WATCH],
    /// Per class of [`Watch`], runs started at a watched address and the
    /// RCs that executed their first context.
    pub watched_runs: [u64; 2],
    pub watched_rcs: [u64; 2],
    /// `watched_rcs` split by the [`Watch`] tag in effect when the run
    /// started.
    pub watched_rcs_by_tag: [[u64; WATCH_TAGS]; 2],
    /// For each class-0 run, the RCs of the latest class-1 run, summed
    /// (the ray tracer: every object test broadcast times the rays of its
    /// pass, the tests the array spent its lanes on).
    pub watched_offered: u64,
}

/// Tags a [`Watch`] can split its counts by.
pub const WATCH_TAGS: usize = 4;

/// A simulator statistic, not a part of the chip: context addresses whose
/// runs are counted when they start, with the RCs that execute their first
/// context, in two classes (the ray tracer: the object tests' kernels, and
/// the kernel that starts a ray pass), and split by a tag: a run that
/// starts at a tagging address sets the tag for the runs that follow (the
/// ray tracer: the kernels that set up eye, shadow and reflected rays).
/// Costs nothing while empty.
#[derive(Clone, Debug, Default)]
pub struct Watch {
    any: bool,
    class: std::collections::HashMap<u16, WatchEntry>,
    tag: usize,
    runs: [u64; 2],
    rcs: [u64; 2],
    rcs_by_tag: [[u64; WATCH_TAGS]; 2],
    /// The RCs of the latest class-1 run, and `offered` its sum over the
    /// class-0 runs since.
    last1: u64,
    offered: u64,
}

#[derive(Clone, Copy, Debug, Default)]
struct WatchEntry {
    class: Option<usize>,
    tag: Option<usize>,
}

impl Watch {
    /// Count runs that start at `ctx` in `class` (0 or 1).
    pub fn add(&mut self, ctx: u16, class: usize) {
        self.class.entry(ctx).or_default().class = Some(class.min(1));
        self.any = true;
    }

    /// A run that starts at `ctx` sets the tag (0..[`WATCH_TAGS`]) under
    /// which the runs that follow are counted; the tag is 0 until then.
    pub fn tag(&mut self, ctx: u16, tag: usize) {
        self.class.entry(ctx).or_default().tag = Some(tag.min(WATCH_TAGS - 1));
        self.any = true;
    }

    /// A run that starts at `ctx` has executed its first context on `rcs`
    /// RCs.
    #[inline(never)]
    fn count(&mut self, ctx: u16, rcs: u32) {
        if let Some(&e) = self.class.get(&ctx) {
            if let Some(t) = e.tag {
                self.tag = t;
            }
            if let Some(c) = e.class {
                let n = rcs as u64;
                self.runs[c] += 1;
                self.rcs[c] += n;
                self.rcs_by_tag[c][self.tag] += n;
                if c == 1 {
                    self.last1 = n;
                } else {
                    self.offered += self.last1;
                }
            }
        }
    }
}

impl Stats {
    /// Fraction of the RCs that executed, over the array's busy cycles.
    pub fn active_rc_fraction(&self) -> f64 {
        if self.array_busy_cycles == 0 {
            0.0
        } else {
            self.active_rc_cycles as f64 / (64.0 * self.array_busy_cycles as f64)
        }
    }
}

/// Every file a waveform of the chip at `wave` may come with (save file,
/// the units' translate filters, the firmware's label filters and Surfer
/// decoders), for checking outputs before a run.
pub fn waveform_side_files(wave: &std::path::Path) -> Vec<(std::path::PathBuf, String)> {
    crate::trace::side_files(
        wave,
        &[
            crate::tinyrisc::decode::INSTR_FILTER.name,
            crate::tinyrisc::STATE_FILTER.name,
            crate::rc::OP_FILTER.name,
            crate::rc::CTX_FILTER.name,
        ],
    )
}

/// The chip, generic over its datapath word: `Chip` (= `Chip<i16>`) is the
/// paper's 16-bit chip, `Chip<i32>` the 32-bit variant ([`Chip::new_wide`]);
/// see `docs/isa.md`, "The 32-bit datapath".
pub struct Chip<W: Word = i16> {
    pub risc: TinyRisc,
    pub bcast: Broadcast,
    pub array: Array<W>,
    pub ctx_mem: ContextMemory,
    pub fb: FrameBuffer<W>,
    pub mem: MainMemory,
    pub dma: Dma,
    pub timing: Timing,
    cycles: u64,
    array_busy: u64,
    active_rc: u64,
    idle_control: u64,
    /// Runs counted for the statistics ([`Watch`]).
    pub watch: Watch,
    /// The fast loops stop before a cycle in which TinyRISC's PC is this
    /// ([`run_to_pc`]; `NO_STOP`: never).
    stop_pc: u32,
    /// [`run_to_halt`] and [`run_to_pc`] step every cycle through the
    /// plain model: one [`Clocked::eval`] and [`Clocked::commit`] per cycle
    /// (`Sim::step`), no fast path. Slower, and the same cycles, states,
    /// statistics and waveforms (`--plain` on `render`, `run` and `bench`).
    pub plain: bool,
}

/// [`Chip::stop_pc`] when no run stops at a PC (no instruction is fetched
/// from an unaligned address).
const NO_STOP: u32 = u32::MAX;

/// The parts of the chip's walk ([`Traced::trace`]) a fast loop reports
/// unchanged with a sample ([`crate::trace::Probe::unchanged`]): TinyRISC,
/// which waits through a stream after its first cycle, neither evaluated
/// nor clocked ([`Chip::stream`])...
pub(crate) const UNCHANGED_RISC: u8 = 1;
/// ... and the broadcast unit, the DMA and the array, in a cycle in which
/// TinyRISC alone worked, as it did in the cycle before
/// ([`Chip::local_cycles`]).
pub(crate) const UNCHANGED_ARRAY_SIDE: u8 = 2;

/// TinyRISC's view of the chip.
struct View<'a, W: Word> {
    array: &'a Array<W>,
    bcast: &'a Broadcast,
    fb: &'a FrameBuffer<W>,
    mem: &'a MainMemory,
    dma: &'a Dma,
    cycles: u64,
}

fn dma_conflict(dma: &Dma, bank: usize, what: &str) -> Fault {
    let (req, pc) = dma.current().expect("owned bank implies a transfer");
    Fault::new(
        "fb",
        format!(
            "DMA conflict: {what} FB bank {bank} while `{}` (issued at pc 0x{pc:08x}) transfers it",
            req.kind.name()
        ),
    )
}

#[cold]
fn fetch_fault(mem: &MainMemory, pc: u32) -> Fault {
    let f = mem.fault(pc, 4);
    Fault::new("tinyrisc", format!("instruction fetch: {}", f.message))
}

impl<W: Word> Machine for View<'_, W> {
    #[inline(always)]
    fn fetch(&self, pc: u32) -> Result<u32, Fault> {
        match self.mem.word(pc) {
            Some(w) => Ok(w),
            None => Err(fetch_fault(self.mem, pc)),
        }
    }
    fn load(&self, addr: u32, size: u32) -> Result<u32, Fault> {
        self.mem.check(addr, size)?;
        Ok(self.mem.read(addr, size))
    }
    fn check_store(&self, addr: u32, size: u32) -> Result<(), Fault> {
        self.mem.check(addr, size)
    }
    fn fb_read(&self, addr: u16) -> Result<i32, Fault> {
        if self.dma.owned_fb_banks() >> fb::bank(addr) & 1 != 0 {
            return Err(dma_conflict(self.dma, fb::bank(addr), "TinyRISC reads"));
        }
        Ok(self.fb.read(addr).to_i64() as i32)
    }
    fn check_fb_write(&self, addr: u16, words: u32) -> Result<(), Fault> {
        let last = (addr as u32 + words.max(1) - 1).min(0xFFFF) as u16;
        for b in fb::bank(addr)..=fb::bank(last) {
            if self.dma.owned_fb_banks() >> b & 1 != 0 {
                return Err(dma_conflict(self.dma, b, "a write to"));
            }
        }
        Ok(())
    }
    fn rc_out(&self, lane: usize) -> i32 {
        self.array.rc.out[lane].to_i64() as i32
    }
    fn fb_word_bytes(&self) -> u32 {
        W::BITS / 8
    }
    fn rc_flags(&self) -> (u64, u64) {
        (self.array.rc.flags.f, self.array.rc.flags.sleep)
    }
    fn array_can_issue(&self) -> bool {
        self.bcast.can_issue()
    }
    fn array_idle(&self) -> bool {
        self.bcast.idle()
    }
    fn dma_idle(&self) -> bool {
        self.dma.idle()
    }
    fn mem_size(&self) -> usize {
        self.mem.size()
    }
    fn cycle(&self) -> u64 {
        self.cycles
    }
}

impl Chip {
    /// The paper's 16-bit chip.
    pub fn new(timing: Timing, mem_bytes: usize) -> Chip {
        Chip::build(timing, mem_bytes)
    }
}

impl Chip<i32> {
    /// The 32-bit datapath variant.
    pub fn new_wide(timing: Timing, mem_bytes: usize) -> Chip<i32> {
        Chip::build(timing, mem_bytes)
    }
}

impl<W: Word> Chip<W> {
    /// A chip of datapath `W` (`i16` or `i32`).
    pub fn build(timing: Timing, mem_bytes: usize) -> Chip<W> {
        Chip {
            risc: TinyRisc::new(0, timing.risc),
            bcast: Broadcast::default(),
            array: Array::new(),
            ctx_mem: ContextMemory::for_datapath(W::DATAPATH == Datapath::W32),
            fb: FrameBuffer::default(),
            mem: MainMemory::new(mem_bytes),
            dma: Dma::new(timing.dma),
            timing,
            cycles: 0,
            array_busy: 0,
            active_rc: 0,
            idle_control: 0,
            watch: Watch::default(),
            stop_pc: NO_STOP,
            plain: false,
        }
    }

    /// Load bytes into main memory (the program loader).
    pub fn load(&mut self, addr: u32, bytes: &[u8]) -> Result<(), Fault> {
        self.mem.load(addr, bytes)
    }

    /// Set TinyRISC's start address.
    pub fn set_entry(&mut self, pc: u32) {
        self.risc.pc = pc;
    }

    /// The datapath width.
    pub fn datapath(&self) -> Datapath {
        W::DATAPATH
    }

    pub fn halted(&self) -> bool {
        self.risc.halted()
    }

    pub fn stats(&self) -> Stats {
        Stats {
            cycles: self.cycles,
            array_busy_cycles: self.array_busy,
            active_rc_cycles: self.active_rc,
            risc_instructions: self.risc.issued,
            risc_busy_cycles: self.risc.busy_cycles,
            array_stall_cycles: self.risc.stall_array,
            dma_stall_cycles: self.risc.stall_dma,
            dma_waits_watched: self.risc.dma_waits_watched,
            issues_watched: self.risc.issues_watched,
            array_idle_control_cycles: self.idle_control,
            dma_busy_cycles: self.dma.busy_cycles,
            dma_words: self.dma.words_moved,
            dma_transfers: self.dma.transfers,
            watched_runs: self.watch.runs,
            watched_rcs: self.watch.rcs,
            watched_rcs_by_tag: self.watch.rcs_by_tag,
            watched_offered: self.watch.offered,
        }
    }

    /// TinyRISC's evaluation of the cycle, through its view of the chip.
    #[inline(always)]
    fn eval_risc(&mut self) -> Result<(), Fault> {
        let view = View {
            array: &self.array,
            bcast: &self.bcast,
            fb: &self.fb,
            mem: &self.mem,
            dma: &self.dma,
            cycles: self.cycles,
        };
        self.risc.eval(&view).map_err(|f| self.locate(f))
    }

    /// TinyRISC's write at the clock edge.
    #[inline(always)]
    fn apply(&mut self, cmd: Command) {
        match cmd {
            Command::None => {}
            Command::Store { addr, size, value } => self.mem.write(addr, size, value),
            Command::FbWrite { addr, value } => self.fb.write(addr, W::wrap(value as i64)),
            Command::Wfb { addr } => {
                for (i, v) in self.array.rc.out.iter().enumerate() {
                    self.fb.write(addr + i as u16, *v);
                }
            }
            Command::Dma(req) => self.dma.start(req, self.risc.pc),
            Command::Run(run) => self.bcast.issue(run),
        }
    }

    #[cold]
    fn count_watched(&mut self) {
        if let Some((run, 0, _)) = self.bcast.current() {
            self.watch.count(run.ctx, self.array.active_now);
        }
    }

    /// Add where TinyRISC is to a fault's message.
    fn locate(&self, mut f: Fault) -> Fault {
        let pc = self.risc.pc;
        let text = if self.mem.check(pc, 4).is_ok() {
            decode::disassemble(self.mem.read(pc, 4))
        } else {
            "?".to_string()
        };
        f.message = format!("{} [pc 0x{pc:08x}: `{text}`]", f.message);
        f
    }
}

impl<W: Word> Clocked for Chip<W> {
    #[inline(always)]
    fn eval(&mut self) -> Result<(), Fault> {
        self.eval_risc()?;
        if let Err(f) = self.bcast.eval(
            &self.ctx_mem,
            &self.fb,
            self.dma.owned_fb_banks(),
            self.dma.owned_ctx_banks(),
            &mut self.array,
        ) {
            return Err(self.locate(f));
        }
        if let Err(f) = self.array.eval() {
            return Err(self.locate(f));
        }
        Ok(())
    }

    #[inline]
    fn commit(&mut self) {
        self.array.commit();
        if self.array.is_active() {
            self.array_busy += 1;
            self.active_rc += self.array.active_now as u64;
            if self.watch.any {
                self.count_watched();
            }
        } else if self.risc.state != crate::tinyrisc::State::StallDma {
            self.idle_control += 1;
        }
        self.bcast.commit();
        self.dma
            .tick(&mut self.mem, &mut self.fb, &mut self.ctx_mem);
        self.apply(self.risc.cmd);
        self.risc.commit();
        self.cycles += 1;
    }
}

impl<W: Word> Traced for Chip<W> {
    fn trace<P: Probe>(&self, p: &mut P) {
        // Asked once which of the four are traced; the others are not
        // entered at all.
        const SCOPES: [&str; 4] = ["tinyrisc", "broadcast", "dma", "array"];
        let on = p.open_scopes(4, &mut |i| SCOPES[i].to_string());
        // TinyRISC, unchanged while it waits for a stream.
        let unchanged = p.unchanged();
        if p.section(unchanged & UNCHANGED_RISC != 0) {
            if on & 1 != 0 && p.scope(format_args!("tinyrisc")) {
                self.risc.trace(p);
                p.end();
            }
            p.end_section();
        }
        // The rest, unchanged while TinyRISC works alone.
        if !p.section(unchanged & UNCHANGED_ARRAY_SIDE != 0) {
            return;
        }
        if on & 2 != 0 && p.scope(format_args!("broadcast")) {
            p.block_with(
                &|| {
                    vec![
                        Field::new("", "busy", 1, Display::Bin),
                        Field::new("", "queued", 1, Display::Bin),
                        Field::new("", "run_ctx", 13, Display::Label(LabelKind::Context)),
                        Field::new("", "step", 14, Display::Hex),
                        Field::new("", "fb0_ptr", 16, Display::Hex),
                        Field::new("", "fb1_ptr", 16, Display::Hex),
                    ]
                },
                |v| {
                    // Idle: the context address all ones (no context:
                    // the label filter shows `idle`).
                    let (busy, ctx, k, ptr) = match self.bcast.current() {
                        Some((run, k, ptr)) => (1, run.ctx as u64, k as u64, ptr),
                        None => (0, (1 << 13) - 1, 0, [0, 0]),
                    };
                    *v = [
                        busy,
                        !self.bcast.can_issue() as u64,
                        ctx,
                        k,
                        ptr[0] as u64,
                        ptr[1] as u64,
                    ];
                },
            );
            p.end();
        }
        if on & 4 != 0 && p.scope(format_args!("dma")) {
            p.block_with(
                &|| {
                    vec![
                        Field::new("", "kind", 2, Display::Hex),
                        Field::new("", "mem", 32, Display::Hex),
                        Field::new("", "local", 16, Display::Hex),
                        Field::new("", "remaining", 16, Display::Hex),
                        Field::new("", "fb_banks", 4, Display::Bin),
                        Field::new("", "ctx_banks", 2, Display::Bin),
                    ]
                },
                |v| {
                    let (kind, mem, local) = match self.dma.current() {
                        Some((r, _)) => (r.kind as u64, r.mem as u64, r.local as u64),
                        None => (0, 0, 0),
                    };
                    *v = [
                        kind,
                        mem,
                        local,
                        self.dma.remaining() as u64,
                        self.dma.owned_fb_banks() as u64,
                        self.dma.owned_ctx_banks() as u64,
                    ];
                },
            );
            p.end();
        }
        if on & 8 != 0 && p.scope(format_args!("array")) {
            self.array.trace(p);
            p.end();
        }
        p.end_section();
    }
}

/// How a run ended.
#[derive(Debug)]
pub enum RunError {
    Step(StepError),
    /// The program did not halt within the cycle budget.
    MaxCycles {
        cycles: u64,
        pc: u32,
        text: String,
    },
}

impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RunError::Step(e) => write!(f, "{e}"),
            RunError::MaxCycles { cycles, pc, text } => write!(
                f,
                "cycle {cycles}: sim: no halt within {cycles} cycles [pc 0x{pc:08x}: `{text}`]"
            ),
        }
    }
}

impl std::error::Error for RunError {}

/// Run to `halt` through the plain model alone, one [`Sim::step`] a cycle:
/// what the fast paths of [`run_to_halt`] are held to.
pub fn run_to_halt_plain<W: Word>(
    sim: &mut Sim<Chip<W>>,
    max_cycles: u64,
) -> Result<u64, RunError> {
    while !sim.top.halted() {
        if sim.cycle() >= max_cycles {
            return Err(over_budget(sim));
        }
        sim.step().map_err(RunError::Step)?;
    }
    Ok(sim.cycle())
}

/// Run until TinyRISC's PC is `pc` before a cycle (that cycle not run;
/// at once when it already is) or it halts; returns whether it stopped at
/// `pc`. Through the fast paths unless the chip asks for the plain model
/// ([`Chip::plain`]): the same cycles, states and statistics as stepping
/// ([`Sim::step`]) until the PC is `pc`.
pub fn run_to_pc<W: Word>(
    sim: &mut Sim<Chip<W>>,
    pc: u32,
    max_cycles: u64,
) -> Result<bool, RunError> {
    if sim.top.plain {
        while !sim.top.halted() {
            if sim.top.risc.pc == pc {
                return Ok(true);
            }
            if sim.cycle() >= max_cycles {
                return Err(over_budget(sim));
            }
            sim.step().map_err(RunError::Step)?;
        }
        return Ok(false);
    }
    sim.top.stop_pc = pc;
    let r = run_to_halt(sim, max_cycles);
    sim.top.stop_pc = NO_STOP;
    r?;
    Ok(!sim.top.halted() && sim.top.risc.pc == pc)
}

/// Run to `halt`; returns the cycles used (the halt's cycle included).
/// Through the fast paths ([`fast`]) unless the chip asks for the plain
/// model ([`Chip::plain`]).
///
/// Both datapaths run through a copy of the loop compiled in this crate
/// ([`run_to_halt16`], [`run_to_halt32`]), not instantiated in the caller's:
/// each width's cycle loop is then compiled on its own, with this crate's
/// inlining decisions (a caller's instance runs slower).
pub fn run_to_halt<W: Word>(sim: &mut Sim<Chip<W>>, max_cycles: u64) -> Result<u64, RunError> {
    if sim.top.plain {
        return run_to_halt_plain(sim, max_cycles);
    }
    let any: &mut dyn std::any::Any = sim;
    if let Some(s) = any.downcast_mut::<Sim<Chip<i16>>>() {
        return run_to_halt16(s, max_cycles);
    }
    if let Some(s) = any.downcast_mut::<Sim<Chip<i32>>>() {
        return run_to_halt32(s, max_cycles);
    }
    unreachable!("Word is implemented by i16 and i32 only")
}

/// The error of a run stopped by its cycle budget, with TinyRISC's PC
/// and the instruction there.
#[cold]
pub fn over_budget<W: Word>(sim: &Sim<Chip<W>>) -> RunError {
    let pc = sim.top.risc.pc;
    let text = if sim.top.mem.check(pc, 4).is_ok() {
        decode::disassemble(sim.top.mem.read(pc, 4))
    } else {
        "?".into()
    };
    RunError::MaxCycles {
        cycles: sim.cycle(),
        pc,
        text,
    }
}

// Keep the decoded-context type in the public surface of the chip module.
pub type DecodedContext = Context;
