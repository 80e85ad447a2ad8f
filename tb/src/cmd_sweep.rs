//! `morphosys sweep`: what every knob costs in frame rate and buys in image
//! quality. Renders each scene on the simulated chip under a set of
//! configurations, one knob varied at a time from the paper's configuration
//! (256x256, 64 ways, recursion level 2, BSP depth 15, 5 objects per leaf,
//! the paper's median split; 2 Newton steps, 2 guard bits, no ray offset), and writes `results.csv` and the charts:
//!
//! * `fig8.{svg,png}`: frames/s at 300 MHz against ways (the paper's Fig. 8,
//!   with its 13.3 frames/s at 64 ways marked), and `fig8_active.{svg,png}`,
//!   the active RCs per ray lane (active-RC fraction x 64 / ways) against
//!   ways, which explains the sub-linear growth;
//! * `pareto.{svg,png}`: frames/s against PSNR over every configuration,
//!   with the Pareto front; the datapath-width series (the paper's
//!   configuration on the 16-bit chip and on the 32-bit variant) has hollow
//!   markers for the 32-bit chip;
//! * `pareto_cost.{svg,png}`: the same points with the silicon's price on
//!   the speed axis: frames/s at each datapath's estimated clock per
//!   million transistors of its array (`morphosys cost`), so that the
//!   32-bit chip's larger, slower RCs count;
//! * `scaling.{svg,png}`: chip cycles per frame against primitive count,
//!   over SPD families generated at sizes 1 to `--max-size` (balls and
//!   tetra by default, at a smaller image, 64x64), one series per family
//!   and node layout (Fig. 5 bit vectors, compact index lists); hollow
//!   markers are scenes streamed from main memory.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};
use firmware::tracer::{Numerics, Options, Traversal};
use rtl::tinyrisc::IssueModel;
use rtl::Timing;

use crate::cmd_scene::load_scene;

mod knobs;
mod plan;
mod plots;
mod tasks;
use knobs::{configs, packet_config, paper_config, Config, Knob};
pub use plan::merge;
use plan::*;
pub use plots::loglog_slope;
use plots::*;
use tasks::{sweep_tasks, ChainRun};

/// `morphosys sweep` as the command line gives it.
#[derive(clap::Args, Debug)]
pub struct SweepCli {
    /// Scene files (default: scenes/default.toml).
    pub scenes: Vec<PathBuf>,
    /// Where results.csv and the charts go (with --merge: default the
    /// plan's folder).
    #[arg(long, value_name = "DIR", required_unless_present_any = ["plan", "merge"])]
    pub out_dir: Option<PathBuf>,
    /// Render nothing: write DIR/jobs.txt, one self-contained `morphosys
    /// render ... --json DIR/points/NAME.json` per distinct render of the
    /// sweep (for GNU parallel or a Slurm job array; a rerun skips the
    /// renders already done), and DIR/sweep.toml, what was asked. Every
    /// size of the size sweep is planned (--size-seconds does not apply).
    #[arg(long, value_name = "PLAN", conflicts_with_all = ["out_dir", "size_seconds", "merge"])]
    pub plan: Option<PathBuf>,
    /// Merge a plan's renders: results.csv and the charts, as the sweep
    /// run here would write them; missing or failed renders are named
    /// and left out.
    #[arg(long, value_name = "PLAN", conflicts_with_all = ["scenes", "size", "only", "families", "max_size", "family_size", "size_seconds", "timing"])]
    pub merge: Option<PathBuf>,
    /// Image size (each side 1..=4096).
    #[arg(long, value_name = "WxH", value_parser = crate::cli::parse_size, default_value = "256x256")]
    pub size: (u32, u32),
    /// Run only one part: `knobs` (every knob on SCENES), `sizes` (the
    /// SPD families at sizes 1..=--max-size, both traversals) or
    /// `broadcast` (both traversals on SCENES under both issue models).
    #[arg(long, value_name = "knobs|sizes|broadcast", value_parser = ["knobs", "sizes", "broadcast"])]
    pub only: Option<String>,
    /// SPD generators of the size sweep, comma-separated.
    #[arg(
        long,
        value_name = "NAMES",
        value_delimiter = ',',
        default_value = FAMILIES,
        value_parser = clap::builder::PossibleValuesParser::new(firmware::scene::spd::names())
    )]
    pub families: Vec<String>,
    /// Largest SPD size factor of the size sweep.
    #[arg(long, value_name = "N", default_value_t = 4, value_parser = crate::cli::parse_count::<u32>)]
    pub max_size: u32,
    /// Image size of the size sweep (streamed scenes of thousands of
    /// objects take minutes of host time at 256x256).
    #[arg(long, value_name = "WxH", value_parser = crate::cli::parse_size, default_value = "64x64")]
    pub family_size: (u32, u32),
    /// Skip a family's larger sizes (with a traversal) once one of its
    /// renders' chips took longer than this many host seconds
    /// (summed over the threads: about one thread's time, whatever runs
    /// beside it).
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0, value_parser = crate::cli::parse_seconds)]
    pub size_seconds: f64,
    /// Timing files: the paper's configuration and the packet
    /// traversal on each scene under each (the `timing` knob, one
    /// series each in timing.png).
    #[arg(long, value_name = "FILE.toml", num_args = 1..)]
    pub timing: Vec<PathBuf>,
}

