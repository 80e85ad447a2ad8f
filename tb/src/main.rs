//! `morphosys`: testbenches, runs and renders on the simulated MorphoSys.
//!
//! Every subcommand lives in its own module of the `tb` library; this file
//! only parses arguments and reports errors as one line with a non-zero exit.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

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
}

#[derive(Subcommand)]
enum Command {
    /// Run a testbench: drive a block of the chip, check it against a
    /// reference model, write its waveform.
    Tb {
        #[command(subcommand)]
        bench: Bench,
    },
}

#[derive(Subcommand)]
enum Bench {
    /// One Reconfigurable Cell: every ALU, shifter, multiplier, register-file
    /// and RAM operation, checked against an independent reference model.
    Rc {
        /// Write the waveform here (a GTKWave `.gtkw` save file and the
        /// translate filters go beside it).
        #[arg(long, value_name = "PATH")]
        vcd: Option<PathBuf>,
        #[command(flatten)]
        window: tb::cli::TraceWindow,
    },
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Tb { bench } => match bench {
            Bench::Rc { vcd, window } => tb::testbench::rc::command(vcd, window),
        },
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("morphosys: error: {e:#}");
            ExitCode::FAILURE
        }
    }
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
    let first = text
        .lines()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("bad arguments")
        .trim_start_matches("error: ");
    let tip = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("tip: "))
        .map(|t| format!("; {t}"))
        .unwrap_or_default();
    eprintln!("morphosys: error: {first}{tip} (see `morphosys --help`)");
    ExitCode::from(2)
}
