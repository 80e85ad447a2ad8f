//! Rendering on the simulated chip: compile the scene, generate and
//! assemble the tracer firmware, run it on one chip over the frame's tiles,
//! read the pixels back from main memory.
//!
//! The frame is one chip's work: its start-up (loading the FB, the
//! contexts and the RC tables), then every tile in order. The host cuts
//! the tile list into work items sized by its thread count
//! ([`work_items`]) and runs each on a fresh chip (rayon), which first
//! runs the tile before the item's own (a warm-up) so that each tile is
//! counted exactly as in the one chip ([`run_item`]); the pixels are placed
//! by tile. The image and every figure are identical for any thread
//! count.

use anyhow::{anyhow, Result};
use firmware::asm::{self, Image};
use firmware::scene::Scene;
use firmware::tracer::{self, data, mem, Firmware, Numerics, Options};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use rtl::chip::run_to_halt;
use rtl::rc::{Datapath, Word};
use rtl::{Chip, Sim, Stats, Timing};

use crate::reference::NO_HIT;

/// The chip's image and figures.
#[derive(Clone, Debug)]
pub struct ChipRender {
    pub width: u32,
    pub height: u32,
    pub rgb8: Vec<u8>,
    /// Per pixel the object the eye ray hit ([`NO_HIT`] for none).
    pub hits: Vec<u32>,
    /// Frame cycles by the simulator's count: the chip from reset to
    /// `halt`.
    pub cycles: u64,
    /// The chip's cycles from reset to the first `tile` (the start-up).
    pub startup_cycles: u64,
    /// The same frame by the firmware's own count (its `T_END`, which it
    /// reads from the cycle counter before `halt`), which the program can
    /// get wrong: see [`ChipRender::firmware_count_disagrees`].
    pub firmware_cycles: u64,
    pub stats: Stats,
    pub passes: u64,
    /// The streamed packet traversal's leaf cache (`None` for other
    /// layouts): leaves whose first piece was in its slot, and those whose
    /// first piece was not (counted by the simulator).
    pub leaf_cache: Option<LeafCache>,
    pub tiles: usize,
    pub firmware: Firmware,
    /// With [`RenderSettings::profile`]: where the tile loop's cycles went.
    pub profile: Option<crate::profile::Profile>,
    /// Host seconds the work items' chips ran, summed over them: from the
    /// waveform's creation, if any, to its end (the frame's setup, the
    /// firmware and the image's assembly, aside).
    pub chip_seconds: f64,
    /// The host seconds of each work item's whole work (building and
    /// loading its chip, running it, reading its pixels back), in tile
    /// order: what the host's threads shared.
    pub item_seconds: Vec<f64>,
    /// The host seconds of each tile (in the chip's order) within its
    /// item, and an item's mean seconds apart from its tiles: the frame as
    /// `bench`'s schedule model cuts it for any thread count
    /// ([`ChipRender::work`]).
    pub tile_seconds: Vec<f64>,
    pub item_own_seconds: f64,
    /// Host seconds of the chip render: from assembling the firmware to
    /// the assembled image (the firmware's generation and any probe
    /// before it aside); the instances and its serial part.
    pub render_seconds: f64,
}

/// The streamed packet traversal's leaf cache over a frame
/// (`docs/tracer.md`, "Leaves and pieces").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LeafCache {
    /// Leaves reached whose first piece was in its slot, moved there
    /// earlier in the tile.
    pub hits: u64,
    /// Leaves reached whose first piece was not in its slot: moved by
    /// DMA, or (a large one, `LEAF_LATE`) left unmoved where every awake
    /// ray had tested its objects.
    pub misses: u64,
}

/// Everything a render takes besides the scene and the tracer's options:
/// the firmware's numeric knobs, the chip's timing, and how the host runs
/// it (progress, waveform, profile).
#[derive(Clone, Debug, Default)]
pub struct RenderSettings {
    /// The firmware's numeric knobs (Newton-Raphson steps, table entries,
    /// guard bits, ray offset, normals).
    pub numerics: Numerics,
    /// Stream the scene from main memory (leaf blocks moved into FB bank 1
    /// by DMA) even where it fits the FB.
    pub streamed: bool,
    pub progress: bool,
    pub trace: Option<rtl::trace::TraceConfig>,
    /// Charge every cycle of the tile loops to a kernel or a TinyRISC
    /// label ([`crate::profile`]; steps cycle by cycle, several times
    /// slower).
    pub profile: bool,
    /// The chip's timing (`--timing FILE.toml`).
    pub timing: Timing,
    /// Tiles per host work item ([`work_items`]; `None`: sized by the
    /// thread count). Any size gives the same frame.
    pub item_tiles: Option<usize>,
}

impl ChipRender {
    /// When the firmware's own count of the frame
    /// ([`ChipRender::firmware_cycles`]) differs from the simulator's by
    /// more than 1%: a sentence saying so. (The tracer's reads the counter
    /// a few instructions from where the simulator splits start-up and
    /// tile loop and from `halt`: a handful of cycles.)
    pub fn firmware_count_disagrees(&self) -> Option<String> {
        let (sim, fw) = (self.cycles, self.firmware_cycles);
        (sim.abs_diff(fw) as f64 > 0.01 * sim as f64).then(|| {
            format!(
                "the firmware's own count of the frame (T_START, T_END) is {fw} cycles, \
                 the simulator counted {sim}: the figures are the simulator's"
            )
        })
    }
    /// The chip render's host work ([`crate::schedule::FrameWork`]).
    pub fn work(&self) -> crate::schedule::FrameWork {
        crate::schedule::FrameWork {
            tiles: self.tile_seconds.clone(),
            item: self.item_own_seconds,
        }
    }
    pub fn fps_at(&self, clock_hz: u64) -> f64 {
        if self.cycles == 0 {
            0.0
        } else {
            clock_hz as f64 / self.cycles as f64
        }
    }
    /// Objects broadcast to a packet, averaged over the packets' passes
    /// (eye, shadow and reflection); each awake ray of the packet is tested
    /// against each (the paper's traversal: every ray of the pass not yet
    /// done; the packet traversal: the rays that reach the object's cell).
    pub fn objects_tested_per_ray(&self) -> f64 {
        if self.passes == 0 {
            0.0
        } else {
            self.object_tests() as f64 / self.passes as f64
        }
    }