/// `morphosys sweep`: merge a plan's renders (`--merge`), or run or plan
/// the sweep the arguments ask for.
pub fn run(a: SweepCli) -> Result<()> {
    if let Some(dir) = &a.merge {
        return merge(dir, a.out_dir.as_deref().unwrap_or(dir));
    }
    let only = a.only.as_deref();
    command(SweepArgs {
        scenes: a.scenes,
        out_dir: a.out_dir.unwrap_or_default(),
        plan: a.plan,
        size: a.size,
        knobs: only != Some("sizes"),
        families: if only.is_some() && only != Some("sizes") {
            vec![]
        } else {
            a.families
        },
        broadcast_only: only == Some("broadcast"),
        max_size: a.max_size,
        family_size: a.family_size,
        size_seconds: a.size_seconds,
        timing: a.timing,
        work: None,
    })
}

pub struct SweepArgs {
    pub scenes: Vec<PathBuf>,
    pub out_dir: PathBuf,
    pub size: (u32, u32),
    /// Run the knob sweep over `scenes`.
    pub knobs: bool,
    /// Run the scene-size sweep: these SPD generators at sizes
    /// 1..=`max_size`, both node layouts, at `family_size`.
    pub families: Vec<String>,
    pub max_size: u32,
    pub family_size: (u32, u32),
    /// A family's larger sizes are skipped once a render's chips
    /// took longer than this (host seconds, summed over the threads).
    pub size_seconds: f64,
    /// Timing files: both traversals on each scene under each.
    pub timing: Vec<PathBuf>,
    /// Run only the issue-model comparison (`--only broadcast`): the
    /// paper's configuration and the packet traversal under both models.
    pub broadcast_only: bool,
    /// Render nothing: write the plan into this folder (`jobs.txt`, one
    /// `morphosys render` per distinct render, and `sweep.toml`), for
    /// GNU parallel or a Slurm job array, then `sweep --merge`.
    pub plan: Option<PathBuf>,
    /// Where each render's work is recorded, when asked (`bench --sweep`'s
    /// schedule model).
    pub work: Option<std::sync::Arc<std::sync::Mutex<Vec<crate::schedule::RecordedRender>>>>,
}

/// The SPD generators of the size sweep unless asked otherwise.
pub const FAMILIES: &str = "balls,tetra,rings,gears,lattice";

/// Knob name of the rows of the scene-size sweep.
const SCENE_SIZE: &str = "scene_size";

