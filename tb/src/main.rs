//! `morphosys`: testbenches, runs and renders on the simulated MorphoSys.
//!
//! Every subcommand lives in its own module of the `tb` library; this file
//! only parses arguments and reports errors as one line with a non-zero exit.

use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "morphosys",
    version,
    about = "Cycle-level model of the MorphoSys reconfigurable SIMD processor and its BSP ray tracer",
    after_help = "Environment: RAYON_NUM_THREADS=N sets the host threads (default: every core, \
at most 8 per core; the outputs are the same on any number); MORPHOSYS_SIMD=portable|avx2|avx512 forces the \
instruction set of the simulator's per-cycle path (default: the widest the CPU has; the \
same bits on every path).",
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
    Asm(tb::cmd_asm::AsmArgs),
    /// Run a program (assembly source or image) on the chip to its halt and
    /// print the cycles used.
    Run(tb::cmd_run::RunArgs),
    /// Write docs/results.md (and the README's results table) from renders
    /// of the current build; run from the repository's root.
    Report(tb::cmd_report::ReportArgs),
    /// Measure the simulator: array cycles per host second with tracing off
    /// and on, the speed-up on every core, and what 16 and 64 cores would
    /// give (the schedule model).
    Bench(tb::cmd_bench::BenchArgs),
    /// Render scenes under many configurations (ways, recursion, BSP depth,
    /// leaf size, split rule, datapath) and chart frame rate against image
    /// quality, also with the silicon's cost on the speed axis (frames/s
    /// at each datapath's estimated clock per million array transistors,
    /// from `morphosys cost`; results.csv: clock_mhz_estimate,
    /// array_transistors, fps_per_m_transistors).
    Sweep(tb::cmd_sweep::SweepCli),
    /// Print a shell completion script: `morphosys completions bash >
    /// ~/.local/share/bash-completion/completions/morphosys` (zsh: into a
    /// folder of $fpath as `_morphosys`; fish: ~/.config/fish/completions/).
    Completions {
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the chip's default timing as a TOML file, every field with
    /// where its value comes from; edit a copy and pass it with --timing.
    Timing(tb::timing::TimingArgs),
    /// Fuzz the scene parsers, the assembler and the program loader with
    /// mutated and random inputs; any panic or unlocated error is a finding.
    Fuzz(tb::cmd_fuzz::FuzzArgs),
    /// What the RC costs in silicon: the Verilog RC (rtl/verilog/)
    /// synthesized by Yosys per unit at 16 and 32 bits: cells, transistors,
    /// path depth, the array's area and a clock estimate (from the
    /// committed results; --synthesize runs Yosys).
    Cost(tb::cost::CostArgs),
    /// Run a testbench: drive a block of the chip, check it against a
    /// reference model, write its waveform.
    Tb {
        #[command(subcommand)]
        bench: Bench,
    },
    /// Render a scene with the float reference renderer (the golden model):
    /// Whitted ray tracing in f64, written as PNG.
    Reference(tb::cmd_scene::ReferenceArgs),
    /// Compile a scene into the chip's fixed-point memory image (BSP in the
    /// paper's Fig. 5 layout) and report format, errors and footprint.
    Compile(tb::cmd_scene::CompileArgs),
    /// Render a scene with the paper's BSP ray tracer on the simulated chip;
    /// report frames/s at 300 MHz and the error against the reference.
    Render(tb::cmd_render::RenderArgs),
    /// Compare two images: PSNR over 8-bit RGB, share of pixels off by more
    /// than a threshold, and (with --hits) per-pixel hit agreement.
    Compare(tb::cmd_scene::CompareArgs),
    /// Estimate what regrouping rays into other packets would buy: the
    /// object tests of the chip's packets (a tile, a light) against rays
    /// split into quadrants or regrouped over tiles and sorted, and the
    /// simd efficiency of each grouping, from the f64 reference's rays on
    /// a SAH tree (docs/tracer.md, "Regrouping").
    Regroup(tb::cmd_regroup::RegroupArgs),
    /// Generate one of Eric Haines' Standard Procedural Databases in NFF
    /// (balls, gears, jacks, lattice, mount, rings, shells, tetra, tree).
    Spd(tb::cmd_spd::SpdArgs),
}

