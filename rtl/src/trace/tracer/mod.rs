//! The [`Tracer`]: created with its file, declared by a first walk of the
//! chip, sampled each traced cycle, finished into its file.

mod sampler;
#[cfg(test)]
pub(super) use sampler::Chunk;

use std::collections::BTreeSet;
use std::io;
use std::path::{Path, PathBuf};

use super::files::{
    check_scope_patterns, decoder_path, filter_path, forget_partial, glob, open_output,
    save_file_path, stage, SideFiles,
};
use super::format::{Clock, Decl, SigId, NOT_TRACED};
use super::handoff::{queue_cycle, BATCH};
use super::label_text;
use super::sink::{header_sink, Sink};
use super::Traced;
use super::{is_fst, Display, Filter, LabelKind, TraceConfig, BYTES_PER_SIGNAL_CYCLE, FST_SMALLER};
use sampler::{Declaring, Progress, Sampler};

/// The VCD writer. Attach it to a [`crate::kernel::Sim`].
pub struct Tracer {
    pub(super) cfg: TraceConfig,
    /// The temporary file renamed onto the waveform's file by `finish`;
    /// `None` when the waveform goes straight to a device or FIFO.
    pub(super) tmp_path: Option<tempfile::TempPath>,
    /// The regular file the waveform ends up in (a symbolic link followed).
    pub(super) target: PathBuf,
    pub(super) top: String,
    pub(super) w: Sink,
    pub(super) patterns: Vec<Vec<String>>,
    // declaration state
    pub(super) stack: Vec<String>,
    /// Every top-level scope declared (matched or not), for the message
    /// when the scope patterns match no signal.
    pub(super) top_scopes: Vec<String>,
    pub(super) decls: Vec<Decl>,
    // per-call tables, indexed by call order
    pub(super) scope_on: Vec<bool>,
    /// Answers of [`Probe::open_scopes`], in call order.
    pub(super) open_masks: Vec<u64>,
    /// Per [`Probe::block_versioned`] call: the version last sampled and
    /// the block's size.
    pub(super) versions: Vec<(u64, usize)>,
    /// Per [`Probe::block`] call: the signal calls it takes, 0 when none
    /// of its fields is traced (its values are then not kept at all).
    pub(super) block_n: Vec<u32>,
    /// Per [`Probe::section`]: the calls of each table made by its end
    /// ([`Progress`], counted from the walk's start; the walk makes the
    /// same calls every cycle), where a section skipped moves on to.
    pub(super) sections: Vec<Progress>,
    /// While declaring: the sections open.
    pub(super) open_sections: Vec<usize>,
    /// Per signal call (in call order, traced or not), while declaring:
    /// the mask of its width (0 when it is not traced, so it never
    /// changes).
    pub(super) masks: Vec<u64>,
    /// While sampling, from word [`Tracer::hot_at`] on, three arrays of a
    /// word per signal call padded with untraced calls to a multiple of
    /// 64: the value reported in the cycle being sampled
    /// (a block or section skipped leaves the last one; the walk only
    /// copies values here, they are compared 64 at a time after it), the
    /// mask of its width, and the value last written. One allocation,
    /// each array on whole cache lines, so that no vector access splits a
    /// line or a page: with the arrays wherever the heap put them (the
    /// last values once straddled a 4 KB page), the simulating thread's
    /// time depended on where an unrelated allocation put them.
    pub(super) hot: Vec<u64>,
    pub(super) hot_at: usize,
    /// Signal calls declared (before the padding).
    pub(super) n_slots: usize,
    /// Per signal call: the bytes a change of it adds to the waveform
    /// (about).
    pub(super) costs: Vec<u8>,
    /// Messages for the writing thread ([`Sink::Threaded`]): this
    /// thread's own batch, handed over as a copy ([`copy_streaming`])
    /// once [`BATCH`] words wait (checked after each cycle: room for the
    /// most a cycle adds is reserved beyond it).
    pub(super) batch: Vec<u64>,
    /// Per signal call: the index of its declaration, [`NOT_TRACED`] if none.
    pub(super) slot_decl: Vec<u32>,
    // sampling state
    /// In the first sampled cycle every call counts as a change (and the
    /// traced ones are written).
    pub(super) first_sample: bool,
    /// The cycle sampled last, its values in [`Tracer::hot`] still to be
    /// compared and written ([`Tracer::sample`]).
    pub(super) pending: Option<u64>,
    /// The digits of the times written, the time that takes one more (the
    /// times only grow) and the first cycle at that time.
    pub(super) digits: u64,
    pub(super) digits_below: u64,
    pub(super) digits_cycle: u64,
    pub(super) seen: Vec<BTreeSet<u64>>,
    pub(super) clk: SigId,
    pub(super) cycle_id: SigId,
    pub(super) sampled: u64,
    pub(super) last_cycle: Option<u64>,
    pub(super) note: Option<String>,
    /// First I/O error met while declaring (the Probe calls cannot return it).
    pub(super) err: Option<io::Error>,
    /// Approximate bytes of value changes written so far.
    pub(super) bytes: u64,
    /// Cycle at which the size limit stopped the trace.
    pub(super) truncated_at: Option<u64>,
}