/// A result row.
#[derive(Clone, Debug, serde::Serialize)]
struct Row {
    scene: String,
    primitives: usize,
    knob: String,
    value: String,
    width: u32,
    height: u32,
    ways: u32,
    recursion: u32,
    bsp_max_depth: u32,
    bsp_max_leaf: usize,
    split: String,
    newton_steps: u32,
    table_entries: u32,
    guard_bits: u32,
    ray_offset_lsb: i32,
    /// `fine` or `coarse` (`render --normals`).
    normals: String,
    /// RC datapath width: 16 (the paper's chip) or 32.
    datapath_bits: u32,
    format: String,
    cycles: u64,
    fps_at_300mhz: f64,
    /// What the configuration's silicon costs (`morphosys cost`): the
    /// clock its RC's path depth allows (300 MHz for the 16-bit RC), the
    /// frame rate at that clock, the transistors of the array's 64 RCs
    /// with their RAM, and frames/s per million of those transistors at
    /// the estimated clock.
    clock_mhz_estimate: f64,
    fps_at_estimated_clock: f64,
    array_transistors: u64,
    fps_per_m_transistors: f64,
    psnr_db: f64,
    hit_agreement: f64,
    active_rc_fraction: f64,
    objects_tested_per_ray: f64,
    /// Ray-object tests the RCs executed per ray traced, and the share of
    /// cycles the array waited for TinyRISC.
    ray_tests_per_ray: f64,
    array_idle_on_control: f64,
    /// The object tests whose ray needed them over every test broadcast
    /// times the rays of its pass, and the share of cycles TinyRISC waits
    /// for the DMA.
    simd_efficiency: f64,
    dma_stall_share: f64,
    /// The BSP traversal (paper or packet) and the tree built (the split
    /// rule and depth limit it chose).
    traversal: String,
    bsp_split: String,
    bsp_depth_limit: u32,
    /// The chip's issue model (run or instruction) and timing ("default",
    /// "M1 issue" or a timing file's name).
    issue: String,
    timing: String,
    /// Node layout (fig5 or compact), whether the scene was resident in
    /// FB set 0 or streamed, and the FB words the resident image needs
    /// (all, and the BSP nodes alone) with that layout.
    layout: String,
    fb_layout: String,
    resident_fb_words: u64,
    resident_node_words: u64,
}

/// The knob sweep's points (every knob on the default timing), for the
/// render options' round-trip test.
#[cfg(test)]
pub(crate) fn knob_points(width: u32, height: u32) -> Vec<(Options, Numerics)> {
    knobs::knobs(width, height)
        .into_iter()
        .map(|k| (k.opt, k.nm))
        .collect()
}

fn key(o: &Options, n: &Numerics) -> String {
    format!(
        "{}x{} w{} d{} bd{} bl{} {:?} {:?} {} {} {} {} {} {}",
        o.width,
        o.height,
        o.ways,
        o.depth,
        o.bsp.max_depth,
        o.bsp.max_leaf,
        o.bsp.rule,
        n,
        o.layout,
        o.datapath,
        o.traversal,
        o.collapse,
        o.pieces,
        o.shadows
    )
}

/// A scene of the sweep: its name in the table (the file as given, or
/// the generated file's name), its object count, the file a planned render
/// reads, and for the size sweep its SPD family and size.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
struct SceneRef {
    name: String,
    primitives: usize,
    file: PathBuf,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    family: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    size: Option<u32>,
}

/// One row of the sweep to measure: a scene under a configuration, and the
/// render that measures it (configurations equal on a scene, such as the
/// paper's and `newton_steps=2`, share one).
struct Point {
    scene: usize,
    cfg: Config,
    job: usize,
}

/// One distinct render of the sweep: its name (that of its first point;
/// the plan's `points/NAME.json`) and its first point.
struct Job {
    name: String,
    point: usize,
}

