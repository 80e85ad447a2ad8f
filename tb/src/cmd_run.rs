//! `morphosys run FILE`: assemble (or load) a program, run it on the chip to
//! its `halt`, print the cycles used and the statistics.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context as _};
use firmware::asm::{self, Image};
use rtl::chip::{run_to_halt, RunError};
use rtl::rc::{Datapath, Word};
use rtl::{Chip, Sim, Stats, Timing};

/// Assembly source, or an image written by `morphosys asm -o`.
pub fn load_program(path: &Path) -> anyhow::Result<Image> {
    let bytes =
        firmware::input::read(path).with_context(|| format!("reading {}", path.display()))?;
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
    run_image_on(img, timing, max_cycles, trace, false)
}

/// Load `img` into a fresh chip of datapath `W` and run it to halt
/// (`plain`: stepping every cycle through the plain model,
/// [`rtl::Chip::plain`]).
pub fn run_image_on<W: Word>(
    img: &Image,
    timing: Timing,
    max_cycles: u64,
    trace: Option<rtl::trace::TraceConfig>,
    plain: bool,
) -> anyhow::Result<Outcome<W>> {
    let mut chip = Chip::<W>::build(timing, DEFAULT_MEMORY);
    chip.plain = plain;
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

pub(crate) fn print_stats(s: &Stats) {
    crate::report!("cycles               {}", s.cycles);
    crate::report!("tinyrisc issued      {}", s.risc_instructions);
    crate::report!("array busy cycles    {}", s.array_busy_cycles);
    crate::report!("active RC fraction   {:.3}", s.active_rc_fraction());
    crate::report!("array stall cycles   {}", s.array_stall_cycles);
    crate::report!("dma stall cycles     {}", s.dma_stall_cycles);
    crate::report!(
        "dma busy cycles      {}  ({} transfers, {} words)",
        s.dma_busy_cycles,
        s.dma_transfers,
        s.dma_words
    );
}

/// Arguments of `morphosys run`.
#[derive(clap::Args, Debug)]
pub struct RunArgs {
    pub file: PathBuf,
    /// Stop with an error after this many cycles.
    #[arg(long, value_name = "N", default_value_t = 100_000_000)]
    pub max_cycles: u64,
    /// Write the waveform here: VCD, or FST where the path ends in `.fst`
    /// (GTKWave save file and filters beside it).
    #[arg(long, value_name = "PATH")]
    pub vcd: Option<PathBuf>,
    #[command(flatten)]
    pub window: crate::cli::TraceWindow,
    /// RC datapath width in bits: 16 (the paper's chip) or 32 (default:
    /// the source's `.datapath`, else 16).
    #[arg(long, value_name = "16|32", value_parser = crate::cli::parse_datapath)]
    pub datapath: Option<rtl::rc::Datapath>,
    /// The chip's timing from a TOML file (any subset of the fields
    /// `morphosys timing` prints; the rest keep their defaults).
    #[arg(long, value_name = "FILE.toml")]
    pub timing: Option<PathBuf>,
    /// After the halt, TinyRISC register REG must hold VALUE (e.g.
    /// `r3=38`, `r1=0x1`); repeatable. Any mismatch exits 1. Without
    /// it, a halt with r1 = 0xBAD (the conformance programs' failure
    /// code, docs/isa.md) exits 1.
    #[arg(long, value_name = "REG=VALUE", value_parser = crate::cmd_run::parse_expect)]
    pub expect: Vec<(u8, u32)>,
    /// Write the cycles, the registers (decimal and hex) and the
    /// statistics as JSON here.
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Step every cycle through the plain register-transfer model (one
    /// eval and commit per cycle) instead of the fast paths: slower, and
    /// the same cycles, states and waveform.
    #[arg(long)]
    pub plain: bool,
}

/// The failure code of the conformance programs: a halt with r1 = 0xBAD
/// (and r2 = the number of the failed check).
pub(crate) const FAIL_CODE: u32 = 0xBAD;

/// `--expect REG=VALUE`: `r0`..`r15` and a decimal or `0x` hex value.
pub(crate) fn parse_expect(s: &str) -> Result<(u8, u32), String> {
    let (r, v) = s
        .split_once('=')
        .ok_or_else(|| format!("expected REG=VALUE (e.g. r3=38), found '{s}'"))?;
    let reg = r
        .trim()
        .strip_prefix('r')
        .and_then(|n| n.parse::<u8>().ok())
        .filter(|n| *n < 16)
        .ok_or_else(|| format!("'{r}' is not a TinyRISC register (r0..r15)"))?;
    let v = v.trim();
    let value = if let Some(h) = v.strip_prefix("0x").or_else(|| v.strip_prefix("0X")) {
        u32::from_str_radix(h, 16).ok()
    } else if let Some(n) = v.strip_prefix('-') {
        n.parse::<u32>().ok().map(|n| n.wrapping_neg())
    } else {
        v.parse::<u32>().ok()
    }
    .ok_or_else(|| format!("'{v}' is not a 32-bit value (decimal or 0x hex)"))?;
    Ok((reg, value))
}

pub fn command(a: RunArgs) -> anyhow::Result<()> {
    let mut files = crate::output::Files::new();
    files.input(&a.file, "FILE");
    if let Some(t) = &a.timing {
        files.input(t, "--timing");
    }
    if let Some(p) = &a.json {
        files.output(p, "--json");
    }
    if let Some(p) = &a.vcd {
        files.waveform(p, "--vcd");
    }
    files.check()?;
    let timing = crate::timing::load_or_default(a.timing.as_deref())?;
    // The source's `.datapath` unless --datapath says otherwise (and then
    // they must agree).
    let source = firmware::input::read(&a.file)
        .ok()
        .filter(|b| !Image::is_image(b))
        .and_then(|b| String::from_utf8(b).ok());
    let declared = source.as_deref().map(crate::render::source_datapath);
    let datapath = match (a.datapath, declared) {
        (Some(d), Some(s))
            if d != s && source.as_deref().is_some_and(|t| t.contains(".datapath")) =>
        {
            anyhow::bail!(
                "{}: the program is for the {}-bit datapath (`.datapath`), --datapath {} asks for {}",
                a.file.display(),
                s.bits(),
                d.bits(),
                d.bits()
            )
        }
        (Some(d), _) => d,
        (None, Some(s)) => s,
        (None, None) => Datapath::W16,
    };
    match datapath {
        Datapath::W16 => command_on::<i16>(&a, datapath, timing),
        Datapath::W32 => command_on::<i32>(&a, datapath, timing),
    }
}

fn command_on<W: Word>(a: &RunArgs, datapath: Datapath, timing: Timing) -> anyhow::Result<()> {
    let img = load_program(&a.file)?;
    let trace = a.vcd.clone().map(|p| {
        let mut c = a.window.config(p);
        // The PC and the broadcast unit's context by the program's labels
        // (its contexts taken as loaded into context 0 from its `.ctx`).
        if let Some(base) = img.ctx_base().or((!img.labels.is_empty()).then_some(0)) {
            c.labels = Some(std::sync::Arc::new(img.trace_labels(base)));
        }
        c
    });
    let t0 = std::time::Instant::now();
    let out = run_image_on::<W>(&img, timing, a.max_cycles, trace, a.plain)?;
    let secs = t0.elapsed().as_secs_f64();
    for f in &out.files {
        crate::note!("wrote {}", f.display());
    }
    let cycles = match &out.result {
        Ok(c) => *c,
        Err(e @ RunError::MaxCycles { .. }) => {
            return Err(anyhow!(
                "{e}; raise --max-cycles (now {}) to run longer",
                a.max_cycles
            ))
        }
        Err(e) => return Err(anyhow!("{e}")),
    };
    if a.vcd.is_some() && a.window.trace_from >= cycles {
        eprintln!(
            "morphosys: warning: --trace-from {} is past the program's halt at cycle {cycles}: the waveform holds no cycles",
            a.window.trace_from
        );
    }
    crate::report!(
        "halted after {cycles} cycles ({:.3} us at {} MHz), {}-bit datapath",
        cycles as f64 * 1e6 / timing.clock_hz as f64,
        timing.clock_hz as f64 / 1e6,
        datapath.bits()
    );
    print_stats(&out.stats());
    let r = |k| out.reg(k);
    for row in [[1, 2, 3, 4], [5, 6, 7, 8]] {
        let cells: Vec<String> = row
            .iter()
            .map(|&k| format!("r{k} {:#010x} ({:>10})", r(k), r(k) as i32))
            .collect();
        crate::report!("{}", cells.join("  "));
    }
    if secs > 0.0 {
        crate::report!(
            "host: {:.3} s, {:.1} M cycles/s",
            secs,
            cycles as f64 / secs / 1e6
        );
    }
    if let Some(p) = &a.json {
        let s = out.stats();
        let regs: Vec<serde_json::Value> = (0..16)
            .map(|k| serde_json::json!({"reg": format!("r{k}"), "value": r(k), "signed": r(k) as i32, "hex": format!("{:#010x}", r(k))}))
            .collect();
        let v = serde_json::json!({
            "program": a.file.display().to_string(),
            "datapath_bits": datapath.bits(),
            "cycles": cycles,
            "registers": regs,
            "risc_instructions": s.risc_instructions,
            "array_busy_cycles": s.array_busy_cycles,
            "active_rc_fraction": s.active_rc_fraction(),
            "array_stall_cycles": s.array_stall_cycles,
            "dma_stall_cycles": s.dma_stall_cycles,
            "dma_busy_cycles": s.dma_busy_cycles,
            "host_seconds": secs,
        });
        crate::output::write(p, (serde_json::to_string_pretty(&v)? + "\n").as_bytes())?;
        crate::note!("wrote {}", p.display());
    }
    // Did the program pass?
    if a.expect.is_empty() {
        if r(1) == FAIL_CODE {
            anyhow::bail!(
                "{}: the program signalled failure: halted with r1 = 0xBAD (check number r2 = {})",
                a.file.display(),
                r(2)
            );
        }
    } else {
        let wrong: Vec<String> = a
            .expect
            .iter()
            .filter(|(k, v)| r(*k) != *v)
            .map(|(k, v)| {
                format!(
                    "r{k} = {:#x} ({}), expected {v:#x} ({v})",
                    r(*k),
                    r(*k) as i32
                )
            })
            .collect();
        if !wrong.is_empty() {
            anyhow::bail!("{}: {}", a.file.display(), wrong.join("; "));
        }
    }
    Ok(())
}
