//! `morphosys`: testbenches, runs and renders on the simulated MorphoSys.
//!
//! Every subcommand lives in its own module of the `tb` library; this file
//! only parses arguments and reports errors as one line with a non-zero exit.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "morphosys",
    version,
    about = "Cycle-level model of the MorphoSys reconfigurable SIMD processor and its BSP ray tracer",
    propagate_version = true
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// No progress bars and no "wrote FILE" lines (figures, warnings and
    /// errors still print).
    #[arg(long, short, global = true)]
    quiet: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Assemble TinyRISC code and RC contexts; with -o write the image,
    /// without print the listing.
    Asm {
        file: PathBuf,
        /// Write the assembled image here.
        #[arg(short, long, value_name = "FILE.img")]
        out: Option<PathBuf>,
    },
    /// Run a program (assembly source or image) on the chip to its halt and
    /// print the cycles used.
    Run {
        file: PathBuf,
        /// Stop with an error after this many cycles.
        #[arg(long, value_name = "N", default_value_t = 100_000_000)]
        max_cycles: u64,
        /// Write the waveform here: VCD, or FST where the path ends in `.fst`
        /// (GTKWave save file and filters beside it).
        #[arg(long, value_name = "PATH")]
        vcd: Option<PathBuf>,
        #[command(flatten)]
        window: tb::cli::TraceWindow,
        /// RC datapath width in bits: 16 (the paper's chip) or 32 (default:
        /// the source's `.datapath`, else 16).
        #[arg(long, value_name = "16|32", value_parser = tb::cli::parse_datapath)]
        datapath: Option<rtl::rc::Datapath>,
        /// The chip's timing from a TOML file (any subset of the fields
        /// `morphosys timing` prints; the rest keep their defaults).
        #[arg(long, value_name = "FILE.toml")]
        timing: Option<PathBuf>,
        /// After the halt, TinyRISC register REG must hold VALUE (e.g.
        /// `r3=38`, `r1=0x1`); repeatable. Any mismatch exits 1. Without
        /// it, a halt with r1 = 0xBAD (the conformance programs' failure
        /// code, docs/isa.md) exits 1.
        #[arg(long, value_name = "REG=VALUE", value_parser = tb::cmd_run::parse_expect)]
        expect: Vec<(u8, u32)>,
        /// Write the cycles, the registers (decimal and hex) and the
        /// statistics as JSON here.
        #[arg(long, value_name = "PATH")]
        json: Option<PathBuf>,
    },
    /// Write docs/results.md (and the README's results table) from renders
    /// of the current build; run from the repository's root.
    Report(tb::cmd_report::ReportArgs),
    /// Measure the simulator: array cycles per host second with tracing off
    /// and on, and the speed-up on every core.
    Bench {
        /// Scene file (.nff or .toml); default scenes/default.toml.
        scene: Option<PathBuf>,
        /// Image size of the throughput workload (each side 1..=4096).
        #[arg(long, value_name = "WxH", value_parser = tb::cmd_scene::parse_size, default_value = "128x128")]
        size: (u32, u32),
        /// Runs per configuration; the fastest counts.
        #[arg(long, value_name = "N", default_value_t = 3, value_parser = tb::cli::parse_count::<u32>)]
        repeat: u32,
        /// Write the figures as JSON here.
        #[arg(long, value_name = "PATH")]
        json: Option<PathBuf>,
        /// The chip's timing from a TOML file (`morphosys timing`).
        #[arg(long, value_name = "FILE.toml")]
        timing: Option<PathBuf>,
    },
    /// Render scenes under many configurations (ways, recursion, BSP depth,
    /// leaf size, split rule) and chart frame rate against image quality.
    Sweep {
        /// Scene files (default: scenes/default.toml).
        scenes: Vec<PathBuf>,
        /// Where results.csv and the charts go (with --merge: default the
        /// plan's folder).
        #[arg(long, value_name = "DIR", required_unless_present_any = ["plan", "merge"])]
        out_dir: Option<PathBuf>,
        /// Render nothing: write DIR/jobs.txt, one self-contained `morphosys
        /// render ... --json DIR/points/NAME.json` per distinct render of the
        /// sweep (for GNU parallel or a Slurm job array; a rerun skips the
        /// renders already done), and DIR/sweep.toml, what was asked. Every
        /// size of the size sweep is planned (--size-seconds does not apply).
        #[arg(long, value_name = "PLAN", conflicts_with_all = ["out_dir", "size_seconds", "merge"])]
        plan: Option<PathBuf>,
        /// Merge a plan's renders: results.csv and the charts, as the sweep
        /// run here would write them; missing or failed renders are named
        /// and left out.
        #[arg(long, value_name = "PLAN", conflicts_with_all = ["scenes", "size", "only", "families", "max_size", "family_size", "size_seconds", "timing"])]
        merge: Option<PathBuf>,
        /// Image size (each side 1..=4096).
        #[arg(long, value_name = "WxH", value_parser = tb::cmd_scene::parse_size, default_value = "256x256")]
        size: (u32, u32),
        /// Run only one part: `knobs` (every knob on SCENES), `sizes` (the
        /// SPD families at sizes 1..=--max-size, both traversals) or
        /// `broadcast` (both traversals on SCENES under both issue models).
        #[arg(long, value_name = "knobs|sizes|broadcast", value_parser = ["knobs", "sizes", "broadcast"])]
        only: Option<String>,
        /// SPD generators of the size sweep, comma-separated.
        #[arg(
            long,
            value_name = "NAMES",
            value_delimiter = ',',
            default_value = "balls,tetra,rings,gears,lattice",
            value_parser = clap::builder::PossibleValuesParser::new(firmware::scene::spd::names())
        )]
        families: Vec<String>,
        /// Largest SPD size factor of the size sweep.
        #[arg(long, value_name = "N", default_value_t = 4, value_parser = tb::cli::parse_count::<u32>)]
        max_size: u32,
        /// Image size of the size sweep (streamed scenes of thousands of
        /// objects take minutes of host time at 256x256).
        #[arg(long, value_name = "WxH", value_parser = tb::cmd_scene::parse_size, default_value = "64x64")]
        family_size: (u32, u32),
        /// Skip a family's larger sizes (with a traversal) once one of its
        /// renders took longer than this many host seconds.
        #[arg(long, value_name = "SECONDS", default_value_t = 60.0, value_parser = tb::cli::parse_seconds)]
        size_seconds: f64,
        /// Timing files: the paper's configuration and the packet
        /// traversal on each scene under each (the `timing` knob, one
        /// series each in timing.png).
        #[arg(long, value_name = "FILE.toml", num_args = 1..)]
        timing: Vec<PathBuf>,
    },
    /// Print a shell completion script: `morphosys completions bash >
    /// ~/.local/share/bash-completion/completions/morphosys` (zsh: into a
    /// folder of $fpath as `_morphosys`; fish: ~/.config/fish/completions/).
    Completions {
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the chip's default timing as a TOML file, every field with
    /// where its value comes from; edit a copy and pass it with --timing.
    Timing {
        /// Write it here instead of standard output.
        #[arg(long, value_name = "FILE.toml")]
        out: Option<PathBuf>,
        /// The issue model: `run` (ours, the default) or `instruction` (the
        /// M1 chip's: TinyRISC issues each context by an instruction).
        #[arg(long, value_name = "run|instruction", value_parser = clap::builder::PossibleValuesParser::new(["run", "instruction"]))]
        issue: Option<String>,
    },
    /// Fuzz the scene parsers, the assembler and the program loader with
    /// mutated and random inputs; any panic or unlocated error is a finding.
    Fuzz {
        /// Targets (default: all).
        #[arg(value_enum)]
        targets: Vec<tb::fuzz::Target>,
        /// Inputs per target.
        #[arg(long, value_name = "N", default_value_t = 100_000, value_parser = tb::cli::parse_count::<u64>)]
        count: u64,
        /// Random seed (runs are reproducible).
        #[arg(long, value_name = "N", default_value_t = 1)]
        seed: u64,
        /// Save the inputs of findings under DIR/<target>/.
        #[arg(long, value_name = "DIR")]
        save: Option<PathBuf>,
        /// Write the figures per target (inputs, accepted, rejected,
        /// findings, inputs per second, slowest input) as JSON here.
        #[arg(long, value_name = "PATH")]
        json: Option<PathBuf>,
    },
    /// Run a testbench: drive a block of the chip, check it against a
    /// reference model, write its waveform.
    Tb {
        #[command(subcommand)]
        bench: Bench,
    },
    /// Render a scene with the float reference renderer (the golden model):
    /// Whitted ray tracing in f64, written as PNG.
    Reference {
        /// Scene file (.nff or .toml); default scenes/default.toml.
        scene: Option<PathBuf>,
        /// Image size WIDTHxHEIGHT, each side 1..=4096 (default: the scene's resolution).
        #[arg(long, value_name = "WxH", value_parser = tb::cmd_scene::parse_size)]
        size: Option<(u32, u32)>,
        /// Maximum ray depth 1..=8; the eye ray is depth 1 (default 2, the
        /// paper's recursion level, as `render` and `sweep`, so their images
        /// compare as they are; `--spd-stats`: 5, the SPD's).
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=firmware::tracer::MAX_RAY_DEPTH as i64))]
        depth: Option<u32>,
        /// Write the image here (default: <scene>-reference.png).
        #[arg(long, value_name = "PNG")]
        out: Option<PathBuf>,
        /// Write ray counts and timing as JSON here.
        #[arg(long, value_name = "PATH")]
        json: Option<PathBuf>,
        /// Write the per-pixel hit map (which object each eye ray hit) here.
        #[arg(long, value_name = "PATH")]
        hits: Option<PathBuf>,
        /// Count rays as the SPD prescribes: 512x512, rays through pixel
        /// corners (513x513 eye rays), depth 5.
        #[arg(long)]
        spd_stats: bool,
    },
    /// Compile a scene into the chip's fixed-point memory image (BSP in the
    /// paper's Fig. 5 layout) and report format, errors and footprint.
    Compile {
        /// Scene file (.nff or .toml); default scenes/default.toml.
        scene: Option<PathBuf>,
        /// Write the report as JSON here.
        #[arg(long, value_name = "PATH")]
        json: Option<PathBuf>,
        /// Write the memory image (16-bit little-endian words) here.
        #[arg(long, value_name = "FILE.img")]
        out: Option<PathBuf>,
        /// BSP split rule: median (the paper's spatial median, axes in turn)
        /// or sah (surface area heuristic); `--sah` is short for `--split sah`.
        #[arg(long, value_name = "median|sah", default_value = "median", value_parser = ["median", "sah"])]
        split: String,
        #[arg(long, hide = true)]
        sah: bool,
        /// Maximum BSP depth (1..=32).
        #[arg(long, value_name = "N", default_value_t = 15, value_parser = clap::value_parser!(u32).range(1..=firmware::scene_image::MAX_BSP_DEPTH as i64))]
        max_depth: u32,
        /// Maximum objects per BSP leaf.
        #[arg(long, value_name = "N", default_value_t = 5, value_parser = tb::cli::parse_count::<usize>)]
        max_leaf: usize,
        /// How BSP nodes name their objects: fig5 (the paper's bit
        /// vectors) or compact (index lists), as `render --layout`
        /// (default: the smaller).
        #[arg(long, value_name = "fig5|compact", value_parser = parse_layout)]
        layout: Option<firmware::tracer::NodeLayout>,
    },
    /// Render a scene with the paper's BSP ray tracer on the simulated chip;
    /// report frames/s at 300 MHz and the error against the reference.
    Render {
        /// Scene file (.nff or .toml); default scenes/default.toml.
        scene: Option<PathBuf>,
        /// Image size WIDTHxHEIGHT, each side 1..=4096 (default 256x256).
        #[arg(long, value_name = "WxH", value_parser = tb::cmd_scene::parse_size)]
        size: Option<(u32, u32)>,
        /// Rays traced in parallel: 4, 8, 16, 32 or 64.
        #[arg(long, value_name = "N", default_value_t = 64, value_parser = parse_ways)]
        ways: u32,
        /// Maximum ray depth 1..=8; the eye ray is depth 1 (default: the
        /// paper's recursion level 2; the SPD's is 5).
        #[arg(long, value_name = "N", default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=firmware::tracer::MAX_RAY_DEPTH as i64))]
        depth: u32,
        /// Write the image here (default: <scene>-chip.png).
        #[arg(long, value_name = "PNG")]
        out: Option<PathBuf>,
        /// Write the figures as JSON here.
        #[arg(long, value_name = "PATH")]
        json: Option<PathBuf>,
        /// Write the chip's hit map here (the object each pixel's eye ray
        /// hit), for `compare --hits` against `reference --hits`.
        #[arg(long, value_name = "PATH")]
        hits: Option<PathBuf>,
        /// Write the waveform of the first chip instance here: VCD, or FST
        /// where the path ends in `.fst` (GTKWave save file and filters
        /// beside it).
        #[arg(long, value_name = "PATH")]
        vcd: Option<PathBuf>,
        #[command(flatten)]
        window: tb::cli::TraceWindow,
        /// Write the generated firmware (assembly source) here.
        #[arg(long, value_name = "FILE.s")]
        emit_asm: Option<PathBuf>,
        /// Maximum BSP depth: a number (1..=32) or auto (the paper's 15 for
        /// the paper's traversal; for the packet traversal 15 for a median
        /// tree and 8 + 1.3 log2(objects) for an SAH tree).
        #[arg(long, value_name = "auto|N", default_value = "auto", value_parser = parse_depth)]
        max_depth: u32,
        /// Maximum objects per BSP leaf.
        #[arg(long, value_name = "N", default_value_t = 5, value_parser = tb::cli::parse_count::<usize>)]
        max_leaf: usize,
        /// BSP split rule: median (the paper's spatial median, axes in turn),
        /// sah (surface area heuristic) or auto (median for the paper's
        /// traversal; for the packet traversal the cheaper of the two trees
        /// by its cost model).
        #[arg(long, value_name = "auto|median|sah", default_value = "auto", value_parser = ["auto", "median", "sah"])]
        split: String,
        /// How BSP nodes name their objects: fig5 (the paper's bit vectors)
        /// or compact (index lists); the same image either way.
        #[arg(long, value_name = "fig5|compact", default_value = "fig5", value_parser = parse_layout)]
        layout: firmware::tracer::NodeLayout,
        /// BSP traversal: paper (the paper's: where the rays disagree, test
        /// every object under the node) or packet (per-ray intervals; a
        /// child is visited only by the rays that reach it).
        #[arg(long, value_name = "packet|paper", default_value = "packet", value_parser = parse_traversal)]
        traversal: firmware::tracer::Traversal,
        /// Packet traversal: which BSP subtrees to walk as one leaf of all
        /// their objects: auto (where that costs less than walking them, by
        /// the cells' surface areas and the kernels' lengths) or N (those
        /// with at most N objects; 0: none).
        #[arg(long, value_name = "auto|N", default_value = "auto", value_parser = parse_collapse)]
        collapse: firmware::tracer::Collapse,
        /// RC datapath width in bits: 16 (the paper's chip), 32 (the
        /// variant the paper announces; every format gets 16 more fraction
        /// bits), or auto: 16 unless the 16-bit chip cannot hold the scene or
        /// renders a probe of the frame (1/16 of the tiles) under 30 dB or
        /// 99% hit agreement against the reference where 32 bits do better.
        #[arg(long, value_name = "auto|16|32", value_parser = tb::cli::parse_datapath_choice, default_value = "auto")]
        datapath: tb::cli::DatapathChoice,
        /// Newton-Raphson steps after each reciprocal / square-root table
        /// lookup (0..=3).
        #[arg(long, value_name = "N", default_value_t = 2, value_parser = clap::value_parser!(u32).range(0..=3))]
        newton_steps: u32,
        /// Entries of the reciprocal and reciprocal square-root tables in
        /// every RC's RAM: 16, 32, 64 or 128.
        #[arg(long, value_name = "N", default_value_t = 128, value_parser = parse_table_entries)]
        table_entries: u32,
        /// Guard bits of the coordinate format above the scene's largest
        /// object or eye coordinate (2..=4; more: a coarser format).
        #[arg(long, value_name = "N", default_value_t = 2, value_parser = clap::value_parser!(u32).range(2..=4))]
        guard_bits: u32,
        /// Offset of spawned (shadow, reflected, refracted) rays along the
        /// normal, in LSBs of the coordinate format (0..=64).
        #[arg(long, value_name = "N", default_value_t = firmware::tracer::shading::EPS_LSB, value_parser = clap::value_parser!(i32).range(0..=64))]
        ray_offset_lsb: i32,
        /// Normals of spheres and cylinders: fine (the eye moved onto the
        /// coordinate format's grid with the whole scene, and the
        /// perpendicular vector formed from unrounded centres and axes and
        /// kept perpendicular to the ray: 9 more cycles per sphere test, 19
        /// per cylinder test), coarse (the kernels as first written, with
        /// which the comparison with the paper was made) or auto (fine on
        /// the 16-bit chip, coarse on the 32-bit one)
        #[arg(long, value_name = "auto|fine|coarse", default_value = "auto", value_parser = parse_normals)]
        normals: firmware::tracer::Normals,
        /// With --json: when that file already holds a complete render made
        /// with these same arguments from the same scene, timing file,
        /// firmware and build (their SHA-256 digests, `inputs` in the
        /// JSON), say so and stop without rendering (a rerun of a sweep
        /// plan's jobs runs only what is missing).
        #[arg(long, requires = "json")]
        skip_done: bool,
        /// Print (and put in the JSON) where the frame's cycles go: per RC kernel while the array works, per TinyRISC
        /// label while it waits (steps every cycle: several times slower).
        #[arg(long)]
        profile: bool,
        /// The chip's timing from a TOML file (any subset of the fields
        /// `morphosys timing` prints; the rest keep their defaults).
        #[arg(long, value_name = "FILE.toml")]
        timing: Option<PathBuf>,
        /// Render with the program assembled from this file (what
        /// `--emit-asm` writes, edited or not) instead of the generated
        /// one; the scene's data image is built as usual, with the same
        /// options the file was emitted with.
        #[arg(long, value_name = "FILE.s")]
        firmware: Option<PathBuf>,
    },
    /// Compare two images: PSNR over 8-bit RGB, share of pixels off by more
    /// than a threshold, and (with --hits) per-pixel hit agreement.
    Compare {
        a: PathBuf,
        b: PathBuf,
        /// A pixel is "off" when a channel differs by more than this.
        #[arg(long, value_name = "N", default_value_t = 8)]
        threshold: u8,
        /// Hit maps of A and B (from `reference --hits`).
        #[arg(long, num_args = 2, value_names = ["HITS_A", "HITS_B"])]
        hits: Option<Vec<PathBuf>>,
        /// Write the figures as JSON here.
        #[arg(long, value_name = "PATH")]
        json: Option<PathBuf>,
    },
    /// Generate one of Eric Haines' Standard Procedural Databases in NFF
    /// (balls, gears, jacks, lattice, mount, rings, shells, tetra, tree).
    Spd {
        #[arg(value_parser = clap::builder::PossibleValuesParser::new(firmware::scene::spd::names()))]
        name: String,
        /// SPD size factor (default: the SPD program's default).
        #[arg(long, value_name = "N", value_parser = tb::cli::parse_count::<u32>)]
        size: Option<u32>,
        /// Write the NFF here (default: stdout).
        #[arg(long, value_name = "FILE.nff")]
        out: Option<PathBuf>,
    },
}