/// Every point of the sweep in the order of the table (the knob sweep on
/// each scene, then the size sweep), and the distinct renders they need.
fn points(scenes: &[SceneRef], cfgs: &[Config], family_size: (u32, u32)) -> (Vec<Point>, Vec<Job>) {
    let mut pts = Vec::new();
    for (i, sc) in scenes.iter().enumerate() {
        if sc.family.is_none() {
            for c in cfgs {
                pts.push((i, c.clone()));
            }
        }
    }
    let nm = Numerics::default();
    for (i, sc) in scenes.iter().enumerate() {
        let Some(size) = sc.size.filter(|_| sc.family.is_some()) else {
            continue;
        };
        let (w, h) = family_size;
        for traversal in Traversal::ALL {
            let opt = match traversal {
                Traversal::Paper => paper_config(w, h),
                Traversal::Packet => packet_config(w, h),
            };
            pts.push((
                i,
                Config::from(Knob {
                    knob: SCENE_SIZE,
                    value: size.to_string(),
                    opt,
                    nm,
                }),
            ));
        }
    }
    let mut jobs: Vec<Job> = Vec::new();
    let mut by_key: BTreeMap<String, usize> = BTreeMap::new();
    let mut names: std::collections::BTreeSet<String> = Default::default();
    let points = pts
        .into_iter()
        .enumerate()
        .map(|(n, (scene, cfg))| {
            let k = format!("{scene} {} {}", key(&cfg.opt, &cfg.nm), cfg.timing_name);
            let job = *by_key.entry(k).or_insert_with(|| {
                let stem = short(&scenes[scene].name);
                let what = if cfg.knob == SCENE_SIZE {
                    cfg.opt.traversal.name().to_string()
                } else if cfg.knob == cfg.value {
                    cfg.knob.to_string()
                } else if matches!(cfg.knob, "broadcast" | "timing") {
                    // Both traversals under one timing.
                    format!("{}-{}-{}", cfg.knob, cfg.value, cfg.opt.traversal.name())
                } else {
                    format!("{}-{}", cfg.knob, cfg.value)
                };
                let base: String = format!("{stem}-{what}")
                    .chars()
                    .map(|c| {
                        if c.is_ascii_alphanumeric() || "._-".contains(c) {
                            c
                        } else {
                            '-'
                        }
                    })
                    .collect();
                let mut name = base.clone();
                let mut k = 2;
                while names.contains(&name) {
                    name = format!("{base}-{k}");
                    k += 1;
                }
                names.insert(name.clone());
                jobs.push(Job { name, point: n });
                jobs.len() - 1
            });
            Point { scene, cfg, job }
        })
        .collect();
    (points, jobs)
}

/// The table row of `p`, from its render's JSON.
fn point_row(scenes: &[SceneRef], p: &Point, j: &serde_json::Value) -> Row {
    let sc = &scenes[p.scene];
    let mut r = row(&sc.name, sc.primitives, &p.cfg, j);
    r.issue = p.cfg.timing.risc.issue.name().into();
    r.timing = p.cfg.timing_name.clone();
    r
}

