//! One work item of a frame on a fresh chip ([`run_item`]): the frame's tiles cut into items
//! ([`work_items`]), run in order on the thread pool, counted as one chip running the whole
//! tile list would count them.

use anyhow::{anyhow, Result};
use firmware::asm::Image;
use firmware::tracer::{self, data, mem, Firmware};
use rtl::chip::run_to_halt;
use rtl::rc::Word;
use rtl::{Chip, Sim, Stats, Timing};

use super::memory::{feed, item_memory, read_tiles};
use super::{RAY_EYE, RAY_REFLECT, RAY_REFRACT, RAY_SHADOW};

pub(crate) fn add_stats(a: &mut Stats, b: &Stats) {
    a.cycles += b.cycles;
    a.array_busy_cycles += b.array_busy_cycles;
    a.active_rc_cycles += b.active_rc_cycles;
    a.risc_instructions += b.risc_instructions;
    a.risc_busy_cycles += b.risc_busy_cycles;
    a.array_stall_cycles += b.array_stall_cycles;
    a.dma_stall_cycles += b.dma_stall_cycles;
    a.array_idle_control_cycles += b.array_idle_control_cycles;
    a.dma_busy_cycles += b.dma_busy_cycles;
    a.dma_words += b.dma_words;
    a.dma_transfers += b.dma_transfers;
    a.dma_waits_watched += b.dma_waits_watched;
    for (a, b) in a.issues_watched.iter_mut().zip(b.issues_watched) {
        *a += b;
    }
    a.watched_offered += b.watched_offered;
    for c in 0..2 {
        a.watched_runs[c] += b.watched_runs[c];
        a.watched_rcs[c] += b.watched_rcs[c];
        for t in 0..rtl::chip::WATCH_TAGS {
            a.watched_rcs_by_tag[c][t] += b.watched_rcs_by_tag[c][t];
        }
    }
}

fn sub_stats(a: &mut Stats, b: &Stats) {
    a.cycles -= b.cycles.min(a.cycles);
    a.array_busy_cycles -= b.array_busy_cycles.min(a.array_busy_cycles);
    a.active_rc_cycles -= b.active_rc_cycles.min(a.active_rc_cycles);
    a.risc_instructions -= b.risc_instructions.min(a.risc_instructions);
    a.risc_busy_cycles -= b.risc_busy_cycles.min(a.risc_busy_cycles);
    a.array_stall_cycles -= b.array_stall_cycles.min(a.array_stall_cycles);
    a.dma_stall_cycles -= b.dma_stall_cycles.min(a.dma_stall_cycles);
    a.array_idle_control_cycles -= b.array_idle_control_cycles.min(a.array_idle_control_cycles);
    a.dma_busy_cycles -= b.dma_busy_cycles.min(a.dma_busy_cycles);
    a.dma_words -= b.dma_words.min(a.dma_words);
    a.dma_transfers -= b.dma_transfers.min(a.dma_transfers);
    a.dma_waits_watched -= b.dma_waits_watched.min(a.dma_waits_watched);
    for (a, b) in a.issues_watched.iter_mut().zip(b.issues_watched) {
        *a -= b.min(*a);
    }
    a.watched_offered -= b.watched_offered.min(a.watched_offered);
    for c in 0..2 {
        a.watched_runs[c] -= b.watched_runs[c].min(a.watched_runs[c]);
        a.watched_rcs[c] -= b.watched_rcs[c].min(a.watched_rcs[c]);
        for t in 0..rtl::chip::WATCH_TAGS {
            a.watched_rcs_by_tag[c][t] -=
                b.watched_rcs_by_tag[c][t].min(a.watched_rcs_by_tag[c][t]);
        }
    }
}

/// The addresses of the leaf cache's lookup and miss (the streamed packet
/// traversal's `leaf_first` and `leaf_miss`), whose issues the simulator
/// counts.
pub(crate) fn leaf_watch(img: &Image) -> Option<(i64, i64)> {
    img.symbol(data::LEAF_FIRST.0)
        .zip(img.symbol(data::LEAF_MISS.0))
}