pub(super) fn human_bytes(b: f64) -> String {
    let units = ["B", "KB", "MB", "GB", "TB", "PB"];
    let mut v = b;
    let mut u = 0;
    while v >= 1000.0 && u + 1 < units.len() {
        v /= 1000.0;
        u += 1;
    }
    format!("{v:.1} {}", units[u])
}

impl Drop for Tracer {
    fn drop(&mut self) {
        // Not finished: the temporary file goes (TempPath removes it), and
        // leaves the list of partial files.
        if let Some(t) = &self.tmp_path {
            forget_partial(self.cfg.partial_files, t);
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
        let (file, tmp_path, target) = open_output(&cfg)?;
        let mut w = header_sink(&cfg, file, tmp_path.is_some())?;
        w.add_module(top_name)?;
        let clk = w.add_wire(1, "clk")?;
        let cycle_id = w.add_wire(64, "cycle")?;
        let patterns = scope_patterns(&cfg.scope, top_name);
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
        t.refuse_too_large()?;
        t.start_body()?;
        Ok(t)
    }

    /// Refuse up front a trace that would fill the disk: the signals over
    /// the cycles it may run, as VCD (or FST, compressed), against the
    /// limit.
    fn refuse_too_large(&self) -> io::Result<()> {
        let t = self;
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
        Ok(())
    }

    /// The declarations ended: the writer's thread started on the traced
    /// slots, the per-cycle state laid out.
    fn start_body(&mut self) -> io::Result<()> {
        let t = self;
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
        Ok(())
    }

    /// Number of signals that passed the scope filter.
    pub fn signal_count(&self) -> usize {
        self.decls.len()
    }

    /// The first cycle whose rising edge is at `t` ps or later.
    pub(super) fn first_cycle_at(&self, t: u64) -> u64 {
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

    pub(super) fn time(&self, cycle: u64) -> u64 {
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
    pub fn sample<T: Traced>(&mut self, cycle: u64, top: &T, unchanged: u8) -> io::Result<()> {
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
            unchanged,
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
    pub(super) fn write_cycle(&mut self, cycle: u64) -> io::Result<()> {
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
        // into place only when the waveform is complete (the two threads
        // finish at once instead of in turn).
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
        forget_partial(self.cfg.partial_files, &partial);
        done?;
        let mut written = vec![self.cfg.path.clone(), files.gtkw];
        written.extend(files.filters.into_iter().map(|(_, p)| p));
        written.extend(files.decoders.into_iter().map(|(_, _, p)| p));
        Ok(written)
    }

    /// The files beside the waveform: its save file and a filter file
    /// per translate filter.
    pub(super) fn side_files(&self) -> io::Result<SideFiles> {
        let vcd_abs = std::path::absolute(&self.cfg.path)?;
        // The save file names the waveform and its filters one per line:
        // a line break in the path would add lines (GTKWave runs a
        // process filter a `^>` line names).
        if let Some(c) = vcd_abs.to_string_lossy().chars().find(|c| c.is_control()) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "the waveform's path holds the control character U+{:04X}, which its GTKWave save file cannot name",
                    c as u32
                ),
            ));
        }
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
    pub(super) fn filter_file(&self, name: &str) -> String {
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
    pub(super) fn surfer_decoder(&self, kind: LabelKind, width: u32) -> String {
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
    pub(super) fn save_file(&self, files: &SideFiles) -> String {
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

    pub(super) fn matches_prefix(&self, path: &[String], complete: bool) -> bool {
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
/// The scope patterns of `--trace-scope`: each a path of names, the top's
/// own name dropped.
fn scope_patterns(scope: &str, top_name: &str) -> Vec<Vec<String>> {
    scope
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
        .collect()
}