fn row(scene: &str, primitives: usize, c: &Config, j: &serde_json::Value) -> Row {
    let (opt, nm) = (&c.opt, &c.nm);
    let f = |n: &str| j[n].as_f64().unwrap_or(f64::NAN);
    let s = |n: &str| j[n].as_str().unwrap_or("?").to_string();
    let cost = crate::cost::Synthesis::committed();
    // The chip's clock and frame rate as the render gave them (a timing
    // file's clock where it set one), else from the synthesis.
    let clock = j["clock_mhz"]
        .as_f64()
        .unwrap_or_else(|| cost.clock_mhz(opt.datapath));
    let fps_at_clock = j["fps"]
        .as_f64()
        .unwrap_or_else(|| f("fps_at_300mhz") * clock / crate::cost::CLOCK_MHZ_16);
    let array = cost.array_transistors(opt.datapath);
    Row {
        scene: scene.into(),
        primitives,
        knob: c.knob.into(),
        value: c.value.clone(),
        width: opt.width,
        height: opt.height,
        ways: opt.ways,
        recursion: opt.depth,
        bsp_max_depth: opt.bsp.max_depth,
        bsp_max_leaf: opt.bsp.max_leaf,
        split: format!("{:?}", opt.bsp.rule).to_lowercase(),
        newton_steps: nm.newton_steps,
        table_entries: nm.table_entries,
        guard_bits: nm.guard_bits,
        ray_offset_lsb: nm.eps_lsb,
        normals: if nm.normals.fine_on(opt.datapath) {
            "fine"
        } else {
            "coarse"
        }
        .into(),
        datapath_bits: opt.datapath.bits(),
        format: s("format"),
        cycles: j["cycles"].as_u64().unwrap_or(0),
        fps_at_300mhz: f("fps_at_300mhz"),
        clock_mhz_estimate: clock,
        fps_at_estimated_clock: fps_at_clock,
        array_transistors: array,
        fps_per_m_transistors: fps_at_clock / (array as f64 / 1e6),
        psnr_db: f("psnr_db"),
        hit_agreement: f("hit_agreement"),
        active_rc_fraction: f("active_rc_fraction"),
        objects_tested_per_ray: f("objects_tested_per_ray"),
        ray_tests_per_ray: f("ray_tests_per_ray"),
        array_idle_on_control: f("array_idle_on_control"),
        simd_efficiency: f("simd_efficiency"),
        dma_stall_share: f("dma_stall_share"),
        traversal: opt.traversal.name().into(),
        bsp_split: s("bsp_split"),
        bsp_depth_limit: j["bsp_depth_limit"].as_u64().unwrap_or(0) as u32,
        issue: IssueModel::Run.name().into(),
        timing: "default".into(),
        layout: opt.layout.name().into(),
        fb_layout: s("fb_layout"),
        resident_fb_words: j["resident_fb_words"].as_u64().unwrap_or(0),
        resident_node_words: j["resident_node_words"].as_u64().unwrap_or(0),
    }
}

/// The timing files' names (their stems) and timings.
fn timing_files(paths: &[PathBuf]) -> Result<Vec<(String, Timing)>> {
    let names = timing_names(paths);
    let mut files = Vec::new();
    for (p, name) in paths.iter().zip(names) {
        files.push((name, crate::timing::load(p)?));
    }
    Ok(files)
}

/// The series' names of the timing files `paths`: each file's stem, or,
/// where that is not unique (two `t.toml` in different folders) or is a
/// built-in series' ("default", "M1 issue"), the path as given; every
/// name distinct. A control character (a newline would split a planned
/// job's line) becomes `_`.
fn timing_names(paths: &[PathBuf]) -> Vec<String> {
    let clean = |s: String| -> String {
        s.chars()
            .map(|c| if c.is_control() { '_' } else { c })
            .collect()
    };
    let stem = |p: &PathBuf| {
        clean(p.file_stem().map_or_else(
            || p.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        ))
    };
    let stems: Vec<String> = paths.iter().map(stem).collect();
    let mut names: Vec<String> = Vec::new();
    for (p, s) in paths.iter().zip(&stems) {
        let shared = stems.iter().filter(|t| *t == s).count() > 1;
        let mut name = if shared || s == "default" || s == "M1 issue" {
            clean(p.display().to_string())
        } else {
            s.clone()
        };
        let base = name.clone();
        let mut k = 2;
        while names.contains(&name) || name == "default" || name == "M1 issue" {
            name = format!("{base} ({k})");
            k += 1;
        }
        names.push(name);
    }
    names
}

/// A timing file's copy in a plan (and its path in the jobs' arguments):
/// numbered, so that two files of one name stay two.
fn timing_copy_name(i: usize, name: &str) -> String {
    format!(
        "{i:02}-{}.toml",
        plain_file_name(name.trim_end_matches(".toml"))
    )
}

/// The configurations asked: every knob (or, with `--only broadcast`, the
/// issue-model comparison), under the timing files too.
fn asked_configs(
    size: (u32, u32),
    broadcast_only: bool,
    files: &[(String, Timing)],
) -> Vec<Config> {
    let mut cfgs = configs(size.0, size.1, files);
    if broadcast_only {
        cfgs.retain(|c| matches!(c.knob, "paper" | "traversal" | "broadcast" | "timing"));
    }
    cfgs
}