pub(crate) fn watch(img: &Image, fw: &Firmware) -> rtl::chip::Watch {
    let mut w = rtl::chip::Watch::default();
    let ctx = |n: &str| {
        img.symbol(n)
            .map(|v| ((v as u32 - mem::CTX_BASE) / 4) as u16)
    };
    for k in tracer::primitives::TEST_KERNELS {
        if let Some(a) = ctx(k) {
            w.add(a, 0);
        }
    }
    use tracer::kernel_names as names;
    let start = match fw.layout.traversal {
        tracer::Traversal::Paper => names::sign(0),
        tracer::Traversal::Packet if fw.layout.root_leaf => names::sign(0),
        tracer::Traversal::Packet => names::PASS_START.into(),
    };
    // Every kernel the census and the test count name must be there.
    let ctx = |n: &str| {
        let a = ctx(n);
        debug_assert!(
            a.is_some() || !fw.kernels.iter().any(|(k, _)| k == n),
            "{n}"
        );
        a
    };
    if let Some(a) = ctx(&start) {
        w.add(a, 1);
    }
    // The ray census: the kernels that set up each kind of ray tag the
    // passes that follow ([`RAY_EYE`] ...).
    if let Some(a) = ctx(names::EYE) {
        w.tag(a, RAY_EYE);
    }
    if let Some(a) = ctx(names::SHADOW) {
        w.tag(a, RAY_SHADOW);
    }
    for l in 0.. {
        match ctx(&names::reflect(l)) {
            Some(a) => w.tag(a, RAY_REFLECT),
            None => break,
        }
        if let Some(a) = ctx(&names::refract(l)) {
            w.tag(a, RAY_REFRACT);
        }
    }
    w
}

/// One work item's share of a frame: its own tiles' statistics and
/// output, counted as one chip rendering the frame's whole tile list would
/// count them ([`run_item`]).
pub(crate) struct Group {
    /// Statistics at the first arrival at `tile` (the chip's start-up).
    pub(crate) startup: Stats,
    /// Statistics of its own tiles: from the arrival at its first tile to
    /// the arrival at the tile after its last, or to `halt` for the frame's
    /// last item.
    pub(crate) counted: Stats,
    /// The firmware's passes over the same span.
    pub(crate) passes: u64,
    /// The chip halted within the item's span (always for the frame's
    /// last item; for another, the program ended the frame early).
    pub(crate) halted: bool,
    /// When it did, the firmware's `T_END` less the cycle counter at the
    /// span's start: the end of the firmware's own count of the frame
    /// ([`ChipRender::firmware_cycles`]); or, where `T_END` is below that
    /// counter (not a reading taken at the end), `T_END` itself.
    pub(crate) t_end_tail: u64,
    pub(crate) t_end_raw: Option<u64>,
    /// Per own tile, the 256 output words.
    pub(crate) out: Vec<Vec<i32>>,
    /// Per own tile, the passes the firmware counted.
    pub(crate) tile_passes: Vec<u64>,
    /// Host seconds of each own tile (reading its pixels back included),
    /// and of the item's own work (building and loading the chip, the
    /// start-up, the run from the last tile to `halt`).
    pub(crate) tile_seconds: Vec<f64>,
    pub(crate) own_seconds: f64,
    pub(crate) profile: Option<crate::profile::Profile>,
    /// Host seconds from the waveform's creation to its end.
    pub(crate) seconds: f64,
}

pub(crate) fn sym(img: &Image, name: &str) -> Result<u32> {
    img.symbol(name)
        .map(|v| v as u32)
        .ok_or_else(|| anyhow!("internal: firmware symbol {name} missing"))
}

/// Tiles of the waveform's work item: a render with `--trace` records
/// the chip on the frame's first `TRACED_TILES` tiles (one item, whatever
/// the thread count).
pub const TRACED_TILES: usize = 32;
/// The fewest tiles a work item is cut to (but the frame's last): its
/// warm-up tile and its chip's set-up stay a small share.
const MIN_ITEM_TILES: usize = 16;
/// Cycle budget of one tile on the chip (and of the start-up).
pub(crate) const MAX_CYCLES_PER_TILE: u64 = 62_500_000;