    /// The object tests broadcast: the runs of the test kernels (counted
    /// by the simulator, [`watch`]).
    pub fn object_tests(&self) -> u64 {
        self.stats.watched_runs[0]
    }

    /// The rays the chip traced, by kind: the RCs awake at the start of
    /// each pass, counted by the simulator under the kind of the kernel
    /// that set the pass up (eye, shadow, reflect, refract).
    pub fn ray_census(&self) -> [u64; 4] {
        self.stats.watched_rcs_by_tag[1]
    }

    /// Ray-object tests the RCs executed per ray traced: the awake RCs at
    /// the start of every object test over the rays that started a pass
    /// (counted by the simulator, [`rtl::chip::Watch`]).
    /// The share of the object tests the array ran lanes for whose ray
    /// needed them: the RCs that executed an object test (their ray
    /// reaches the object's cell) over each test broadcast times the rays
    /// of its pass.
    pub fn simd_efficiency(&self) -> f64 {
        let offered = self.stats.watched_offered;
        if offered == 0 {
            0.0
        } else {
            self.stats.watched_rcs[0] as f64 / offered as f64
        }
    }

    /// The share of the frame's cycles TinyRISC waits for the DMA channel.
    /// Cycles in which the array had no context while TinyRISC waited
    /// for the DMA (TinyRISC's DMA stall less the cycles in which the
    /// array still ran the runs queued before the wait).
    pub fn array_idle_on_dma(&self) -> u64 {
        let s = &self.stats;
        s.cycles
            .saturating_sub(s.array_busy_cycles + s.array_idle_control_cycles)
    }

    pub fn dma_stall_share(&self) -> f64 {
        if self.stats.cycles == 0 {
            0.0
        } else {
            self.stats.dma_stall_cycles as f64 / self.stats.cycles as f64
        }
    }

    pub fn tests_per_ray(&self) -> f64 {
        let rays = self.stats.watched_rcs[1];
        if rays == 0 {
            0.0
        } else {
            self.stats.watched_rcs[0] as f64 / rays as f64
        }
    }
}

/// A colour channel in Q3.12 (16-bit chip) or Q3.28 (32-bit chip) to 8 bits.
fn to8(v: i32, datapath: Datapath) -> u8 {
    let one = ((12 + datapath.bits() - 16) as f64).exp2();
    ((v as f64 / one).clamp(0.0, 1.0) * 255.0).round() as u8
}

