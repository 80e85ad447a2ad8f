//! `morphosys bench`: how fast the simulator runs.
//!
//! The workload is the ray tracer itself: the default scene (or SCENE) at a
//! small size, rendered on the simulated chip. Measured:
//!
//! * tracing off, one host thread: simulated chip (array) cycles per host
//!   second over a frame of `--size` (default 128x128: 256 tiles, so the
//!   start-up is amortised), the figure the project's goal is stated in;
//! * tracing on (a VCD of TinyRISC, the broadcast unit and one RC, the kind
//!   of trace a user asks for), one host thread, against the same frame
//!   untraced: the whole render (`traced_slowdown`, what a user waits
//!   for) and the chip alone, from the waveform's creation to its
//!   end (`traced_slowdown_chip`: the frame's setup, firmware generation
//!   and assembly and the image's assembly, the same in both runs, left
//!   out);
//! * the speed-up of rendering a 256x256 frame on every core (its tiles
//!   as work items, a chip each) over one core, and the schedule model's
//!   prediction of it on this machine's thread count, 16 and 64 cores from
//!   the frame's tiles measured on one thread ([`crate::schedule`]).
//!
//! The workload runs the paper's traversal by default (the simulator's
//! workload since the first bench); `--traversal packet` runs what
//! `render` runs.
//!
//! Each configuration runs `--repeat` times, the configurations in turn
//! (one run of each per round); the best (least disturbed) run of each
//! counts. The reference render is not part of any timing.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, Result};
use firmware::bsp::BspParams;
use firmware::tracer::Options;
use serde_json::json;

use crate::cmd_scene::load_scene;

#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// Scene file (.nff or .toml); default scenes/default.toml.
    pub scene: Option<PathBuf>,
    /// Image size of the throughput workload (each side 1..=4096).
    #[arg(long, value_name = "WxH", value_parser = crate::cli::parse_size, default_value = "128x128")]
    pub size: (u32, u32),
    /// Runs per configuration; the fastest counts.
    #[arg(long, value_name = "N", default_value_t = 3, value_parser = crate::cli::parse_count::<u32>)]
    pub repeat: u32,
    /// Write the figures as JSON here.
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// The chip's timing from a TOML file (`morphosys timing`).
    #[arg(long, value_name = "FILE.toml")]
    pub timing: Option<PathBuf>,
    /// BSP traversal of the workload: paper (the paper's tracer and its
    /// median BSP, the simulator's workload since the first bench) or
    /// packet (what `render` runs by default, its BSP chosen as `render`
    /// chooses it).
    #[arg(long, value_name = "paper|packet", default_value = "paper")]
    pub traversal: firmware::tracer::Traversal,
    /// Also run `morphosys sweep` of these scenes (comma-separated; its
    /// knobs and its size sweep of the SPD families) on one thread and on
    /// every core, and give the schedule model's prediction for it
    /// (minutes).
    #[arg(long, value_name = "SCENES", value_delimiter = ',')]
    pub sweep: Vec<PathBuf>,
    /// Image size of `--sweep`'s knob renders (the sweep's `--size`).
    #[arg(long, value_name = "WxH", value_parser = crate::cli::parse_size, default_value = "256x256")]
    pub sweep_size: (u32, u32),
    /// Largest SPD size of `--sweep`'s size sweep (the sweep's
    /// `--max-size`).
    #[arg(long, value_name = "N", default_value_t = 4, value_parser = crate::cli::parse_count::<u32>)]
    pub sweep_max_size: u32,
    /// Step every cycle through the plain register-transfer model (one
    /// eval and commit per cycle) instead of the fast paths: slower, and
    /// the same cycles, states and waveform.
    #[arg(long)]
    pub plain: bool,
}

fn pool(threads: usize) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start host threads")
}