/// The frame's `tiles` (in the chip's order) cut into work items for
/// `threads` host threads, taken in order by the first thread free
/// ([`in_order`]): one item on one thread, else each item the tiles left
/// over the thread count (at least [`MIN_ITEM_TILES`]), large ones first
/// and small ones to even the threads out at the end (guided
/// self-scheduling); with `traced`, the first [`TRACED_TILES`] are one
/// item of their own. Any cut gives the same frame ([`run_item`]).
pub(crate) fn work_items(
    tiles: usize,
    threads: usize,
    traced: bool,
) -> Vec<std::ops::Range<usize>> {
    let first = if traced { tiles.min(TRACED_TILES) } else { 0 };
    let mut items = Vec::new();
    if first > 0 {
        items.push(0..first);
    }
    let mut at = first;
    while at < tiles {
        let left = tiles - at;
        let n = if threads <= 1 {
            left
        } else {
            (left / threads).max(MIN_ITEM_TILES).min(left)
        };
        items.push(at..at + n);
        at += n;
    }
    items
}

/// `f` of `0..n` on the thread pool, each index taken in order by the first
/// thread free (a work-stealing pool would start a second thread in the
/// middle of the list); the results in index order.
fn in_order<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let next = AtomicUsize::new(0);
    let out: Vec<std::sync::Mutex<Option<T>>> =
        (0..n).map(|_| std::sync::Mutex::new(None)).collect();
    let take = || loop {
        let k = next.fetch_add(1, Ordering::Relaxed);
        if k >= n {
            break;
        }
        let v = f(k);
        if let Ok(mut slot) = out[k].lock() {
            *slot = Some(v);
        }
    };
    let workers = rayon::current_num_threads().min(n);
    rayon::scope(|s| {
        for _ in 1..workers {
            s.spawn(|_| take());
        }
        take();
    });
    out.into_iter()
        .filter_map(|m| m.into_inner().ok().flatten())
        .collect()
}

/// What a frame's work items share: the assembled program and its
/// firmware, the frame's tiles in the chip's order, and how the host runs
/// each item's chip.
#[derive(Clone, Copy)]
pub(crate) struct Frame<'a> {
    pub img: &'a Image,
    pub fw: &'a Firmware,
    pub tiles: &'a [(u32, u32)],
    pub timing: &'a Timing,
    /// Step every cycle through the plain model ([`rtl::Chip::plain`]).
    pub plain: bool,
    /// Say which files a waveform wrote.
    pub say_files: bool,
}