#[derive(Subcommand)]
enum Bench {
    /// One Reconfigurable Cell: every ALU, shifter, multiplier, register-file
    /// and RAM operation, checked against an independent reference model.
    Rc {
        /// Write the waveform here: VCD, or FST where the path ends in
        /// `.fst` (a GTKWave `.gtkw` save file and the translate filters go
        /// beside it).
        #[arg(long, value_name = "PATH")]
        vcd: Option<PathBuf>,
        #[command(flatten)]
        window: tb::cli::TraceWindow,
        /// Write the result (cycles, contexts, values checked, mismatches)
        /// as JSON here.
        #[arg(long, value_name = "PATH")]
        json: Option<PathBuf>,
    },
}

/// `--table-entries`: the table sizes that fit a 128-word slot of an RC's RAM.
fn parse_table_entries(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n) if firmware::tracer::math::TABLE_SIZES.contains(&n) => Ok(n),
        _ => Err(format!(
            "expected 16, 32, 64 or 128 (each table has a 128-word slot of the RC's 512-word RAM), found '{s}'"
        )),
    }
}

fn parse_normals(s: &str) -> Result<firmware::tracer::Normals, String> {
    s.parse()
}

fn parse_layout(s: &str) -> Result<firmware::tracer::NodeLayout, String> {
    s.parse()
}

