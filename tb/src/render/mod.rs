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
use firmware::asm;
use firmware::scene::Scene;
use firmware::tracer::{self, Firmware, Numerics, Options};
use indicatif::{ProgressBar, ProgressStyle};
use rtl::rc::Datapath;
use rtl::{Stats, Timing};

use crate::reference::NO_HIT;

mod item;
mod measure;
mod memory;
mod probe;
mod source;

pub use crate::autotune::choose_firmware;
pub(crate) use crate::autotune::choose_firmware_probed;
pub use item::TRACED_TILES;
use item::{add_stats, leaf_watch, run_item, run_items, Frame};
pub(crate) use item::{work_items, MAX_CYCLES_PER_TILE};
pub use measure::{render, RenderReport};
pub(crate) use measure::{render_and_measure, render_json};
pub(crate) use probe::faster;
pub use probe::{probe, ProbeRender};
pub(crate) use source::{firmware_from_source, source_datapath};

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
    /// ([`crate::schedule::FrameWork::of`]).
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
    /// The timing file sets the clock (`clock_hz`): the frame rate is
    /// quoted at it, else at the chip's own ([`crate::cost::chip_clock`]).
    pub clock_given: bool,
    /// Tiles per host work item ([`work_items`]; `None`: sized by the
    /// thread count). Any size gives the same frame.
    pub item_tiles: Option<usize>,
    /// The frame's chips step every cycle through the plain model
    /// ([`rtl::Chip::plain`], `--plain`; the probes that choose the
    /// firmware run on the fast paths, which count the same cycles).
    pub plain: bool,
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
    /// by the simulator, [`item::watch`]).
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
    let one = ((12 + datapath.extra_bits()) as f64).exp2();
    ((v as f64 / one).clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Tags of the simulator's ray census ([`rtl::chip::Watch::tag`]): the
/// kind of the rays of a pass.
pub(crate) const RAY_EYE: usize = 0;
pub(crate) const RAY_SHADOW: usize = 1;
pub(crate) const RAY_REFLECT: usize = 2;
pub(crate) const RAY_REFRACT: usize = 3;

/// Render `scene` on the simulated chip.
pub fn render_chip(scene: &Scene, opt: &Options, settings: &RenderSettings) -> Result<ChipRender> {
    let fw = if settings.streamed {
        tracer::build_streamed_with(scene, opt, &settings.numerics).map_err(|e| anyhow!("{e}"))?
    } else {
        choose_firmware(scene, opt, &settings.numerics, &settings.timing)?
    };
    render_firmware(fw, opt, settings)
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

/// The frame's work items: `host.item_tiles` tiles each where asked, else
/// as [`work_items`] cuts the `tiles` for the host's threads.
fn frame_items(host: &RenderSettings, tiles: usize) -> Vec<std::ops::Range<usize>> {
    match host.item_tiles {
        Some(n) => {
            let n = n.max(1);
            (0..tiles.div_ceil(n))
                .map(|i| i * n..(i + 1).saturating_mul(n).min(tiles))
                .collect()
        }
        None => work_items(tiles, rayon::current_num_threads(), host.trace.is_some()),
    }
}

/// The frame's progress bar of `tiles` tiles (hidden without `progress`
/// or for one tile).
fn tile_bar(progress: bool, tiles: usize) -> ProgressBar {
    if !(progress && tiles > 1) {
        return ProgressBar::hidden();
    }
    let b = crate::output::progress_bar(tiles as u64);
    b.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} tiles, {eta} left")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b.set_message("chip");
    b
}

/// One tile's output words (per lane: red, green, blue, the hit object)
/// into the frame's image and hit map, the tile of `tile` pixels at
/// `corner`, its lanes outside the frame of `frame` pixels left out.
fn place_tile(
    out: &[i32],
    corner: (u32, u32),
    tile: (u32, u32),
    fw: &Firmware,
    frame: (u32, u32),
    rgb8: &mut [u8],
    hits: &mut [u32],
) {
    let ((x0, y0), (tw, th), (w, h)) = (corner, tile, frame);
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

/// Assemble the tracer's generated program (for ray depth `depth`): a
/// program over TinyRISC's code space is said as such (each level of
/// recursion adds its code), any other failure is an internal error.
pub(crate) fn assemble_generated(fw: &Firmware, depth: u32) -> Result<asm::Image> {
    asm::assemble(&fw.source, "tracer.s").map_err(|e| {
        let text = e.to_string();
        let bytes = text
            .split("sections overlap: ")
            .nth(1)
            .filter(|t| t.contains("(.text) run into"))
            .and_then(|t| t.split(' ').next())
            .and_then(|n| n.parse::<u64>().ok());
        match bytes {
            Some(n) => anyhow!(
                "the program generated for ray depth {depth} is {n} bytes of TinyRISC code, over the \
                 65,536 below its data: lower --depth (each level of recursion adds its shading code)"
            ),
            None => anyhow!("internal: the generated firmware does not assemble:\n{e}"),
        }
    })
}

fn render_firmware(fw: Firmware, opt: &Options, host: &RenderSettings) -> Result<ChipRender> {
    let t0 = std::time::Instant::now();
    let progress = host.progress;
    let img = assemble_generated(&fw, opt.depth)?;
    let (w, h) = (opt.width, opt.height);
    let (tw, th) = (fw.tile_w, fw.tile_h);
    let mut tiles = Vec::new();
    for ty in 0..h.div_ceil(th) {
        for tx in 0..w.div_ceil(tw) {
            tiles.push((tx * tw, ty * th));
        }
    }
    let items = frame_items(host, tiles.len());
    let bar = tile_bar(progress, tiles.len());
    // Each work item with the host seconds of all its work (building the
    // chip and loading it, running it, reading its pixels back).
    let frame = Frame {
        img: &img,
        fw: &fw,
        tiles: &tiles,
        timing: &host.timing,
        plain: host.plain,
        say_files: progress,
    };
    let results = run_items(&img, &items, |gi, seed| {
        let t0 = std::time::Instant::now();
        let t = if gi == 0 { host.trace.clone() } else { None };
        let p = host.profile;
        let own = items[gi].clone();
        let n = own.len() as u64;
        let r = match fw.datapath {
            Datapath::W16 => run_item::<i16>(&frame, own, seed, t, p),
            Datapath::W32 => run_item::<i32>(&frame, own, seed, t, p),
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
            let corner = tiles[items[gi].start + k];
            place_tile(out, corner, (tw, th), &fw, (w, h), &mut rgb8, &mut hits);
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