#[derive(Subcommand)]
enum Bench {
    /// One Reconfigurable Cell: every ALU, shifter, multiplier, register-file
    /// and RAM operation, checked against an independent reference model.
    Rc(tb::testbench::rc::RcArgs),
    /// The RC in Verilog (rtl/verilog/) against the Rust RC, cycle for
    /// cycle under Verilator: the RC testbench's stream and random context
    /// streams, both widths; the first difference is printed with the cycle,
    /// the context and both states.
    Cosim(tb::testbench::cosim::CosimArgs),
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Asm(a) => tb::cmd_asm::run(a),
        Command::Run(a) => tb::cmd_run::command(a),
        Command::Report(a) => tb::cmd_report::command(a),
        Command::Bench(a) => tb::cmd_bench::command(a),
        Command::Sweep(a) => tb::cmd_sweep::run(a),
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
        Command::Timing(a) => tb::timing::command(a),
        Command::Fuzz(a) => tb::cmd_fuzz::run(a),
        Command::Cost(a) => tb::cost::command(a),
        Command::Tb { bench } => match bench {
            Bench::Rc(a) => tb::testbench::rc::command(a.vcd, a.window, a.json),
            Bench::Cosim(a) => tb::testbench::cosim::command(a),
        },
        Command::Reference(a) => tb::cmd_scene::reference(a),
        Command::Compile(a) => tb::cmd_scene::compile_cmd(a),
        Command::Render(a) => tb::cmd_render::command(tb::cmd_render::RenderArgs {
            argv: std::env::args().skip(1).collect(),
            ..a
        }),
        Command::Compare(a) => tb::cmd_scene::compare_cmd(a),
        Command::Spd(a) => tb::cmd_spd::run(a),
        Command::Regroup(a) => tb::cmd_regroup::command(a),
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
    // The instruction set of the per-cycle path: checked before any work.
    if let Err(e) = rtl::simd::Simd::from_env().and_then(rtl::simd::set) {
        eprintln!("morphosys: error: {}", printable(&e));
        return ExitCode::from(2);
    }
    // The host threads, checked alike.
    match host_threads() {
        Ok(Some(note)) if !cli.quiet => eprintln!("morphosys: {}", printable(&note)),
        Ok(_) => {}
        Err(e) => {
            eprintln!("morphosys: error: {}", printable(&e));
            return ExitCode::from(2);
        }
    }
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

/// `RAYON_NUM_THREADS`, checked as `MORPHOSYS_SIMD` is: a count of host
/// threads (0: every core), at most [`THREADS_PER_CORE`] per core (more
/// only slow the work, with the same results; issue 62 reported 1,000
/// threads 60 times slower than 2 on a small render). The global pool is started with it;
/// `Some` says where the count was capped.
fn host_threads() -> Result<Option<String>, String> {
    let Some(v) = std::env::var_os("RAYON_NUM_THREADS") else {
        return Ok(None);
    };
    let s = v.to_string_lossy();
    let n: usize = s.trim().parse().map_err(|_| {
        format!("RAYON_NUM_THREADS={s}: not a number of host threads (0 or unset: every core)")
    })?;
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let cap = THREADS_PER_CORE * cores;
    let (threads, note) = match n > cap {
        true => (
            cap,
            Some(format!(
                "RAYON_NUM_THREADS={n}: {cap} host threads ({THREADS_PER_CORE} per core of {cores}; more only slow the work)"
            )),
        ),
        false => (n, None),
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()
        .map_err(|e| format!("cannot start {threads} host threads: {e}"))?;
    Ok(note)
}

/// The most host threads per core `RAYON_NUM_THREADS` gets.
const THREADS_PER_CORE: usize = 8;

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