/// `--ways`: 4, 8, 16, 32 or 64 rays in flight (a tile of 2x2 .. 8x8).
fn parse_ways(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n @ (4 | 8 | 16 | 32 | 64)) => Ok(n),
        _ => Err(format!("expected 4, 8, 16, 32 or 64, found '{s}'")),
    }
}

fn parse_depth(s: &str) -> Result<u32, String> {
    if s == "auto" {
        return Ok(0);
    }
    match s.parse::<u32>() {
        Ok(d) if (1..=firmware::scene_image::MAX_BSP_DEPTH).contains(&d) => Ok(d),
        _ => Err(format!(
            "expected auto or a depth 1..={}",
            firmware::scene_image::MAX_BSP_DEPTH
        )),
    }
}

fn parse_collapse(s: &str) -> Result<firmware::tracer::Collapse, String> {
    s.parse()
}

fn parse_traversal(s: &str) -> Result<firmware::tracer::Traversal, String> {
    s.parse()
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Asm { file, out } => tb::cmd_asm::command(file, out),
        Command::Run {
            file,
            max_cycles,
            vcd,
            window,
            datapath,
            timing,
            expect,
            json,
        } => tb::cmd_run::command(tb::cmd_run::RunArgs {
            file,
            max_cycles,
            vcd,
            window,
            datapath,
            timing,
            expect,
            json,
        }),
        Command::Report(a) => tb::cmd_report::command(a),
        Command::Bench {
            scene,
            size,
            repeat,
            json,
            timing,
        } => tb::cmd_bench::command(tb::cmd_bench::BenchArgs {
            scene,
            size,
            repeat,
            json,
            timing,
        }),
        Command::Sweep {
            merge: Some(dir),
            out_dir,
            ..
        } => tb::cmd_sweep::merge(&dir, out_dir.as_deref().unwrap_or(&dir)),
        Command::Sweep {
            scenes,
            out_dir,
            plan,
            merge: None,
            size,
            only,
            families,
            max_size,
            family_size,
            size_seconds,
            timing,
        } => tb::cmd_sweep::command(tb::cmd_sweep::SweepArgs {
            scenes,
            out_dir: out_dir.unwrap_or_default(),
            plan,
            size,
            knobs: only.as_deref() != Some("sizes"),
            families: if only.is_some() && only.as_deref() != Some("sizes") {
                vec![]
            } else {
                families
            },
            broadcast_only: only.as_deref() == Some("broadcast"),
            max_size,
            family_size,
            size_seconds,
            timing,
        }),
        Command::Completions { shell } => {
            use clap::CommandFactory;
            let mut cmd = Cli::command();
            let mut text = Vec::new();
            clap_complete::generate(shell, &mut cmd, "morphosys", &mut text);
            use std::io::Write;
            let mut o = std::io::stdout().lock();
            o.write_all(&text)
                .and_then(|_| o.flush())
                .map_err(|e| anyhow::anyhow!("writing the completions to standard output: {e}"))
        }
        Command::Timing { out, issue } => {
            let mut t = rtl::Timing::default();
            if let Some(i) = issue {
                t.risc.issue = i
                    .parse()
                    .map_err(|e: String| anyhow::anyhow!("--issue: {e}"))?;
            }
            let text = tb::timing::to_toml(&t);
            match out {
                Some(p) => {
                    tb::output::Files::new().output(&p, "--out").check()?;
                    tb::cmd_scene::write_output(&p, text.as_bytes())?;
                    tb::note!("wrote {}", p.display());
                    Ok(())
                }
                None => {
                    use std::io::Write;
                    let mut o = std::io::stdout().lock();
                    o.write_all(text.as_bytes())
                        .and_then(|_| o.flush())
                        .map_err(|e| anyhow::anyhow!("writing the timing to standard output: {e}"))
                }
            }
        }
        Command::Fuzz {
            targets,
            count,
            seed,
            save,
            json,
        } => tb::cmd_fuzz::command(targets, count, seed, save, json),
        Command::Tb { bench } => match bench {
            Bench::Rc { vcd, window, json } => tb::testbench::rc::command(vcd, window, json),
        },
        Command::Reference {
            scene,
            size,
            depth,
            out,
            json,
            hits,
            spd_stats,
        } => tb::cmd_scene::reference(tb::cmd_scene::ReferenceArgs {
            scene,
            size,
            depth,
            out,
            json,
            hits,
            spd_stats,
        }),
        Command::Compile {
            scene,
            json,
            out,
            split,
            sah,
            max_depth,
            max_leaf,
            layout,
        } => {
            let sah = sah || split == "sah";
            let layout = layout.map(|l| match l {
                firmware::tracer::NodeLayout::Compact => firmware::scene_image::Layout::IndexLists,
                firmware::tracer::NodeLayout::Fig5 => firmware::scene_image::Layout::BitVectors,
            });
            tb::cmd_scene::compile_cmd(tb::cmd_scene::CompileArgs {
                scene,
                json,
                out,
                sah,
                max_depth,
                max_leaf,
                layout,
            })
        }
        Command::Render {
            scene,
            size,
            ways,
            depth,
            out,
            json,
            hits,
            vcd,
            window,
            emit_asm,
            max_depth,
            max_leaf,
            split,
            layout,
            traversal,
            collapse,
            datapath,
            newton_steps,
            table_entries,
            guard_bits,
            ray_offset_lsb,
            normals,
            skip_done,
            profile,
            timing,
            firmware,
        } => tb::cmd_render::command(tb::cmd_render::RenderArgs {
            scene,
            size,
            ways,
            depth,
            out,
            json,
            hits,
            vcd,
            window,
            emit_asm,
            max_depth,
            max_leaf,
            split,
            layout,
            traversal,
            collapse,
            datapath,
            newton_steps,
            table_entries,
            guard_bits,
            ray_offset_lsb,
            normals,
            skip_done,
            argv: std::env::args().skip(1).collect(),
            profile,
            timing,
            firmware,
        }),
        Command::Compare {
            a,
            b,
            threshold,
            hits,
            json,
        } => {
            let hits = hits.map(|h| (h[0].clone(), h[1].clone()));
            tb::cmd_scene::compare(&a, &b, threshold, hits, json)
        }
        Command::Spd { name, size, out } => tb::cmd_spd::command(&name, size, out),
    }
}