pub fn command(a: BenchArgs) -> Result<()> {
    if let Some(j) = &a.json {
        crate::output::Files::new()
            .input(
                &a.scene
                    .clone()
                    .unwrap_or_else(crate::cmd_scene::default_scene),
                "SCENE",
            )
            .output(j, "--json")
            .check()?;
    }
    let scene = load_scene(a.scene.as_deref())?;
    // `--sweep`'s scenes, checked before minutes of work.
    for s in &a.sweep {
        load_scene(Some(s))?;
    }
    let timing = crate::timing::load_or_default(a.timing.as_deref())?;
    let (width, height) = a.size;
    let opt = bench_options(a.traversal, width, height);
    let repeat = a.repeat.max(1);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let tmp = tempfile::tempdir().context("cannot create a temporary directory")?;
    crate::output::register_temporary(tmp.path());

    // One pool per thread count, kept for all the rounds.
    let one_thread = pool(1)?;
    let every_core = pool(cores)?;
    let Measured {
        best,
        frame,
        serial,
        chip_render,
    } = measure(
        &scene,
        &opt,
        &a,
        &timing,
        tmp.path(),
        [&one_thread, &every_core],
        cores,
    )?;
    let [(cycles, one, _), (traced_cycles, traced, traced_chip), (_, untraced_small, untraced_small_chip), (big_cycles, big_one, _), (_, all, _)] =
        best;
    let off = cycles as f64 / one;
    let on = traced_cycles as f64 / traced;
    let speedup = big_one / all;
    // What the figures were measured on: the fastest of `repeat` runs each.
    let cpu = host_cpu();
    let traced_slowdown = traced / untraced_small;
    // The same without the frame's setup and the image's assembly (the
    // same in both runs): the chip alone, from the waveform's creation to
    // its end.
    let traced_slowdown_chip = traced_chip / untraced_small_chip;
    println!(
        "host                           {cpu}, {cores} threads; each figure the fastest of {repeat} runs, taken in turn{}",
        if a.plain { "; the plain model (--plain)" } else { "" }
    );
    let simd = rtl::simd::level();
    println!("simd path                      {}", simd_path(simd));
    println!(
        "workload                       {} at {width}x{height}, 64 ways: {cycles} chip cycles",
        scene.source
    );
    println!(
        "tracing off, 1 thread          {:.2} M array cycles per host second ({one:.3} s)",
        off / 1e6
    );
    println!(
        "tracing on, 1 thread           {:.2} M array cycles per host second at 64x32 ({traced:.3} s against {untraced_small:.3} s untraced, {traced_slowdown:.1}x; the chip alone {traced_chip:.4} s against {untraced_small_chip:.4} s, {traced_slowdown_chip:.1}x; VCD of tinyrisc, broadcast, rc_r0_c0)",
        on / 1e6
    );
    let model = |n: usize| crate::schedule::frame_speedup(serial, &frame, n);
    let chip_speedup = chip_render[0] / chip_render[1];
    println!(
        "{cores} threads                      256x256 ({big_cycles} chip cycles, {} work items): {all:.3} s against {big_one:.3} s, speed-up {speedup:.2}x; the chip render alone {:.3} s against {:.3} s, {chip_speedup:.2}x (the schedule model: {:.2}x)",
        frame.items(cores).len(),
        chip_render[1],
        chip_render[0],
        model(cores)
    );
    print_schedule(&frame, serial);
    let sweep = if a.sweep.is_empty() {
        serde_json::Value::Null
    } else {
        sweep_model(&a, tmp.path(), [&one_thread, &every_core], cores)?
    };
    if let Some(p) = &a.json {
        let predicted = predictions(cores, model);
        let v = json!({
            "scene": scene.source,
            "width": width,
            "height": height,
            "chip_cycles": cycles,
            "array_cycles_per_host_second": off,
            "array_cycles_per_host_second_traced": on,
            "host_seconds_1_thread": one,
            "traced_workload": "64x32, tinyrisc + broadcast + array.rc_r0_c0",
            "speedup_workload": "256x256",
            "speedup_host_seconds_1_thread": big_one,
            "host_seconds_all_threads": all,
            "threads": cores,
            "speedup": speedup,
            "repeat": repeat,
            "statistic": format!("fastest of {repeat} runs, the measurements taken in turn"),
            "host_cpu": cpu,
            "simd": simd.name(),
            "traced_slowdown": traced_slowdown,
            "traced_slowdown_chip": traced_slowdown_chip,
            "host_seconds_traced": traced,
            "host_seconds_untraced_small": untraced_small,
            "traversal": opt.traversal.name(),
            "schedule": schedule_json(&frame, serial, chip_render, predicted),
            "sweep": sweep,
        });
        crate::output::write(p, (serde_json::to_string_pretty(&v)? + "\n").as_bytes())?;
        crate::note!("wrote {}", p.display());
    }
    Ok(())
}

