//! Waveform tracing: VCD through the `vcd` crate, or FST (GTKWave's and
//! Surfer's compressed format; a path ending in `.fst`) through the
//! `fst-writer` crate, plus a GTKWave save file and translate-filter files
//! beside it.
//!
//! Modules describe their signals through one function, [`Traced::trace`],
//! which both declares them (once, when a tracer is attached) and reports
//! their values (each traced cycle). The tracer walks the same calls in the
//! same order in both phases, so names and values cannot drift apart.
//!
//! * Only cycles inside the window (`first`, `count`) are sampled; outside
//!   it, and with no tracer attached, the simulator pays nothing.
//! * A scope filter (`--trace-scope`) keeps only the signals whose path
//!   matches one of its patterns; a module skips a whole scope that nothing
//!   under it can match.
//! * A value is written only when it changed; the changes are formatted
//!   and written by a second thread (`waveform writer`), fed in batches,
//!   so the simulation does not wait for the formatting.
//! * A module asks once which of its scopes ([`Probe::open_scopes`]) and
//!   signals ([`Probe::traced_signals`]) are traced, and reports only
//!   those; a module's signals are one call ([`Probe::block`]), and a
//!   register file that changes only when its version does is skipped
//!   while the version holds ([`Probe::block_versioned`]).
//! * The values a cycle reports are kept and compared with the last ones
//!   written after the cycle's walk, 64 at a time into a mask of the
//!   changes; the changes go to the writing thread packed in 64-bit
//!   words, and it computes the clock edges' times.
//! * [`Traced::trace`] is generic over the probe: the walk is compiled
//!   for the [`Tracer`], its calls inline, and the declaring half of each
//!   call is a cold function of its own.
//! * Names are GTKWave- and Surfer-safe: letters, digits and `_`, scopes for
//!   hierarchy, never `name[3]` indices (`rc_r3_c4`, `r12`).
//!
//! Time: one clock period of `clock_hz` (300 MHz by default) per cycle, in
//! picoseconds; the rising edge of cycle `c` is at `c * 1e12 / clock_hz` ps
//! (rounded down). A `clk` and a `cycle` signal sit at the top.

use std::collections::BTreeSet;
use std::fmt;
use std::fs::File;
use std::io::{self, BufWriter, Seek, Write};
use std::path::{Path, PathBuf};

use vcd::TimescaleUnit;

/// How GTKWave should show a signal.
#[derive(Clone, Copy)]
pub enum Display {
    Hex,
    /// Signed decimal.
    Signed,
    Bin,
    /// Through a translate filter: `text(value)` gives the mnemonic.
    Translate(&'static Filter),
    /// An address, shown as `label+offset` of the program being run
    /// ([`TraceConfig::labels`]; hex without them); all ones is `idle`.
    Label(LabelKind),
}

impl Display {
    /// Does GTKWave show it through a filter file (its values are kept)?
    fn filtered(self) -> bool {
        matches!(self, Display::Translate(_) | Display::Label(_))
    }
}

/// Which labels an address signal is shown by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LabelKind {
    /// TinyRISC code: a byte address (the PC).
    Code,
    /// Context memory: a context word's index.
    Context,
}

impl LabelKind {
    /// The filter file's name (`<stem>.<name>.txt`).
    fn filter_name(self) -> &'static str {
        match self {
            LabelKind::Code => "code_labels",
            LabelKind::Context => "context_labels",
        }
    }
}

/// The labels of the program being run, by address: its TinyRISC code
/// (byte addresses) and its context memory (context indices), each sorted
/// by address. A waveform shows the PC and the broadcast unit's context
/// address as `label+offset` of the nearest label at or before it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Labels {
    pub code: Vec<(u32, String)>,
    pub context: Vec<(u32, String)>,
}

impl Labels {
    /// `label+offset` (offset in bytes for code, in contexts for context
    /// memory; `label` alone at the label), `None` before the first label.
    pub fn locate(&self, kind: LabelKind, addr: u32) -> Option<String> {
        let list = match kind {
            LabelKind::Code => &self.code,
            LabelKind::Context => &self.context,
        };
        let i = list.partition_point(|(a, _)| *a <= addr);
        let (a, name) = list.get(i.checked_sub(1)?)?;
        Some(match addr - a {
            0 => name.clone(),
            d => format!("{name}+{d}"),
        })
    }
}

/// An address's text: `label+offset`, or `idle` for all ones (no address:
/// the broadcast unit idle).
fn label_text(labels: &Labels, kind: LabelKind, width: u32, v: u64) -> Option<String> {
    if width < 64 && v == (1u64 << width) - 1 {
        Some("idle".to_string())
    } else {
        labels.locate(kind, v as u32)
    }
}

/// A translate filter: a name (the file is `<stem>.<name>.txt`) and the
/// function that turns a value into text (`None`: leave it as hex).
pub struct Filter {
    pub name: &'static str,
    pub text: fn(u64) -> Option<String>,
}

/// The visitor every traced module reports to.
pub trait Probe {
    /// Enter a scope. Returns `false` when nothing under it is traced; the
    /// caller then skips its contents and does not call [`Probe::end`].
    fn scope(&mut self, name: fmt::Arguments<'_>) -> bool;
    fn end(&mut self);
    /// Which of `n` sibling scopes, named `name(i)`, may hold traced
    /// signals (bit i). The caller then enters only those, so a probe
    /// that traces one RC of 64 is asked about 64 scopes once, not 64
    /// times a cycle. The answer must not change between calls in the
    /// same order (it is computed once, while declaring).
    fn open_scopes(&mut self, n: usize, name: &mut dyn FnMut(usize) -> String) -> u64 {
        let _ = name;
        if n >= 64 {
            u64::MAX
        } else {
            (1u64 << n) - 1
        }
    }
    /// A signal of `width` bits (1..=64) with its current value (only the
    /// low `width` bits are used).
    fn signal(&mut self, name: &str, width: u32, display: Display, value: u64);
    /// Several signals of one width and display in one call (a register
    /// file): the same as calling [`Probe::signal`] for each in turn.
    fn signal_row(&mut self, names: &[&str], width: u32, display: Display, values: &[u64]) {
        for (n, &v) in names.iter().zip(values) {
            self.signal(n, width, display, v);
        }
    }
    /// Which of the signals `names` of the current scope are traced (bit
    /// i); the caller then reports only those, and need not compute the
    /// others' values. Like [`Probe::open_scopes`], computed once while
    /// declaring.
    fn traced_signals(&mut self, names: &[&str]) -> u64 {
        if names.len() >= 64 {
            u64::MAX
        } else {
            (1u64 << names.len()) - 1
        }
    }
    /// A module's signals in one call: `fields()` describes them (called
    /// only while declaring) and `values[k]` is field k's value. The same
    /// as, for each run of consecutive fields with the same
    /// [`Field::scope`], entering that scope (none for `""`), calling
    /// [`Probe::signal`] for each field and leaving it; but one call a
    /// cycle instead of one per signal and scope.
    fn block(&mut self, fields: &dyn Fn() -> Vec<Field>, values: &[u64]) {
        let fields = fields();
        for (scope, run) in scope_runs(&fields) {
            let open = scope.is_empty() || self.scope(format_args!("{scope}"));
            if open {
                for (f, &v) in fields[run.clone()].iter().zip(&values[run]) {
                    self.signal(f.name, f.width, f.display, v);
                }
                if !scope.is_empty() {
                    self.end();
                }
            }
        }
    }
    /// [`Probe::block`] with its `N` values written by `fill` into the
    /// array it is given: a probe that keeps the values may give it its
    /// own storage, so that they are not gathered first and copied, and
    /// need not call it at all when none of the fields is traced (`fill`
    /// only computes values).
    fn block_with<const N: usize>(
        &mut self,
        fields: &dyn Fn() -> Vec<Field>,
        fill: impl FnOnce(&mut [u64; N]),
    ) where
        Self: Sized,
    {
        let mut v = [0; N];
        fill(&mut v);
        self.block(fields, &v);
    }
    /// A part of the walk, up to the matching [`Probe::end_section`],
    /// that reports (when `unchanged`) the values it reported in the last
    /// cycle sampled. `false`: the probe skips it (the caller does not
    /// walk it, nor call `end_section`). A probe that keeps the last
    /// values may skip it; the part must make the same calls every cycle.
    fn section(&mut self, unchanged: bool) -> bool {
        let _ = unchanged;
        true
    }
    /// The end of a [`Probe::section`] walked.
    fn end_section(&mut self) {}
    /// [`Probe::block`] for signals that change only when `version` does
    /// (a register file and its count of writes): `fill` writes their
    /// values into the slice it is given. A probe that remembers the
    /// version it saw at this call may skip the block while it is the
    /// same, without asking for the values.
    fn block_versioned(
        &mut self,
        version: u64,
        fields: &dyn Fn() -> Vec<Field>,
        fill: &mut dyn FnMut(&mut [u64]),
    ) {
        let _ = version;
        let f = fields();
        let mut values = vec![0; f.len()];
        fill(&mut values);
        self.block(&|| f.clone(), &values);
    }
}

/// The runs of consecutive fields in one scope: each scope and its range.
fn scope_runs(fields: &[Field]) -> Vec<(&'static str, std::ops::Range<usize>)> {
    let mut runs: Vec<(&'static str, std::ops::Range<usize>)> = Vec::new();
    for (k, f) in fields.iter().enumerate() {
        match runs.last_mut() {
            Some((scope, run)) if *scope == f.scope => run.end = k + 1,
            _ => runs.push((f.scope, k..k + 1)),
        }
    }
    runs
}

/// One signal of a [`Probe::block`].
#[derive(Clone, Copy)]
pub struct Field {
    /// The scope it sits in, under the scope the block is reported in
    /// (`""`: that scope itself).
    pub scope: &'static str,
    pub name: &'static str,
    pub width: u32,
    pub display: Display,
}

impl Field {
    pub const fn new(
        scope: &'static str,
        name: &'static str,
        width: u32,
        display: Display,
    ) -> Field {
        Field {
            scope,
            name,
            width,
            display,
        }
    }
}

/// A module that has signals. Generic over the probe, so that a waveform's
/// walk through the modules is compiled for the [`Tracer`] with its calls
/// inline (through `dyn Probe` a traced cycle cost some twenty indirect
/// calls).
pub trait Traced {
    fn trace<P: Probe>(&self, p: &mut P);
}

/// What to trace.
#[derive(Clone, Debug)]
pub struct TraceConfig {
    pub path: PathBuf,
    /// First cycle traced.
    pub first: u64,
    /// Number of cycles traced (`None`: to the end).
    pub count: Option<u64>,
    /// Comma-separated scope patterns (`*` and `?` globs per component);
    /// empty: everything.
    pub scope: String,
    pub clock_hz: u64,
    /// The most cycles the run can take (its cycle budget), if known: with
    /// an open-ended window the trace may cover all of them.
    pub budget_cycles: Option<u64>,
    /// Refuse, before writing anything, a trace whose estimated size
    /// exceeds this (default 4 GiB).
    pub max_bytes: u64,
    /// FST only: bytes of value changes held in memory before they are
    /// compressed into the file as one section ([`FST_SECTION_BYTES`]).
    pub fst_section_bytes: usize,
    /// The program's labels: the PC and the broadcast unit's context
    /// address are shown as `label+offset` (filter files beside the
    /// waveform).
    pub labels: Option<std::sync::Arc<Labels>>,
}

/// Whether a waveform path asks for FST (`.fst`) rather than VCD.
pub fn is_fst(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("fst"))
}

/// Value changes an FST writer holds in memory before it writes them out
/// as one compressed section (the default of
/// [`TraceConfig::fst_section_bytes`]).
pub const FST_SECTION_BYTES: usize = 64 << 20;

/// The largest waveform written by default (4 GiB).
pub const MAX_TRACE_BYTES: u64 = 4 << 30;

/// How many times smaller an FST is than the VCD of the same window, at
/// the least (measured on render windows: 11 to 19 times); the size
/// limits, counted in VCD bytes, allow an FST this many times more.
pub const FST_SMALLER: f64 = 10.0;

/// Estimated VCD bytes per traced signal per cycle: about a quarter of the
/// signals change in a typical cycle of the tracer, at about 8 bytes a
/// change (measured on `morphosys run` and `render` traces: 1.5 to 2.5).
pub const BYTES_PER_SIGNAL_CYCLE: f64 = 2.0;

impl TraceConfig {
    pub fn new(path: impl Into<PathBuf>) -> TraceConfig {
        TraceConfig {
            path: path.into(),
            first: 0,
            count: None,
            scope: String::new(),
            clock_hz: 300_000_000,
            budget_cycles: None,
            max_bytes: MAX_TRACE_BYTES,
            fst_section_bytes: FST_SECTION_BYTES,
            labels: None,
        }
    }
}

/// Where value changes go: a VCD text stream, or an FST file (header
/// while declaring, body while sampling).
enum Sink {
    /// The `vcd` crate writes the header; timestamps and value changes are
    /// formatted as bytes by [`VcdBody`] (`core::fmt` cost more than the
    /// simulation).
    Vcd(vcd::Writer<BufWriter<File>>, VcdBody),
    FstHeader(fst_writer::FstHeaderWriter<BufWriter<File>>),
    FstBody(fst_writer::FstBodyWriter<BufWriter<File>>),
    /// While sampling: value changes go in batches ([`Tracer::batch`])
    /// to a thread that writes them into the sink it owns (the simulation
    /// does not wait for the formatting); [`Sink::hand_last`] hands it
    /// the end.
    Threaded {
        queue: std::sync::Arc<Handoff>,
        worker: std::thread::JoinHandle<Written>,
        /// The values of the signals with translate filters, sent once
        /// the last batch is written (before the file is closed).
        seen: std::sync::mpsc::Receiver<Vec<BTreeSet<u64>>>,
    },
    /// Between the two FST phases, or after finishing.
    Gone,
}

/// What the writing thread hands back: the sink, closed, and how writing
/// went.
type Written = (Sink, io::Result<()>);

/// What the sampling thread hands the writing thread, packed in 64-bit
/// words (the messages are most of the traffic between the two cores):
///
/// * a sampled cycle `c` begins, `MSG_CYCLE << 48 | c` (or, from 2^48 on,
///   `MSG_LONG << 48` and `c` in the next word): the falling edge of the
///   cycle sampled before it, if any (its timestamp and `clk` 0), then
///   this cycle's rising edge (its timestamp, `clk` 1 and the `cycle`
///   counter); the writing thread computes the times;
/// * signal calls `64 j` to `64 j + 63` (in call order) changed in the
///   cycle: `MSG_CHUNK << 48 | j`, the mask of those that did (bit `k`:
///   call `64 j + k`), and their new values, one word each, in call order.
const MSG_CHUNK: u64 = 0xFFFD;
const MSG_CYCLE: u64 = 0xFFFE;
const MSG_LONG: u64 = 0xFFFF;
const MSG_VALUE: u64 = (1 << 48) - 1;

/// Words per batch handed to the writing thread (128 KB: a batch stays in
/// the cores' second-level caches);
/// at most [`QUEUED_BATCHES`] wait, so memory stays bounded when the disk
/// is slower than the simulation.
const BATCH: usize = 1 << 14;
const QUEUED_BATCHES: usize = 8;
/// Emptied batches the writing thread makes ready before the first comes.
const SPARE_BATCHES: usize = 3;

/// The batches between the two threads, handed over without a system
/// call while both are busy. A channel woke the writing thread at every
/// batch it waited for: a system call on the simulating thread each time
/// (0.5-1 ms of the bench's traced frame). Here the writing thread polls
/// every [`POLL`] while batches come, and only after [`IDLE_POLLS`] empty
/// polls says it is asleep and waits to be woken.
struct Handoff {
    full: std::sync::Mutex<std::collections::VecDeque<Vec<u64>>>,
    /// Emptied batches, for the simulating thread to fill again.
    empty: std::sync::Mutex<Vec<Vec<u64>>>,
    /// The writing thread waits to be woken.
    asleep: std::sync::atomic::AtomicBool,
    /// The simulating thread has handed over its last batch.
    done: std::sync::atomic::AtomicBool,
    /// Set before `done`: the time the waveform ends at, and the note to
    /// leave in it ([`Tracer::note`]).
    end: std::sync::Mutex<Option<(u64, Option<String>)>>,
    /// The writing thread takes no more batches (it ended or panicked).
    gone: std::sync::atomic::AtomicBool,
}

const POLL: std::time::Duration = std::time::Duration::from_micros(50);
const IDLE_POLLS: u32 = 20;

impl Handoff {
    fn new() -> Handoff {
        use std::sync::atomic::AtomicBool;
        Handoff {
            full: Default::default(),
            empty: Default::default(),
            asleep: AtomicBool::new(false),
            done: AtomicBool::new(false),
            end: Default::default(),
            gone: AtomicBool::new(false),
        }
    }