pub fn command(a: SweepArgs) -> Result<()> {
    let files = timing_files(&a.timing)?;
    let file_clocks = file_clocks(&a.timing)?;
    let cfgs = if a.knobs {
        asked_configs(a.size, a.broadcast_only, &files)
    } else {
        vec![]
    };
    let scenes = sweep_scenes(&a)?;
    let refs: Vec<SceneRef> = scenes.iter().map(|s| s.0.clone()).collect();
    let (pts, jobs) = points(&refs, &cfgs, a.family_size);
    if let Some(dir) = &a.plan {
        return write_plan(dir, &a, &files, scenes, &pts, &jobs);
    }
    // Every render's JSON is kept under OUT/points as it finishes: a sweep
    // that was interrupted resumes where it stopped (the JSON records the
    // render's arguments, so a changed configuration renders again).
    let points_dir = a.out_dir.join("points");
    std::fs::create_dir_all(&points_dir)
        .with_context(|| format!("cannot create {}", points_dir.display()))?;
    let resumed = std::sync::atomic::AtomicUsize::new(0);
    let mut rows: Vec<Row> = Vec::new();
    let skipped = std::sync::atomic::AtomicUsize::new(0);
    let count = |n: &std::sync::atomic::AtomicUsize| {
        n.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    };
    let bar = sweep_bar(pts.len());
    // The measured renders by job; a job that failed or was skipped is
    // None.
    let mut done: BTreeMap<usize, Option<serde_json::Value>> = BTreeMap::new();
    // One point's render: taken from an earlier run's JSON when its
    // arguments and inputs are the same, else rendered and its JSON kept.
    // `task` and `step` place it in the sweep's schedule (`a.work`).
    let measure = |p: &Point, task: usize, step: usize| -> Result<serde_json::Value> {
        let t0 = std::time::Instant::now();
        let (sc, scene) = &scenes[p.scene];
        let c = &p.cfg;
        let name = &jobs[p.job].name;
        let argv = render_argv(&a.out_dir, &sc.file, c, name);
        let json_path = points_dir.join(format!("{name}.json"));
        let host = crate::render::RenderSettings {
            numerics: c.nm,
            timing: c.timing,
            clock_given: c.timing_file.is_some_and(|i| file_clocks[i]),
            ..Default::default()
        };
        let inputs = crate::inputs::inputs(scene, &c.timing, None);
        let earlier = crate::render::render_json(&json_path, &argv, &inputs);
        if let Err(why) = &earlier {
            if why.starts_with("made before") {
                bar.suspend(|| eprintln!("{name}: {why}: rendering again"));
            }
        }
        if let Ok(j) = earlier {
            count(&resumed);
            return Ok(j);
        }
        crate::render::render(scene, &c.opt, &host).and_then(|(chip, mut rep)| {
            rep.json["argv"] = argv.clone().into();
            rep.json["inputs"] = inputs.clone();
            crate::output::write(
                &json_path,
                (serde_json::to_string_pretty(&rep.json)? + "\n").as_bytes(),
            )?;
            if let Some(w) = &a.work {
                let all = t0.elapsed().as_secs_f64();
                let prep = (all - chip.item_seconds.iter().sum::<f64>()).max(0.0);
                if let Ok(mut w) = w.lock() {
                    w.push(crate::schedule::RecordedRender {
                        task,
                        step,
                        prep,
                        frame: crate::schedule::FrameWork::of(&chip),
                    });
                }
            }
            Ok(rep.json)
        })
    };
    let mut per_job = vec![0u64; jobs.len()];
    for p in &pts {
        per_job[p.job] += 1;
    }
    let tasks = sweep_tasks(&jobs, &pts, &scenes);
    {
        use rayon::prelude::*;
        let measured: Vec<Vec<(usize, Option<serde_json::Value>)>> = tasks
            .par_iter()
            .enumerate()
            .map(|(task, chain)| {
                let run = ChainRun {
                    pts: &pts,
                    jobs: &jobs,
                    scenes: &scenes,
                    per_job: &per_job,
                    bar: &bar,
                    skipped: &skipped,
                    size_seconds: a.size_seconds,
                };
                run.chain(chain, task, &measure)
            })
            .collect();
        done.extend(measured.into_iter().flatten());
    }
    for p in &pts {
        if let Some(Some(j)) = done.get(&p.job) {
            rows.push(point_row(&refs, p, j));
        }
    }
    bar.finish_and_clear();
    report_counts(resumed.into_inner(), skipped.into_inner(), &points_dir);
    if rows.is_empty() {
        anyhow::bail!("no configuration of the sweep could be rendered (see above)");
    }
    write_results(&rows, &a.out_dir)
}