/// The per-cycle path's instruction set, how it was chosen, and the
/// widest this CPU has.
fn simd_path(simd: rtl::simd::Simd) -> String {
    format!(
        "{} ({}; the widest this CPU has: {})",
        simd.name(),
        if std::env::var_os(rtl::simd::ENV).is_some_and(|v| !v.is_empty()) {
            "forced by MORPHOSYS_SIMD"
        } else {
            "chosen at run time"
        },
        rtl::simd::Simd::best().name()
    )
}

/// The schedule model's measurements of the 256x256 chip render on one
/// thread, and its predictions for 16 and 64 cores.
fn print_schedule(frame: &crate::schedule::FrameWork, serial: f64) {
    let model = |n: usize| crate::schedule::frame_speedup(serial, frame, n);
    let (shortest, longest) = frame
        .tiles
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &t| {
            (lo.min(t), hi.max(t))
        });
    println!(
        "schedule model                 the 256x256 chip render on one thread: {} tiles of {:.2} to {:.2} ms, {:.2} ms a work item's own, {serial:.4} s serial; predicted speed-up {:.1}x on 16 cores ({} items), {:.1}x on 64 ({} items)",
        frame.tiles.len(),
        shortest * 1e3,
        longest * 1e3,
        frame.item * 1e3,
        model(16),
        frame.items(16).len(),
        model(64),
        frame.items(64).len()
    );
}

/// The JSON of the schedule model: the chip render's seconds on one thread
/// and on every core, its serial part and tiles, the predictions.
fn schedule_json(
    frame: &crate::schedule::FrameWork,
    serial: f64,
    chip_render: [f64; 2],
    predicted: serde_json::Map<String, serde_json::Value>,
) -> serde_json::Value {
    json!({
        "model": "the chip render of the 256x256 frame: its serial part, then its tiles cut into the work items N threads run (each an item's own work, its tiles and a warm-up tile), in order, each taken by the first free thread",
        "chip_render_seconds_1_thread": chip_render[0],
        "chip_render_seconds_all_threads": chip_render[1],
        "chip_render_speedup": chip_render[0] / chip_render[1],
        "serial_seconds": serial,
        "tile_seconds": frame.tiles,
        "item_own_seconds": frame.item,
        "predicted_speedup": predicted,
    })
}

/// The bench's workload: the paper's configuration (its traversal and
/// BSP), the workload the simulator's speed has been measured on since the
/// first bench, or the packet traversal with its defaults.
fn bench_options(traversal: firmware::tracer::Traversal, width: u32, height: u32) -> Options {
    match traversal {
        firmware::tracer::Traversal::Paper => Options {
            width,
            height,
            ways: 64,
            depth: 2,
            bsp: BspParams::default(),
            layout: Default::default(),
            datapath: Default::default(),
            traversal: firmware::tracer::Traversal::Paper,
            collapse: Default::default(),
            pieces: Default::default(),
            shadows: Default::default(),
            test_cuts: Default::default(),
            child_order: Default::default(),
            sub_edges: Default::default(),
            positions: Default::default(),
        },
        firmware::tracer::Traversal::Packet => Options {
            width,
            height,
            traversal: firmware::tracer::Traversal::Packet,
            ..Options::default()
        },
    }
}