    /// Queue `batch` for the writing thread `writer`: at once while fewer
    /// than [`QUEUED_BATCHES`] wait, else once one is taken (the disk is
    /// slower than the simulation). `false`: the writing thread is gone.
    fn send(&self, batch: Vec<u64>, writer: &std::thread::Thread) -> bool {
        use std::sync::atomic::{fence, Ordering::SeqCst};
        let mut batch = Some(batch);
        loop {
            if self.gone.load(SeqCst) {
                return false;
            }
            {
                let mut q = self.full.lock().unwrap_or_else(|e| e.into_inner());
                if q.len() < QUEUED_BATCHES {
                    q.extend(batch.take());
                }
            }
            // Seen asleep after the batch is queued: wake it (it said so
            // before it looked at the queue a last time).
            fence(SeqCst);
            if self.asleep.swap(false, SeqCst) || batch.is_some() {
                writer.unpark();
            }
            if batch.is_none() {
                return true;
            }
            std::thread::sleep(POLL);
        }
    }

    /// The next batch, waiting for it; `None` once the last is taken.
    fn recv(&self) -> Option<Vec<u64>> {
        use std::sync::atomic::{fence, Ordering::SeqCst};
        let mut idle = 0;
        loop {
            let done = self.done.load(SeqCst);
            if let Some(b) = self
                .full
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .pop_front()
            {
                return Some(b);
            }
            if done {
                return None;
            }
            idle += 1;
            if idle < IDLE_POLLS {
                std::thread::park_timeout(POLL);
                continue;
            }
            self.asleep.store(true, SeqCst);
            fence(SeqCst);
            let empty = self
                .full
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .is_empty();
            if empty && !self.done.load(SeqCst) {
                std::thread::park();
            }
            self.asleep.store(false, SeqCst);
            idle = 0;
        }
    }

    /// An emptied batch for the simulating thread to fill again.
    fn give_back(&self, mut batch: Vec<u64>) {
        batch.clear();
        let mut e = self.empty.lock().unwrap_or_else(|e| e.into_inner());
        if e.len() < QUEUED_BATCHES + 2 {
            e.push(batch);
        }
    }
}

/// A waveform its writing thread is finishing ([`Sink::hand_last`]).
struct Closing {
    worker: std::thread::JoinHandle<Written>,
    seen: std::sync::mpsc::Receiver<Vec<BTreeSet<u64>>>,
    /// The last batch reached the thread.
    sent: bool,
}

impl Closing {
    /// Per traced signal the values it took if it has a translate filter,
    /// once every change is written; `None` when the thread ended without
    /// sending them ([`Closing::join`] then says how).
    fn seen(&self) -> Option<Vec<BTreeSet<u64>>> {
        self.seen.recv().ok()
    }

    /// Wait for the file to be closed; how writing went.
    fn join(self) -> io::Result<()> {
        let (_sink, res) = self
            .worker
            .join()
            .map_err(|_| io::Error::other("the waveform writer panicked"))?;
        res?;
        if !self.sent {
            return Err(io::Error::other("the waveform writer stopped"));
        }
        Ok(())
    }
}

/// Marks the [`Handoff`] gone when the writing thread ends, however.
struct WriterGone(std::sync::Arc<Handoff>);

impl Drop for WriterGone {
    fn drop(&mut self) {
        self.0.gone.store(true, std::sync::atomic::Ordering::SeqCst);
    }
}

/// Queue the start of cycle `c` for the writing thread.
#[inline(always)]
fn queue_cycle(batch: &mut Vec<u64>, c: u64) {
    if c <= MSG_VALUE {
        batch.push(MSG_CYCLE << 48 | c);
    } else {
        batch.push(MSG_LONG << 48);
        batch.push(c);
    }
}

/// Append `src` to `dst`. With AVX-512 the whole cache lines are stored
/// by non-temporal stores, which go to memory without taking the lines
/// into this core's caches: the sampling thread writes its messages into
/// one batch of its own that stays in its caches, and the copies the
/// writing thread reads never come back to it.
fn copy_streaming(dst: &mut Vec<u64>, src: &[u64]) {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
    {
        use std::arch::x86_64::*;
        dst.reserve(src.len());
        let len = dst.len();
        let out = dst.spare_capacity_mut().as_mut_ptr().cast::<u64>();
        // Words before the first 64-byte boundary, stored plainly.
        let head = (out.align_offset(64)).min(src.len());
        let lines = (src.len() - head) / 8;
        // SAFETY: every store lies inside the `src.len()` words of spare
        // capacity reserved above (`head + 8 * lines` <= `src.len()`), the
        // streaming ones at 64-byte boundaries (`align_offset`; should it
        // not know, `head` takes every word); all `src.len()` words after
        // `len` are written before `set_len`; the fence orders the
        // streaming stores before the batch is handed over.
        unsafe {
            for k in 0..head {
                out.add(k).write(src[k]);
            }
            for k in 0..lines {
                let at = head + 8 * k;
                let v = _mm512_loadu_si512(src.as_ptr().add(at).cast());
                _mm512_stream_si512(out.add(at).cast(), v);
            }
            for k in head + 8 * lines..src.len() {
                out.add(k).write(src[k]);
            }
            _mm_sfence();
            dst.set_len(len + src.len());
        }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx512f")))]
    dst.extend_from_slice(src);
}

/// A traced signal call's handle, width, whether its signal has a
/// translate filter, and its signal's index in declaration order.
type Slot = (SigId, u32, bool, u32);

/// One signal's handle in the file.
#[derive(Clone, Copy)]
enum SigId {
    /// Index into the VCD body's identifier codes.
    Vcd(u32),
    Fst(fst_writer::FstSignalId),
}

fn fst_err(e: fst_writer::FstWriteError) -> io::Error {
    match e {
        fst_writer::FstWriteError::Io(e) => e,
        e => io::Error::other(e.to_string()),
    }
}

/// The times of clock edges in picoseconds: the rising edge of cycle `c`
/// at `c * 1e12 / hz` rounded down. Consecutive cycles (the common case)
/// step by the period's quotient and remainder instead of dividing.
struct Clock {
    hz: u64,
    /// `1e12 / hz` and `1e12 % hz`.
    q: u64,
    r: u64,
    /// The last cycle asked for, its time and `c * 1e12 % hz`.
    c: u64,
    t: u64,
    rem: u64,
}

impl Clock {
    fn new(hz: u64) -> Clock {
        let hz = hz.max(1);
        Clock {
            hz,
            q: 1_000_000_000_000 / hz,
            r: 1_000_000_000_000 % hz,
            c: 0,
            t: 0,
            rem: 0,
        }
    }

    /// The time of cycle `c`'s rising edge.
    #[inline]
    fn time(&mut self, c: u64) -> u64 {
        if c == self.c.wrapping_add(1) {
            self.c = c;
            self.rem += self.r;
            // Without a branch: the carry comes every few cycles, at a
            // rhythm the branch predictor missed.
            let carry = (self.rem >= self.hz) as u64;
            self.rem -= carry * self.hz;
            self.t += self.q + carry;
        } else if c != self.c {
            let ps = c as u128 * 1_000_000_000_000u128;
            self.c = c;
            self.t = (ps / self.hz as u128) as u64;
            self.rem = (ps % self.hz as u128) as u64;
        }
        self.t
    }

    /// The rising and falling edges of cycle `c` (the fall half a period,
    /// rounded down, after the rise).
    #[inline]
    fn edges(&mut self, c: u64) -> (u64, u64) {
        let t = self.time(c);
        let next = self.time(c + 1);
        (t, t + (next - t) / 2)
    }
}

/// The 8 bits of `b` as ASCII `0`/`1`, most significant first, in the
/// bytes of a little-endian word: `b` copied into every byte, byte `j`
/// masked to bit `7 - j`, each nonzero byte turned into 1 (adding 0x7F
/// sets its top bit, with no carry out of the byte) and added to `'0'`.
#[inline(always)]
fn bin8(b: u8) -> u64 {
    const ONES: u64 = 0x0101_0101_0101_0101;
    let x = (b as u64).wrapping_mul(ONES) & 0x0102_0408_1020_4080;
    (((x + 0x7F * ONES) >> 7) & ONES) | (b'0' as u64 * ONES)
}

/// The `bits` significant binary digits of `v` (1 to 64), most
/// significant first, in ASCII at the start of `dst`, which takes 64
/// bytes (those after the digits are left undefined).
///
/// With AVX-512 all at once: the digits as the bits of a mask, first
/// digit lowest (`v` shifted up to its top bit and its bits reversed),
/// which picks `1` or `0` for each of 64 bytes; one store. Otherwise 8
/// at a time ([`bin8`]) from the most significant byte; each loop's end,
/// at a count of bytes that varies from value to value, was a branch the
/// predictor often missed.
#[inline(always)]
fn binary(dst: &mut [u8], v: u64, bits: usize) {
    let dst = &mut dst[..64];
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512bw"))]
    {
        use std::arch::x86_64::*;
        let digits = (v << (64 - bits)).reverse_bits();
        // SAFETY: a store of 64 bytes into the 64 of `dst`.
        unsafe {
            let ascii = _mm512_mask_blend_epi8(
                digits,
                _mm512_set1_epi8(b'0' as i8),
                _mm512_set1_epi8(b'1' as i8),
            );
            _mm512_storeu_si512(dst.as_mut_ptr().cast(), ascii);
        }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx512bw")))]
    {
        binary_portable(dst, v, bits);
    }
}

/// [`binary`] 8 digits at a time: the top byte's digits shifted down to
/// its significant ones, then whole bytes (the bytes stored past the
/// digits are overwritten by the next ones, or lie in the 64).
#[cfg_attr(
    all(target_arch = "x86_64", target_feature = "avx512bw"),
    allow(dead_code)
)]
#[inline(always)]
fn binary_portable(dst: &mut [u8], v: u64, bits: usize) {
    let bytes = bits.div_ceil(8);
    let top = bits - 8 * (bytes - 1);
    let first = bin8((v >> (8 * (bytes - 1))) as u8) >> (8 * (8 - top));
    dst[..8].copy_from_slice(&first.to_le_bytes());
    let mut k = top;
    for byte in (0..bytes - 1).rev() {
        dst[k..k + 8].copy_from_slice(&bin8((v >> (8 * byte)) as u8).to_le_bytes());
        k += 8;
    }
}

/// The 8 decimal digits of `x` < 10^8, most significant first, in the
/// bytes of a little-endian word (digit values, not ASCII): the halves
/// `x / 10^4` and `x % 10^4` in two 32-bit lanes, each split into
/// hundreds and the rest in 16-bit lanes, each of those into tens and
/// units in bytes; every division a multiplication by a reciprocal, exact
/// in its range.
#[inline(always)]
fn digits8(x: u64) -> u64 {
    let abcd_efgh = (x / 10_000) | ((x % 10_000) << 32);
    let ab_ef = ((abcd_efgh * 10_486) >> 20) & 0x0000_007F_0000_007F;
    let ab_cd_ef_gh = ab_ef | (abcd_efgh - ab_ef * 100) << 16;
    let a_c_e_g = ((ab_cd_ef_gh * 103) >> 10) & 0x000F_000F_000F_000F;
    a_c_e_g | (ab_cd_ef_gh - a_c_e_g * 10) << 8
}

/// The 16 decimal digits of `x` < 10^16 as byte values, the units in the
/// lowest byte.
#[inline(always)]
fn digits16(x: u64) -> u128 {
    (digits8(x / 100_000_000) as u128 | (digits8(x % 100_000_000) as u128) << 64).swap_bytes()
}

/// The times of a VCD (they only grow, mostly by the same few steps: half
/// a clock period, rounded down or up) in decimal, each the one before
/// plus the step, added 16 digits at once: the step's digits from a
/// table of four (refilled around a step not in it), the carries between
/// digits made by the addition itself (each digit biased by 246, so that
/// 10 or more carries out of its byte; those that did not carry out lose
/// the bias again).
struct Decimal {
    /// The last time, and its digits ([`digits16`]); `None` before the
    /// first one and after one of 10^16 or more.
    last: Option<(u64, u128)>,
    /// The steps in the table: `base` to `base + 3`.
    base: u64,
    steps: [u128; 4],
}

/// 10^16: the times [`Decimal`] writes are below.
const DECIMAL_LIMIT: u64 = 10_000_000_000_000_000;

impl Decimal {
    fn new() -> Decimal {
        Decimal {
            last: None,
            // No step (below 10^16) is within 4 of this one: the first
            // step refills the table.
            base: DECIMAL_LIMIT,
            steps: [0; 4],
        }
    }

    /// `t` in ASCII without leading zeros, in the low bytes of the result
    /// (the first digit in the lowest), and its digit count; `None` from
    /// 10^16 on.
    #[inline(always)]
    fn next(&mut self, t: u64) -> Option<(u128, usize)> {
        const BIAS: u128 = u128::from_le_bytes([246; 16]);
        const ONES: u128 = u128::from_le_bytes([1; 16]);
        const ZEROS: u128 = u128::from_le_bytes([b'0'; 16]);
        if t >= DECIMAL_LIMIT {
            self.last = None;
            return None;
        }
        let d = match self.last {
            Some((before, digits)) if t >= before => {
                let mut i = (t - before).wrapping_sub(self.base);
                if i >= 4 {
                    self.refill(t - before);
                    i = t - before - self.base;
                }
                let x = digits + self.steps[(i & 3) as usize] + BIAS;
                x - ((x >> 7) & ONES) * 246
            }
            _ => digits16(t),
        };
        self.last = Some((t, d));
        let n = 16 - ((d | 1).leading_zeros() / 8) as usize;
        Some(((d.swap_bytes() | ZEROS) >> (8 * (16 - n)), n))
    }