fn main() -> ExitCode {
    stdout_errors_are_errors();
    // Interrupted (SIGINT, SIGTERM, SIGHUP): no partial waveform, temporary
    // file or folder is left behind.
    let _ = ctrlc::set_handler(|| {
        tb::output::remove_temporaries();
        eprintln!("morphosys: interrupted; partial and temporary files removed");
        std::process::exit(130);
    });
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    tb::output::set_quiet(cli.quiet);
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        // A reader that went away (`morphosys spd balls | head`) ends the
        // command quietly, as it ends `cat` or `rg`.
        Err(e)
            if e.chain().any(|c| {
                c.downcast_ref::<std::io::Error>()
                    .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            }) =>
        {
            ExitCode::SUCCESS
        }
        Err(e) => match e.downcast_ref::<tb::cli::UsageError>() {
            Some(u) => {
                eprintln!(
                    "morphosys: error: {} (see `morphosys {} --help`)",
                    printable(&u.message),
                    u.command
                );
                ExitCode::from(2)
            }
            None => {
                eprintln!("morphosys: error: {}", printable(&format!("{e:#}")));
                ExitCode::FAILURE
            }
        },
    }
}

/// An error's text as the terminal should get it: a control character
/// from the input (an escape sequence, a NUL in a scene's token or a file
/// name) written as `U+001B`, as the assembler writes them; line breaks
/// and tabs of the message itself kept.
fn printable(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if c.is_control() && c != '\n' && c != '\t' {
            out.push_str(&format!("U+{:04X}", c as u32));
        } else {
            out.push(c);
        }
    }
    out
}