/// The host's CPU, as /proc/cpuinfo names it (else the architecture).
fn host_cpu() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

/// The bench's measurements: per run (chip cycles, best host seconds, best
/// host seconds of the chips alone), the schedule model's frame and serial
/// part, and the fastest chip render on one thread and on every core.
struct Measured {
    best: [(u64, f64, f64); 5],
    frame: crate::schedule::FrameWork,
    serial: f64,
    chip_render: [f64; 2],
}

/// Run the bench's frames `a.repeat` times each, in turn, on the pools of
/// one thread and of every core.
fn measure(
    scene: &firmware::scene::Scene,
    opt: &Options,
    a: &BenchArgs,
    timing: &rtl::Timing,
    tmp: &std::path::Path,
    pools: [&rayon::ThreadPool; 2],
    cores: usize,
) -> Result<Measured> {
    let repeat = a.repeat.max(1);
    // Throughput: a frame on one thread (start-up amortised). Tracing on: a
    // smaller frame, all of it traced, against the same frame untraced.
    // Speed-up: a 256x256 frame on every core against one core.
    let traced_opt = Options {
        width: 64,
        height: 32,
        ..*opt
    };
    let big = Options {
        width: 256,
        height: 256,
        ..*opt
    };
    // (frame, host threads, traced)
    let runs = [
        (opt, 1, false),
        (&traced_opt, 1, true),
        (&traced_opt, 1, false),
        (&big, 1, false),
        (&big, cores, false),
    ];
    // Each measurement: (chip cycles, best host seconds, best host seconds
    // of the chips alone). The measurements are taken in turn,
    // one run of each per round, so that the two sides of a ratio see the
    // same phases of the host: one after the other, a slow spell of the
    // machine could fall on all the repeats of one side (a traced frame
    // once measured 3.6x its untraced one where the runs around it gave
    // 2.7-2.8x).
    let mut best = [(0u64, f64::INFINITY, f64::INFINITY); 5];
    // The schedule model's measurements: the tiles and an item's own work
    // of the fastest 256x256 frame on one thread and the rest of its chip
    // render (the serial part), and the fastest chip render (the
    // firmware's generation and probe aside) on one thread and on every
    // core.
    let mut frame = crate::schedule::FrameWork::default();
    let mut serial = 0.0;
    let mut chip_render = [f64::INFINITY; 2];
    for k in 0..repeat {
        for (run, (&(opt, threads, trace), b)) in runs.iter().zip(&mut best).enumerate() {
            let cfg = trace.then(|| {
                let mut c = rtl::trace::TraceConfig::new(tmp.join(format!("bench{k}.vcd")));
                c.scope = "tinyrisc,broadcast,array.rc_r0_c0".into();
                c
            });
            let p = if threads == 1 { pools[0] } else { pools[1] };
            let t0 = Instant::now();
            let r = p.install(|| {
                crate::render::render_chip(
                    scene,
                    opt,
                    &crate::render::RenderSettings {
                        trace: cfg,
                        timing: *timing,
                        plain: a.plain,
                        ..Default::default()
                    },
                )
            })?;
            let s = t0.elapsed().as_secs_f64();
            // Runs 3 and 4: the 256x256 frame on one thread and on every
            // core.
            if run >= 3 {
                let k = run - 3;
                if k == 0 && r.render_seconds < chip_render[0] {
                    serial = (r.render_seconds - r.item_seconds.iter().sum::<f64>()).max(0.0);
                    frame = crate::schedule::FrameWork::of(&r);
                }
                chip_render[k] = chip_render[k].min(r.render_seconds);
            }
            *b = (r.cycles, b.1.min(s), b.2.min(r.chip_seconds));
        }
    }
    Ok(Measured {
        best,
        frame,
        serial,
        chip_render,
    })
}