    /// The table around `step`: `step - 1` to `step + 2`.
    #[cold]
    #[inline(never)]
    fn refill(&mut self, step: u64) {
        self.base = step.saturating_sub(1);
        for (k, s) in self.steps.iter_mut().enumerate() {
            *s = digits16((self.base + k as u64).min(DECIMAL_LIMIT - 1));
        }
    }
}

/// Bytes of VCD body gathered before they are handed to the file: 256 KB
/// (one `write` of 64 KB each took the kernel more in all: the bench's
/// traced frame 0.027-0.028 s against 0.025-0.026 s).
const VCD_CHUNK: usize = 1 << 18;
/// Room after the chunk for the longest line (a 64-bit value, its code).
const VCD_SLACK: usize = 128;
/// Room after the chunk for a cycle's edges (five lines between two checks
/// for a full chunk, [`vcd_batch`]).
const VCD_ROOM: usize = 4 * VCD_SLACK;

/// The body of a VCD file: timestamps and value changes, formatted into a
/// buffer of its own and written to the file [`VCD_CHUNK`] bytes at a time.
struct VcdBody {
    /// Each signal's identifier code, padded, and its length.
    ids: Vec<([u8; 16], u8)>,
    buf: Box<[u8]>,
    len: usize,
    time: Decimal,
    /// Bytes of body handed to the file so far.
    written: u64,
    /// The file's blocks are allocated ahead of the writes up to here
    /// ([`VcdBody::reserve`]); `None` when the file cannot be (a device,
    /// a pipe, a file system without `fallocate`).
    reserved: Option<u64>,
}

/// Bytes of a VCD file allocated at a time ahead of its writes.
const VCD_RESERVE: u64 = 4 << 20;

impl VcdBody {
    /// A body with its buffer (the tests'; the tracer's is allocated by
    /// its writing thread).
    #[cfg(test)]
    fn new(reserve: bool) -> VcdBody {
        let mut b = VcdBody::unallocated(reserve);
        b.allocate();
        b
    }

    /// `reserve`: allocate the file's blocks ahead of the writes (a
    /// regular file; trimmed by [`VcdBody::trim`]). Without its buffer,
    /// for the writing thread to allocate ([`VcdBody::allocate`]).
    fn unallocated(reserve: bool) -> VcdBody {
        VcdBody {
            ids: Vec::new(),
            buf: Box::default(),
            len: 0,
            time: Decimal::new(),
            written: 0,
            reserved: reserve.then_some(0),
        }
    }

    /// Allocate the buffer, by the thread that writes it: its pages are
    /// then first touched there (allocated with the tracer, the
    /// simulating thread took the page faults of a quarter megabyte).
    fn allocate(&mut self) {
        if self.buf.is_empty() {
            self.buf = vec![0; VCD_CHUNK + VCD_ROOM].into_boxed_slice();
        }
    }

    /// Allocate the file's blocks some megabytes ahead of the next `n`
    /// bytes (the header counted generously), without changing its
    /// length: the kernel then copies the writes into blocks it has
    /// instead of reserving space page by page (30 MB written to ext4 in
    /// 256 KB pieces: 4.8-5.1 ms, 2.7-2.8 ms allocated ahead). Where the
    /// file system cannot allocate ahead, the file is simply written.
    fn reserve(&mut self, out: &BufWriter<File>, n: usize) {
        let Some(r) = self.reserved else { return };
        let end = self.written + n as u64 + (1 << 16);
        if end <= r {
            return;
        }
        let to = end.next_multiple_of(VCD_RESERVE) + VCD_RESERVE;
        self.reserved = allocate_ahead(out.get_ref(), r, to - r).then_some(to);
    }

    /// Give back the blocks allocated past the end of the file.
    fn trim(&self, out: &mut BufWriter<File>) -> io::Result<()> {
        if self.reserved.is_some_and(|r| r > 0) {
            out.flush()?;
            let f = out.get_mut();
            let len = f.stream_position()?;
            f.set_len(len)?;
        }
        Ok(())
    }

    fn add_id(&mut self, code: &str) -> io::Result<u32> {
        let b = code.as_bytes();
        if b.len() > 16 {
            return Err(io::Error::other("VCD identifier code longer than 16 bytes"));
        }
        let mut id = [0u8; 16];
        id[..b.len()].copy_from_slice(b);
        self.ids.push((id, b.len() as u8));
        Ok(self.ids.len() as u32 - 1)
    }

    /// `#t`: below 10^16 (about three hours of simulated time in
    /// picoseconds) carried forward in decimal from the time written
    /// before ([`Decimal`]) and stored as one 16-byte word (a loop of
    /// half-period steps: 6.1 against 7.0 ns a timestamp for `itoa` and
    /// a copy of its digits, a call to `memcpy` of a length known only at
    /// run time; the two were a sixth of the writing thread).
    #[inline(always)]
    fn timestamp(&mut self, t: u64) {
        let dst = &mut self.buf[self.len..self.len + VCD_SLACK];
        dst[0] = b'#';
        let n = match self.time.next(t) {
            Some((ascii, n)) => {
                dst[1..17].copy_from_slice(&ascii.to_le_bytes());
                n
            }
            None => {
                let mut digits = itoa::Buffer::new();
                let d = digits.format(t).as_bytes();
                dst[1..1 + d.len()].copy_from_slice(d);
                d.len()
            }
        };
        dst[1 + n] = b'\n';
        self.len += n + 2;
    }

    /// `0!` for one bit, `b1011 !` for a vector (no leading zeros).
    #[inline(always)]
    fn change(&mut self, id: u32, width: u32, v: u64) {
        let (code, n) = self.ids[id as usize];
        let dst = &mut self.buf[self.len..self.len + VCD_SLACK];
        let mut k;
        if width == 1 {
            dst[0] = b'0' + (v & 1) as u8;
            k = 1;
        } else {
            dst[0] = b'b';
            let bits = 64 - (v | 1).leading_zeros() as usize;
            binary(&mut dst[1..], v, bits);
            k = 1 + bits;
            dst[k] = b' ';
            k += 1;
        }
        dst[k..k + 16].copy_from_slice(&code);
        k += n as usize;
        dst[k] = b'\n';
        self.len += k + 1;
    }

    /// Hand the gathered bytes to the file once a chunk is full (`all`:
    /// whatever is gathered).
    #[inline(always)]
    fn flush(&mut self, out: &mut BufWriter<File>, all: bool) -> io::Result<()> {
        if self.len >= VCD_CHUNK || (all && self.len > 0) {
            return self.write_out(out);
        }
        Ok(())
    }

    #[inline(never)]
    fn write_out(&mut self, out: &mut BufWriter<File>) -> io::Result<()> {
        let n = std::mem::take(&mut self.len);
        self.reserve(out, n);
        self.written += n as u64;
        out.write_all(&self.buf[..n])
    }
}

/// Allocate `len` bytes of `f`'s blocks from `offset` on, its length
/// unchanged; whether it could.
#[cfg(target_os = "linux")]
fn allocate_ahead(f: &File, offset: u64, len: u64) -> bool {
    rustix::fs::fallocate(f, rustix::fs::FallocateFlags::KEEP_SIZE, offset, len).is_ok()
}

#[cfg(not(target_os = "linux"))]
fn allocate_ahead(_: &File, _: u64, _: u64) -> bool {
    false
}

impl Sink {
    fn add_module(&mut self, name: &str) -> io::Result<()> {
        match self {
            Sink::Vcd(w, _) => w.add_module(name),
            Sink::FstHeader(h) => h
                .scope(name, "", fst_writer::FstScopeType::Module)
                .map_err(fst_err),
            _ => Ok(()),
        }
    }

    fn upscope(&mut self) -> io::Result<()> {
        match self {
            Sink::Vcd(w, _) => w.upscope(),
            Sink::FstHeader(h) => h.up_scope().map_err(fst_err),
            _ => Ok(()),
        }
    }

    fn add_wire(&mut self, width: u32, name: &str) -> io::Result<SigId> {
        match self {
            Sink::Vcd(w, body) => {
                let id = w.add_wire(width, name)?;
                body.add_id(&id.to_string()).map(SigId::Vcd)
            }
            Sink::FstHeader(h) => h
                .var(
                    name,
                    fst_writer::FstSignalType::bit_vec(width),
                    fst_writer::FstVarType::Wire,
                    fst_writer::FstVarDirection::Implicit,
                    None,
                )
                .map(SigId::Fst)
                .map_err(fst_err),
            _ => Err(io::Error::other("waveform declared after its header")),
        }
    }

    /// End of the declarations.
    fn end_definitions(&mut self) -> io::Result<()> {
        match std::mem::replace(self, Sink::Gone) {
            Sink::Vcd(mut w, body) => {
                w.enddefinitions()?;
                *self = Sink::Vcd(w, body);
            }
            Sink::FstHeader(h) => *self = Sink::FstBody(h.finish().map_err(fst_err)?),
            other => *self = other,
        }
        Ok(())
    }

    /// Hand the sink to a writing thread (see [`Sink::Threaded`]).
    /// `slots`: per signal call (in call order), its [`Slot`] if traced
    /// (its values are kept if it has a translate filter); `signals`: how
    /// many signals are traced; `clk` and `cycle`: the signals a cycle's
    /// edges set; `clock_hz`: the clock the times are in;
    /// `section_bytes`: see [`TraceConfig::fst_section_bytes`];
    /// `batch_words`: the capacity of a batch.
    #[allow(clippy::too_many_arguments)]
    fn threaded(
        self,
        slots: Vec<Option<Slot>>,
        signals: usize,
        clk: SigId,
        cycle_id: SigId,
        clock_hz: u64,
        section_bytes: usize,
        batch_words: usize,
    ) -> io::Result<Sink> {
        let queue = std::sync::Arc::new(Handoff::new());
        let rx = WriterGone(queue.clone());
        let (seen_tx, seen_rx) = std::sync::mpsc::sync_channel(1);
        let worker = std::thread::Builder::new()
            .name("waveform writer".into())
            .spawn(move || {
                let mut sink = self;
                if let Sink::Vcd(_, body) = &mut sink {
                    body.allocate();
                }
                // Batches for the simulating thread to copy its messages
                // into, their pages touched here rather than there.
                for _ in 0..SPARE_BATCHES {
                    let mut b = vec![0u64; batch_words];
                    b.clear();
                    rx.0.give_back(b);
                }
                let mut res = Ok(());
                // Values of the filtered signals, deduplicated whenever a
                // list doubles (a set insertion per change cost more).
                let mut seen = Seen::new(signals);
                // A VCD's handles, for its own loop ([`vcd_batch`]); an
                // untraced call's never appears in a message.
                let vcd_ids = match (clk, cycle_id) {
                    (SigId::Vcd(clk), SigId::Vcd(cycle)) => slots
                        .iter()
                        .map(|s| match *s {
                            Some((SigId::Vcd(id), w, f, i)) => Some((id, w, f, i)),
                            Some((SigId::Fst(_), ..)) => None,
                            None => Some((0, 0, false, NOT_TRACED)),
                        })
                        .collect::<Option<Vec<_>>>()
                        .map(|s| (s, clk, cycle)),
                    _ => None,
                };
                let mut clock = Clock::new(clock_hz);
                // The falling edge of the last cycle begun, written when
                // the next one begins or the trace ends.
                let mut fall: Option<u64> = None;
                // A section can end only after a time step of its own (the
                // FST writer cannot start one at the time it ended at).
                let mut stepped = false;
                let cycle = |sink: &mut Sink,
                             c: u64,
                             clock: &mut Clock,
                             fall: &mut Option<u64>,
                             stepped: &mut bool|
                 -> io::Result<()> {
                    if let Some(t) = fall.take() {
                        sink.timestamp(t)?;
                        sink.change(clk, 1, 0)?;
                        *stepped = true;
                    }
                    if std::mem::take(stepped) {
                        sink.fst_section(section_bytes)?;
                    }
                    let (rise, f) = clock.edges(c);
                    *fall = Some(f);
                    sink.timestamp(rise)?;
                    sink.change(clk, 1, 1)?;
                    sink.change(cycle_id, 64, c)
                };
                while let Some(batch) = rx.0.recv() {
                    if res.is_err() {
                        continue; // keep draining: the sender must not block
                    }
                    if let (Sink::Vcd(w, body), Some((ids, clk, cycle))) = (&mut sink, &vcd_ids) {
                        let edges = (&mut clock, &mut fall, *clk, *cycle);
                        res = vcd_batch(w.writer(), body, &batch, ids, &mut seen, edges);
                        rx.0.give_back(batch);
                        continue;
                    }
                    let mut k = 0;
                    while k < batch.len() {
                        let m = batch[k];
                        k += 1;
                        let (tag, low) = (m >> 48, m & MSG_VALUE);
                        let r = match tag {
                            MSG_CHUNK => {
                                let Some(&bits) = batch.get(k) else {
                                    res = Err(io::Error::other("a change message cut short"));
                                    break;
                                };
                                k += 1;
                                let mut r = Ok(());
                                for (s, v) in changes(low, bits, &batch, &mut k) {
                                    let Some((id, w, filtered, i)) =
                                        slots.get(s).copied().flatten()
                                    else {
                                        r = Err(io::Error::other(
                                            "a change of a signal not declared",
                                        ));
                                        break;
                                    };
                                    if filtered {
                                        seen.add(i as usize, v);
                                    }
                                    r = sink.change(id, w, v);
                                    if r.is_err() {
                                        break;
                                    }
                                }
                                r
                            }
                            _ => {
                                let c = if tag == MSG_LONG {
                                    k += 1;
                                    batch.get(k - 1).copied().unwrap_or(0)
                                } else {
                                    low
                                };
                                cycle(&mut sink, c, &mut clock, &mut fall, &mut stepped)
                            }
                        };
                        if let Err(e) = r {
                            res = Err(e);
                            break;
                        }
                    }
                    rx.0.give_back(batch);
                }
                if res.is_ok() {
                    if let Some(t) = fall {
                        res = sink.timestamp(t).and_then(|_| sink.change(clk, 1, 0));
                    }
                }
                // The values first, so that the filter files are written
                // while this thread closes the waveform.
                let seen = seen.lists.into_iter().map(BTreeSet::from_iter).collect();
                let _ = seen_tx.send(seen);
                if res.is_ok() {
                    let end = rx.0.end.lock().unwrap_or_else(|e| e.into_inner()).take();
                    res = match end {
                        Some((t, note)) => sink.close(t, note.as_deref()),
                        None => Err(io::Error::other("the waveform ended without an end time")),
                    };
                }
                (sink, res)
            })?;
        Ok(Sink::Threaded {
            queue,
            worker,
            seen: seen_rx,
        })
    }

    /// Write the end of the waveform at time `t`, with `note`, flush it and
    /// give back the blocks allocated past its end. Not synced to the
    /// disk: the rename in [`Tracer::finish`] keeps an interrupted run
    /// from leaving a partial file under the waveform's name; an fsync of
    /// a 30 MB trace took longer than simulating it.
    fn close(&mut self, t: u64, note: Option<&str>) -> io::Result<()> {
        self.timestamp(t)?;
        match self {
            Sink::Vcd(w, body) => {
                body.flush(w.writer(), true)?;
                if let Some(n) = note {
                    w.comment(n)?;
                }
                w.flush()?;
                body.trim(w.writer())
            }
            Sink::FstBody(_) => match std::mem::replace(self, Sink::Gone) {
                // FST has no comments: the note went to standard error.
                Sink::FstBody(b) => b.finish().map_err(fst_err)?.flush(),
                _ => unreachable!(),
            },
            _ => Err(io::Error::other("waveform finished twice")),
        }
    }

    /// Hand the writing thread the last batch, the time the waveform ends
    /// at and `note`: it writes them and closes the file
    /// ([`Sink::close`]) while this thread goes on ([`Closing`]).
    fn hand_last(self, batch: Vec<u64>, t: u64, note: Option<String>) -> io::Result<Closing> {
        match self {
            Sink::Threaded {
                queue,
                worker,
                seen,
            } => {
                let sent = queue.send(batch, worker.thread());
                *queue.end.lock().unwrap_or_else(|e| e.into_inner()) = Some((t, note));
                queue.done.store(true, std::sync::atomic::Ordering::SeqCst);
                worker.thread().unpark();
                Ok(Closing { worker, seen, sent })
            }
            _ => Err(io::Error::other("waveform finished twice")),
        }
    }