/// Run the work item `own` of the frame's tile list `tiles` on a fresh
/// chip, counted as one chip running the whole list would count it.
///
/// The chip runs the item's tiles after the tile before them (a warm-up,
/// not counted), from its first arrival at the tile loop's `tile` label:
/// what carries from one tile to the next (the output DMA of the tile
/// before, which the next one's start waits on or overlaps, the transfers
/// of a streamed scene still draining, and the output bank, which
/// alternates by tile: the host sets `TL_BANK` as one chip has it at the
/// warm-up tile) is then as in one chip, and nothing carries further (the
/// tile's rays, passes and leaf blocks are its own, and no RC's work
/// depends on the hit records an earlier tile left: the tracer's shading
/// reads only its pass's), but for the paper's pass numbers
/// ([`pass_seeds`]: `pass_seed`). Its own tiles count from the arrival at
/// the first to the arrival at the tile after the last (where the list
/// ends here, one chip would go on to the next tile), or to `halt` for the
/// frame's last item. `tb/tests/render.rs` holds whole frames cut at every
/// tile against one item on each traversal, resident and streamed.
pub(crate) fn run_item<W: Word>(
    frame: &Frame,
    own: std::ops::Range<usize>,
    pass_seed: Option<u32>,
    trace: Option<rtl::trace::TraceConfig>,
    profile: bool,
) -> Result<Group> {
    let Frame {
        img,
        fw,
        tiles,
        say_files,
        ..
    } = *frame;
    let t_item = std::time::Instant::now();
    let warm = own.start > 0;
    let list = &tiles[own.start - warm as usize..own.end];
    let (output, mem_bytes) = item_memory(img, fw, list.len());
    let (chip, fed) = item_chip::<W>(
        frame,
        list,
        own.start - warm as usize,
        output,
        mem_bytes,
        pass_seed,
    )?;
    let mut sim = Sim::new(chip);
    let t0 = std::time::Instant::now();
    if let Some(mut cfg) = trace {
        // The PC and the broadcast unit's context by the program's labels.
        cfg.labels = Some(std::sync::Arc::new(img.trace_labels(mem::CTX_BASE)));
        let path = cfg.path.clone();
        sim.trace(cfg, "morphosys")
            .map_err(|e| anyhow!("creating {}: {e}", path.display()))?;
    }
    let mut run = ItemRun {
        frame,
        own: own.clone(),
        list,
        fed,
        output,
        names: profile.then(|| crate::profile::Names::new(img, mem::CTX_BASE)),
        prof: None,
        s: Spans {
            tile_passes: Vec::with_capacity(own.len()),
            tile_seconds: Vec::with_capacity(own.len()),
            own_seconds: t_item.elapsed().as_secs_f64(),
            ..Spans::default()
        },
    };
    let mut result = run.spans(&mut sim)?;
    if result.is_ok() {
        result = run.to_halt(&mut sim)?;
    }
    let files = sim
        .finish_trace()
        .map_err(|e| anyhow!("writing the waveform: {e}"))?;
    let seconds = t0.elapsed().as_secs_f64();
    // (Not for `bench`, whose waveforms are temporary.)
    if say_files {
        for f in files {
            crate::note!("wrote {}", f.display());
        }
    }
    result?;
    let ItemRun { s, prof, .. } = run;
    let mut tile_seconds = s.tile_seconds;
    let mut tile_passes = s.tile_passes;
    tile_seconds.resize(own.len(), 0.0);
    tile_passes.resize(own.len(), 0);
    let mut counted = s.to.unwrap_or_default();
    sub_stats(&mut counted, &s.from);
    let mem = &sim.top.mem;
    let t_out = std::time::Instant::now();
    let out = read_tiles(mem, fw, output, warm as usize..list.len());
    // Reading a tile's pixels back is that tile's work.
    let per_tile = t_out.elapsed().as_secs_f64() / own.len().max(1) as f64;
    tile_seconds.iter_mut().for_each(|t| *t += per_tile);
    Ok(Group {
        startup: s.startup,
        counted,
        passes: s.passes,
        halted: s.halted,
        t_end_tail: s.t_end_tail,
        t_end_raw: s.t_end_raw,
        out,
        tile_seconds,
        own_seconds: s.own_seconds,
        tile_passes,
        profile: prof,
        seconds,
    })
}

/// What an item's spans measured ([`run_item`]).
#[derive(Default)]
struct Spans {
    /// At the first arrival at `tile`.
    startup: Stats,
    /// At the arrival at the first own tile, and at the end.
    from: Stats,
    to: Option<Stats>,
    halted: bool,
    /// The firmware's pass count at the first own tile, and the passes
    /// since.
    passes0: u64,
    passes: u64,
    t_end_tail: u64,
    t_end_raw: Option<u64>,
    /// Each own tile's passes and host seconds.
    tile_passes: Vec<u64>,
    tile_seconds: Vec<f64>,
    /// The item's own work: building and loading the chip, the start-up,
    /// the run from the last tile to `halt`.
    own_seconds: f64,
}

/// One work item's chip as it runs its spans.
struct ItemRun<'a> {
    frame: &'a Frame<'a>,
    own: std::ops::Range<usize>,
    /// The tiles it runs (the warm-up tile first, if any), and how many
    /// of them its tile list holds so far.
    list: &'a [(u32, u32)],
    fed: usize,
    output: u32,
    names: Option<crate::profile::Names>,
    prof: Option<crate::profile::Profile>,
    s: Spans,
}