/// `--sweep`: the sweep of `a.sweep` on one thread (its renders' work
/// recorded) and on every core; prints and returns the measured speed-up
/// and the schedule model's.
fn sweep_model(
    a: &BenchArgs,
    tmp: &std::path::Path,
    pools: [&rayon::ThreadPool; 2],
    cores: usize,
) -> Result<serde_json::Value> {
    use std::sync::{Arc, Mutex};
    let mut seconds = [0.0; 2];
    let mut work = Vec::new();
    for (k, pool) in pools.into_iter().enumerate() {
        let recorded = Arc::new(Mutex::new(Vec::new()));
        let args = crate::cmd_sweep::SweepArgs {
            scenes: a.sweep.clone(),
            out_dir: tmp.join(format!("sweep-{k}")),
            size: a.sweep_size,
            knobs: true,
            families: crate::cmd_sweep::FAMILIES
                .split(',')
                .map(String::from)
                .collect(),
            max_size: a.sweep_max_size,
            family_size: (64, 64),
            size_seconds: 60.0,
            timing: Vec::new(),
            broadcast_only: false,
            plan: None,
            work: Some(recorded.clone()),
        };
        let t0 = Instant::now();
        pool.install(|| crate::cmd_sweep::command(args))?;
        seconds[k] = t0.elapsed().as_secs_f64();
        if k == 0 {
            work = std::mem::take(&mut *recorded.lock().map_err(|_| anyhow::anyhow!("poisoned"))?);
        }
    }
    let on = |n: usize| work.iter().map(|w| w.on(n)).collect::<Vec<_>>();
    let one = on(1);
    let rendered: f64 = one
        .iter()
        .map(|w| w.prep + w.items.iter().sum::<f64>())
        .sum();
    let serial = (seconds[0] - rendered).max(0.0);
    let model = |n: usize| crate::schedule::sweep_speedup(serial, &one, &on(n), n);
    let measured = seconds[0] / seconds[1];
    let names: Vec<String> = a.sweep.iter().map(|p| p.display().to_string()).collect();
    println!(
        "sweep                          {} at {}x{} and the SPD families at sizes 1..={} (64x64): {} renders, {:.1} s on 1 thread, {:.1} s on {cores}: speed-up {measured:.2}x (the schedule model: {:.2}x); predicted {:.1}x on 16 cores, {:.1}x on 64",
        names.join(", "),
        a.sweep_size.0,
        a.sweep_size.1,
        a.sweep_max_size,
        work.len(),
        seconds[0],
        seconds[1],
        model(cores),
        model(16),
        model(64)
    );
    let predicted = predictions(cores, model);
    Ok(json!({
        "scenes": names,
        "size": format!("{}x{}", a.sweep_size.0, a.sweep_size.1),
        "max_size": a.sweep_max_size,
        "renders": work.len(),
        "host_seconds_1_thread": seconds[0],
        "host_seconds_all_threads": seconds[1],
        "speedup": measured,
        "model": "each render's preparation, then its work items as N threads cut its tiles, a size-sweep family's renders one after the other; each free thread takes the item ready longest",
        "serial_seconds": serial,
        "renders_work": work.iter().map(|w| json!({
            "task": w.task,
            "step": w.step,
            "prep_seconds": w.prep,
            "tile_seconds": w.frame.tiles,
            "item_own_seconds": w.frame.item,
        })).collect::<Vec<_>>(),
        "predicted_speedup": predicted,
    }))
}

/// A model's predicted speed-ups on this machine's threads, 16 and 64, by
/// thread count (the JSON's `predicted_speedup`).
fn predictions(
    cores: usize,
    model: impl Fn(usize) -> f64,
) -> serde_json::Map<String, serde_json::Value> {
    [cores, 16, 64]
        .into_iter()
        .map(|n| (n.to_string(), json!(model(n))))
        .collect()
}