    /// Hand a full batch to the writing thread: a copy of it (into a
    /// batch the thread has emptied, or a new one), `batch` left empty.
    fn hand_over(&mut self, batch: &mut Vec<u64>) -> io::Result<()> {
        match self {
            Sink::Threaded { queue, worker, .. } => {
                let spare = queue.empty.lock().unwrap_or_else(|e| e.into_inner()).pop();
                let mut copy = spare.unwrap_or_else(|| Vec::with_capacity(batch.capacity()));
                copy.clear();
                copy_streaming(&mut copy, batch);
                batch.clear();
                if queue.send(copy, worker.thread()) {
                    Ok(())
                } else {
                    Err(io::Error::other("the waveform writer stopped"))
                }
            }
            _ => Err(io::Error::other("a value change outside sampling")),
        }
    }

    /// The FST writer holds value changes in memory until a flush, which
    /// writes them as one compressed section; it can flush only right
    /// before a new time step, so this is called at each rising edge, and
    /// flushes once more than `limit` bytes wait.
    fn fst_section(&mut self, limit: usize) -> io::Result<()> {
        if let Sink::FstBody(b) = self {
            if b.size() > limit {
                b.flush().map_err(fst_err)?;
            }
        }
        Ok(())
    }

    fn timestamp(&mut self, t: u64) -> io::Result<()> {
        match self {
            Sink::Vcd(w, body) => {
                body.timestamp(t);
                body.flush(w.writer(), false)
            }
            Sink::FstBody(b) => b.time_change(t).map_err(fst_err),
            // While sampling, time moves only with the clock edges.
            Sink::Threaded { .. } => Err(io::Error::other("a timestamp outside the clock edges")),
            _ => Ok(()),
        }
    }

    /// A new value of a `width`-bit signal (a VCD's batches go through
    /// [`vcd_batch`] instead).
    fn change(&mut self, id: SigId, width: u32, v: u64) -> io::Result<()> {
        match (self, id) {
            (Sink::Vcd(w, body), SigId::Vcd(id)) => {
                body.change(id, width, v);
                body.flush(w.writer(), false)
            }
            (Sink::FstBody(b), SigId::Fst(id)) => fst_change(b, id, width, v),
            _ => Ok(()),
        }
    }
}

fn fst_change(
    b: &mut fst_writer::FstBodyWriter<BufWriter<File>>,
    id: fst_writer::FstSignalId,
    width: u32,
    v: u64,
) -> io::Result<()> {
    let mut bits = [b'0'; 64];
    let w = width as usize;
    for (k, bit) in bits[..w].iter_mut().enumerate() {
        if v >> (w - 1 - k) & 1 == 1 {
            *bit = b'1';
        }
    }
    b.signal_change(id, &bits[..w]).map_err(fst_err)
}

/// Bit k: `cur[k] & mask[k]` differs from `last[k]`.
#[inline(always)]
fn changed_mask(cur: &[u64; 64], mask: &[u64; 64], last: &[u64; 64]) -> u64 {
    let mut bits = 0;
    for k in 0..64 {
        bits |= u64::from(cur[k] & mask[k] != last[k]) << k;
    }
    bits
}

/// The values each signal with a translate filter took, gathered by the
/// writing thread and deduplicated whenever a list doubles (a set
/// insertion per change cost more). A value found in a small
/// direct-mapped table of the values met last is not gathered again: an
/// instruction word or a context word comes back thousands of times, and
/// without the table the lists were sorted every few hundred changes.
struct Seen {
    lists: Vec<Vec<u64>>,
    cap: Vec<usize>,
    recent: Vec<[u64; RECENT]>,
}

/// Entries of [`Seen`]'s table of recent values, per signal.
const RECENT: usize = 256;

impl Seen {
    fn new(n: usize) -> Seen {
        Seen {
            lists: vec![Vec::new(); n],
            cap: vec![1024; n],
            // u64::MAX is no value: no signal is wider than 64 bits, and
            // a 64-bit one of all ones is simply gathered each time.
            recent: vec![[u64::MAX; RECENT]; n],
        }
    }

    #[inline(always)]
    fn add(&mut self, i: usize, v: u64) {
        let slot = (v.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 56) as usize % RECENT;
        let r = &mut self.recent[i][slot];
        if *r == v {
            return;
        }
        *r = v;
        let l = &mut self.lists[i];
        l.push(v);
        if l.len() >= self.cap[i] {
            l.sort_unstable();
            l.dedup();
            self.cap[i] = (2 * l.len()).max(1024);
        }
    }
}

/// The changes of a [`MSG_CHUNK`] message of chunk `j` with mask `bits`,
/// its values from `batch[*k]` on (`k` left after them): each call's
/// index and value. A message cut short ends early.
#[inline(always)]
fn changes<'a>(
    j: u64,
    mut bits: u64,
    batch: &'a [u64],
    k: &'a mut usize,
) -> impl Iterator<Item = (usize, u64)> + 'a {
    std::iter::from_fn(move || {
        if bits == 0 {
            return None;
        }
        let s = 64 * j as usize + bits.trailing_zeros() as usize;
        bits &= bits - 1;
        let v = *batch.get(*k)?;
        *k += 1;
        Some((s, v))
    })
}

/// The writing thread's loop over a batch for a VCD (the general loop of
/// [`Sink::threaded`] matches the sink and the handle at every message):
/// `ids` per signal call its code, width, whether it has a translate
/// filter and its signal's index (untraced: [`NOT_TRACED`]); `edges` the
/// clock, the falling edge still to write, and the codes of `clk` and
/// `cycle`.
#[inline(never)]
fn vcd_batch(
    out: &mut BufWriter<File>,
    body: &mut VcdBody,
    batch: &[u64],
    ids: &[(u32, u32, bool, u32)],
    seen: &mut Seen,
    (clock, fall, clk, cycle): (&mut Clock, &mut Option<u64>, u32, u32),
) -> io::Result<()> {
    let mut k = 0;
    while k < batch.len() {
        let m = batch[k];
        k += 1;
        let (tag, mut v) = (m >> 48, m & MSG_VALUE);
        if tag == MSG_CHUNK {
            let Some(&bits) = batch.get(k) else {
                return Err(io::Error::other("a change message cut short"));
            };
            k += 1;
            for (s, v) in changes(v, bits, batch, &mut k) {
                let Some(&(id, w, filtered, i)) = ids.get(s).filter(|d| d.3 != NOT_TRACED) else {
                    return Err(io::Error::other("a change of a signal not declared"));
                };
                if filtered {
                    seen.add(i as usize, v);
                }
                body.change(id, w, v);
                body.flush(out, false)?;
            }
            continue;
        }
        if tag == MSG_LONG {
            v = batch.get(k).copied().unwrap_or(0);
            k += 1;
        }
        let (rise, f) = clock.edges(v);
        if let Some(t) = fall.replace(f) {
            body.timestamp(t);
            body.change(clk, 1, 0);
        }
        body.timestamp(rise);
        body.change(clk, 1, 1);
        body.change(cycle, 64, v);
        body.flush(out, false)?;
    }
    Ok(())
}

/// [`Tracer::slot_decl`] of a signal call that is not traced.
const NOT_TRACED: u32 = u32::MAX;

#[derive(Clone, Copy)]
struct SigInfo {
    id: SigId,
    width: u32,
    display: Display,
}

struct Decl {
    path: Vec<String>,
    info: SigInfo,
}

/// The VCD writer. Attach it to a [`crate::kernel::Sim`].
pub struct Tracer {
    cfg: TraceConfig,
    /// The temporary file renamed onto the waveform's file by `finish`;
    /// `None` when the waveform goes straight to a device or FIFO.
    tmp_path: Option<tempfile::TempPath>,
    /// The regular file the waveform ends up in (a symbolic link followed).
    target: PathBuf,
    top: String,
    w: Sink,
    patterns: Vec<Vec<String>>,
    // declaration state
    stack: Vec<String>,
    /// Every top-level scope declared (matched or not), for the message
    /// when the scope patterns match no signal.
    top_scopes: Vec<String>,
    decls: Vec<Decl>,
    // per-call tables, indexed by call order
    scope_on: Vec<bool>,
    /// Answers of [`Probe::open_scopes`], in call order.
    open_masks: Vec<u64>,
    /// Per [`Probe::block_versioned`] call: the version last sampled and
    /// the block's size.
    versions: Vec<(u64, usize)>,
    /// Per [`Probe::block`] call: the signal calls it takes, 0 when none
    /// of its fields is traced (its values are then not kept at all).
    block_n: Vec<u32>,
    /// Per [`Probe::section`]: the calls of each table made by its end
    /// ([`Progress`], counted from the walk's start; the walk makes the
    /// same calls every cycle), where a section skipped moves on to.
    sections: Vec<Progress>,
    /// While declaring: the sections open.
    open_sections: Vec<usize>,
    /// Per signal call (in call order, traced or not), while declaring:
    /// the mask of its width (0 when it is not traced, so it never
    /// changes).
    masks: Vec<u64>,
    /// While sampling, from word [`Tracer::hot_at`] on, three arrays of a
    /// word per signal call padded with untraced calls to a multiple of
    /// 64: the value reported in the cycle being sampled
    /// (a block or section skipped leaves the last one; the walk only
    /// copies values here, they are compared 64 at a time after it), the
    /// mask of its width, and the value last written. One allocation,
    /// each array on whole cache lines, so that no vector access splits a
    /// line or a page: with the arrays wherever the heap put them (the
    /// last values once straddled a 4 KB page), a throwaway allocation
    /// before them moved the simulating thread's time for the bench's
    /// frame by up to 0.8 ms; laid out here, 0.0173-0.0177 s against
    /// 0.0176-0.0179 s (docs/performance.md).
    hot: Vec<u64>,
    hot_at: usize,
    /// Signal calls declared (before the padding).
    n_slots: usize,
    /// Per signal call: the bytes a change of it adds to the waveform
    /// (about).
    costs: Vec<u8>,
    /// Messages for the writing thread ([`Sink::Threaded`]): this
    /// thread's own batch, handed over as a copy ([`copy_streaming`])
    /// once [`BATCH`] words wait (checked after each cycle: room for the
    /// most a cycle adds is reserved beyond it).
    batch: Vec<u64>,
    /// Per signal call: the index of its declaration, [`NOT_TRACED`] if none.
    slot_decl: Vec<u32>,
    // sampling state
    /// In the first sampled cycle every call counts as a change (and the
    /// traced ones are written).
    first_sample: bool,
    /// The cycle sampled last, its values in [`Tracer::hot`] still to be
    /// compared and written ([`Tracer::sample`]).
    pending: Option<u64>,
    /// The digits of the times written, the time that takes one more (the
    /// times only grow) and the first cycle at that time.
    digits: u64,
    digits_below: u64,
    digits_cycle: u64,
    seen: Vec<BTreeSet<u64>>,
    clk: SigId,
    cycle_id: SigId,
    sampled: u64,
    last_cycle: Option<u64>,
    note: Option<String>,
    /// First I/O error met while declaring (the Probe calls cannot return it).
    err: Option<io::Error>,
    /// Approximate bytes of value changes written so far.
    bytes: u64,
    /// Cycle at which the size limit stopped the trace.
    truncated_at: Option<u64>,
}

fn human_bytes(b: f64) -> String {
    let units = ["B", "KB", "MB", "GB", "TB", "PB"];
    let mut v = b;
    let mut u = 0;
    while v >= 1000.0 && u + 1 < units.len() {
        v /= 1000.0;
        u += 1;
    }
    format!("{v:.1} {}", units[u])
}

/// Temporary files are created 0600; outputs are ordinary files (0644).
/// A temporary file in `dir` (named by `b`) that becomes `target`: with
/// the mode `target` has when it exists, else as any new file (0666 less
/// the umask), not tempfile's private 0600.
fn output_tempfile(
    b: &mut tempfile::Builder,
    dir: &Path,
    target: &Path,
) -> io::Result<tempfile::NamedTempFile> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let tmp = b.tempfile_in(dir)?;
    if let Ok(m) = std::fs::metadata(target) {
        tmp.as_file().set_permissions(m.permissions())?;
    }
    Ok(tmp)
}

/// The waveforms being written right now (their temporary files), for a
/// signal handler to remove: [`partial_files`].
static PARTIALS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// The temporary files of the waveforms being written now: what an
/// interrupted run must remove (the `morphosys` command does so on SIGINT,
/// SIGTERM and SIGHUP).
pub fn partial_files() -> Vec<PathBuf> {
    PARTIALS.lock().map(|v| v.clone()).unwrap_or_default()
}

fn forget_partial(p: &Path) {
    if let Ok(mut v) = PARTIALS.lock() {
        v.retain(|q| q != p);
    }
}

/// A waveform's temporary file is `.<name>.<pid>.<random>.partial` beside
/// it. Those of `target` left by a process that no longer runs (killed
/// outright, with no chance to clean up) are removed.
fn remove_stale_partials(dir: &Path, name: &str) {
    let proc_fs = Path::new("/proc/self").exists();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let prefix = format!(".{name}.");
    for e in entries.flatten() {
        let f = e.file_name().to_string_lossy().into_owned();
        let Some(rest) = f
            .strip_prefix(&prefix)
            .and_then(|r| r.strip_suffix(".partial"))
        else {
            continue;
        };
        let Some(pid) = rest.split('.').next().and_then(|p| p.parse::<u32>().ok()) else {
            continue;
        };
        if proc_fs && pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// Write a small text file through a temporary file and a rename.
/// `text` in a temporary file beside `path`, to be renamed onto it.
fn stage(path: &Path, text: &str) -> io::Result<tempfile::NamedTempFile> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = output_tempfile(&mut tempfile::Builder::new(), dir, path)?;
    tmp.write_all(text.as_bytes())?;
    Ok(tmp)
}

/// A waveform's GTKWave save file: `<stem>.gtkw`.
fn save_file_path(wave: &Path) -> PathBuf {
    wave.with_extension("gtkw")
}

/// A waveform's translate filter `name`: `<stem>.<name>.txt`.
fn filter_path(wave: &Path, name: &str) -> PathBuf {
    PathBuf::from(format!("{}.{name}.txt", wave.with_extension("").display()))
}

/// A waveform's Surfer decoder of the labels `name`:
/// `.surfer/decoders/<stem>.<name>/<name>.toml` in its folder.
fn decoder_path(wave: &Path, name: &str) -> PathBuf {
    let stem = wave.with_extension("");
    let stem_name = stem.file_name().unwrap_or_default().to_string_lossy();
    wave.parent()
        .unwrap_or(Path::new("."))
        .join(".surfer/decoders")
        .join(format!("{stem_name}.{name}"))
        .join(format!("{name}.toml"))
}

/// Every file that may be written beside a waveform at `wave` whose
/// signals use the translate filters `filters` (names) and, with labels,
/// the label kinds: its save file, filter files and Surfer decoders, each
/// with what it is. Commands check these against their inputs and other
/// outputs before the work ([`Tracer::finish`] writes those the traced
/// signals need).
pub fn side_files(wave: &Path, filters: &[&str]) -> Vec<(PathBuf, String)> {
    let wave = std::path::absolute(wave).unwrap_or_else(|_| wave.to_path_buf());
    let mut v = vec![(save_file_path(&wave), "save file".to_string())];
    for name in filters {
        v.push((filter_path(&wave, name), format!("filter file `{name}`")));
    }
    for k in [LabelKind::Code, LabelKind::Context] {
        let name = k.filter_name();
        v.push((filter_path(&wave, name), format!("filter file `{name}`")));
        v.push((
            decoder_path(&wave, name),
            format!("Surfer decoder `{name}`"),
        ));
    }
    v
}

/// The files written beside a waveform ([`Tracer::side_files`]).
struct SideFiles {
    vcd_abs: PathBuf,
    gtkw: PathBuf,
    /// Per translate filter its name and file.
    filters: Vec<(&'static str, PathBuf)>,
    /// Per label kind shown, Surfer's decoder of it: the kind, the
    /// signal's width and the file (`.surfer/decoders/<stem>.<name>/`
    /// beside the waveform, where Surfer started there finds it).
    decoders: Vec<(LabelKind, u32, PathBuf)>,
}

fn glob(p: &str, s: &str) -> bool {
    let (p, s) = (p.as_bytes(), s.as_bytes());
    let (mut pi, mut si, mut star, mut mark) = (0, 0, None, 0);
    while si < s.len() {
        if pi < p.len() && (p[pi] == b'?' || p[pi] == s[si]) {
            pi += 1;
            si += 1;
        } else if pi < p.len() && p[pi] == b'*' {
            star = Some(pi);
            mark = si;
            pi += 1;
        } else if let Some(st) = star {
            pi = st + 1;
            mark += 1;
            si = mark;
        } else {
            return false;
        }
    }
    while pi < p.len() && p[pi] == b'*' {
        pi += 1;
    }
    pi == p.len()
}

/// Check a scope pattern list for the command line: components of letters,
/// digits, `_`, `*`, `?`, separated by dots.
pub fn check_scope_patterns(s: &str) -> Result<(), String> {
    for pat in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        for comp in pat.split('.') {
            if comp.is_empty()
                || !comp
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '*' | '?'))
            {
                return Err(format!(
                    "bad scope pattern `{pat}`: use dot-separated names with `*` and `?` globs, e.g. `rc.alu` or `array.rc_r*_c0`"
                ));
            }
        }
    }
    Ok(())
}

