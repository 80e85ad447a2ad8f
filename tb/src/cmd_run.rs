//! `morphosys run FILE`: assemble (or load) a program, run it on the chip to
//! its `halt`, print the cycles used and the statistics.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context as _};
use firmware::asm::{self, Image};
use rtl::chip::{run_to_halt, RunError};
use rtl::rc::{Datapath, Word};
use rtl::{Chip, Sim, Stats, Timing};

use crate::cli::TraceWindow;

/// Assembly source, or an image written by `morphosys asm -o`.
pub fn load_program(path: &Path) -> anyhow::Result<Image> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    if Image::is_image(&bytes) {
        return Image::from_bytes(&bytes).map_err(|e| anyhow!("{}: {e}", path.display()));
    }
    let src = String::from_utf8(bytes).map_err(|_| {
        anyhow!(
            "{}: neither UTF-8 assembly source nor a morphosys image",
            path.display()
        )
    })?;
    let img = asm::assemble(&src, &path.display().to_string()).map_err(|e| anyhow!("{e}"))?;
    if img.segments.iter().all(|s| s.data.is_empty()) {
        return Err(anyhow!(
            "{}: empty program: no instructions or data to run",
            path.display()
        ));
    }
    Ok(img)
}

/// A finished (or stopped) run.
pub struct Outcome<W: Word = i16> {
    pub sim: Sim<Chip<W>>,
    /// `Ok(cycles)` at halt, or why it stopped.
    pub result: Result<u64, RunError>,
    pub files: Vec<PathBuf>,
}

impl<W: Word> Outcome<W> {
    pub fn stats(&self) -> Stats {
        self.sim.top.stats()
    }
    /// TinyRISC register `k`.
    pub fn reg(&self, k: u8) -> u32 {
        self.sim.top.risc.regs.read(k)
    }
}

pub const DEFAULT_MEMORY: usize = rtl::memory::DEFAULT_SIZE;

/// Load `img` into a fresh 16-bit chip and run it to halt.
pub fn run_image(
    img: &Image,
    timing: Timing,
    max_cycles: u64,
    trace: Option<rtl::trace::TraceConfig>,
) -> anyhow::Result<Outcome> {
    run_image_on(img, timing, max_cycles, trace)
}

/// Load `img` into a fresh chip of datapath `W` and run it to halt.
pub fn run_image_on<W: Word>(
    img: &Image,
    timing: Timing,
    max_cycles: u64,
    trace: Option<rtl::trace::TraceConfig>,
) -> anyhow::Result<Outcome<W>> {
    let mut chip = Chip::<W>::build(timing, DEFAULT_MEMORY);
    img.load(&mut chip).map_err(|f| anyhow!("{f}"))?;
    let mut sim = Sim::new(chip);
    if let Some(cfg) = trace {
        let path = cfg.path.clone();
        sim.trace(cfg, "morphosys")
            .with_context(|| format!("creating {}", path.display()))?;
    }
    let result = run_to_halt(&mut sim, max_cycles);
    let files = sim.finish_trace().context("writing the waveform")?;
    Ok(Outcome { sim, result, files })
}

pub fn print_stats(s: &Stats) {
    println!("cycles               {}", s.cycles);
    println!("tinyrisc issued      {}", s.risc_instructions);
    println!("array busy cycles    {}", s.array_busy_cycles);
    println!("active RC fraction   {:.3}", s.active_rc_fraction());
    println!("array stall cycles   {}", s.array_stall_cycles);
    println!("dma stall cycles     {}", s.dma_stall_cycles);
    println!(
        "dma busy cycles      {}  ({} transfers, {} words)",
        s.dma_busy_cycles, s.dma_transfers, s.dma_words
    );
}

pub fn command(
    file: PathBuf,
    max_cycles: u64,
    vcd: Option<PathBuf>,
    window: TraceWindow,
    datapath: Datapath,
    timing: Option<PathBuf>,
) -> anyhow::Result<()> {
    if let Some(v) = &vcd {
        let mut files = crate::output::Files::new();
        files.input(&file, "FILE");
        if let Some(t) = &timing {
            files.input(t, "--timing");
        }
        files.output(v, "--vcd").check()?;
    }
    let timing = crate::timing::load_or_default(timing.as_deref())?;
    match datapath {
        Datapath::W16 => command_on::<i16>(file, max_cycles, vcd, window, timing),
        Datapath::W32 => command_on::<i32>(file, max_cycles, vcd, window, timing),
    }
}

fn command_on<W: Word>(
    file: PathBuf,
    max_cycles: u64,
    vcd: Option<PathBuf>,
    window: TraceWindow,
    timing: Timing,
) -> anyhow::Result<()> {
    let img = load_program(&file)?;
    let trace = vcd.map(|p| window.config(p));
    let t0 = std::time::Instant::now();
    let out = run_image_on::<W>(&img, timing, max_cycles, trace)?;
    let secs = t0.elapsed().as_secs_f64();
    for f in &out.files {
        eprintln!("wrote {}", f.display());
    }
    match &out.result {
        Ok(cycles) => {
            println!(
                "halted after {cycles} cycles ({:.3} us at {} MHz)",
                *cycles as f64 * 1e6 / timing.clock_hz as f64,
                timing.clock_hz as f64 / 1e6
            );
            print_stats(&out.stats());
            let r = |k| out.reg(k);
            println!(
                "r1 {:#010x}  r2 {:#010x}  r3 {:#010x}  r4 {:#010x}",
                r(1),
                r(2),
                r(3),
                r(4)
            );
            if secs > 0.0 {
                println!(
                    "host: {:.3} s, {:.1} M cycles/s",
                    secs,
                    *cycles as f64 / secs / 1e6
                );
            }
            Ok(())
        }
        Err(e) => Err(anyhow!("{e}")),
    }
}