impl ItemRun<'_> {
    /// A firmware variable's word in the chip's memory.
    fn var<W: Word>(&self, sim: &Sim<Chip<W>>, v: &data::Var) -> Result<u64> {
        Ok(sim.top.mem.read(sym(self.frame.img, v.name)?, 4) as u64)
    }

    /// The start-up, the warm-up tile and the own tiles, each to the next
    /// arrival at `tile` within its own cycle budget; the error of the
    /// span that failed (the outer error: reading the chip's memory).
    fn spans<W: Word>(&mut self, sim: &mut Sim<Chip<W>>) -> Result<Result<()>> {
        let (img, tiles) = (self.frame.img, self.frame.tiles);
        let own = self.own.clone();
        let warm = own.start > 0;
        let tile_pc = sym(img, data::TILE.0)?;
        let mut last_passes = 0;
        for k in 0..1 + warm as usize + own.len() {
            // The frame's tile this span runs (none for the start-up).
            let tile = (k > 0).then(|| own.start - warm as usize + k - 1);
            let counting = k > warm as usize;
            let begun = sim.cycle();
            let t_span = std::time::Instant::now();
            let names = self.names.as_ref().filter(|_| counting);
            let r = advance(sim, tile_pc, k > 0, names, &mut self.prof);
            let span_seconds = t_span.elapsed().as_secs_f64();
            if counting {
                self.s.tile_seconds.push(span_seconds);
            } else if k == 0 {
                self.s.own_seconds += span_seconds;
            }
            if let Err(e) = r {
                let at = tile.map(|t| (t, tiles[t]));
                return Ok(Err(span_error(e, at, sim.cycle() - begun)));
            }
            if k == 0 {
                self.s.startup = sim.top.stats();
            }
            if k == warm as usize {
                self.s.from = sim.top.stats();
                self.s.passes0 = self.var(sim, &data::PASSES)?;
                last_passes = self.s.passes0;
            }
            if counting {
                let p = self.var(sim, &data::PASSES)?;
                self.s
                    .tile_passes
                    .push(p.wrapping_sub(last_passes) & 0xffff_ffff);
                last_passes = p;
            }
            if sim.top.halted() {
                self.s.halted = true;
                break;
            }
            if self.fed < self.list.len() && self.var(sim, &data::TL_CNT)? == 0 {
                self.feed_chunk(sim)?;
            }
        }
        Ok(Ok(()))
    }

    /// At `tile` with the tile list's chunk taken: the next one, and the
    /// program's list state pointed at it (as a longer list would have
    /// it, at no cycle).
    fn feed_chunk<W: Word>(&mut self, sim: &mut Sim<Chip<W>>) -> Result<()> {
        let (img, fw) = (self.frame.img, self.frame.fw);
        let n = feed(
            &mut sim.top,
            self.list,
            self.fed,
            self.output,
            fw.out_tile_bytes(),
        )?;
        let at = |v: &data::Var| sym(img, v.name);
        sim.top.mem.write(at(&data::TL_PTR)?, 4, mem::TILE_LIST + 4);
        sim.top
            .mem
            .write(at(&data::TL_CNT)?, 4, (n - self.fed) as u32);
        self.fed = n;
        Ok(())
    }

    /// After the own tiles: the passes they ran, and on to `halt`,
    /// counted for the frame's last item (one chip ends there too), not
    /// for the others (one chip goes on to the next tile; this one's last
    /// pixels are still on their way out by DMA); `T_END` where the chip
    /// halted.
    fn to_halt<W: Word>(&mut self, sim: &mut Sim<Chip<W>>) -> Result<Result<()>> {
        let last = self.own.end == self.frame.tiles.len();
        self.s.to = Some(sim.top.stats());
        self.s.passes = self.passes_since(sim)?;
        let mut result = Ok(());
        if !self.s.halted {
            let t = (last && self.own.end > 0).then(|| self.own.end - 1);
            let n = if last { self.names.as_ref() } else { None };
            let begun = sim.cycle();
            let t_end = std::time::Instant::now();
            let r = advance(sim, u32::MAX, false, n, &mut self.prof);
            self.s.own_seconds += t_end.elapsed().as_secs_f64();
            match r {
                Ok(_) => {
                    if last {
                        self.s.to = Some(sim.top.stats());
                        self.s.passes = self.passes_since(sim)?;
                        self.s.halted = true;
                    }
                }
                Err(e) => {
                    let at = t.map(|t| (t, self.frame.tiles[t]));
                    result = Err(span_error(e, at, sim.cycle() - begun))
                }
            }
        }
        if self.s.halted {
            // T_END as a reading of the counter after the span's start (as
            // the tracer's is: then exactly one chip's reading); a value
            // below it, not the counter at the end (a program's own
            // arithmetic on its start-up's reading, the same in every
            // item), is kept as it is ([`Group::t_end_tail`]).
            let t_end = self.var(sim, &data::T_END)?;
            let from = self.s.from.cycles & 0xffff_ffff;
            self.s.t_end_tail = t_end.wrapping_sub(from) as u32 as u64;
            self.s.t_end_raw = (t_end < from).then_some(t_end);
        }
        Ok(result)
    }

    /// The firmware's passes since the first own tile.
    fn passes_since<W: Word>(&self, sim: &Sim<Chip<W>>) -> Result<u64> {
        Ok(self.var(sim, &data::PASSES)?.wrapping_sub(self.s.passes0) & 0xffff_ffff)
    }
}