impl Drop for Tracer {
    fn drop(&mut self) {
        // Not finished: the temporary file goes (TempPath removes it), and
        // leaves the list of partial files.
        if let Some(t) = &self.tmp_path {
            forget_partial(t);
        }
        // The writing thread, if any, is told there is no more and waited
        // for (it writes what it has into the file that goes and ends
        // without an end time); else it would wait for batches for the
        // rest of the process.
        if let Sink::Threaded { queue, worker, .. } = std::mem::replace(&mut self.w, Sink::Gone) {
            queue.done.store(true, std::sync::atomic::Ordering::SeqCst);
            worker.thread().unpark();
            let _ = worker.join();
        }
    }
}

impl Tracer {
    /// Create the VCD file and declare the signals of `top` (named `top_name`).
    pub fn create<T: Traced>(cfg: TraceConfig, top_name: &str, top: &T) -> io::Result<Tracer> {
        check_scope_patterns(&cfg.scope)
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e))?;
        if let Some(dir) = cfg.path.parent() {
            if !dir.as_os_str().is_empty() {
                std::fs::create_dir_all(dir)?;
            }
        }
        // A regular file is written to a temporary file beside it and
        // renamed into place by finish(), so an interrupted run never leaves
        // a truncated waveform under the requested name; a symbolic link is
        // followed (its target replaced, the link kept); a device or FIFO
        // (`/dev/null`, a named pipe) is written through.
        let through = matches!(std::fs::metadata(&cfg.path), Ok(m) if !m.is_file() && !m.is_dir());
        if through && is_fst(&cfg.path) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "{}: an FST waveform needs a regular file (it is written out of order); \
                     give a path ending in .vcd to write through a device or pipe",
                    cfg.path.display()
                ),
            ));
        }
        let (file, tmp_path, target) = match std::fs::metadata(&cfg.path) {
            Ok(m) if !m.is_file() && !m.is_dir() => (
                std::fs::OpenOptions::new().write(true).open(&cfg.path)?,
                None,
                cfg.path.clone(),
            ),
            _ => {
                let target = std::fs::canonicalize(&cfg.path).unwrap_or_else(|_| cfg.path.clone());
                let dir = match target.parent() {
                    Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                    _ => PathBuf::from("."),
                };
                let name = target
                    .file_name()
                    .map_or_else(|| "waveform".into(), |n| n.to_string_lossy().into_owned());
                remove_stale_partials(&dir, &name);
                let tmp = output_tempfile(
                    tempfile::Builder::new()
                        .prefix(&format!(".{name}.{}.", std::process::id()))
                        .suffix(".partial"),
                    &dir,
                    &target,
                )?;
                let (file, tmp_path) = tmp.into_parts();
                if let Ok(mut v) = PARTIALS.lock() {
                    v.push(tmp_path.to_path_buf());
                }
                (file, Some(tmp_path), target)
            }
        };
        let out = BufWriter::with_capacity(1 << 16, file);
        let version = concat!("morphosys ", env!("CARGO_PKG_VERSION"));
        let mut w = if is_fst(&cfg.path) {
            let info = fst_writer::FstInfo {
                // FST files start at 0 (the writer's first frame): signals
                // are undefined (x) up to the window, as in the VCD.
                start_time: 0,
                timescale_exponent: -12,
                version: version.to_string(),
                date: String::new(),
                file_type: fst_writer::FstFileType::Verilog,
            };
            Sink::FstHeader(fst_writer::FstHeaderWriter::new(out, &info).map_err(fst_err)?)
        } else {
            let mut w = vcd::Writer::new(out);
            w.version(version)?;
            w.timescale(1, TimescaleUnit::PS)?;
            Sink::Vcd(w, VcdBody::unallocated(tmp_path.is_some()))
        };
        w.add_module(top_name)?;
        let clk = w.add_wire(1, "clk")?;
        let cycle_id = w.add_wire(64, "cycle")?;
        let patterns = cfg
            .scope
            .split(',')
            .map(str::trim)
            .filter(|p| !p.is_empty())
            .map(|p| {
                let mut c: Vec<String> = p.split('.').map(String::from).collect();
                if c.len() > 1 && c[0] == top_name {
                    c.remove(0);
                }
                c
            })
            .collect();
        let mut t = Tracer {
            cfg,
            tmp_path,
            target,
            top: top_name.to_string(),
            w,
            patterns,
            stack: Vec::new(),
            top_scopes: Vec::new(),
            decls: Vec::new(),
            scope_on: Vec::new(),
            open_masks: Vec::new(),
            versions: Vec::new(),
            block_n: Vec::new(),
            sections: Vec::new(),
            open_sections: Vec::new(),
            masks: Vec::new(),
            hot: Vec::new(),
            hot_at: 0,
            n_slots: 0,
            batch: Vec::new(),
            slot_decl: Vec::new(),
            first_sample: true,
            pending: None,
            digits_cycle: 0,
            digits: 1,
            digits_below: 10,
            seen: Vec::new(),
            clk,
            cycle_id,
            sampled: 0,
            last_cycle: None,
            note: None,
            err: None,
            bytes: 0,
            truncated_at: None,
            costs: Vec::new(),
        };
        top.trace(&mut Declaring(&mut t));
        if !t.open_sections.is_empty() {
            t.err
                .get_or_insert(io::Error::other("a module began a section it did not end"));
        }
        if let Some(e) = t.err.take() {
            return Err(e);
        }
        if t.decls.is_empty() && !t.cfg.scope.trim().is_empty() {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "--trace-scope '{}' matches no signal; the top-level scopes are {} (e.g. `--trace-scope {}`)",
                    t.cfg.scope,
                    t.top_scopes.join(", "),
                    t.top_scopes.first().map_or("*", String::as_str)
                ),
            ));
        }
        // Refuse up front a trace that would fill the disk.
        let cycles = match (t.cfg.count, t.cfg.budget_cycles) {
            (Some(n), Some(b)) => Some(n.min(b.saturating_sub(t.cfg.first))),
            (Some(n), None) => Some(n),
            (None, Some(b)) => Some(b.saturating_sub(t.cfg.first)),
            (None, None) => None,
        };
        if let Some(c) = cycles {
            let vcd = (t.decls.len() + 2) as f64 * c as f64 * BYTES_PER_SIGNAL_CYCLE;
            // An FST is written compressed: its estimate is the VCD's over
            // FST_SMALLER.
            let (est, kind) = if is_fst(&t.cfg.path) {
                (vcd / FST_SMALLER, "FST")
            } else {
                (vcd, "VCD")
            };
            if est > t.cfg.max_bytes as f64 {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!(
                        "tracing {} signals over up to {c} cycles would write about {} of {kind}, over the {} limit; \
                         narrow it with --trace-cycles and --trace-scope (e.g. `--trace-scope tinyrisc,array.rc_r0_c0`)",
                        t.decls.len(),
                        human_bytes(est),
                        human_bytes(t.cfg.max_bytes as f64)
                    ),
                ));
            }
        }
        t.w.upscope()?;
        t.w.end_definitions()?;
        let slots = t
            .slot_decl
            .iter()
            .map(|&i| {
                let d = t.decls.get(i as usize)?;
                let filtered = d.info.display.filtered();
                Some((d.info.id, d.info.width, filtered, i))
            })
            .collect();
        t.n_slots = t.masks.len();
        let padded = t.n_slots.next_multiple_of(64);
        // Room beyond a full batch for the most a cycle adds: its start,
        // and per chunk of calls its message, mask and 64 values (the
        // last ones stored as 8 words wherever they end, see
        // `Chunk::changes`).
        let batch_words = BATCH + 2 + 2 * padded + 8;
        t.w = std::mem::replace(&mut t.w, Sink::Gone).threaded(
            slots,
            t.decls.len(),
            t.clk,
            t.cycle_id,
            t.cfg.clock_hz,
            t.cfg.fst_section_bytes,
            batch_words,
        )?;
        t.digits_cycle = t.first_cycle_at(t.digits_below);
        t.masks.resize(padded, 0);
        t.hot = vec![0; 3 * padded + 8];
        t.hot_at = (64 - t.hot.as_ptr() as usize % 64) % 64 / 8;
        let masks = t.hot_at + padded;
        t.hot[masks..masks + padded].copy_from_slice(&t.masks);
        t.slot_decl.resize(padded, NOT_TRACED);
        // A change costs about its width in digits and 6 bytes more.
        t.costs = t.masks.iter().map(|m| m.count_ones() as u8 + 6).collect();
        t.batch = Vec::with_capacity(batch_words);
        Ok(t)
    }

    /// Number of signals that passed the scope filter.
    pub fn signal_count(&self) -> usize {
        self.decls.len()
    }

    /// The first cycle whose rising edge is at `t` ps or later.
    fn first_cycle_at(&self, t: u64) -> u64 {
        // `c * 1e12 / hz` rounded down is at least `t` when `c * 1e12 /
        // hz` is: `c >= t * hz / 1e12`, rounded up.
        let hz = self.cfg.clock_hz.max(1) as u128;
        let c = (t as u128 * hz).div_ceil(1_000_000_000_000);
        c.min(u64::MAX as u128) as u64
    }

    /// Is `cycle` inside the trace window?
    #[inline]
    pub fn in_window(&self, cycle: u64) -> bool {
        self.truncated_at.is_none()
            && cycle >= self.cfg.first
            && self.cfg.count.is_none_or(|n| cycle - self.cfg.first < n)
    }

    fn time(&self, cycle: u64) -> u64 {
        Clock::new(self.cfg.clock_hz).time(cycle)
    }

    /// Record the values of `top` during `cycle`. Out of line: the
    /// untraced cycle loop keeps only the test for a tracer.
    ///
    /// The values are written one sample late: this call first writes
    /// the changes of the cycle sampled before (kept pending), then
    /// walks `top`. The comparison then loads the values long after the
    /// walk stored them; right after it, its vector loads waited for the
    /// walk's narrower stores to reach the cache (a store the processor
    /// cannot forward to a wider load).
    #[inline(never)]
    pub fn sample<T: Traced>(&mut self, cycle: u64, top: &T) -> io::Result<()> {
        if let Some(c) = self.pending.take() {
            self.write_cycle(c)?;
        }
        if !self.in_window(cycle) {
            return Ok(());
        }
        let padded = self.n_slots.next_multiple_of(64);
        let at = self.hot_at;
        let mut s = Sampler {
            scope_on: &self.scope_on,
            open_masks: &self.open_masks,
            versions: &mut self.versions,
            block_n: &self.block_n,
            sections: &self.sections,
            cur: self.hot.get_mut(at..at + padded).unwrap_or_default(),
            first: self.first_sample,
            at: Progress::default(),
            undeclared: false,
        };
        top.trace(&mut s);
        let (slots, undeclared) = (s.at.slots, s.undeclared);
        if undeclared {
            return Err(io::Error::other(
                "a module reported a block of signals it did not declare",
            ));
        }
        if slots != self.n_slots {
            return Err(io::Error::other(format!(
                "a module reported {} signals where it declared {}",
                slots, self.n_slots
            )));
        }
        self.pending = Some(cycle);
        self.sampled += 1;
        self.last_cycle = Some(cycle);
        Ok(())
    }

    /// Write the changes of `cycle`, sampled last.
    fn write_cycle(&mut self, cycle: u64) -> io::Result<()> {
        queue_cycle(&mut self.batch, cycle);
        self.write_changes();
        if let Some(e) = self.err.take() {
            return Err(e);
        }
        if self.batch.len() >= BATCH {
            self.w.hand_over(&mut self.batch)?;
        }
        // This cycle's own lines: two timestamps, the clock twice, the
        // cycle number in binary.
        while cycle >= self.digits_cycle {
            self.digits += 1;
            self.digits_below = self.digits_below.saturating_mul(10);
            self.digits_cycle = self.first_cycle_at(self.digits_below);
        }
        self.bytes += 2 * (self.digits + 2) + 6 + (64 - cycle.leading_zeros()).max(1) as u64 + 6;
        // `bytes` counts the VCD text; an FST is at least FST_SMALLER
        // times smaller.
        let written = if is_fst(&self.cfg.path) {
            self.bytes as f64 / FST_SMALLER
        } else {
            self.bytes as f64
        };
        if written > self.cfg.max_bytes as f64 {
            // An open-ended trace that outgrew the limit stops here, and says so.
            self.truncated_at = Some(cycle + 1);
            let msg = format!(
                "waveform stopped at cycle {} after about {} (limit {}); narrow it with --trace-cycles and --trace-scope",
                cycle + 1,
                human_bytes(written),
                human_bytes(self.cfg.max_bytes as f64)
            );
            eprintln!("morphosys: warning: {msg}");
            self.note.get_or_insert(msg);
        }
        Ok(())
    }

    /// Leave a note in the waveform (for example why the run stopped).
    pub fn note(&mut self, text: &str) {
        self.note = Some(text.to_string());
    }

    /// Close the VCD and write `<stem>.gtkw` and the filter files beside it.
    /// Returns the paths written.
    pub fn finish(mut self) -> io::Result<Vec<PathBuf>> {
        if let Some(c) = self.pending.take() {
            self.write_cycle(c)?;
        }
        let end = self.last_cycle.map_or(self.cfg.first, |c| c + 1);
        let t = self.time(end);
        let batch = std::mem::take(&mut self.batch);
        let closing =
            std::mem::replace(&mut self.w, Sink::Gone).hand_last(batch, t, self.note.clone())?;
        let Some(tmp_path) = self.tmp_path.take() else {
            // Written through to a device or FIFO: no file to save beside.
            closing.join()?;
            return Ok(vec![self.cfg.path.clone()]);
        };
        // While the writing thread writes the last changes and closes the
        // file: the save file, then the filter files once the values are
        // all known, each in a temporary file beside its name, renamed
        // into place only when the waveform is complete (the two threads'
        // shares of the end in turn took 0.7 ms of the bench's frame).
        let files = self.side_files()?;
        let save = stage(&files.gtkw, &self.save_file(&files))?;
        let Some(seen) = closing.seen() else {
            closing.join()?;
            return Err(io::Error::other("the waveform writer stopped"));
        };
        self.seen = seen;
        let mut filters = Vec::new();
        for (name, path) in &files.filters {
            filters.push(stage(path, &self.filter_file(name))?);
        }
        let mut decoders = Vec::new();
        for (kind, width, path) in &files.decoders {
            if let Some(dir) = path.parent() {
                std::fs::create_dir_all(dir)?;
            }
            decoders.push(stage(path, &self.surfer_decoder(*kind, *width))?);
        }
        closing.join()?;
        // The filter files and decoders, the save file, the waveform last.
        for (tmp, (_, path)) in filters.into_iter().zip(&files.filters) {
            tmp.persist(path).map_err(|e| e.error)?;
        }
        for (tmp, (_, _, path)) in decoders.into_iter().zip(&files.decoders) {
            tmp.persist(path).map_err(|e| e.error)?;
        }
        save.persist(&files.gtkw).map_err(|e| e.error)?;
        let partial = tmp_path.to_path_buf();
        let done = tmp_path.persist(&self.target).map_err(|e| e.error);
        forget_partial(&partial);
        done?;
        let mut written = vec![self.cfg.path.clone(), files.gtkw];
        written.extend(files.filters.into_iter().map(|(_, p)| p));
        written.extend(files.decoders.into_iter().map(|(_, _, p)| p));
        Ok(written)
    }

    /// The files beside the waveform: its save file and a filter file
    /// per translate filter.
    fn side_files(&self) -> io::Result<SideFiles> {
        let vcd_abs = std::path::absolute(&self.cfg.path)?;
        let gtkw = save_file_path(&vcd_abs);
        let mut filters: Vec<(&'static str, PathBuf)> = Vec::new();
        let mut decoders: Vec<(LabelKind, u32, PathBuf)> = Vec::new();
        for d in &self.decls {
            if let (Display::Label(k), Some(_)) = (d.info.display, &self.cfg.labels) {
                if !decoders.iter().any(|(dk, _, _)| *dk == k) {
                    decoders.push((k, d.info.width, decoder_path(&vcd_abs, k.filter_name())));
                }
            }
            let name = match d.info.display {
                Display::Translate(f) => f.name,
                Display::Label(k) if self.cfg.labels.is_some() => k.filter_name(),
                _ => continue,
            };
            if !filters.iter().any(|(n, _)| *n == name) {
                filters.push((name, filter_path(&vcd_abs, name)));
            }
        }
        Ok(SideFiles {
            vcd_abs,
            gtkw,
            filters,
            decoders,
        })
    }

    /// The filter file of the filter `name`: every value seen in the
    /// trace (plus the filter's whole table when it is small).
    fn filter_file(&self, name: &str) -> String {
        let mut vals: BTreeSet<(u32, u64)> = BTreeSet::new();
        // An address through the program's labels.
        if let Some(labels) = &self.cfg.labels {
            let mut kind = None;
            for (i, d) in self.decls.iter().enumerate() {
                if let Display::Label(k) = d.info.display {
                    if k.filter_name() == name {
                        kind = Some(k);
                        for v in &self.seen[i] {
                            vals.insert((d.info.width, *v));
                        }
                    }
                }
            }
            if let Some(kind) = kind {
                let mut s = format!(
                    "# GTKWave translate filter `{name}` written by morphosys: label+offset\n"
                );
                for (w, v) in &vals {
                    let digits = w.div_ceil(4) as usize;
                    if let Some(text) = label_text(labels, kind, *w, *v) {
                        s.push_str(&format!("{v:0digits$X} {text}\n"));
                    }
                }
                return s;
            }
        }
        let mut filter: Option<&Filter> = None;
        for (i, d) in self.decls.iter().enumerate() {
            if let Display::Translate(f) = d.info.display {
                if f.name == name {
                    filter = Some(f);
                    for v in &self.seen[i] {
                        vals.insert((d.info.width, *v));
                    }
                    if d.info.width <= 8 {
                        for v in 0..(1u64 << d.info.width) {
                            vals.insert((d.info.width, v));
                        }
                    }
                }
            }
        }
        let f = filter.expect("filter has a declaration");
        let mut s = String::new();
        s.push_str(&format!(
            "# GTKWave translate filter `{name}` written by morphosys\n"
        ));
        for (w, v) in vals {
            if let Some(text) = (f.text)(v) {
                let digits = w.div_ceil(4) as usize;
                s.push_str(&format!("{v:0digits$X} {text}\n"));
            }
        }
        s
    }

    /// Surfer's decoder of the addresses of `kind` (signals `width` bits
    /// wide) in the TOML format of the `instruction-decoder` crate: one
    /// exact-match entry per value seen in the trace, named by its
    /// `label+offset` (the same text as the GTKWave filter's).
    fn surfer_decoder(&self, kind: LabelKind, width: u32) -> String {
        let Some(labels) = &self.cfg.labels else {
            return String::new();
        };
        let mut vals: BTreeSet<u64> = BTreeSet::new();
        for (i, d) in self.decls.iter().enumerate() {
            if matches!(d.info.display, Display::Label(k) if k == kind) && d.info.width == width {
                vals.extend(self.seen[i].iter().copied());
            }
        }
        let name = kind.filter_name();
        let stem = self
            .cfg
            .path
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy();
        let mask = if width >= 64 { !0 } else { (1u64 << width) - 1 };
        let mut s = format!(
            "# Surfer decoder written by morphosys beside {}: label+offset of the program run\n\
             set = \"{stem} {name}\"\nwidth = {width}\n\n\
             [formats]\nnames = [\"label\"]\nparts = [[\"addr\", {width}, \"u64\"]]\n\n\
             [types]\nnames = [\"addr\"]\n\n[[types.addr]]\nname = \"addr\"\ntop = {}\nbot = 0\n\n\
             [label]\ntype = \"addr\"\n\n[label.repr]\ndefault = \"$name$\"\n",
            self.cfg.path.display(),
            width - 1
        );
        for v in vals {
            if let Some(text) = label_text(labels, kind, width, v) {
                let key = text.replace('\\', "\\\\").replace('"', "\\\"");
                s.push_str(&format!(
                    "\n[label.instructions.\"{key}\"]\nmask = {mask:#x}\nmatch = {v:#x}\n"
                ));
            }
        }
        s
    }

    /// The GTKWave save file.
    fn save_file(&self, files: &SideFiles) -> String {
        let (vcd_abs, gtkw, filters) = (&files.vcd_abs, &files.gtkw, &files.filters);
        let mut s = String::new();
        s.push_str("[*]\n[*] GTKWave save file written by morphosys\n[*]\n");
        s.push_str(&format!("[dumpfile] \"{}\"\n", vcd_abs.display()));
        s.push_str(&format!("[savefile] \"{}\"\n", gtkw.display()));
        s.push_str("[timestart] 0\n[size] 1400 900\n[pos] -1 -1\n");
        // Zoom: at zoom 0 GTKWave draws about 200 pixels per time unit and
        // each step of -1 halves that (measured with GTKWave 3.3.118); aim
        // for about 25 pixels per clock period. No markers set.
        let period = (self.time(self.cfg.first + 1) - self.time(self.cfg.first)).max(1) as f64;
        let zoom = -(period * 8.0).log2();
        s.push_str(&format!("*{zoom:.6} -1{}\n", " -1".repeat(26)));
        s.push_str(
            "[sst_width] 260\n[signals_width] 320\n[sst_expanded] 1\n[sst_vpaned_height] 240\n",
        );
        s.push_str(&format!("[treeopen] {}.\n", self.top));
        s.push_str(&format!(
            "@28\n{}.clk\n@24\n{}.cycle[63:0]\n",
            self.top, self.top
        ));
        // Group consecutive signals by their scope.
        let groups: Vec<(String, Vec<usize>)> = {
            let mut g: Vec<(String, Vec<usize>)> = Vec::new();
            for (i, d) in self.decls.iter().enumerate() {
                let scope = d.path[..d.path.len() - 1].join(".");
                match g.last_mut() {
                    Some((s, v)) if *s == scope => v.push(i),
                    _ => g.push((scope, vec![i])),
                }
            }
            g
        };
        // Groups open, whatever the size: GTKWave 3.3 shows a group saved
        // closed as an empty pair of braces (`tinyrisc {` / `} tinyrisc`)
        // until it is opened, which reads as an empty trace.
        for (scope, sigs) in &groups {
            let label = if scope.is_empty() {
                self.top.clone()
            } else {
                scope.clone()
            };
            s.push_str(&format!("@{:x}\n-{label}\n", 0x800200));
            for &i in sigs {
                let d = &self.decls[i];
                let name = format!("{}.{}", self.top, d.path.join("."));
                let name = if d.info.width > 1 {
                    format!("{name}[{}:0]", d.info.width - 1)
                } else {
                    name
                };
                match d.info.display {
                    Display::Hex => s.push_str(&format!("@22\n{name}\n")),
                    Display::Signed => s.push_str(&format!("@424\n{name}\n")),
                    Display::Bin => s.push_str(&format!("@28\n{name}\n")),
                    Display::Translate(_) | Display::Label(_) => {
                        let fname = match d.info.display {
                            Display::Translate(f) => f.name,
                            Display::Label(k) => k.filter_name(),
                            _ => "",
                        };
                        match filters.iter().position(|(n, _)| *n == fname) {
                            Some(k) => s.push_str(&format!(
                                "^{} {}\n@2022\n{name}\n",
                                k + 1,
                                filters[k].1.display()
                            )),
                            // An address without the program's labels.
                            None => s.push_str(&format!("@22\n{name}\n")),
                        }
                    }
                }
            }
            s.push_str(&format!("@{:x}\n-{label}\n", 0x1000200));
        }
        s
    }

    /// Paths of the files [`Tracer::finish`] writes, before it writes them.
    pub fn vcd_path(&self) -> &Path {
        &self.cfg.path
    }

    pub fn cycles_sampled(&self) -> u64 {
        self.sampled
    }

    fn matches_prefix(&self, path: &[String], complete: bool) -> bool {
        if self.patterns.is_empty() {
            return true;
        }
        self.patterns.iter().any(|pat| {
            let n = pat.len().min(path.len());
            let prefix_ok = (0..n).all(|i| glob(&pat[i], &path[i]));
            // A signal matches when the pattern covers a prefix of its path;
            // a scope may contain matches when the two agree so far.
            prefix_ok && (!complete || pat.len() <= path.len())
        })
    }
}

