//! Where value changes go (a VCD stream or an FST file), and the writing
//! thread's loop that formats each batch of changes into it.

use super::format::NOT_TRACED;
use super::format::{fst_err, Clock, SigId, Slot, VcdBody};
use super::handoff::{
    copy_streaming, Handoff, WriterGone, MSG_CHUNK, MSG_LONG, MSG_VALUE, SPARE_BATCHES,
};
use super::{is_fst, TraceConfig};
use std::collections::BTreeSet;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use vcd::TimescaleUnit;

/// Where value changes go: a VCD text stream, or an FST file (header
/// while declaring, body while sampling).
pub(super) enum Sink {
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
pub(super) type Written = (Sink, io::Result<()>);

/// A waveform its writing thread is finishing ([`Sink::hand_last`]).
pub(super) struct Closing {
    pub(super) worker: std::thread::JoinHandle<Written>,
    pub(super) seen: std::sync::mpsc::Receiver<Vec<BTreeSet<u64>>>,
    /// The last batch reached the thread.
    pub(super) sent: bool,
}

impl Closing {
    /// Per traced signal the values it took if it has a translate filter,
    /// once every change is written; `None` when the thread ended without
    /// sending them ([`Closing::join`] then says how).
    pub(super) fn seen(&self) -> Option<Vec<BTreeSet<u64>>> {
        self.seen.recv().ok()
    }