/// An item's chip, built and loaded: the program and its watches, the FB
/// image and the streamed scene, the first chunk of the tile list `list`
/// (whose first tile is the frame's `first`), the output bank and the
/// pass number one chip has there. Returns the chip and how much of the
/// list it holds.
fn item_chip<W: Word>(
    frame: &Frame,
    list: &[(u32, u32)],
    first: usize,
    output: u32,
    mem_bytes: usize,
    pass_seed: Option<u32>,
) -> Result<(Chip<W>, usize)> {
    let Frame {
        img,
        fw,
        timing,
        plain,
        ..
    } = *frame;
    let mut chip = Chip::<W>::build(*timing, mem_bytes);
    chip.plain = plain;
    img.load(&mut chip).map_err(|f| anyhow!("{f}"))?;
    chip.watch = watch(img, fw);
    // The leaf pieces' waits for their DMA (the streamed packet traversal).
    chip.risc.dma_wait_watch = img
        .symbol(data::LEAF_LOAD.0)
        .map(|a| a as u32)
        .into_iter()
        .collect();
    // The leaf cache's lookups and misses (the streamed packet traversal):
    // counted by the simulator, at no cycle of the program's.
    if let Some((first, miss)) = leaf_watch(img) {
        chip.risc.issue_watch = [Some(first as u32), Some(miss as u32)];
    }
    let fb = fw.fb_bytes();
    chip.load(mem::FB_IMAGE, &fb).map_err(|f| anyhow!("{f}"))?;
    if let Some(st) = &fw.layout.stream {
        chip.load(st.base, &st.image).map_err(|f| anyhow!("{f}"))?;
    }
    // The tile list, in chunks of what fits below `mem::OUTPUT`: the next
    // chunk goes in when the program has taken the last tile of one
    // ([`feed`]).
    let fed = feed(&mut chip, list, 0, output, fw.out_tile_bytes())?;
    // The tracer's output banks alternate by tile (`TL_BANK`, 0 at the
    // first): the list's first tile takes the bank it has in one chip.
    if let Some(bank) = img.symbol(data::TL_BANK.name) {
        chip.mem.write(bank as u32, 4, first as u32 % 2);
    }
    // The pass number one chip has before the list's first tile, where it
    // matters ([`pass_seeds`]).
    if let Some(seed) = pass_seed {
        chip.mem.write(sym(img, data::PASS.name)?, 4, seed);
    }
    Ok((chip, fed))
}

/// `run` (item index, pass seed) of every one of `items`, taken in order by
/// the first thread free ([`in_order`]); then the items in which one chip's
/// pass numbers wrap again, from the number one chip has there
/// ([`pass_seeds`]), their host seconds added to the first run's.
pub(crate) fn run_items(
    img: &Image,
    items: &[std::ops::Range<usize>],
    run: impl Fn(usize, Option<u32>) -> (Result<Group>, f64) + Sync,
) -> Vec<(Result<Group>, f64)> {
    let mut results = in_order(items.len(), |i| run(i, None));
    let again = pass_seeds(img, items, &results);
    for (i, r) in in_order(again.len(), |k| run(again[k].0, Some(again[k].1)))
        .into_iter()
        .enumerate()
    {
        let i = again[i].0;
        let seconds = results[i].1 + r.1;
        results[i] = (r.0, seconds);
    }
    results
}