/// Standard output that cannot be written (a full disk) ends the command
/// with one error line and exit code 1, and a reader that went away ends it
/// quietly (exit 0), not a panic: `print!` panics on a write error, and this hook turns that panic
/// into the message (every other panic keeps the default report).
fn stdout_errors_are_errors() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let p = info.payload();
        let msg = p
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| p.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if let Some(why) = msg.strip_prefix("failed printing to stdout: ") {
            if why.contains("Broken pipe") {
                // The reader went away: end quietly, as `cat` does.
                std::process::exit(0);
            }
            eprintln!("morphosys: error: writing to standard output: {why}");
            std::process::exit(1);
        }
        default(info)
    }));
}

/// Help and version go to stdout as clap renders them; a usage error becomes
/// one line on stderr and exit code 2.
fn usage_error(e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind::*;
    if matches!(
        e.kind(),
        DisplayHelp | DisplayVersion | DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        let _ = e.print();
        return if e.kind() == DisplayHelpOnMissingArgumentOrSubcommand {
            ExitCode::from(2)
        } else {
            ExitCode::SUCCESS
        };
    }
    let text = e.render().to_string();
    let mut lines = text.lines().skip_while(|l| l.trim().is_empty());
    let mut first = lines
        .next()
        .unwrap_or("bad arguments")
        .trim_start_matches("error: ")
        .to_string();
    // "the following required arguments were not provided:" lists them on
    // the lines below: keep them on the one line.
    if first.ends_with(':') {
        let items: Vec<&str> = lines
            .take_while(|l| !l.trim().is_empty())
            .map(str::trim)
            .collect();
        first = format!("{} {}", first, items.join(", "));
    }
    let tip = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("tip: "))
        .map(|t| format!("; {t}"))
        .unwrap_or_default();
    // Point to the help of the subcommand at fault, where there is one.
    let args: Vec<String> = std::env::args().skip(1).collect();
    let command = Cli::command();
    let sub = args
        .iter()
        .find(|a| command.find_subcommand(a.as_str()).is_some())
        .map(|a| format!("{a} "))
        .unwrap_or_default();
    eprintln!(
        "morphosys: error: {} (see `morphosys {sub}--help`)",
        printable(&format!("{first}{tip}"))
    );
    ExitCode::from(2)
}