/// Which of the timing files `paths` set the clock (their points are
/// quoted at it, not at the chip's own).
fn file_clocks(paths: &[PathBuf]) -> Result<Vec<bool>> {
    paths
        .iter()
        .map(|p| Ok(crate::timing::load_file(p)?.1))
        .collect()
}

/// The sweep's progress bar over `n` renders.
fn sweep_bar(n: usize) -> indicatif::ProgressBar {
    let bar = crate::output::progress_bar(n as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("sweep [{bar:40}] {pos}/{len} renders {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar
}

/// What the sweep took from an earlier run and what it skipped.
fn report_counts(resumed: usize, skipped: usize, points_dir: &Path) {
    if resumed > 0 {
        eprintln!(
            "{resumed} renders taken from an earlier run ({}/NAME.json, same arguments)",
            points_dir.display()
        );
    }
    if skipped > 0 {
        eprintln!("{skipped} configurations skipped (see above)");
    }
}

/// The sweep's scenes, loaded (or generated) up front: a bad one stops the
/// sweep before any render.
fn sweep_scenes(a: &SweepArgs) -> Result<Vec<(SceneRef, firmware::scene::Scene)>> {
    let mut scenes: Vec<(SceneRef, firmware::scene::Scene)> = Vec::new();
    if a.knobs {
        let asked: Vec<Option<&Path>> = if a.scenes.is_empty() {
            vec![None]
        } else {
            a.scenes.iter().map(|p| Some(p.as_path())).collect()
        };
        for p in asked {
            let scene = load_scene(p)?;
            let file = p.map_or_else(crate::cmd_scene::default_scene, Path::to_path_buf);
            scenes.push((
                SceneRef {
                    name: scene.source.clone(),
                    primitives: scene.objects.len(),
                    file,
                    family: None,
                    size: None,
                },
                scene,
            ));
        }
    }
    for f in &a.families {
        firmware::scene::spd::default_size(f).map_err(|e| anyhow::anyhow!("--families: {e}"))?;
        for size in 1..=a.max_size {
            let s = firmware::scene::spd::scene(f, size)
                .map_err(|e| anyhow::anyhow!("--max-size {}: {}", a.max_size, e.message))?;
            scenes.push((
                SceneRef {
                    name: s.source.clone(),
                    primitives: s.objects.len(),
                    file: PathBuf::from(&s.source),
                    family: Some(f.clone()),
                    size: Some(size),
                },
                s,
            ));
        }
    }
    Ok(scenes)
}

/// Write `results.csv` and the charts into `dir`.
fn write_results(rows: &[Row], dir: &Path) -> Result<()> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r)?;
    }
    let csv_path = dir.join("results.csv");
    crate::output::write(&csv_path, &w.into_inner().context("csv")?)?;
    crate::note!("wrote {}", csv_path.display());
    for p in charts_for(rows, dir)? {
        crate::note!("wrote {}", p.display());
    }
    Ok(())
}

// ---------------------------------------------------------------------------
// Plans: the sweep as independent jobs, and their merge