/// The items to run again, each with the pass number one chip has before
/// its list's first tile: those in which one chip's pass numbers wrap.
///
/// The paper's traversal numbers its passes in 16 bits for its mailboxes
/// (`PASS`): a pass that would reach `PASS_WRAP` clears them and takes the
/// number one. A chip that starts with the mailboxes clear and the number
/// one chip has at the same tile runs as that chip does (every mailbox then
/// holds an older pass's number in both); an item that wraps nowhere runs
/// so from any start, and the others run again from one chip's number,
/// known once every tile's passes are (extra host work only for frames of
/// 32,767 passes or more).
fn pass_seeds(
    img: &Image,
    items: &[std::ops::Range<usize>],
    results: &[(Result<Group>, f64)],
) -> Vec<(usize, u32)> {
    let Some(wrap) = img.symbol(data::PASS_WRAP.0).map(|w| w as u64) else {
        return Vec::new();
    };
    // Passes before each tile (one chip's count), as far as the items ran.
    let mut before = vec![0u64];
    for (r, _) in results {
        match r {
            Ok(g) => {
                for p in &g.tile_passes {
                    before.push(before[before.len() - 1] + p);
                }
            }
            Err(_) => return Vec::new(),
        }
    }
    // One chip's pass number after `n` passes.
    let number = |n: u64| {
        if n < wrap {
            n
        } else {
            (n - wrap) % (wrap - 1) + 1
        }
    };
    // Whether one of passes n + 1 ..= m wraps: the number reaches `wrap`.
    let wraps_in = |n: u64, m: u64| number(n) + (m - n) >= wrap;
    items
        .iter()
        .enumerate()
        .filter_map(|(i, own)| {
            let first = own.start.saturating_sub(1);
            let (n, m) = (*before.get(first)?, *before.get(own.end)?);
            // (An item from the frame's first tile starts as one chip.)
            (n > 0 && wraps_in(n, m)).then(|| (i, number(n) as u32))
        })
        .collect()
}

/// Run the chip to the next arrival at `pc` (the PC comes to it; with
/// `leave`, first out of a stay there) or to `halt` (`pc` `u32::MAX`:
/// there), within [`MAX_CYCLES_PER_TILE`] cycles; with `names`, each cycle
/// charged to `prof`. Returns whether it arrived (else it halted).
fn advance<W: Word>(
    sim: &mut Sim<Chip<W>>,
    pc: u32,
    leave: bool,
    names: Option<&crate::profile::Names>,
    prof: &mut Option<crate::profile::Profile>,
) -> std::result::Result<bool, rtl::chip::RunError> {
    let budget = sim.cycle() + MAX_CYCLES_PER_TILE;
    if let Some(names) = names {
        let p = crate::profile::run(sim, names, budget, Some(pc).filter(|&pc| pc != u32::MAX))?;
        *prof = Some(match prof.take() {
            None => p,
            Some(q) => crate::profile::Profile::merge(q, p),
        });
        return Ok(!sim.top.halted());
    }
    if pc == u32::MAX {
        return run_to_halt(sim, budget).map(|_| false);
    }
    if leave {
        while !sim.top.halted() && sim.top.risc.pc == pc {
            if sim.cycle() >= budget {
                return Err(rtl::chip::over_budget(sim));
            }
            sim.step().map_err(rtl::chip::RunError::Step)?;
        }
    }
    rtl::chip::run_to_pc(sim, pc, budget)
}

/// A chip's error in a span of its work item, named by the frame's tile
/// (`None`: the start-up) and the cycle within it, `at` (not the chip's
/// own count, which depends on where the frame was cut).
fn span_error(e: rtl::chip::RunError, tile: Option<(usize, (u32, u32))>, at: u64) -> anyhow::Error {
    let span = match tile {
        None => "the start-up (before the tile loop)".to_string(),
        Some((k, (x, y))) => format!("tile {k} (pixels from ({x}, {y}))"),
    };
    match e {
        rtl::chip::RunError::MaxCycles { pc, text, .. } => anyhow!(
            "the tracer firmware stopped: {span} took more than {MAX_CYCLES_PER_TILE} cycles \
             [pc 0x{pc:08x}: `{text}`]; a render allows that many per tile and for the start-up: \
             a smaller scene, or a faster --timing"
        ),
        rtl::chip::RunError::Step(rtl::kernel::StepError::Fault { fault, .. }) => {
            anyhow!("the tracer firmware stopped in {span}, at its cycle {at}: {fault}")
        }
        rtl::chip::RunError::Step(e) => anyhow!("the tracer firmware stopped in {span}: {e}"),
    }
}
