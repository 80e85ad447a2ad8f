//! Rendering on the simulated chip: compile the scene, generate and
//! assemble the tracer firmware, run independent chip instances over
//! groups of tiles (rayon), read the pixels back from main memory.
//!
//! Determinism: the tiles are cut into groups of a fixed size whatever the
//! number of host threads, each group runs on its own fresh chip, and the
//! results are placed by tile; the image and every figure are identical for
//! any thread count. Cycle count of a frame: the start-up of one chip
//! (loading the FB, the contexts and the RC tables) plus the tile loops of
//! every group, as if one chip rendered every tile in sequence.

use anyhow::{anyhow, Result};
use firmware::asm::{self, Image};
use firmware::scene::Scene;
use firmware::tracer::{self, mem, Firmware, Numerics, Options};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use rtl::chip::run_to_halt;
use rtl::rc::{Datapath, Word};
use rtl::{Chip, Sim, Stats, Timing};

use crate::reference::NO_HIT;

/// Tiles per chip instance.
pub const TILES_PER_CHIP: usize = 32;
/// Cycle budget of one chip instance.
pub(crate) const MAX_CYCLES_PER_CHIP: u64 = 2_000_000_000;

/// The chip's image and figures.
#[derive(Clone, Debug)]
pub struct ChipRender {
    pub width: u32,
    pub height: u32,
    pub rgb8: Vec<u8>,
    /// Per pixel the object the eye ray hit ([`NO_HIT`] for none).
    pub hits: Vec<u32>,
    /// Frame cycles by the simulator's count: every chip instance from
    /// reset to `halt`, its start-up (reset to the first `tile`) counted
    /// once.
    pub cycles: u64,
    /// The first chip instance's cycles from reset to the first `tile`.
    pub startup_cycles: u64,
    /// The same frame by the firmware's own count (its `T_START` of the
    /// first instance plus every instance's `T_END - T_START`), which the
    /// program can get wrong: see [`ChipRender::firmware_count_disagrees`].
    pub firmware_cycles: u64,
    pub stats: Stats,
    pub object_tests: u64,
    pub passes: u64,
    pub tiles: usize,
    pub chips: usize,
    pub firmware: Firmware,
    /// With [`RenderSettings::profile`]: where the tile loops' cycles went
    /// (every chip instance).
    pub profile: Option<crate::profile::Profile>,
    /// Host seconds the chip instances ran, summed over them: from the
    /// waveform's creation, if any, to its end (the frame's setup, the
    /// firmware and the image's assembly, aside).
    pub chip_seconds: f64,
    /// The host seconds of each chip instance's whole work (building and
    /// loading the chip, running it, reading its pixels back), in tile
    /// order: the work items the host's threads share (`bench`'s schedule
    /// model).
    pub instance_seconds: Vec<f64>,
    /// Host seconds of the chip render: from assembling the firmware to
    /// the assembled image (the firmware's generation and any probe
    /// before it aside); the instances and its serial part.
    pub render_seconds: f64,
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
}

impl ChipRender {
    /// When the firmware's own count of the frame
    /// ([`ChipRender::firmware_cycles`]) differs from the simulator's by
    /// more than 1%: a sentence saying so. (The tracer's reads the counter
    /// a few instructions from where the simulator splits start-up and
    /// tile loop and from `halt`: a handful of cycles per chip instance.)
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
            self.object_tests as f64 / self.passes as f64
        }
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
    for c in 0..2 {
        a.watched_runs[c] -= b.watched_runs[c].min(a.watched_runs[c]);
        a.watched_rcs[c] -= b.watched_rcs[c].min(a.watched_rcs[c]);
        for t in 0..rtl::chip::WATCH_TAGS {
            a.watched_rcs_by_tag[c][t] -=
                b.watched_rcs_by_tag[c][t].min(a.watched_rcs_by_tag[c][t]);
        }
    }
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

struct Group {
    start: u64,
    end: u64,
    tests: u64,
    passes: u64,
    stats: Stats,
    /// Statistics at the start of the tile loop.
    startup: Stats,
    /// Per tile, the 256 output words.
    out: Vec<Vec<i32>>,
    profile: Option<crate::profile::Profile>,
    /// Host seconds from the waveform's creation to its end.
    seconds: f64,
}

fn sym(img: &Image, name: &str) -> Result<u32> {
    img.symbol(name)
        .map(|v| v as u32)
        .ok_or_else(|| anyhow!("internal: firmware symbol {name} missing"))
}