/// The declaration's walk ([`Tracer::create`]): each [`Probe`] call
/// declares what it reports and records in the tracer's tables what the
/// sampled walks ([`Sampler`]) replay.
struct Declaring<'a>(&'a mut Tracer);

impl Probe for Declaring<'_> {
    fn block_versioned(
        &mut self,
        version: u64,
        fields: &dyn Fn() -> Vec<Field>,
        _fill: &mut dyn FnMut(&mut [u64]),
    ) {
        self.0.declare_versioned(version, fields);
    }

    fn block(&mut self, fields: &dyn Fn() -> Vec<Field>, values: &[u64]) {
        let n = self.0.declare_block(fields, values);
        self.0.block_n.push(n as u32);
    }

    fn signal_row(&mut self, names: &[&str], width: u32, display: Display, _values: &[u64]) {
        for n in names {
            self.0.declare_signal(n, width, display);
        }
    }

    fn traced_signals(&mut self, names: &[&str]) -> u64 {
        self.0
            .declare_mask(names.len(), &mut |i| names[i].to_string(), true)
    }

    fn open_scopes(&mut self, n: usize, name: &mut dyn FnMut(usize) -> String) -> u64 {
        self.0.declare_mask(n, name, false)
    }

    fn scope(&mut self, name: fmt::Arguments<'_>) -> bool {
        self.0.declare_scope(name)
    }

    fn end(&mut self) {
        self.0.declare_end();
    }

    fn section(&mut self, _unchanged: bool) -> bool {
        self.0.declare_section();
        true
    }

    fn end_section(&mut self) {
        self.0.declare_end_section();
    }

    fn signal(&mut self, name: &str, width: u32, display: Display, _value: u64) {
        self.0.declare_signal(name, width, display);
    }
}

/// A sampled cycle's walk ([`Tracer::sample`]): each [`Probe`] call only
/// moves on through the tables the declaration made and copies the
/// values it reports, with no test of a phase. A section skipped moves
/// on to where it ends, a copy: when it added its counts, the compiler
/// added the six indices with vector instructions that loaded them right
/// after the calls before had stored them one by one, a store the
/// processor cannot forward. Moved here from the tracer, the walk took as
/// long; with the copy, the simulating thread's time for the bench's
/// traced frame went from 0.0166 to 0.0155 s (docs/performance.md).
struct Sampler<'a> {
    scope_on: &'a [bool],
    open_masks: &'a [u64],
    /// Per [`Probe::block_versioned`]: the version last sampled and the
    /// block's size.
    versions: &'a mut [(u64, usize)],
    block_n: &'a [u32],
    sections: &'a [Progress],
    /// A word per signal call: the value reported in this cycle (a block
    /// or section skipped leaves the last one).
    cur: &'a mut [u64],
    /// Every call counts as changed (the first cycle sampled).
    first: bool,
    /// The calls of each table so far.
    at: Progress,
    /// A block reported that was not declared.
    undeclared: bool,
}

impl Sampler<'_> {
    /// The next signal calls reported `values`.
    #[inline]
    fn calls(&mut self, values: &[u64]) {
        let start = self.at.slots;
        self.at.slots += values.len();
        if let Some(cur) = self.cur.get_mut(start..start + values.len()) {
            cur.copy_from_slice(values);
        } // else more calls than declared: reported after the walk
    }

    /// The next answer of [`Probe::open_scopes`] or
    /// [`Probe::traced_signals`], in the order they were declared.
    #[inline]
    fn next_mask(&mut self) -> u64 {
        let m = self.open_masks.get(self.at.masks).copied().unwrap_or(0);
        self.at.masks += 1;
        m
    }
}

impl Probe for Sampler<'_> {
    fn block_versioned(
        &mut self,
        version: u64,
        _fields: &dyn Fn() -> Vec<Field>,
        fill: &mut dyn FnMut(&mut [u64]),
    ) {
        let Some(v) = self.versions.get_mut(self.at.versions) else {
            self.undeclared = true;
            return;
        };
        let (last, n) = *v;
        v.0 = version;
        self.at.versions += 1;
        let start = self.at.slots;
        self.at.slots += n;
        if n == 0 || (version == last && !self.first) {
            // Nothing traced, or unchanged: the values last written still
            // hold.
            return;
        }
        if let Some(cur) = self.cur.get_mut(start..start + n) {
            fill(cur);
        }
    }

    fn block(&mut self, _fields: &dyn Fn() -> Vec<Field>, values: &[u64]) {
        let n = self.block_n.get(self.at.blocks).copied();
        self.at.blocks += 1;
        if n != Some(0) {
            self.calls(values);
        }
    }

    #[inline]
    fn block_with<const N: usize>(
        &mut self,
        _fields: &dyn Fn() -> Vec<Field>,
        fill: impl FnOnce(&mut [u64; N]),
    ) {
        let n = self.block_n.get(self.at.blocks).copied();
        self.at.blocks += 1;
        if n == Some(0) {
            return;
        }
        let start = self.at.slots;
        self.at.slots += N;
        if let Some(cur) = self
            .cur
            .get_mut(start..start + N)
            .and_then(|c| <&mut [u64; N]>::try_from(c).ok())
        {
            fill(cur);
        } // else more calls than declared: reported after the walk
    }

    fn signal_row(&mut self, names: &[&str], _width: u32, _display: Display, values: &[u64]) {
        self.calls(&values[..names.len()]);
    }

    fn traced_signals(&mut self, _names: &[&str]) -> u64 {
        self.next_mask()
    }

    fn open_scopes(&mut self, _n: usize, _name: &mut dyn FnMut(usize) -> String) -> u64 {
        self.next_mask()
    }

    fn scope(&mut self, _name: fmt::Arguments<'_>) -> bool {
        let on = self.scope_on.get(self.at.scopes).copied().unwrap_or(false);
        self.at.scopes += 1;
        on
    }

    fn end(&mut self) {}

    fn section(&mut self, unchanged: bool) -> bool {
        let end = self.sections.get(self.at.sections).copied();
        match end {
            Some(end) if unchanged && !self.first => {
                // The values of its calls are those in `cur` already: on
                // to where it ends.
                self.at = end;
                false
            }
            _ => {
                self.at.sections += 1;
                true
            }
        }
    }

    fn end_section(&mut self) {}

    #[inline]
    fn signal(&mut self, _name: &str, _width: u32, _display: Display, value: u64) {
        self.calls(&[value]);
    }
}