    /// Wait for the file to be closed; how writing went.
    pub(super) fn join(self) -> io::Result<()> {
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

impl Sink {
    pub(super) fn add_module(&mut self, name: &str) -> io::Result<()> {
        match self {
            Sink::Vcd(w, _) => w.add_module(name),
            Sink::FstHeader(h) => h
                .scope(name, "", fst_writer::FstScopeType::Module)
                .map_err(fst_err),
            _ => Ok(()),
        }
    }

    pub(super) fn upscope(&mut self) -> io::Result<()> {
        match self {
            Sink::Vcd(w, _) => w.upscope(),
            Sink::FstHeader(h) => h.up_scope().map_err(fst_err),
            _ => Ok(()),
        }
    }

    pub(super) fn add_wire(&mut self, width: u32, name: &str) -> io::Result<SigId> {
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
    pub(super) fn end_definitions(&mut self) -> io::Result<()> {
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
    pub(super) fn threaded(
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
        // A VCD's handles, for its own loop ([`vcd_batch`]); an untraced
        // call's never appears in a message.
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
        let mut w = WritingThread {
            sink: self,
            slots,
            seen: Seen::new(signals),
            vcd_ids,
            clock: Clock::new(clock_hz),
            fall: None,
            stepped: false,
            clk,
            cycle_id,
            section_bytes,
        };
        let worker = std::thread::Builder::new()
            .name("waveform writer".into())
            .spawn(move || {
                if let Sink::Vcd(_, body) = &mut w.sink {
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
                while let Some(batch) = rx.0.recv() {
                    if res.is_err() {
                        continue; // keep draining: the sender must not block
                    }
                    res = w.batch(&batch);
                    rx.0.give_back(batch);
                }
                w.finish(res, &rx, seen_tx)
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
    pub(super) fn close(&mut self, t: u64, note: Option<&str>) -> io::Result<()> {
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
    pub(super) fn hand_last(
        self,
        batch: Vec<u64>,
        t: u64,
        note: Option<String>,
    ) -> io::Result<Closing> {
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
    pub(super) fn hand_over(&mut self, batch: &mut Vec<u64>) -> io::Result<()> {
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
    pub(super) fn fst_section(&mut self, limit: usize) -> io::Result<()> {
        if let Sink::FstBody(b) = self {
            if b.size() > limit {
                b.flush().map_err(fst_err)?;
            }
        }
        Ok(())
    }

    pub(super) fn timestamp(&mut self, t: u64) -> io::Result<()> {
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
    pub(super) fn change(&mut self, id: SigId, width: u32, v: u64) -> io::Result<()> {
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

pub(super) fn fst_change(
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
pub(super) fn changed_mask(cur: &[u64; 64], mask: &[u64; 64], last: &[u64; 64]) -> u64 {
    let mut bits = 0;
    for k in 0..64 {
        bits |= u64::from(cur[k] & mask[k] != last[k]) << k;
    }
    bits
}

/// The waveform's writing thread ([`Sink::threaded`]): the sink it owns
/// and what it keeps between batches.
struct WritingThread {
    sink: Sink,
    /// Per signal call, its [`Slot`] if traced.
    slots: Vec<Option<Slot>>,
    /// Values of the filtered signals, deduplicated whenever a list
    /// doubles (a set insertion per change cost more).
    seen: Seen,
    /// A VCD's handles, for its own loop ([`vcd_batch`]).
    vcd_ids: Option<(Vec<(u32, u32, bool, u32)>, u32, u32)>,
    clock: Clock,
    /// The falling edge of the last cycle begun, written when the next
    /// one begins or the trace ends.
    fall: Option<u64>,
    /// A section can end only after a time step of its own (the FST
    /// writer cannot start one at the time it ended at).
    stepped: bool,
    clk: SigId,
    cycle_id: SigId,
    section_bytes: usize,
}

impl WritingThread {
    /// Write one batch of messages.
    fn batch(&mut self, batch: &[u64]) -> io::Result<()> {
        if let (Sink::Vcd(w, body), Some((ids, clk, cycle))) = (&mut self.sink, &self.vcd_ids) {
            let edges = (&mut self.clock, &mut self.fall, *clk, *cycle);
            return vcd_batch(w.writer(), body, batch, ids, &mut self.seen, edges);
        }
        let mut k = 0;
        while k < batch.len() {
            let m = batch[k];
            k += 1;
            let (tag, low) = (m >> 48, m & MSG_VALUE);
            match tag {
                MSG_CHUNK => {
                    let Some(&bits) = batch.get(k) else {
                        return Err(io::Error::other("a change message cut short"));
                    };
                    k += 1;
                    for (s, v) in changes(low, bits, batch, &mut k) {
                        let Some((id, w, filtered, i)) = self.slots.get(s).copied().flatten()
                        else {
                            return Err(io::Error::other("a change of a signal not declared"));
                        };
                        if filtered {
                            self.seen.add(i as usize, v);
                        }
                        self.sink.change(id, w, v)?;
                    }
                }
                _ => {
                    let c = if tag == MSG_LONG {
                        k += 1;
                        batch.get(k - 1).copied().unwrap_or(0)
                    } else {
                        low
                    };
                    self.cycle(c)?;
                }
            }
        }
        Ok(())
    }

    /// Cycle `c` begins: the falling edge of the cycle before (if any),
    /// then this cycle's rising edge, `clk` and the `cycle` counter.
    fn cycle(&mut self, c: u64) -> io::Result<()> {
        let sink = &mut self.sink;
        if let Some(t) = self.fall.take() {
            sink.timestamp(t)?;
            sink.change(self.clk, 1, 0)?;
            self.stepped = true;
        }
        if std::mem::take(&mut self.stepped) {
            sink.fst_section(self.section_bytes)?;
        }
        let (rise, f) = self.clock.edges(c);
        self.fall = Some(f);
        sink.timestamp(rise)?;
        sink.change(self.clk, 1, 1)?;
        sink.change(self.cycle_id, 64, c)
    }

    /// After the last batch: the last falling edge, the filtered signals'
    /// values (first, so that the filter files are written while this
    /// thread closes the waveform), then the file closed at the end time
    /// the simulating thread left.
    fn finish(
        mut self,
        mut res: io::Result<()>,
        rx: &WriterGone,
        seen_tx: std::sync::mpsc::SyncSender<Vec<BTreeSet<u64>>>,
    ) -> Written {
        let sink = &mut self.sink;
        if res.is_ok() {
            if let Some(t) = self.fall {
                res = sink.timestamp(t).and_then(|_| sink.change(self.clk, 1, 0));
            }
        }
        let seen = self
            .seen
            .lists
            .into_iter()
            .map(BTreeSet::from_iter)
            .collect();
        let _ = seen_tx.send(seen);
        if res.is_ok() {
            let end = rx.0.end.lock().unwrap_or_else(|e| e.into_inner()).take();
            res = match end {
                Some((t, note)) => sink.close(t, note.as_deref()),
                None => Err(io::Error::other("the waveform ended without an end time")),
            };
        }
        (self.sink, res)
    }
}

/// The values each signal with a translate filter took, gathered by the
/// writing thread and deduplicated whenever a list doubles (a set
/// insertion per change cost more). A value found in a small
/// direct-mapped table of the values met last is not gathered again: an
/// instruction word or a context word comes back thousands of times, and
/// without the table the lists were sorted every few hundred changes.
pub(super) struct Seen {
    pub(super) lists: Vec<Vec<u64>>,
    pub(super) cap: Vec<usize>,
    pub(super) recent: Vec<[u64; RECENT]>,
}

/// Entries of [`Seen`]'s table of recent values, per signal.
pub(super) const RECENT: usize = 256;

impl Seen {
    pub(super) fn new(n: usize) -> Seen {
        Seen {
            lists: vec![Vec::new(); n],
            cap: vec![1024; n],
            // u64::MAX is no value: no signal is wider than 64 bits, and
            // a 64-bit one of all ones is simply gathered each time.
            recent: vec![[u64::MAX; RECENT]; n],
        }
    }

    #[inline(always)]
    pub(super) fn add(&mut self, i: usize, v: u64) {
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
pub(super) fn changes<'a>(
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

crate::simd::versions! {
    /// The writing thread's loop over a batch for a VCD (the general loop of
    /// [`Sink::threaded`] matches the sink and the handle at every message):
    /// `ids` per signal call its code, width, whether it has a translate
    /// filter and its signal's index (untraced: [`NOT_TRACED`]); `edges` the
    /// clock, the falling edge still to write, and the codes of `clk` and
    /// `cycle`.
    pub(super) fn vcd_batch(
        out: &mut BufWriter<File>,
        body: &mut VcdBody,
        batch: &[u64],
        ids: &[(u32, u32, bool, u32)],
        seen: &mut Seen,
        edges: (&mut Clock, &mut Option<u64>, u32, u32),
    ) -> io::Result<()>;
    versions vcd_batch_portable vcd_batch_avx2 vcd_batch_avx512;
    {
        let (clock, fall, clk, cycle) = edges;
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
}

/// The writer of the waveform's header: FST where the path ends in `.fst`,
/// else VCD (`partial`: written to a temporary file).
pub(super) fn header_sink(
    cfg: &TraceConfig,
    file: std::fs::File,
    partial: bool,
) -> io::Result<Sink> {
    let out = BufWriter::with_capacity(1 << 16, file);
    let version = concat!("morphosys ", env!("CARGO_PKG_VERSION"));
    Ok(if is_fst(&cfg.path) {
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
        Sink::Vcd(w, VcdBody::unallocated(partial))
    })
}