fn run_group<W: Word>(
    img: &Image,
    fw: &Firmware,
    tiles: &[(u32, u32)],
    trace: Option<rtl::trace::TraceConfig>,
    profile: bool,
    timing: &Timing,
    say_files: bool,
) -> Result<Group> {
    // Main memory as large as the program touches (its segments, the tile
    // list, the output tiles and the streamed scene image), not the
    // 16 MiB default: a fresh instance per group must not zero-fill memory
    // nobody reads.
    let wb = fw.fb_word_bytes();
    let ends = img
        .segments
        .iter()
        .map(|s| s.addr as usize + s.data.len())
        .chain([
            mem::FB_IMAGE as usize + wb as usize * fw.fb.len(),
            mem::TILE_LIST as usize + 4 + 12 * tiles.len(),
            (mem::OUTPUT + tiles.len() as u32 * fw.out_tile_bytes()) as usize,
        ])
        .chain(
            fw.layout
                .stream
                .as_ref()
                // the image, then the mailboxes (a half-word per object)
                .map(|st| {
                    (st.base as usize + st.image.len())
                        .max(st.mailbox as usize + 2 * fw.layout.objects)
                }),
        )
        .chain(
            // the packet traversal's mailboxes (main memory, resident or
            // streamed)
            (fw.layout.traversal == tracer::Traversal::Packet)
                .then(|| fw.layout.mailbox + tracer::layout::PK_MAILBOX_BYTES * fw.layout.objects),
        );
    let mem_bytes = ends.max().unwrap_or(0).next_multiple_of(1 << 16);
    let mut chip = Chip::<W>::build(*timing, mem_bytes);
    img.load(&mut chip).map_err(|f| anyhow!("{f}"))?;
    chip.watch = watch(img, fw);
    let fb = fw.fb_bytes();
    chip.load(mem::FB_IMAGE, &fb).map_err(|f| anyhow!("{f}"))?;
    if let Some(st) = &fw.layout.stream {
        chip.load(st.base, &st.image).map_err(|f| anyhow!("{f}"))?;
    }
    let mut list = Vec::with_capacity(4 + 12 * tiles.len());
    list.extend((tiles.len() as u32).to_le_bytes());
    for (k, (x, y)) in tiles.iter().enumerate() {
        list.extend(x.to_le_bytes());
        list.extend(y.to_le_bytes());
        list.extend((mem::OUTPUT + k as u32 * fw.out_tile_bytes()).to_le_bytes());
    }
    chip.load(mem::TILE_LIST, &list)
        .map_err(|f| anyhow!("{f}"))?;
    let mut sim = Sim::new(chip);
    let t0 = std::time::Instant::now();
    if let Some(mut cfg) = trace {
        // The PC and the broadcast unit's context by the program's labels.
        cfg.labels = Some(std::sync::Arc::new(img.trace_labels(mem::CTX_BASE)));
        let path = cfg.path.clone();
        sim.trace(cfg, "morphosys")
            .map_err(|e| anyhow!("creating {}: {e}", path.display()))?;
    }
    // Start-up (FB and context loads, RC tables) ends where the tile loop
    // begins: its statistics are taken apart so that a frame counts one
    // start-up whatever the number of chip instances.
    let tile_pc = sym(img, "tile")?;
    let mut startup = Stats::default();
    let mut result = Ok(0);
    while !sim.top.halted() {
        if sim.top.risc.pc == tile_pc {
            startup = sim.top.stats();
            break;
        }
        if sim.cycle() >= MAX_CYCLES_PER_CHIP {
            break;
        }
        if let Err(e) = sim.step() {
            result = Err(rtl::chip::RunError::Step(e));
            break;
        }
    }
    let mut prof = None;
    if result.is_ok() {
        if profile {
            let names = crate::profile::Names::new(img, mem::CTX_BASE);
            match crate::profile::run(&mut sim, &names, MAX_CYCLES_PER_CHIP) {
                Ok(p) => {
                    result = Ok(p.cycles);
                    prof = Some(p);
                }
                Err(e) => result = Err(e),
            }
        } else {
            result = run_to_halt(&mut sim, MAX_CYCLES_PER_CHIP);
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
    result.map_err(|e| match e {
        rtl::chip::RunError::MaxCycles { .. } => anyhow!(
            "the tracer firmware stopped: {e}; a render allows {MAX_CYCLES_PER_CHIP} cycles per chip \
             instance (up to {TILES_PER_CHIP} tiles): a smaller --size, or a faster --timing"
        ),
        e => anyhow!("the tracer firmware stopped: {e}"),
    })?;
    let m = &sim.top.mem;
    let rd = |name: &str| -> Result<u64> { Ok(m.read(sym(img, name)?, 4) as u64) };
    let out = (0..tiles.len())
        .map(|k| {
            let base = mem::OUTPUT + k as u32 * fw.out_tile_bytes();
            (0..256)
                .map(|i| {
                    let v = m.read(base + wb * i, wb);
                    if wb == 2 {
                        v as u16 as i16 as i32
                    } else {
                        v as i32
                    }
                })
                .collect()
        })
        .collect();
    Ok(Group {
        start: rd("T_START")?,
        end: rd("T_END")?,
        tests: rd("TESTS")?,
        passes: rd("PASSES")?,
        stats: sim.top.stats(),
        startup,
        out,
        profile: prof,
        seconds,
    })
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
}

/// Run the probe's tiles of `opt`'s frame on the chip with `fw`.
pub fn probe(fw: &Firmware, opt: &Options, timing: &Timing) -> Result<ProbeRender> {
    let (tw, th) = (fw.tile_w, fw.tile_h);
    let (nx, ny) = (opt.width.div_ceil(tw), opt.height.div_ceil(th));
    let pick = |n: u32| -> Vec<u32> {
        let v: Vec<u32> = (0..n)
            .filter(|k| k % PROBE_STRIDE == PROBE_STRIDE / 2)
            .collect();
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
    let groups: Vec<&[(u32, u32)]> = tiles.chunks(TILES_PER_CHIP).collect();
    let runs: Vec<Result<Group>> = groups
        .par_iter()
        .with_max_len(1)
        .map(|g| match fw.datapath {
            Datapath::W16 => run_group::<i16>(&img, fw, g, None, false, timing, false),
            Datapath::W32 => run_group::<i32>(&img, fw, g, None, false, timing, false),
        })
        .collect();
    let mut p = ProbeRender {
        cycles: 0,
        pixels: Vec::new(),
        rgb8: Vec::new(),
        hits: Vec::new(),
        reference: None,
    };
    for (gi, r) in runs.into_iter().enumerate() {
        let g = r?;
        p.cycles += g.stats.cycles - g.startup.cycles;
        for (k, out) in g.out.iter().enumerate() {
            let (x0, y0) = groups[gi][k];
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
/// traversal's median and SAH trees), each is run on the probe (every
/// fourth row and column of tiles, at the frame's size, so each packet is
/// as coherent as in the frame) and compared with the f64 reference on the
/// same pixels: the tree with the fewest cycles is kept among those whose
/// probe is within [`TREE_PSNR_SLACK`] dB of the best one's (a faster tree
/// must not cost image quality: the trees find the same hits up to ties,
/// but a tie between surfaces of different colours is visible); ties go
/// to the first. Deterministic.
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
    for sym in [
        "FBIMG", "FBWORDS", "TILELIST", "FB_EYE", "FB_POST", "ROOT", "MAILBOX", "NOBJ", "ROOTBOX",
        "SPLIT", "SBANK",
    ] {
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
    let groups: Vec<&[(u32, u32)]> = tiles.chunks(TILES_PER_CHIP).collect();
    let bar = if progress && groups.len() > 1 {
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
    let first_trace = host.trace.clone();
    // Each chip instance with the host seconds of all its work (building
    // the chip and loading it, running it, reading its pixels back); one
    // task each, so that a thread that is done takes the next instance
    // rather than half of a run of them (2 threads: gears-2's chip render
    // 1.93x-1.98x one thread's against 1.78x-1.87x).
    let results: Vec<(Result<Group>, f64)> = groups
        .par_iter()
        .with_max_len(1)
        .enumerate()
        .map(|(gi, g)| {
            let t0 = std::time::Instant::now();
            let t = if gi == 0 { first_trace.clone() } else { None };
            let p = host.profile;
            let r = match fw.datapath {
                Datapath::W16 => run_group::<i16>(&img, &fw, g, t, p, &host.timing, progress),
                Datapath::W32 => run_group::<i32>(&img, &fw, g, t, p, &host.timing, progress),
            };
            bar.inc(g.len() as u64);
            (r, t0.elapsed().as_secs_f64())
        })
        .collect();
    bar.finish_and_clear();
    let mut rgb8 = vec![0u8; (w * h * 3) as usize];
    let mut hits = vec![NO_HIT; (w * h) as usize];
    let mut stats = Stats::default();
    let (mut fw_cycles, mut startup, mut tests, mut passes) = (0u64, 0u64, 0u64, 0u64);
    let mut chip_seconds = 0.0;
    let mut instance_seconds = Vec::with_capacity(groups.len());
    let mut profile = None;
    for (gi, (r, item_seconds)) in results.into_iter().enumerate() {
        let mut g = r?;
        instance_seconds.push(item_seconds);
        if let Some(p) = g.profile.take() {
            profile = Some(match profile {
                None => p,
                Some(q) => crate::profile::Profile::merge(q, p),
            });
        }
        if gi == 0 {
            startup = g.startup.cycles;
            fw_cycles = g.start;
        }
        fw_cycles += g.end.saturating_sub(g.start);
        chip_seconds += g.seconds;
        tests += g.tests;
        passes += g.passes;
        add_stats(&mut stats, &g.stats);
        if gi > 0 {
            sub_stats(&mut stats, &g.startup);
        }
        for (k, out) in g.out.iter().enumerate() {
            let (x0, y0) = groups[gi][k];
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
        object_tests: tests,
        passes,
        tiles: tiles.len(),
        chips: groups.len(),
        firmware: fw,
        profile,
        chip_seconds,
        instance_seconds,
        render_seconds: t0.elapsed().as_secs_f64(),
    })
}