/// The declaring halves of the [`Probe`] calls.
impl Tracer {
    #[cold]
    #[inline(never)]
    fn declare_versioned(&mut self, version: u64, fields: &dyn Fn() -> Vec<Field>) {
        let n = self.declare_block(fields, &vec![0; fields().len()]);
        self.versions.push((version, n));
    }

    /// The scopes and signals [`Probe::block`] describes, with a slot for
    /// every field (those of scopes left out untraced), as the sampled
    /// cycles report every value; a block none of whose fields is traced
    /// takes no slot (its values are not kept, and the comparison after
    /// the walk has fewer to look at: a trace of the default scope went
    /// from 68 calls to 52, two chunks of 64 to one). The slots it takes.
    #[cold]
    #[inline(never)]
    fn declare_block(&mut self, fields: &dyn Fn() -> Vec<Field>, values: &[u64]) -> usize {
        let fields = fields();
        let (slots, decls) = (self.masks.len(), self.decls.len());
        for (scope, run) in scope_runs(&fields) {
            let open = scope.is_empty() || self.enter_scope(scope.to_string());
            for f in &fields[run] {
                if open {
                    self.declare_signal(f.name, f.width, f.display);
                } else {
                    self.untraced_slot();
                }
            }
            if open && !scope.is_empty() {
                self.declare_end();
            }
        }
        if values.len() != fields.len() {
            self.err.get_or_insert(io::Error::other(format!(
                "a block of {} signals reported {} values",
                fields.len(),
                values.len()
            )));
        }
        if self.decls.len() == decls {
            self.masks.truncate(slots);
            self.slot_decl.truncate(slots);
            return 0;
        }
        fields.len()
    }

    /// The calls of each table declared so far.
    fn progress(&self) -> Progress {
        Progress {
            scopes: self.scope_on.len(),
            slots: self.masks.len(),
            blocks: self.block_n.len(),
            masks: self.open_masks.len(),
            versions: self.versions.len(),
            sections: self.sections.len(),
        }
    }

    #[cold]
    #[inline(never)]
    fn declare_section(&mut self) {
        self.sections.push(Progress::default());
        self.open_sections.push(self.sections.len() - 1);
    }

    #[cold]
    #[inline(never)]
    fn declare_end_section(&mut self) {
        let Some(i) = self.open_sections.pop() else {
            self.err.get_or_insert(io::Error::other(
                "a module ended a section it did not begin",
            ));
            return;
        };
        self.sections[i] = self.progress();
    }

    #[cold]
    #[inline(never)]
    fn declare_scope(&mut self, name: fmt::Arguments<'_>) -> bool {
        let on = self.enter_scope(name.to_string());
        self.scope_on.push(on);
        on
    }

    /// Enter scope `name` while declaring if the patterns may take in
    /// something under it (then the caller leaves it with
    /// [`Tracer::declare_end`]); whether it did.
    fn enter_scope(&mut self, name: String) -> bool {
        self.stack.push(name);
        if self.stack.len() == 1 && !self.top_scopes.contains(&self.stack[0]) {
            self.top_scopes.push(self.stack[0].clone());
        }
        let on = self.matches_prefix(&self.stack, false);
        if on {
            if let Err(e) = self.w.add_module(self.stack.last().unwrap()) {
                self.err.get_or_insert(e);
            }
        } else {
            self.stack.pop();
        }
        on
    }

    #[cold]
    #[inline(never)]
    fn declare_end(&mut self) {
        self.stack.pop();
        if let Err(e) = self.w.upscope() {
            self.err.get_or_insert(e);
        }
    }
}

impl Tracer {
    /// Which of `n` names under the current scope the patterns take in
    /// (`complete`: as signals, else as scopes that may hold some):
    /// computed while declaring, replayed in the same order while sampling
    /// ([`Sampler::next_mask`]).
    #[cold]
    #[inline(never)]
    fn declare_mask(
        &mut self,
        n: usize,
        name: &mut dyn FnMut(usize) -> String,
        complete: bool,
    ) -> u64 {
        let mut mask = 0u64;
        for i in 0..n.min(64) {
            let mut path = self.stack.clone();
            path.push(name(i));
            if path.len() == 1 && !self.top_scopes.contains(&path[0]) {
                self.top_scopes.push(path[0].clone());
            }
            if self.matches_prefix(&path, complete) {
                mask |= 1 << i;
            }
        }
        self.open_masks.push(mask);
        mask
    }

    #[cold]
    #[inline(never)]
    fn declare_signal(&mut self, name: &str, width: u32, display: Display) {
        let mut path = self.stack.clone();
        path.push(name.to_string());
        if self.matches_prefix(&path, true) {
            let id = match self.w.add_wire(width, name) {
                Ok(id) => id,
                Err(e) => {
                    self.err.get_or_insert(e);
                    SigId::Vcd(0)
                }
            };
            self.masks.push(u64::MAX >> (64 - width.clamp(1, 64)));
            self.slot_decl.push(self.decls.len() as u32);
            self.decls.push(Decl {
                path,
                info: SigInfo { id, width, display },
            });
        } else {
            self.untraced_slot();
        }
    }

    /// A signal call that is not traced: its value is masked to 0.
    fn untraced_slot(&mut self) {
        self.masks.push(0);
        self.slot_decl.push(NOT_TRACED);
    }

    /// Write the values of the cycle's walk that changed (all traced
    /// ones the first time): per chunk of 64 calls, the mask of those that
    /// changed and their values queued as one message ([`MSG_CHUNK`]).
    fn write_changes(&mut self) {
        let first = std::mem::take(&mut self.first_sample);
        let padded = self.n_slots.next_multiple_of(64);
        let hot = self.hot.get_mut(self.hot_at..).unwrap_or_default();
        let (cur, rest) = hot.split_at_mut(padded.min(hot.len()));
        let (masks, lasts) = rest.split_at_mut(padded.min(rest.len()));
        let (cur, _) = cur.as_chunks::<64>();
        let (masks, _) = masks.as_chunks::<64>();
        let (lasts, _) = lasts.as_chunks_mut::<64>();
        let (costs, _) = self.costs.as_chunks::<64>();
        // Indexed, not zipped: the zip's length (the least of four) took
        // a chain of vector instructions in front of every sample.
        let mut left = self.n_slots;
        let mut j = 0;
        while left > 0 {
            // The groups of 8 calls that hold declared ones (the padding
            // after the last holds none).
            let groups = left.min(64).div_ceil(8);
            left = left.saturating_sub(64);
            let chunk = Chunk {
                c: &cur[j],
                m: &masks[j],
                l: &mut lasts[j],
                cost: &costs[j],
            };
            self.bytes += chunk.changes(&mut self.batch, j as u64, first, groups);
            j += 1;
        }
    }
}

/// The calls of each of the tracer's per-call tables made so far in a
/// walk (or by the end of a [`Probe::section`]).
#[derive(Clone, Copy, Default)]
struct Progress {
    scopes: usize,
    slots: usize,
    blocks: usize,
    masks: usize,
    versions: usize,
    sections: usize,
}

/// A chunk of 64 signal calls in a sampled cycle: the values the walk
/// reported, the masks of their widths (0 for a call not traced), the
/// values last written, and the bytes a change of each adds (about).
struct Chunk<'a> {
    c: &'a [u64; 64],
    m: &'a [u64; 64],
    l: &'a mut [u64; 64],
    cost: &'a [u8; 64],
}

