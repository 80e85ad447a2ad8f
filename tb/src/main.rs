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
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("morphosys: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