fn add_stats(a: &mut Stats, b: &Stats) {
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
fn leaf_watch(img: &Image) -> Option<(i64, i64)> {
    img.symbol(data::LEAF_FIRST.0)
        .zip(img.symbol(data::LEAF_MISS.0))
}

fn watch(img: &Image, fw: &Firmware) -> rtl::chip::Watch {
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

/// Tags of the simulator's ray census ([`rtl::chip::Watch::tag`]): the
/// kind of the rays of a pass.
pub(crate) const RAY_EYE: usize = 0;
pub(crate) const RAY_SHADOW: usize = 1;
pub(crate) const RAY_REFLECT: usize = 2;
pub(crate) const RAY_REFRACT: usize = 3;

/// One work item's share of a frame: its own tiles' statistics and
/// output, counted as one chip rendering the frame's whole tile list would
/// count them ([`run_item`]).
struct Group {
    /// Statistics at the first arrival at `tile` (the chip's start-up).
    startup: Stats,
    /// Statistics of its own tiles: from the arrival at its first tile to
    /// the arrival at the tile after its last, or to `halt` for the frame's
    /// last item.
    counted: Stats,
    /// The firmware's passes over the same span.
    passes: u64,
    /// The chip halted within the item's span (always for the frame's
    /// last item; for another, the program ended the frame early).
    halted: bool,
    /// When it did, the firmware's `T_END` less the cycle counter at the
    /// span's start: the end of the firmware's own count of the frame
    /// ([`ChipRender::firmware_cycles`]); or, where `T_END` is below that
    /// counter (not a reading taken at the end), `T_END` itself.
    t_end_tail: u64,
    t_end_raw: Option<u64>,
    /// Per own tile, the 256 output words.
    out: Vec<Vec<i32>>,
    /// Per own tile, the passes the firmware counted.
    tile_passes: Vec<u64>,
    /// Host seconds of each own tile (reading its pixels back included),
    /// and of the item's own work (building and loading the chip, the
    /// start-up, the run from the last tile to `halt`).
    tile_seconds: Vec<f64>,
    own_seconds: f64,
    profile: Option<crate::profile::Profile>,
    /// Host seconds from the waveform's creation to its end.
    seconds: f64,
}

fn sym(img: &Image, name: &str) -> Result<u32> {
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
#[allow(clippy::too_many_arguments)]
fn run_item<W: Word>(
    img: &Image,
    fw: &Firmware,
    tiles: &[(u32, u32)],
    own: std::ops::Range<usize>,
    pass_seed: Option<u32>,
    trace: Option<rtl::trace::TraceConfig>,
    profile: bool,
    timing: &Timing,
    say_files: bool,
) -> Result<Group> {
    let t_item = std::time::Instant::now();
    let warm = own.start > 0;
    let list = &tiles[own.start - warm as usize..own.end];
    let last = own.end == tiles.len();
    // Main memory as large as the program touches (its segments, the tile
    // list, the output tiles and the streamed scene image), not the
    // 16 MiB default: a fresh instance per item must not zero-fill memory
    // nobody reads.
    let wb = fw.fb_word_bytes();
    // What lies above `mem::OUTPUT`: the streamed scene image and its
    // mailboxes, the packet traversal's mailboxes.
    let above = fw
        .layout
        .stream
        .as_ref()
        // the image, then the mailboxes (a half-word per object)
        .map(|st| {
            (st.base as usize + st.image.len()).max(st.mailbox as usize + 2 * fw.layout.objects)
        })
        .into_iter()
        .chain(
            // the packet traversal's mailboxes (main memory, resident or
            // streamed)
            (fw.layout.traversal == tracer::Traversal::Packet)
                .then(|| fw.layout.mailbox + tracer::layout::PK_MAILBOX_BYTES * fw.layout.objects),
        )
        .max()
        .unwrap_or(0);
    // The tiles' pixels: at `mem::OUTPUT`, or past that data where an
    // item's tiles would reach it (each tile's address is in the list).
    let out_bytes = list.len() * fw.out_tile_bytes() as usize;
    let output = if above > mem::OUTPUT as usize
        && mem::OUTPUT as usize + out_bytes > mem::STREAM as usize
    {
        above.next_multiple_of(1 << 12) as u32
    } else {
        mem::OUTPUT
    };
    let ends = img
        .segments
        .iter()
        .map(|s| s.addr as usize + s.data.len())
        .chain([
            mem::FB_IMAGE as usize + wb as usize * fw.fb.len(),
            mem::TILE_LIST as usize + 4 + 12 * list.len().min(LIST_CHUNK),
            output as usize + out_bytes,
            above,
        ]);
    let mem_bytes = ends.max().unwrap_or(0).next_multiple_of(1 << 16);
    let mut chip = Chip::<W>::build(*timing, mem_bytes);
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
    let mut fed = feed(&mut chip, list, 0, output, fw.out_tile_bytes())?;
    // The tracer's output banks alternate by tile (`TL_BANK`, 0 at the
    // first): the list's first tile takes the bank it has in one chip.
    if let Some(bank) = img.symbol(data::TL_BANK.name) {
        let first = (own.start - warm as usize) as u32;
        chip.mem.write(bank as u32, 4, first % 2);
    }
    // The pass number one chip has before the list's first tile, where it
    // matters ([`pass_seeds`]).
    if let Some(seed) = pass_seed {
        chip.mem.write(sym(img, data::PASS.name)?, 4, seed);
    }
    let mut sim = Sim::new(chip);
    let t0 = std::time::Instant::now();
    if let Some(mut cfg) = trace {
        // The PC and the broadcast unit's context by the program's labels.
        cfg.labels = Some(std::sync::Arc::new(img.trace_labels(mem::CTX_BASE)));
        let path = cfg.path.clone();
        sim.trace(cfg, "morphosys")
            .map_err(|e| anyhow!("creating {}: {e}", path.display()))?;
    }
    let tile_pc = sym(img, data::TILE.0)?;
    let m = |sim: &Sim<Chip<W>>, name: &str| -> Result<u64> {
        Ok(sim.top.mem.read(sym(img, name)?, 4) as u64)
    };
    let names = profile.then(|| crate::profile::Names::new(img, mem::CTX_BASE));
    let mut prof: Option<crate::profile::Profile> = None;
    // The spans the chip runs: the start-up (to the first arrival at
    // `tile`), the warm-up tile, the own tiles (each to the next arrival),
    // and `halt`; each within its own cycle budget, an error naming it.
    let mut startup = Stats::default();
    let mut from = Stats::default();
    let mut to: Option<Stats> = None;
    let mut halted = false;
    let (mut passes, mut t_end_tail) = (0, 0);
    let mut t_end_raw = None;
    let mut passes0 = 0;
    // Each own tile's passes (the firmware's count).
    let (mut tile_passes, mut last_passes) = (Vec::with_capacity(own.len()), 0);
    let mut tile_seconds = Vec::with_capacity(own.len());
    // The item's own work: building and loading the chip, the start-up,
    // the run from the last tile to `halt`.
    let mut own_seconds = 0.0;
    let mut result: Result<()> = Ok(());
    let spans = 1 + warm as usize + own.len();
    own_seconds += t_item.elapsed().as_secs_f64();
    for k in 0..spans {
        // The frame's tile this span runs (none for the start-up).
        let tile = (k > 0).then(|| own.start - warm as usize + k - 1);
        let counting = k > warm as usize;
        let begun = sim.cycle();
        let t_span = std::time::Instant::now();
        let r = advance(
            &mut sim,
            tile_pc,
            k > 0,
            names.as_ref().filter(|_| counting),
            &mut prof,
        );
        let span_seconds = t_span.elapsed().as_secs_f64();
        if counting {
            tile_seconds.push(span_seconds);
        } else if k == 0 {
            own_seconds += span_seconds;
        }
        if let Err(e) = r {
            result = Err(span_error(
                e,
                tile.map(|t| (t, tiles[t])),
                sim.cycle() - begun,
            ));
            break;
        }
        if k == 0 {
            startup = sim.top.stats();
        }
        if k == warm as usize {
            from = sim.top.stats();
            passes0 = m(&sim, "PASSES")?;
            last_passes = passes0;
        }
        if counting {
            let p = m(&sim, "PASSES")?;
            tile_passes.push(p.wrapping_sub(last_passes) & 0xffff_ffff);
            last_passes = p;
        }
        if sim.top.halted() {
            halted = true;
            break;
        }
        if fed < list.len() && m(&sim, "TL_CNT")? == 0 {
            // At `tile` with the chunk taken: the next one, and the
            // program's list state pointed at it (as a longer list would
            // have it, at no cycle).
            let n = feed(&mut sim.top, list, fed, output, fw.out_tile_bytes())?;
            let at = |name: &str| sym(img, name);
            sim.top.mem.write(at("TL_PTR")?, 4, mem::TILE_LIST + 4);
            sim.top.mem.write(at("TL_CNT")?, 4, (n - fed) as u32);
            fed = n;
        }
    }
    if result.is_ok() {
        to = Some(sim.top.stats());
        passes = m(&sim, "PASSES")?.wrapping_sub(passes0) & 0xffff_ffff;
        if !halted {
            // On to `halt`: counted for the frame's last item (one chip
            // ends there too), not for the others (one chip goes on to
            // the next tile; this one's last pixels are still on their way
            // out by DMA).
            let t = (last && own.end > 0).then(|| own.end - 1);
            let n = if last { names.as_ref() } else { None };
            let begun = sim.cycle();
            let t_end = std::time::Instant::now();
            let r = advance(&mut sim, u32::MAX, false, n, &mut prof);
            own_seconds += t_end.elapsed().as_secs_f64();
            match r {
                Ok(_) => {
                    if last {
                        to = Some(sim.top.stats());
                        passes = m(&sim, "PASSES")?.wrapping_sub(passes0) & 0xffff_ffff;
                        halted = true;
                    }
                }
                Err(e) => {
                    result = Err(span_error(e, t.map(|t| (t, tiles[t])), sim.cycle() - begun))
                }
            }
        }
        if halted {
            // T_END as a reading of the counter after the span's start (as
            // the tracer's is: then exactly one chip's reading); a value
            // below it, not the counter at the end (a program's own
            // arithmetic on its start-up's reading, the same in every
            // item), is kept as it is ([`Group::t_end_tail`]).
            let t_end = m(&sim, "T_END")?;
            t_end_tail = t_end.wrapping_sub(from.cycles & 0xffff_ffff) as u32 as u64;
            t_end_raw = (t_end < from.cycles & 0xffff_ffff).then_some(t_end);
        }
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
    tile_seconds.resize(own.len(), 0.0);
    tile_passes.resize(own.len(), 0);
    let mut counted = to.unwrap_or_default();
    sub_stats(&mut counted, &from);
    let mem = &sim.top.mem;
    let t_out = std::time::Instant::now();
    let out: Vec<Vec<i32>> = (warm as usize..list.len())
        .map(|k| {
            let base = output + k as u32 * fw.out_tile_bytes();
            (0..256)
                .map(|i| {
                    let v = mem.read(base + wb * i, wb);
                    if wb == 2 {
                        v as u16 as i16 as i32
                    } else {
                        v as i32
                    }
                })
                .collect()
        })
        .collect();
    // Reading a tile's pixels back is that tile's work.
    let per_tile = t_out.elapsed().as_secs_f64() / own.len().max(1) as f64;
    tile_seconds.iter_mut().for_each(|t| *t += per_tile);
    Ok(Group {
        startup,
        counted,
        passes,
        halted,
        t_end_tail,
        t_end_raw,
        out,
        tile_seconds,
        own_seconds,
        tile_passes,
        profile: prof,
        seconds,
    })
}

/// Tile-list entries a chip's list holds (below `mem::OUTPUT`, 12 bytes
/// each after the count).
const LIST_CHUNK: usize = ((mem::OUTPUT - mem::TILE_LIST - 4) / 12) as usize;

/// Write the tile list's chunk from `list[from]` (count, then per tile its
/// corner and its pixels' address, `output` plus the tile's place in
/// `list`); returns where the next chunk starts.
fn feed<W: Word>(
    chip: &mut Chip<W>,
    list: &[(u32, u32)],
    from: usize,
    output: u32,
    tile_bytes: u32,
) -> Result<usize> {
    let to = list.len().min(from + LIST_CHUNK);
    let mut bytes = Vec::with_capacity(4 + 12 * (to - from));
    bytes.extend(((to - from) as u32).to_le_bytes());
    for (k, (x, y)) in list.iter().enumerate().take(to).skip(from) {
        bytes.extend(x.to_le_bytes());
        bytes.extend(y.to_le_bytes());
        bytes.extend((output + k as u32 * tile_bytes).to_le_bytes());
    }
    chip.load(mem::TILE_LIST, &bytes)
        .map_err(|f| anyhow!("{f}"))?;
    Ok(to)
}

/// `run` (item index, pass seed) of every one of `items`, taken in order by
/// the first thread free ([`in_order`]); then the items in which one chip's
/// pass numbers wrap again, from the number one chip has there
/// ([`pass_seeds`]), their host seconds added to the first run's.
fn run_items(
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

/// Render `scene` on the simulated chip.
pub fn render_chip(scene: &Scene, opt: &Options, settings: &RenderSettings) -> Result<ChipRender> {
    let fw = if settings.streamed {
        tracer::build_streamed_with(scene, opt, &settings.numerics).map_err(|e| anyhow!("{e}"))?
    } else {
        choose_firmware(scene, opt, &settings.numerics, &settings.timing)?
    };
    render_firmware(fw, opt, settings)
}

/// Every `PROBE_STRIDE`-th tile row and column (1/16 of the tiles) make
/// the probe by which [`choose_firmware`] compares BSP trees and
/// `render --datapath auto` the chips.
pub(crate) const PROBE_STRIDE: u32 = 4;

/// A render of the probe's tiles: their cycles, and their pixels (row by
/// row within each tile, tiles in order) with the colours and hit objects.
#[derive(Clone, Debug)]
pub struct ProbeRender {
    pub cycles: u64,
    pub pixels: Vec<(u32, u32)>,
    pub rgb8: Vec<u8>,
    pub hits: Vec<u32>,
    /// The f64 reference's colours and hits on the same pixels, when
    /// computed.
    pub reference: Option<(Vec<u8>, Vec<u32>)>,
    /// The cycles of a close call's second probe, once run ([`faster`]).
    pub second_cycles: Option<u64>,
}

/// Run the probe's tiles of `opt`'s frame on the chip with `fw`.
pub fn probe(fw: &Firmware, opt: &Options, timing: &Timing) -> Result<ProbeRender> {
    probe_at(fw, opt, timing, PROBE_STRIDE / 2)
}

/// Two firmwares' probes this close (a share of the smaller's cycles) are
/// a close call: [`faster`] runs both again on other tiles before it
/// decides.
pub(crate) const CLOSE_CALL: f64 = 0.02;

/// The tile rows and columns of a close call's second probe: those `k`
/// with `k % PROBE_STRIDE == SECOND_PROBE_PHASE`, half a stride from the
/// probe's.
pub(crate) const SECOND_PROBE_PHASE: u32 = 0;

/// Whether `b` (probed as `pb`) renders `opt`'s frame faster than `a`
/// (probed as `pa`) by more than `margin` of `a`'s cycles: decided on the
/// probe, and where the two probes are within [`CLOSE_CALL`] of each
/// other, on the probe and a second probe of as many other tiles together
/// (the probe's 1/16 of the tiles alone misjudged differences of 1% to 4%
/// on the frame). The second probes' cycles are kept in `pa` and `pb`, so
/// a firmware compared again is not probed again.
pub(crate) fn faster(
    (a, pa): (&Firmware, &mut ProbeRender),
    (b, pb): (&Firmware, &mut ProbeRender),
    opt: &Options,
    timing: &Timing,
    margin: f64,
) -> Result<bool> {
    let (lo, hi) = (
        pa.cycles.min(pb.cycles) as f64,
        pa.cycles.max(pb.cycles) as f64,
    );
    if hi > lo * (1.0 + CLOSE_CALL) {
        return Ok((pb.cycles as f64) < pa.cycles as f64 * (1.0 - margin));
    }
    let second = |fw: &Firmware, known: Option<u64>| {
        known.map_or_else(
            || probe_at(fw, opt, timing, SECOND_PROBE_PHASE).map(|p| p.cycles),
            Ok,
        )
    };
    let (qa, qb) = rayon::join(
        || second(a, pa.second_cycles),
        || second(b, pb.second_cycles),
    );
    let (qa, qb) = (qa?, qb?);
    pa.second_cycles = Some(qa);
    pb.second_cycles = Some(qb);
    let (ta, tb) = ((pa.cycles + qa) as f64, (pb.cycles + qb) as f64);
    Ok(tb < ta * (1.0 - margin))
}

/// [`probe`] on the tile rows and columns `k` with `k % PROBE_STRIDE ==
/// phase`.
fn probe_at(fw: &Firmware, opt: &Options, timing: &Timing, phase: u32) -> Result<ProbeRender> {
    let (tw, th) = (fw.tile_w, fw.tile_h);
    let (nx, ny) = (opt.width.div_ceil(tw), opt.height.div_ceil(th));
    let pick = |n: u32| -> Vec<u32> {
        let v: Vec<u32> = (0..n).filter(|k| k % PROBE_STRIDE == phase).collect();
        if v.is_empty() {
            vec![n / 2]
        } else {
            v
        }
    };
    let mut tiles = Vec::new();
    for ty in pick(ny) {
        for tx in pick(nx) {
            tiles.push((tx * tw, ty * th));
        }
    }
    let img = asm::assemble(&fw.source, "tracer.s")
        .map_err(|e| anyhow!("internal: the generated firmware does not assemble:\n{e}"))?;
    let items = work_items(tiles.len(), rayon::current_num_threads(), false);
    let runs = run_items(&img, &items, |gi, seed| {
        let own = items[gi].clone();
        let r = match fw.datapath {
            Datapath::W16 => {
                run_item::<i16>(&img, fw, &tiles, own, seed, None, false, timing, false)
            }
            Datapath::W32 => {
                run_item::<i32>(&img, fw, &tiles, own, seed, None, false, timing, false)
            }
        };
        (r, 0.0)
    });
    let mut p = ProbeRender {
        cycles: 0,
        pixels: Vec::new(),
        rgb8: Vec::new(),
        hits: Vec::new(),
        reference: None,
        second_cycles: None,
    };
    let mut ended = false;
    for (own, (r, _)) in items.iter().zip(runs) {
        let mut g = r?;
        if ended {
            g.out.iter_mut().for_each(|o| o.fill(0));
        } else {
            p.cycles += g.counted.cycles;
            ended = g.halted;
        }
        for (k, out) in g.out.iter().enumerate() {
            let (x0, y0) = tiles[own.start + k];
            for lane in 0..64u32 {
                let (row, col) = (lane / 8, lane % 8);
                let (x, y) = (x0 + col, y0 + row);
                if row >= th || col >= tw || x >= opt.width || y >= opt.height {
                    continue;
                }
                p.pixels.push((x, y));
                for c in 0..3 {
                    p.rgb8.push(to8(out[c * 64 + lane as usize], fw.datapath));
                }
                let id = out[192 + lane as usize];
                p.hits.push(if id < 0 { NO_HIT } else { id as u32 });
            }
        }
    }
    Ok(p)
}

/// The firmware for `opt`. Where the options leave the BSP to the tracer
/// and it has more than one candidate ([`tracer::resolve_bsp`]: the packet
/// traversal's median, SAH and chip-cost SAH trees), each is run on the probe (every
/// fourth row and column of tiles, at the frame's size, so each packet is
/// as coherent as in the frame) and compared with the f64 reference on the
/// same pixels: the tree with the fewest cycles is kept among those whose
/// probe is within [`TREE_PSNR_SLACK`] dB of the best one's (a faster tree
/// must not cost image quality: the trees find the same hits up to ties,
/// but a tie between surfaces of different colours is visible); ties go
/// to the first. With `ShadowPackets::Auto` where merging applies
/// ([`tracer::shadows::applies`]), the chosen tree is probed again with
/// merged shadow packets and the fewer cycles kept (the images are the
/// same); with the second leaf piece `auto` on a streamed scene, the
/// second piece's size likewise ([`choose_pieces`]); with
/// `ChildOrder::Auto`, the order the view's rays ask for likewise
/// ([`choose_child_order`]). Deterministic.
pub fn choose_firmware(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
) -> Result<Firmware> {
    Ok(choose_firmware_probed(scene, opt, nm, timing)?.0)
}

/// See [`choose_firmware`].
pub(crate) const TREE_PSNR_SLACK: f64 = 0.25;

/// [`choose_firmware`], with the chosen firmware's probe when one ran.
pub(crate) fn choose_firmware_probed(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
) -> Result<(Firmware, Option<ProbeRender>)> {
    let (fw, p) = choose_tree(scene, opt, nm, timing)?;
    let (fw, p) = choose_shadows(scene, opt, nm, timing, fw, p)?;
    let (fw, p) = choose_pieces(scene, opt, nm, timing, fw, p)?;
    choose_child_order(scene, opt, nm, timing, fw, p)
}

/// The share of the probe's cycles a second leaf piece of `2 * FIRST`
/// words must save to replace one of REST's ([`choose_pieces`]).
pub(crate) const PIECES_MARGIN: f64 = 0.003;

/// `--leaf-pieces` with the second piece `auto` (the default; streamed
/// scenes): the tree and shadow packets chosen, a second piece of at most
/// `2 * FIRST` words against one of REST's on the probe. The small second
/// piece is a shorter wait after the first piece's tests but one more
/// turn of the leaf's loop, which pays where the array waits for further
/// pieces (SPD rings, mount) and costs where the tests hide the DMA (SPD
/// gears); the same objects are tested in the same order, so the images
/// are the same.
fn choose_pieces(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
    fw: Firmware,
    p: Option<ProbeRender>,
) -> Result<(Firmware, Option<ProbeRender>)> {
    let Some(second) = opt.pieces.auto_second() else {
        return Ok((fw, p));
    };
    if fw.layout.stream.is_none() {
        return Ok((fw, p));
    }
    let small = Options {
        bsp: fw.bsp,
        shadows: fw.shadows,
        pieces: tracer::LeafPieces {
            second: Some(second),
            ..opt.pieces
        },
        ..*opt
    };
    let sfw = tracer::build_with(scene, &small, nm).map_err(|e| anyhow!("{e}"))?;
    keep_faster((fw, p), sfw, opt, timing, PIECES_MARGIN)
}

/// `fw` (with its probe, if one ran) or `alt`, which renders the same
/// image, whichever runs the probe in fewer cycles: `alt` where it saves
/// more than `margin` of `fw`'s ([`faster`]: a close call is probed
/// twice).
fn keep_faster(
    (fw, p): (Firmware, Option<ProbeRender>),
    alt: Firmware,
    opt: &Options,
    timing: &Timing,
    margin: f64,
) -> Result<(Firmware, Option<ProbeRender>)> {
    let (p, ap) = rayon::join(
        || p.map_or_else(|| probe(&fw, opt, timing), Ok),
        || probe(&alt, opt, timing),
    );
    let (mut p, mut ap) = (p?, ap?);
    if faster((&fw, &mut p), (&alt, &mut ap), opt, timing, margin)? {
        ap.reference = p.reference;
        Ok((alt, Some(ap)))
    } else {
        Ok((fw, Some(p)))
    }
}

/// `--shadow-packets auto`: the tree chosen, merged shadow packets
/// against a packet per light on the probe, the fewer cycles kept.
fn choose_shadows(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
    fw: Firmware,
    p: Option<ProbeRender>,
) -> Result<(Firmware, Option<ProbeRender>)> {
    if opt.shadows != tracer::ShadowPackets::Auto || !tracer::shadows::applies(opt, &fw.layout) {
        return Ok((fw, p));
    }
    let merged = Options {
        bsp: fw.bsp,
        shadows: tracer::ShadowPackets::Merged,
        ..*opt
    };
    let mfw = tracer::build_with(scene, &merged, nm).map_err(|e| anyhow!("{e}"))?;
    // The same images: the same rays, traced in other packets.
    keep_faster((fw, p), mfw, opt, timing, 0.0)
}

/// Eye rays the host traces to learn the ways rays end
/// ([`choose_child_order`]): about this many, every k-th pixel of the
/// frame in both directions.
pub(crate) const CHILD_ORDER_SAMPLES: u64 = 16_384;

/// The share of the probe's cycles a child order must save to replace
/// the one it is tried against ([`choose_child_order`]): the probe's
/// 1/16 of the tiles cannot tell smaller differences from the frame's.
pub(crate) const CHILD_ORDER_MARGIN: f64 = 0.003;

/// `--child-order auto` (packet traversal). First the order the view's
/// rays ask for: per axis and kind of pass, the way most of the rays that
/// end went ([`tracer::ChildOrder::from_hits`], from the f64 reference's
/// rays of every k-th pixel: the secondary rays that hit, the shadow rays
/// that are blocked); then, per axis of closest-hit passes that the
/// sample leaves to the majority though its secondary rays go both ways
/// along it, the rule of the way its rays that hit lean, however little.
/// Each is run on the probe: the view's order is kept where it takes
/// fewer cycles than the majority, each axis's rule where it saves more
/// than [`CHILD_ORDER_MARGIN`] of the cycles of the order before it (the
/// same images: the same hits, found in another order).
fn choose_child_order(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
    fw: Firmware,
    p: Option<ProbeRender>,
) -> Result<(Firmware, Option<ProbeRender>)> {
    use tracer::{AxisOrder, ChildOrder};
    if opt.child_order != ChildOrder::Auto || opt.traversal != tracer::Traversal::Packet {
        return Ok((fw, p));
    }
    let pixels = opt.width as u64 * opt.height as u64;
    let stride = ((pixels / CHILD_ORDER_SAMPLES) as f64)
        .sqrt()
        .floor()
        .max(1.0) as u32;
    let w = crate::reference::ray_ways(scene, opt.width, opt.height, opt.depth, stride);
    let prior = ChildOrder::from_hits(
        (&w.secondary_hit, &w.secondary),
        (&w.shadow_blocked, &w.shadow),
    );
    let mixed: Vec<usize> = (0..3)
        .filter(|&a| w.secondary[a][0] > 0 && w.secondary[a][1] > 0)
        .collect();
    if prior == ChildOrder::MAJORITY && mixed.is_empty() {
        return Ok((fw, p));
    }
    // Every order is generated on the same layout (the kept firmware's:
    // the orders differ only in their programs).
    let build = |base: &Firmware, order: ChildOrder| {
        tracer::with_child_order(scene, base, opt, nm, order).map_err(|e| anyhow!("{e}"))
    };
    let mut best = match p {
        Some(p) => (fw, p),
        None => {
            let p = probe(&fw, opt, timing)?;
            (fw, p)
        }
    };
    let keep = |best: &mut (Firmware, ProbeRender), fw: Firmware, mut p: ProbeRender, margin| {
        if faster((&best.0, &mut best.1), (&fw, &mut p), opt, timing, margin)? {
            p.reference = best.1.reference.take();
            *best = (fw, p);
        }
        Ok::<(), anyhow::Error>(())
    };
    if prior != ChildOrder::MAJORITY {
        let pfw = build(&best.0, prior)?;
        let pp = probe(&pfw, opt, timing)?;
        keep(&mut best, pfw, pp, 0.0)?;
    }
    for a in mixed {
        let (mut closest, any) = best.0.child_order.rules();
        if closest[a] != AxisOrder::Majority {
            continue;
        }
        // The way the sample leans, if only a little.
        let [down, up] = w.secondary_hit[a];
        closest[a] = if down >= up {
            AxisOrder::Down
        } else {
            AxisOrder::Up
        };
        let f = build(&best.0, ChildOrder::Fixed { closest, any })?;
        let p = probe(&f, opt, timing)?;
        keep(&mut best, f, p, CHILD_ORDER_MARGIN)?;
    }
    Ok((best.0, Some(best.1)))
}

/// [`choose_firmware_probed`]'s choice of the BSP tree (shadow packets
/// `Auto` built as `PerLight`).
fn choose_tree(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
) -> Result<(Firmware, Option<ProbeRender>)> {
    let cands = tracer::resolve_bsp(opt, scene.objects.len());
    if cands.len() < 2 {
        let fw = tracer::build_with(scene, opt, nm).map_err(|e| anyhow!("{e}"))?;
        return Ok((fw, None));
    }
    let mut tried: Vec<(ProbeRender, f64, Firmware)> = Vec::new();
    let mut reference: Option<(Vec<u8>, Vec<u32>)> = None;
    let mut first_err = None;
    // The candidates built and probed side by side (each probe's chip
    // instances and each tree's build share the thread pool), taken in
    // their order.
    let built: Vec<std::result::Result<Result<(Firmware, ProbeRender)>, String>> = cands
        .par_iter()
        .map(|&bsp| {
            let o = Options { bsp, ..*opt };
            tracer::build_with(scene, &o, nm).map(|fw| probe(&fw, opt, timing).map(|p| (fw, p)))
        })
        .collect();
    for b in built {
        let (fw, mut p) = match b {
            Ok(probed) => probed?,
            Err(e) => {
                first_err.get_or_insert(e);
                continue;
            }
        };
        let (r8, rh) = reference.get_or_insert_with(|| {
            crate::reference::render_pixels(scene, opt.width, opt.height, opt.depth, &p.pixels)
        });
        let psnr = crate::metrics::psnr(&p.rgb8, r8);
        p.reference = Some((r8.clone(), rh.clone()));
        tried.push((p, if psnr.is_finite() { psnr } else { 99.0 }, fw));
    }
    let best_psnr = tried.iter().map(|t| t.1).fold(f64::NEG_INFINITY, f64::max);
    let mut pick: Option<(ProbeRender, f64, Firmware)> = None;
    for t in tried {
        if t.1 >= best_psnr - TREE_PSNR_SLACK
            && pick.as_ref().is_none_or(|(b, _, _)| t.0.cycles < b.cycles)
        {
            pick = Some(t);
        }
    }
    match pick {
        Some((p, _, fw)) => Ok((fw, Some(p))),
        None => Err(anyhow!(
            "{}",
            first_err.unwrap_or_else(|| "internal: no BSP to build".into())
        )),
    }
}

/// The lines of a generated firmware's header that name the options it
/// was generated for (size, ways, depth, datapath, format; traversal and
/// BSP): a program written for other options reads another data image.
fn header(source: &str) -> Vec<&str> {
    source
        .lines()
        .take_while(|l| l.starts_with(';'))
        .skip(1)
        .take(2)
        .collect()
}

/// The `.datapath` a firmware source declares (16 without the directive).
pub(crate) fn source_datapath(source: &str) -> Datapath {
    source
        .lines()
        .map(|l| l.split(';').next().unwrap_or("").trim())
        .find_map(|l| l.strip_prefix(".datapath"))
        .and_then(|v| v.trim().parse::<u32>().ok())
        .and_then(Datapath::from_bits)
        .unwrap_or(Datapath::W16)
}

/// `render --firmware FILE.s`: `fw` (generated for the same scene and
/// options: its data image, FB and streamed, is kept) with its program
/// replaced by the one assembled from `text`. Refused with the file's name
/// when it does not assemble (file:line:col), was generated for other
/// options (its header or the data image's addresses differ), or does not
/// fit below the data the host loads.
pub(crate) fn firmware_from_source(mut fw: Firmware, text: &str, name: &str) -> Result<Firmware> {
    let img = asm::assemble(text, name).map_err(|e| anyhow!("{e}"))?;
    let (want, got) = (header(&fw.source), header(text));
    if want != got {
        fn line<'a>(v: &[&'a str], k: usize) -> &'a str {
            v.get(k).copied().unwrap_or("(no header line)")
        }
        let k = (0..2)
            .find(|&k| line(&want, k) != line(&got, k))
            .unwrap_or(0);
        anyhow::bail!(
            "{name}:{}: the firmware was generated for `{}`; these options give `{}` (render it with the options it was emitted with)",
            k + 2,
            line(&got, k).trim_start_matches("; "),
            line(&want, k).trim_start_matches("; ")
        );
    }
    let gen = asm::assemble(&fw.source, "generated")
        .map_err(|e| anyhow!("internal: the generated firmware does not assemble:\n{e}"))?;
    for data::Label(sym) in data::IMAGE_SYMBOLS {
        if gen.symbol(sym) != img.symbol(sym) {
            anyhow::bail!(
                "{name}: {sym} is {:?} in the file and {:?} in the data image of these options: the file was generated for another scene or options",
                img.symbol(sym),
                gen.symbol(sym)
            );
        }
    }
    // The program must end below the first data the host loads.
    for seg in &img.segments {
        let end = seg.addr as u64 + seg.data.len() as u64;
        if seg.addr < mem::FB_IMAGE && end > mem::FB_IMAGE as u64 {
            anyhow::bail!(
                "{name}: the program's segment at 0x{:x} ends at 0x{end:x}, past 0x{:x} where the host loads the FB image (the context memory holds 8192 words: 0x{:x}..0x{:x})",
                seg.addr,
                mem::FB_IMAGE,
                mem::CTX_BASE,
                mem::CTX_BASE + 4 * 8192
            );
        }
    }
    // The kernels as the file lays them out: `k_NAME` .. `k_NAME_end`.
    let mut kernels: Vec<(i64, String, usize)> = img
        .symbols
        .iter()
        .filter(|(n, v)| n.starts_with("k_") && !n.ends_with("_end") && **v >= mem::CTX_BASE as i64)
        .filter_map(|(n, v)| {
            let e = img.symbol(&format!("{n}_end"))?;
            Some((*v, n.clone(), ((e - v) / 4).max(0) as usize))
        })
        .collect();
    kernels.sort();
    fw.context_words = kernels.iter().map(|k| k.2).sum();
    fw.kernels = kernels.into_iter().map(|(_, n, l)| (n, l)).collect();
    fw.source = text.to_string();
    Ok(fw)
}

/// Render with a firmware already built (for example by
/// [`choose_firmware`]).
pub(crate) fn render_built(
    fw: Firmware,
    opt: &Options,
    host: &RenderSettings,
) -> Result<ChipRender> {
    render_firmware(fw, opt, host)
}

fn render_firmware(fw: Firmware, opt: &Options, host: &RenderSettings) -> Result<ChipRender> {
    let t0 = std::time::Instant::now();
    let progress = host.progress;
    let img = asm::assemble(&fw.source, "tracer.s")
        .map_err(|e| anyhow!("internal: the generated firmware does not assemble:\n{e}"))?;
    let (w, h) = (opt.width, opt.height);
    let (tw, th) = (fw.tile_w, fw.tile_h);
    let mut tiles = Vec::new();
    for ty in 0..h.div_ceil(th) {
        for tx in 0..w.div_ceil(tw) {
            tiles.push((tx * tw, ty * th));
        }
    }
    let items = match host.item_tiles {
        Some(n) => {
            let n = n.max(1);
            (0..tiles.len().div_ceil(n))
                .map(|i| i * n..(i + 1).saturating_mul(n).min(tiles.len()))
                .collect()
        }
        None => work_items(
            tiles.len(),
            rayon::current_num_threads(),
            host.trace.is_some(),
        ),
    };
    let bar = if progress && tiles.len() > 1 {
        let b = crate::output::progress_bar(tiles.len() as u64);
        b.set_style(
            ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} tiles, {eta} left")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b.set_message("chip");
        b
    } else {
        ProgressBar::hidden()
    };
    // Each work item with the host seconds of all its work (building the
    // chip and loading it, running it, reading its pixels back).
    let results = run_items(&img, &items, |gi, seed| {
        let t0 = std::time::Instant::now();
        let t = if gi == 0 { host.trace.clone() } else { None };
        let p = host.profile;
        let (tm, own) = (&host.timing, items[gi].clone());
        let n = own.len() as u64;
        let r = match fw.datapath {
            Datapath::W16 => run_item::<i16>(&img, &fw, &tiles, own, seed, t, p, tm, progress),
            Datapath::W32 => run_item::<i32>(&img, &fw, &tiles, own, seed, t, p, tm, progress),
        };
        bar.inc(n);
        (r, t0.elapsed().as_secs_f64())
    });
    bar.finish_and_clear();
    let mut rgb8 = vec![0u8; (w * h * 3) as usize];
    let mut hits = vec![NO_HIT; (w * h) as usize];
    let mut stats = Stats::default();
    let (mut fw_cycles, mut startup, mut passes) = (0u64, 0u64, 0u64);
    let mut chip_seconds = 0.0;
    let mut item_seconds_all = Vec::with_capacity(items.len());
    let mut tile_seconds = Vec::with_capacity(tiles.len());
    let mut own_seconds = 0.0;
    let mut profile = None;
    let mut ended = false;
    for (gi, (r, item_seconds)) in results.into_iter().enumerate() {
        let mut g = r?;
        item_seconds_all.push(item_seconds);
        tile_seconds.extend(&g.tile_seconds);
        own_seconds += g.own_seconds;
        if let Some(p) = g.profile.take().filter(|_| !ended) {
            profile = Some(match profile {
                None => p,
                Some(q) => crate::profile::Profile::merge(q, p),
            });
        }
        chip_seconds += g.seconds;
        if gi == 0 {
            startup = g.startup.cycles;
            add_stats(&mut stats, &g.startup);
        }
        if ended {
            // One chip halted before these tiles: their output words are
            // the zeros of main memory.
            g.out.iter_mut().for_each(|o| o.fill(0));
        } else {
            if g.halted {
                // The firmware's `T_END` as one chip's counter reads it
                // (taken as a reading of the counter, as the tracer's is).
                fw_cycles = g.t_end_raw.unwrap_or(stats.cycles + g.t_end_tail);
                ended = true;
            }
            passes += g.passes;
            add_stats(&mut stats, &g.counted);
        }
        for (k, out) in g.out.iter().enumerate() {
            let (x0, y0) = tiles[items[gi].start + k];
            for lane in 0..64u32 {
                let (row, col) = (lane / 8, lane % 8);
                if row >= th || col >= tw {
                    continue;
                }
                let (x, y) = (x0 + col, y0 + row);
                if x >= w || y >= h {
                    continue;
                }
                let p = (y * w + x) as usize;
                for c in 0..3 {
                    rgb8[3 * p + c] = to8(out[c * 64 + lane as usize], fw.datapath);
                }
                let id = out[192 + lane as usize];
                hits[p] = if id < 0 { NO_HIT } else { id as u32 };
            }
        }
    }
    Ok(ChipRender {
        width: w,
        height: h,
        rgb8,
        hits,
        cycles: stats.cycles,
        startup_cycles: startup,
        firmware_cycles: fw_cycles,
        stats,
        passes,
        // The leaf cache: every issue at `leaf_first` looks a leaf's first
        // piece up, every one at `leaf_miss` moves it.
        leaf_cache: leaf_watch(&img).is_some().then(|| {
            let [looked, misses] = stats.issues_watched;
            LeafCache {
                hits: looked.saturating_sub(misses),
                misses,
            }
        }),
        tiles: tiles.len(),
        firmware: fw,
        profile,
        chip_seconds,
        item_own_seconds: own_seconds / item_seconds_all.len().max(1) as f64,
        item_seconds: item_seconds_all,
        tile_seconds,
        render_seconds: t0.elapsed().as_secs_f64(),
    })
}