impl Chunk<'_> {
    /// Queue the chunk's changes (every traced call if `first`) as chunk
    /// `j`'s message, if any, and keep the new values; the bytes they add.
    ///
    /// With AVX-512 eight calls at a time, without a branch per change:
    /// the values compared into a mask register, those that changed
    /// packed together by one instruction (`vpcompressq`) and stored as 8
    /// words wherever the last ones ended (the batch keeps room beyond a
    /// cycle's most for the last store), their costs summed by two more.
    /// One change at a time (`changes_portable`), the sampling thread
    /// took 1.5 ms more of the bench's traced frame (0.0194-0.0195 against
    /// 0.0178-0.0180 s); compared first and packed in a second pass, no
    /// less than one at a time.
    #[inline(always)]
    fn changes(self, batch: &mut Vec<u64>, j: u64, first: bool, groups: usize) -> u64 {
        #[cfg(all(
            target_arch = "x86_64",
            target_feature = "avx512f",
            target_feature = "avx512bw"
        ))]
        {
            use std::arch::x86_64::*;
            let Chunk { c, m, l, cost } = self;
            let len = batch.len();
            let spare = batch.spare_capacity_mut();
            // Reserved: the message, the mask and 64 values, the last 8
            // stored whole.
            assert!(spare.len() >= 66, "the batch keeps room for a chunk");
            let dst = spare.as_mut_ptr().cast::<u64>();
            let mut n = 2;
            let mut bits = 0u64;
            // SAFETY: every load and store of the 8 groups lies inside the
            // 64 words of `c`, `m` or `l`, or inside the batch's spare
            // capacity (`n` <= 58 before a store of 8 words, 66 checked
            // above); the first `n` words after `len` are all written
            // before `set_len`.
            unsafe {
                for g in 0..groups.min(8) {
                    let mg = _mm512_loadu_si512(m.as_ptr().add(8 * g).cast());
                    let v = _mm512_and_si512(_mm512_loadu_si512(c.as_ptr().add(8 * g).cast()), mg);
                    let k = if first {
                        _mm512_test_epi64_mask(mg, mg)
                    } else {
                        _mm512_cmpneq_epi64_mask(
                            v,
                            _mm512_loadu_si512(l.as_ptr().add(8 * g).cast()),
                        )
                    };
                    _mm512_mask_storeu_epi64(l.as_mut_ptr().add(8 * g).cast(), k, v);
                    _mm512_storeu_si512(dst.add(n).cast(), _mm512_maskz_compress_epi64(k, v));
                    n += k.count_ones() as usize;
                    bits |= u64::from(k) << (8 * g);
                }
                if bits == 0 {
                    return 0;
                }
                dst.write(MSG_CHUNK << 48 | j);
                dst.add(1).write(bits);
                batch.set_len(len + n);
                let costs = _mm512_maskz_mov_epi8(bits, _mm512_loadu_si512(cost.as_ptr().cast()));
                _mm512_reduce_add_epi64(_mm512_sad_epu8(costs, _mm512_setzero_si512())) as u64
            }
        }
        #[cfg(not(all(
            target_arch = "x86_64",
            target_feature = "avx512f",
            target_feature = "avx512bw"
        )))]
        {
            let _ = groups;
            self.changes_portable(batch, j, first)
        }
    }

    /// [`Chunk::changes`] one change at a time (what other CPUs run).
    #[cfg_attr(
        all(
            target_arch = "x86_64",
            target_feature = "avx512f",
            target_feature = "avx512bw"
        ),
        allow(dead_code)
    )]
    #[inline(always)]
    fn changes_portable(self, batch: &mut Vec<u64>, j: u64, first: bool) -> u64 {
        let Chunk { c, m, l, cost } = self;
        let mut bits = if first {
            changed_mask(m, &[u64::MAX; 64], &[0; 64])
        } else {
            changed_mask(c, m, l)
        };
        if bits == 0 {
            return 0;
        }
        batch.push(MSG_CHUNK << 48 | j);
        batch.push(bits);
        let mut bytes = 0;
        while bits != 0 {
            // Below 64: no bounds checks.
            let k = bits.trailing_zeros() as usize & 63;
            bits &= bits - 1;
            let v = c[k] & m[k];
            l[k] = v;
            bytes += u64::from(cost[k]);
            batch.push(v);
        }
        bytes
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn labels_name_an_address_by_the_label_at_or_before_it() {
        let l = Labels {
            code: vec![(8, "loop".into()), (20, "done".into())],
            context: vec![(0, "k_a".into())],
        };
        assert_eq!(l.locate(LabelKind::Code, 4), None);
        assert_eq!(l.locate(LabelKind::Code, 8).as_deref(), Some("loop"));
        assert_eq!(l.locate(LabelKind::Code, 16).as_deref(), Some("loop+8"));
        assert_eq!(l.locate(LabelKind::Code, 24).as_deref(), Some("done+4"));
        assert_eq!(l.locate(LabelKind::Context, 3).as_deref(), Some("k_a+3"));
    }

    use super::*;
    use crate::kernel::{Clocked, Fault, Sim};

    /// A counter reporting the same signals through blocks (of values
    /// given and filled in, and versioned ones) or through one call per
    /// scope and signal.
    struct Demo {
        t: u64,
        by_block: bool,
    }

    impl Clocked for Demo {
        fn eval(&mut self) -> Result<(), Fault> {
            Ok(())
        }
        fn commit(&mut self) {
            self.t += 1;
        }
    }

    impl Traced for Demo {
        fn trace<P: Probe>(&self, p: &mut P) {
            let t = self.t;
            let (a, b, c, d) = (t, t / 3, (t * 7) as i16 as u64, t % 2);
            let (r0, r1) = (t / 5, t / 5 * 3);
            let (e, f) = (t / 2 % 16, t / 2 % 4);
            if self.by_block {
                p.block_with(
                    &|| {
                        vec![
                            Field::new("", "a", 8, Display::Hex),
                            Field::new("x", "b", 4, Display::Hex),
                            Field::new("x", "c", 16, Display::Signed),
                            Field::new("y", "d", 1, Display::Bin),
                        ]
                    },
                    |v| *v = [a, b, c, d],
                );
                // The registers change every fifth cycle, and two nested
                // sections say so; `e` every second.
                if p.section(t % 5 != 0) {
                    if p.section(t % 5 != 0) {
                        p.block_versioned(
                            t / 5,
                            &|| {
                                vec![
                                    Field::new("regs", "r0", 8, Display::Hex),
                                    Field::new("regs", "r1", 8, Display::Hex),
                                ]
                            },
                            &mut |v| {
                                v[0] = r0;
                                v[1] = r1;
                            },
                        );
                        p.end_section();
                    }
                    p.end_section();
                }
                if p.section(t % 2 == 1) {
                    p.block_versioned(
                        t / 2,
                        &|| vec![Field::new("w", "e", 4, Display::Hex)],
                        &mut |v| v[0] = e,
                    );
                    p.block_with(&|| vec![Field::new("v", "f", 2, Display::Hex)], |v| {
                        *v = [f]
                    });
                    p.end_section();
                }
                p.block(&|| vec![Field::new("u", "g", 1, Display::Bin)], &[d]);
            } else {
                p.signal("a", 8, Display::Hex, a);
                if p.scope(format_args!("x")) {
                    p.signal("b", 4, Display::Hex, b);
                    p.signal("c", 16, Display::Signed, c);
                    p.end();
                }
                if p.scope(format_args!("y")) {
                    p.signal("d", 1, Display::Bin, d);
                    p.end();
                }
                if p.section(t % 5 != 0) {
                    if p.scope(format_args!("regs")) {
                        p.signal_row(&["r0", "r1"], 8, Display::Hex, &[r0, r1]);
                        p.end();
                    }
                    p.end_section();
                }
                if p.section(t % 2 == 1) {
                    if p.scope(format_args!("w")) {
                        p.signal("e", 4, Display::Hex, e);
                        p.end();
                    }
                    if p.scope(format_args!("v")) {
                        if p.traced_signals(&["f"]) & 1 != 0 {
                            p.signal("f", 2, Display::Hex, f);
                        }
                        p.end();
                    }
                    p.end_section();
                }
                if p.scope(format_args!("u")) {
                    if p.traced_signals(&["g"]) & 1 != 0 {
                        p.signal("g", 1, Display::Bin, d);
                    }
                    p.end();
                }
            }
        }
    }

    fn waveform(dir: &Path, by_block: bool, scope: &str, first: u64) -> Vec<u8> {
        let path = dir.join(format!("{by_block}.vcd"));
        let mut cfg = TraceConfig::new(&path);
        cfg.scope = scope.into();
        cfg.first = first;
        let mut sim = Sim::new(Demo { t: 0, by_block });
        sim.trace(cfg, "demo").unwrap();
        for _ in 0..600 {
            sim.step().unwrap();
        }
        sim.finish_trace().unwrap();
        std::fs::read(&path).unwrap()
    }

    /// Blocks and versioned blocks write the waveform that one call per
    /// scope and signal writes, whatever the scope filter and window; and
    /// so do sections skipped while unchanged (the registers' scope, and
    /// their versioned block within two nested sections).
    #[test]
    fn blocks_write_what_single_calls_write() {
        let dir = tempfile::tempdir().unwrap();
        for (scope, first) in [
            ("", 0),
            ("x,regs", 0),
            ("y", 7),
            ("regs.r1,a", 13),
            ("regs", 3),
            ("regs,w", 0),
            ("v.f,x", 5),
            ("v,u.x", 4),
        ] {
            let calls = waveform(dir.path(), false, scope, first);
            let blocks = waveform(dir.path(), true, scope, first);
            assert!(calls.len() > 2000, "{scope}: {} bytes", calls.len());
            assert!(
                calls == blocks,
                "{scope} from {first}: the waveforms differ"
            );
        }
    }

    /// A tracer dropped without being finished (a run that failed) ends
    /// its writing thread and leaves no file.
    #[test]
    fn an_unfinished_waveform_ends_its_writer_and_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cut.vcd");
        let p = path.clone();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut sim = Sim::new(Demo {
                t: 0,
                by_block: true,
            });
            sim.trace(TraceConfig::new(&p), "demo").unwrap();
            for _ in 0..40_000 {
                sim.step().unwrap();
            }
            drop(sim);
            tx.send(()).unwrap();
        });
        rx.recv_timeout(std::time::Duration::from_secs(20))
            .expect("dropping the tracer waited for its writer for ever");
        assert!(!path.exists());
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "{left:?}");
    }

    /// A waveform of some megabytes is written to blocks allocated ahead
    /// of it, and the file keeps none of them past its end: its length is
    /// its content (it ends with the last falling edge and the time the
    /// trace ends at) and it occupies no more than that.
    #[test]
    fn a_long_waveform_keeps_no_blocks_past_its_end() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("long.vcd");
        let mut sim = Sim::new(Demo {
            t: 0,
            by_block: true,
        });
        sim.trace(TraceConfig::new(&path), "demo").unwrap();
        let cycles = 60_000;
        for _ in 0..cycles {
            sim.step().unwrap();
        }
        sim.finish_trace().unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.len() > 3 << 20, "{} bytes", text.len());
        let end = Clock::new(TraceConfig::new("x").clock_hz).time(cycles);
        assert!(
            text.ends_with(&format!("\n0!\n#{end}\n")),
            "ends with {:?}",
            &text[text.len() - 40..]
        );
        #[cfg(target_os = "linux")]
        {
            use std::os::unix::fs::MetadataExt;
            let m = std::fs::metadata(&path).unwrap();
            assert_eq!(m.len(), text.len() as u64);
            assert!(
                m.blocks() * 512 < m.len() + (64 << 10),
                "{} bytes in {} blocks of 512",
                m.len(),
                m.blocks()
            );
        }
    }

    /// A xorshift generator of test values from `seed`.
    fn xorshift(mut x: u64) -> impl FnMut() -> u64 {
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        }
    }

    /// A batch handed over is a copy of every word, whatever its length
    /// and wherever the copy starts against a cache line.
    #[test]
    fn streaming_copies_hold_every_word() {
        let mut next = xorshift(0x0F1E_2D3C_4B5A_6978);
        for len in (0..200).chain([4095, 4096, 4097, BATCH + 77]) {
            let src: Vec<u64> = (0..len).map(|_| next()).collect();
            for skew in 0..9 {
                let mut dst: Vec<u64> = (0..skew).map(|_| next()).collect();
                let mut want = dst.clone();
                want.extend_from_slice(&src);
                copy_streaming(&mut dst, &src);
                assert!(dst == want, "{len} words after {skew}");
            }
        }
    }

    /// Batches handed over arrive whole and in order, whether the writing
    /// thread polls for them, has fallen asleep (long gaps: the first
    /// batch after one wakes it) or is behind (a full queue); a writing
    /// thread that ends stops the sender instead of leaving it waiting.
    #[test]
    fn handed_over_batches_arrive_in_order() {
        use std::sync::Arc;
        use std::time::Duration;
        let q = Arc::new(Handoff::new());
        let rx = WriterGone(q.clone());
        let (ack, acks) = std::sync::mpsc::channel();
        let reader = std::thread::spawn(move || {
            let mut got = Vec::new();
            while let Some(b) = rx.0.recv() {
                if got.len() % 50 < 20 {
                    // Behind: the queue fills.
                    std::thread::sleep(Duration::from_micros(200));
                }
                got.push(b.clone());
                rx.0.give_back(b);
                let _ = ack.send(got.len());
            }
            got
        });
        let mut sent = Vec::new();
        for k in 0..300u64 {
            let mut b = q.empty.lock().unwrap().pop().unwrap_or_default();
            assert!(b.is_empty());
            b.extend((0..k % 7).map(|i| k << 8 | i));
            sent.push(b.clone());
            assert!(q.send(b, reader.thread()));
            if k % 60 == 0 && k > 0 {
                // The batch after the sleep woke the reader (it would
                // otherwise sleep until the queue is full).
                while acks.recv_timeout(Duration::from_secs(10)).expect("woken") <= k as usize {}
            }
            if k % 60 == 59 {
                // Long enough for the reader to fall asleep.
                std::thread::sleep(POLL * IDLE_POLLS * 20);
            }
        }
        q.done.store(true, std::sync::atomic::Ordering::SeqCst);
        reader.thread().unpark();
        assert!(reader.join().unwrap() == sent);

        // A reader that takes two batches and ends.
        let q = Arc::new(Handoff::new());
        let rx = WriterGone(q.clone());
        let reader = std::thread::spawn(move || {
            rx.0.recv();
            rx.0.recv();
        });
        let thread = reader.thread().clone();
        let mut sent = 0;
        while q.send(vec![1], &thread) {
            sent += 1;
            assert!(sent < 100_000, "the sender never saw the reader gone");
        }
        reader.join().unwrap();
        assert!((2..=2 + QUEUED_BATCHES).contains(&sent), "{sent} sent");
    }

    /// Timestamps are written as `core::fmt` writes them: times growing
    /// by the half periods of several clocks (across digit counts and
    /// 10^16), by larger steps, and times out of order.
    #[test]
    fn timestamps_are_formatted_as_core_fmt_formats_them() {
        let mut next = xorshift(0x2545_F491_4F6C_DD1D);
        let mut runs: Vec<Vec<u64>> = Vec::new();
        for hz in [300_000_000u64, 1_000_000_000_000, 7, 123_456_789] {
            for start in [0u64, 99_990_000, 999_999_999_999_000, 9_999_999_999_990_000] {
                let mut clock = Clock::new(hz);
                let c0 = (start as u128 * hz as u128 / 1_000_000_000_000) as u64;
                let mut ts = Vec::new();
                for c in c0..c0 + 3000 {
                    let (rise, fall) = clock.edges(c);
                    ts.extend([rise, fall]);
                }
                runs.push(ts);
            }
        }
        let mut t = 0u64;
        runs.push(
            (0..3000)
                .map(|_| {
                    t += next() % 1_000_000_000;
                    t
                })
                .collect(),
        );
        runs.push((0..3000).map(|_| next() >> (next() % 64)).collect());
        runs.push(vec![
            0,
            0,
            1,
            9,
            10,
            99,
            100,
            u64::MAX,
            5,
            DECIMAL_LIMIT - 1,
            DECIMAL_LIMIT,
            3,
        ]);
        for (r, times) in runs.iter().enumerate() {
            let mut body = VcdBody::new(false);
            let mut want = String::new();
            for (k, &t) in times.iter().enumerate() {
                body.timestamp(t);
                want.push_str(&format!("#{t}\n"));
                if body.len > VCD_CHUNK || k + 1 == times.len() {
                    let got = std::str::from_utf8(&body.buf[..body.len]).unwrap();
                    assert!(got == want, "run {r}, up to time {k}");
                    body.len = 0;
                    want.clear();
                }
            }
        }
    }

    /// Binary digits are the same whichever way they are made (with
    /// AVX-512 where the build has it) and are `core::fmt`'s.
    #[test]
    fn binary_digits_are_core_fmt_binary_digits() {
        let mut next = xorshift(0x0123_4567_89AB_CDEF);
        for round in 0..20_000 {
            let x = next();
            let v = if round < 128 {
                (1u64 << (round % 64)) - (round / 64)
            } else {
                x >> (x % 64)
            };
            let bits = 64 - (v | 1).leading_zeros() as usize;
            let (mut fast, mut slow) = ([b'x'; 64], [b'y'; 64]);
            binary(&mut fast, v, bits);
            binary_portable(&mut slow, v, bits);
            let want = format!("{v:b}");
            assert_eq!(&fast[..bits], want.as_bytes(), "{v:#x}");
            assert_eq!(&slow[..bits], want.as_bytes(), "{v:#x}");
        }
    }

    /// A chunk's change message is the same whichever way it is built
    /// (with AVX-512 where the build has it, over the groups that hold
    /// declared calls; one change at a time otherwise) and says what
    /// changed: every traced call whose value, cut to its width, differs
    /// from the last one written, in order, with the bytes their changes
    /// add.
    #[test]
    fn chunk_messages_hold_the_changed_values_in_order() {
        let mut next = xorshift(0x9E37_79B9_7F4A_7C15);
        for round in 0..2000 {
            let (mut c, mut m, mut l, mut cost) = ([0u64; 64], [0u64; 64], [0u64; 64], [0u8; 64]);
            let density = next() % 65;
            // Calls past the chunk's last group of declared ones are
            // padding (not traced).
            let groups = 1 + (next() % 8) as usize;
            for k in 0..64 {
                let width = if k < 8 * groups { next() % 65 } else { 0 };
                m[k] = if width == 0 {
                    0
                } else {
                    u64::MAX >> (64 - width)
                };
                cost[k] = m[k].count_ones() as u8 + 6;
                l[k] = next() & m[k];
                // Some calls keep their value; some change only above
                // their width (no change).
                c[k] = match next() % 64 {
                    r if r < density => next(),
                    r if r % 2 == 0 => l[k] | !m[k] & next(),
                    _ => l[k],
                };
            }
            let first = round % 7 == 0;
            let j = next() % 5;
            let (mut fast, mut slow) = (vec![7u64], vec![7u64]);
            fast.reserve(80);
            let (mut lf, mut ls) = (l, l);
            let bf = Chunk {
                c: &c,
                m: &m,
                l: &mut lf,
                cost: &cost,
            }
            .changes(&mut fast, j, first, groups);
            let bs = Chunk {
                c: &c,
                m: &m,
                l: &mut ls,
                cost: &cost,
            }
            .changes_portable(&mut slow, j, first);
            assert_eq!((&fast, bf, lf), (&slow, bs, ls), "round {round}");
            // What the message should say, computed plainly.
            let changed: Vec<usize> = (0..64)
                .filter(|&k| m[k] != 0 && (first || c[k] & m[k] != l[k]))
                .collect();
            let mut want = vec![7u64];
            if !changed.is_empty() {
                want.push(MSG_CHUNK << 48 | j);
                want.push(changed.iter().map(|&k| 1u64 << k).sum());
                want.extend(changed.iter().map(|&k| c[k] & m[k]));
            }
            assert_eq!(slow, want, "round {round}");
            let bytes: u64 = changed.iter().map(|&k| u64::from(cost[k])).sum();
            assert_eq!(bs, bytes, "round {round}");
            for k in 0..64 {
                let kept = if changed.contains(&k) {
                    c[k] & m[k]
                } else {
                    l[k]
                };
                assert_eq!(ls[k], kept, "round {round}, call {k}");
            }
        }
    }

    /// A value change is written as `core::fmt` writes it: `b`, the
    /// binary digits without leading zeros, a space and the code (one
    /// digit and the code for one bit).
    #[test]
    fn value_changes_are_formatted_as_core_fmt_formats_them() {
        let mut body = VcdBody::new(false);
        body.add_id("!").unwrap();
        body.add_id("%a~").unwrap();
        let mut values: Vec<u64> = vec![0, 1, 2, 3, 0xFF, 0x100, 0x8000, u64::MAX, 1 << 63];
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..2000 {
            // xorshift, with every width of value
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            values.push(x >> (x % 64));
        }
        let mut want = String::new();
        for (k, &v) in values.iter().enumerate() {
            let (id, code) = if k % 2 == 0 { (0, "!") } else { (1, "%a~") };
            body.change(id, 64, v);
            want.push_str(&format!("b{v:b} {code}\n"));
            body.change(id, 1, v);
            want.push_str(&format!("{}{code}\n", v & 1));
            if body.len > VCD_CHUNK / 2 {
                break;
            }
        }
        assert_eq!(std::str::from_utf8(&body.buf[..body.len]).unwrap(), want);
        // Timestamps: every number of digits, and the edges of each.
        let mut body = VcdBody::new(false);
        let mut want = String::new();
        let mut times = vec![0, 1, 9, 10, 99, 100, 999, u64::MAX, u64::MAX - 1];
        for d in 1..20 {
            let p = 10u64.pow(d);
            times.extend([p - 1, p, p + 1, p + p / 3]);
        }
        for _ in 0..2000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            times.push(x >> (x % 64));
        }
        for t in times {
            body.timestamp(t);
            want.push_str(&format!("#{t}\n"));
        }
        assert_eq!(std::str::from_utf8(&body.buf[..body.len]).unwrap(), want);
        for b in 0..=255u8 {
            assert_eq!(bin8(b).to_le_bytes(), *format!("{b:08b}").as_bytes());
        }
    }

    #[test]
    fn glob_matches_like_a_shell() {
        assert!(glob("rc_r*_c0", "rc_r3_c0"));
        assert!(!glob("rc_r*_c0", "rc_r3_c1"));
        assert!(glob("r?", "r3"));
        assert!(!glob("r?", "r13"));
        assert!(glob("*", "anything"));
        assert!(glob("alu", "alu"));
        assert!(!glob("alu", "alux"));
    }
}
