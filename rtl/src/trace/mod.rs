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

use std::fmt;
use std::path::{Path, PathBuf};

mod files;
mod format;
mod handoff;
mod sink;
mod tracer;

pub(crate) use self::files::side_files;
pub use self::files::{check_scope_patterns, PartialFiles};
pub use self::tracer::Tracer;

#[cfg(test)]
mod tests;

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
    /// The parts of the traced module its simulation reports unchanged
    /// since the last sample (bit k: the module's part k, as it numbers
    /// them): the fast loops know which blocks they did not evaluate and
    /// pass that with each sample ([`crate::kernel::Sim`]). A module asks
    /// here rather than keeping waveform state of its own.
    fn unchanged(&self) -> u8 {
        0
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
    /// What the program does with the waveform's temporary file
    /// ([`PartialFiles`]; `None`: only made and renamed).
    pub partial_files: Option<PartialFiles>,
}

/// Whether a waveform path asks for FST (`.fst`) rather than VCD.
pub(crate) fn is_fst(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("fst"))
}

/// Value changes an FST writer holds in memory before it writes them out
/// as one compressed section (the default of
/// [`TraceConfig::fst_section_bytes`]).
pub(crate) const FST_SECTION_BYTES: usize = 64 << 20;

/// The largest waveform written by default (4 GiB).
pub const MAX_TRACE_BYTES: u64 = 4 << 30;

/// How many times smaller an FST is than the VCD of the same window, at
/// the least (measured on render windows: 11 to 19 times); the size
/// limits, counted in VCD bytes, allow an FST this many times more.
pub(crate) const FST_SMALLER: f64 = 10.0;

/// Estimated VCD bytes per traced signal per cycle: about a quarter of the
/// signals change in a typical cycle of the tracer, at about 8 bytes a
/// change (measured on `morphosys run` and `render` traces: 1.5 to 2.5).
pub(crate) const BYTES_PER_SIGNAL_CYCLE: f64 = 2.0;

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
            partial_files: None,
        }
    }
}
