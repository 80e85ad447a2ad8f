//! Co-simulation: the RC in synthesizable Verilog (`rtl/verilog/`, built
//! by Verilator) against the Rust RC ([`rtl::rc::RcArray`]), cycle for
//! cycle, on both datapath widths.
//!
//! Both receive the same stream of context words (with the datum on the
//! RC's external operand input and the array's lane enable); after every
//! clock edge the co-simulation compares every register, `out`, the
//! accumulator, the four flags, and what the cycle did: whether the word
//! was illegal, whether the RC executed it, an address fault, and the RAM
//! write (address and data). At the end it compares the whole RAM. The
//! first difference stops it with the cycle, the context in disassembly
//! and both states.
//!
//! The Verilog side is `rtl/verilog/cosim/rc_cosim.cpp`, a Verilator
//! harness that reads the stream on its standard input and writes the
//! states on its standard output.

use std::io::{BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout, Command, Stdio};
use std::time::Instant;

use anyhow::{bail, Context as _};
use rtl::rc::context::{Context, Op};
use rtl::rc::{Datapath, LaneNames, RcArray, Word};

use crate::output::thousands;

mod array;
mod bench;
mod stream;

pub use array::run_array;
pub use bench::{bench_array, Speeds};
pub use stream::{array_stream, random_stream, testbench_stream, ArrayStep, Step};

/// Where the Verilog sources are: `MORPHOSYS_VERILOG`, else the source
/// tree this program was built from.
pub fn verilog_dir() -> PathBuf {
    std::env::var_os("MORPHOSYS_VERILOG")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../rtl/verilog");
            p.canonicalize().unwrap_or(p)
        })
}

/// The Verilog files of the RC, in the order Verilator reads them.
pub const RC_FILES: &[&str] = &[
    "rc.v",
    "rc_context.v",
    "rc_alu.v",
    "rc_shifter.v",
    "rc_multiplier.v",
    "rc_register_file.v",
    "rc_ram.v",
    "rc_flags.v",
];

/// What a Verilator harness simulates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Top {
    /// One RC (`rc.v`, harness `cosim/rc_cosim.cpp`).
    Rc,
    /// The 8x8 array with its interconnect (`rc_array.v`, harness
    /// `cosim/rc_array_cosim.cpp`).
    Array,
}

impl Top {
    fn module(self) -> &'static str {
        match self {
            Top::Rc => "rc",
            Top::Array => "rc_array",
        }
    }
    /// Every source of the harness, relative to the Verilog folder.
    pub fn files(self) -> Vec<&'static str> {
        let mut f = match self {
            Top::Rc => vec![],
            Top::Array => vec!["rc_array.v", "rc_interconnect.v"],
        };
        f.extend(RC_FILES);
        f.push(match self {
            Top::Rc => "cosim/rc_cosim.cpp",
            Top::Array => "cosim/rc_array_cosim.cpp",
        });
        f
    }
}

/// Build the Verilator harness of `top` at width `dp` from the Verilog in
/// `src` ([`verilog_dir`]) under `dir`; returns the program. Verilator and
/// make rebuild what changed.
pub fn build(top: Top, dp: Datapath, src: &Path, dir: &Path) -> anyhow::Result<PathBuf> {
    let src = src.canonicalize().with_context(|| {
        format!(
            "the Verilog sources are not at {} (set MORPHOSYS_VERILOG)",
            src.display()
        )
    })?;
    make_safe(&std::path::absolute(dir)?, "the build folder (--build-dir)")?;
    make_safe(&src, "the Verilog sources' folder (MORPHOSYS_VERILOG)")?;
    let obj = dir.join(format!("{}_w{}", top.module(), dp.bits()));
    std::fs::create_dir_all(&obj).with_context(|| format!("cannot make {}", obj.display()))?;
    let obj = obj.canonicalize()?;
    // Make's dependency files name the sources: a build from other
    // sources starts afresh.
    let stamp = obj.join("sources");
    let here = src.display().to_string();
    if std::fs::read_to_string(&stamp).ok().as_deref() != Some(here.as_str()) {
        let _ = std::fs::remove_dir_all(obj.join("obj"));
        std::fs::write(&stamp, &here)
            .with_context(|| format!("cannot write {}", stamp.display()))?;
    }
    let w = dp.bits();
    let program = format!("{}_cosim", top.module());
    let mut cmd = Command::new("verilator");
    cmd.args(["--cc", "--exe", "--build", "-j", "2", "-O3", "-Wall"])
        .arg(format!("-GW={w}"))
        .arg("-DCOSIM")
        .args(["-CFLAGS", &format!("-DRC_W={w}")])
        // the model's code at -O2 (Verilator's makefile builds it at -Os)
        .args(["-MAKEFLAGS", "OPT_FAST=-O2 OPT_SLOW=-O1"])
        .arg("-Mdir")
        .arg(obj.join("obj"))
        .args(["--top-module", top.module(), "-o", &program])
        .arg(format!("-I{}", src.display()));
    for f in top.files() {
        cmd.arg(src.join(f));
    }
    let out = match cmd.output() {
        Ok(o) => o,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => bail!(
            "verilator is not installed (Debian: apt-get install verilator); the co-simulation needs it"
        ),
        Err(e) => return Err(e).context("cannot run verilator"),
    };
    if !out.status.success() {
        let text = String::from_utf8_lossy(&out.stderr).to_string()
            + &String::from_utf8_lossy(&out.stdout);
        let tail: Vec<&str> = text.lines().rev().take(30).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        bail!(
            "verilator failed on the {w}-bit {}:\n{}",
            top.module(),
            tail.join("\n")
        );
    }
    Ok(obj.join("obj").join(program))
}

/// Refuse a path Verilator would hand to make and make to the shell
/// (`make -C <Mdir>`, the sources in its makefile) unless it holds only
/// letters, digits and `/._-+,=@%:~`: a `$(...)`, a quote or a space
/// there would run or break a command.
fn make_safe(p: &Path, what: &str) -> anyhow::Result<()> {
    let text = p.to_string_lossy();
    let ok = |c: char| c.is_ascii_alphanumeric() || "/._-+,=@%:~".contains(c);
    if let Some(c) = text.chars().find(|&c| !ok(c)) {
        let shown = crate::output::escaped(&text);
        let c = match c.is_control() || c == ' ' {
            true => format!("U+{:04X}", c as u32),
            false => format!("`{c}`"),
        };
        bail!(
            "{what} {shown} holds {c}: Verilator hands the path to make and make to the shell, \
             so it may hold only letters, digits and /._-+,=@%:~ (give another folder)"
        );
    }
    Ok(())
}

/// What a co-simulation compared.
#[derive(Debug, Default, Clone)]
pub struct Report {
    pub cycles: u64,
    /// Cycles in which the RC executed its context.
    pub executed: u64,
    pub illegal: u64,
    pub faults: u64,
    pub ram_writes: u64,
    /// Values compared (a register, a flag, a RAM word: one each).
    pub values: u64,
    /// The first difference, with the cycle, the context and both states.
    pub mismatch: Option<String>,
    pub seconds: f64,
}

/// The state after a cycle and what the cycle did, as the harness writes
/// it (bit patterns, zero-extended).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct State {
    out: u64,
    regs: [u64; 16],
    acc: u64,
    f: bool,
    c: bool,
    v: bool,
    sleep: bool,
    illegal: bool,
    en: bool,
    fault: bool,
    ram_we: bool,
    ram_addr: u64,
    ram_wdata: u64,
}

const RECORD: usize = 8 * 19 + 8;

impl State {
    fn parse(b: &[u8; RECORD]) -> State {
        let u = |i: usize| u64::from_le_bytes(b[8 * i..8 * i + 8].try_into().unwrap());
        let bits = u32::from_le_bytes(b[152..156].try_into().unwrap());
        let mut regs = [0; 16];
        for (k, r) in regs.iter_mut().enumerate() {
            *r = u(1 + k);
        }
        let ram_we = bits & 128 != 0;
        State {
            out: u(0),
            regs,
            acc: u(17),
            f: bits & 1 != 0,
            c: bits & 2 != 0,
            v: bits & 4 != 0,
            sleep: bits & 8 != 0,
            illegal: bits & 16 != 0,
            en: bits & 32 != 0,
            fault: bits & 64 != 0,
            ram_we,
            // the address and data matter only with a write
            ram_addr: if ram_we {
                u32::from_le_bytes(b[156..160].try_into().unwrap()) as u64
            } else {
                0
            },
            ram_wdata: if ram_we { u(18) } else { 0 },
        }
    }

    /// The fields that differ, named, and how many fields were compared.
    fn diff(&self, o: &State) -> (Vec<String>, u64) {
        let mut d = Vec::new();
        let mut n = 0;
        let mut cmp = |name: &str, a: u64, b: u64| {
            n += 1;
            if a != b {
                d.push(format!("{name}: Verilog 0x{a:x}, Rust 0x{b:x}"));
            }
        };
        cmp("out", self.out, o.out);
        for k in 0..16 {
            cmp(&format!("r{k}"), self.regs[k], o.regs[k]);
        }
        cmp("acc", self.acc, o.acc);
        cmp("F", self.f as u64, o.f as u64);
        cmp("C", self.c as u64, o.c as u64);
        cmp("V", self.v as u64, o.v as u64);
        cmp("sleep", self.sleep as u64, o.sleep as u64);
        cmp("illegal", self.illegal as u64, o.illegal as u64);
        cmp("executed", self.en as u64, o.en as u64);
        cmp("fault", self.fault as u64, o.fault as u64);
        cmp("ram_we", self.ram_we as u64, o.ram_we as u64);
        cmp("ram_addr", self.ram_addr, o.ram_addr);
        cmp("ram_wdata", self.ram_wdata, o.ram_wdata);
        (d, n)
    }

    fn show(&self) -> String {
        let regs: Vec<String> = self.regs.iter().map(|r| format!("{r:x}")).collect();
        format!(
            "out {:x} acc {:x} F{} C{} V{} sleep{} | r0..r15 {} | illegal {} executed {} fault {} ram_we {} @{:x} = {:x}",
            self.out,
            self.acc,
            self.f as u8,
            self.c as u8,
            self.v as u8,
            self.sleep as u8,
            regs.join(" "),
            self.illegal as u8,
            self.en as u8,
            self.fault as u8,
            self.ram_we as u8,
            self.ram_addr,
            self.ram_wdata
        )
    }
}

/// A running Verilator harness: a thread writes the stream to its
/// standard input while the states are read from its standard output.
struct Harness {
    child: Child,
    writer: std::thread::JoinHandle<std::io::Result<()>>,
    out: BufReader<ChildStdout>,
}

impl Harness {
    fn start(program: &Path, input: Vec<u8>) -> anyhow::Result<Harness> {
        let mut child = Command::new(program)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .with_context(|| format!("cannot run {}", program.display()))?;
        let mut stdin = child.stdin.take().expect("piped");
        let writer = std::thread::spawn(move || stdin.write_all(&input));
        let out = BufReader::with_capacity(1 << 16, child.stdout.take().expect("piped"));
        Ok(Harness { child, writer, out })
    }

    fn read_exact(&mut self, buf: &mut [u8]) -> std::io::Result<()> {
        self.out.read_exact(buf)
    }

    /// Stop it early (a difference found).
    fn stop(mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = self.writer.join();
    }

    /// Its stream written and its exit a success.
    fn finish(mut self) -> anyhow::Result<()> {
        self.writer
            .join()
            .expect("writer thread")
            .context("writing the stream to the Verilog harness")?;
        let status = self.child.wait()?;
        if !status.success() {
            bail!("the Verilog harness exited with {status}");
        }
        Ok(())
    }
}

/// Run `steps` through the harness `program` (from [`build`]) and the
/// Rust RC of width `dp`, comparing after every cycle.
pub fn run(dp: Datapath, program: &Path, steps: &[Step]) -> anyhow::Result<Report> {
    match dp {
        Datapath::W16 => run_w::<i16>(program, steps),
        Datapath::W32 => run_w::<i32>(program, steps),
    }
}

fn run_w<W: Word>(program: &Path, steps: &[Step]) -> anyhow::Result<Report> {
    let t0 = Instant::now();
    let mut input = Vec::with_capacity(steps.len() * 16);
    for s in steps {
        input.extend_from_slice(&s.ctx.to_le_bytes());
        input.extend_from_slice(&(s.lane_en as u32).to_le_bytes());
        input.extend_from_slice(&(s.ext as u64).to_le_bytes());
    }
    let mut from = Harness::start(program, input)?;

    let bits = W::BITS;
    let word = |x: W| x.to_i64() as u64 & mask(bits);
    let wide = W::DATAPATH == Datapath::W32;
    let mut rc: RcArray<1, W> = RcArray::new(LaneNames::Single);
    let mut report = Report::default();
    let mut rec = [0u8; RECORD];
    for (i, s) in steps.iter().enumerate() {
        // The Rust RC's cycle.
        let mut rust = State::default();
        let mut ctx_text = format!("illegal word 0x{:08x}", s.ctx);
        match Context::decode_for(s.ctx, wide) {
            Err(_) => rust.illegal = true,
            Ok(c) => {
                ctx_text = format!("`{c}` (0x{:08x})", s.ctx);
                rc.set_context(s.ctx, c);
                rc.ext[0] = W::wrap(s.ext);
                rc.lane_enable = s.lane_en as u64;
                let faulted = rc.step().is_err();
                rust.en = rc.executed() & 1 != 0;
                rust.fault = faulted;
                if c.op == Op::St && rust.en && !faulted {
                    let a = rc.ram_addr(0) as usize;
                    rust.ram_we = true;
                    rust.ram_addr = a as u64;
                    rust.ram_wdata = word(rc.ram.read(0, a));
                }
            }
        }
        rust.out = word(rc.out[0]);
        for k in 0..16 {
            rust.regs[k] = word(rc.regs.read(k as u8)[0]);
        }
        rust.acc = W::acc_i128(rc.acc[0]) as u64 & mask(2 * bits);
        rust.f = rc.flags.f & 1 != 0;
        rust.c = rc.flags.c & 1 != 0;
        rust.v = rc.flags.v & 1 != 0;
        rust.sleep = rc.flags.sleep & 1 != 0;

        // The Verilog RC's.
        from.read_exact(&mut rec)
            .with_context(|| format!("the Verilog harness stopped before cycle {i}"))?;
        let v = State::parse(&rec);
        report.cycles += 1;
        report.executed += rust.en as u64;
        report.illegal += rust.illegal as u64;
        report.faults += rust.fault as u64;
        report.ram_writes += rust.ram_we as u64;
        let (d, compared) = v.diff(&rust);
        report.values += compared;
        if !d.is_empty() {
            report.mismatch = Some(format!(
                "first difference at cycle {i}: {ctx_text}, ext {}, lane enable {}\n  differs: {}\n  Verilog: {}\n  Rust:    {}",
                s.ext,
                s.lane_en as u8,
                d.join("; "),
                v.show(),
                rust.show()
            ));
            from.stop();
            report.seconds = t0.elapsed().as_secs_f64();
            return Ok(report);
        }
    }
    // The whole RAM.
    let mut ram = vec![0u8; 512 * 8];
    from.read_exact(&mut ram)
        .context("the Verilog harness stopped before its RAM")?;
    for a in 0..512 {
        let vw = u64::from_le_bytes(ram[8 * a..8 * a + 8].try_into().unwrap());
        let rw = word(rc.ram.read(0, a));
        report.values += 1;
        if vw != rw && report.mismatch.is_none() {
            report.mismatch = Some(format!(
                "RAM word {a} after the last cycle: Verilog 0x{vw:x}, Rust 0x{rw:x}"
            ));
        }
    }
    from.finish()?;
    report.seconds = t0.elapsed().as_secs_f64();
    Ok(report)
}

/// The low `bits` bits.
fn mask(bits: u32) -> u64 {
    if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    }
}

/// `tb cosim --bench`: cycles of the stream, and how often it runs.
const BENCH_CYCLES: usize = 100_000;
const BENCH_REPEAT: u32 = 3;

/// The default seed of the random streams ("RCVERILG").
pub const SEED: u64 = 0x5243_5645_5249_4C47;

/// `morphosys tb cosim` arguments.
#[derive(clap::Args, Debug)]
pub struct CosimArgs {
    /// The RC's datapath width: 16, 32, or both (the default).
    #[arg(long, value_name = "16|32|both", default_value = "both", value_parser = parse_widths)]
    pub datapath: Widths,
    /// Random context cycles after the RC testbench's stream, per width
    /// (up to 20,000,000: the stream is made whole before it runs, about
    /// 32 bytes a cycle).
    #[arg(long, value_name = "N", default_value_t = 1_000_000,
          value_parser = |s: &str| parse_count(s, MAX_RANDOM))]
    pub random: usize,
    /// Seed of the random stream.
    #[arg(long, value_name = "SEED", default_value_t = SEED, value_parser = parse_seed)]
    pub seed: u64,
    /// Random cycles of the 8x8 array (the Verilog array with its
    /// interconnect against the Rust array, all three broadcast modes),
    /// per width; 0 leaves the array out (up to 5,000,000: about 110 bytes
    /// a cycle).
    #[arg(long, value_name = "N", default_value_t = 100_000,
          value_parser = |s: &str| parse_count(s, MAX_ARRAY))]
    pub array: usize,
    /// Also measure the Verilated array's speed against the Rust array's
    /// on the same stream (array cycles per second, one thread each).
    #[arg(long)]
    pub bench: bool,
    /// Where Verilator builds the harnesses.
    #[arg(long, value_name = "DIR", default_value = "target/verilator")]
    pub build_dir: PathBuf,
}

/// The widths to co-simulate.
#[derive(Clone, Debug)]
pub struct Widths(pub Vec<Datapath>);

fn parse_widths(s: &str) -> Result<Widths, String> {
    match s {
        "both" => Ok(Widths(vec![Datapath::W16, Datapath::W32])),
        _ => crate::cli::parse_datapath(s)
            .map(|d| Widths(vec![d]))
            .map_err(|e| e.replace("a datapath width:", "a datapath width: both,")),
    }
}

/// The most random RC and array cycles `tb cosim` takes (their streams
/// are made whole before they run).
pub const MAX_RANDOM: usize = 20_000_000;
pub const MAX_ARRAY: usize = 5_000_000;

/// A cycle count from 0 to `max`.
fn parse_count(s: &str, max: usize) -> Result<usize, String> {
    let n: u128 = s
        .trim()
        .replace('_', "")
        .parse()
        .map_err(|_| format!("`{s}` is not a count of cycles (0 to {max})"))?;
    if n > max as u128 {
        return Err(format!(
            "{n} cycles: at most {max} (the stream is made whole before it runs; split a longer run over seeds with --seed)"
        ));
    }
    Ok(n as usize)
}

fn parse_seed(s: &str) -> Result<u64, String> {
    let r = match s.strip_prefix("0x") {
        Some(h) => u64::from_str_radix(h, 16),
        None => s.parse(),
    };
    r.map_err(|_| format!("`{s}` is not a seed (a number, decimal or 0x hex)"))
}

/// `morphosys tb cosim`.
pub fn command(a: CosimArgs) -> anyhow::Result<()> {
    let mut failed = Vec::new();
    for &dp in &a.datapath.0 {
        let t = Instant::now();
        crate::note!(
            "building the {dp} Verilog RC with Verilator in {}",
            a.build_dir.display()
        );
        let program = build(Top::Rc, dp, &verilog_dir(), &a.build_dir)?;
        crate::note!("  built in {:.1} s", t.elapsed().as_secs_f64());
        for (name, steps) in [
            ("the RC testbench's stream", testbench_stream()),
            ("random contexts", random_stream(dp, a.random, a.seed)),
        ] {
            if steps.is_empty() {
                continue;
            }
            let r = run(dp, &program, &steps)?;
            println!(
                "{dp} RC, {name}: {} cycles ({} executed, {} address faults, {} illegal words, {} RAM writes), {} values compared in {:.1} s: {}",
                thousands(r.cycles),
                thousands(r.executed),
                thousands(r.faults),
                thousands(r.illegal),
                thousands(r.ram_writes),
                thousands(r.values),
                r.seconds,
                if r.mismatch.is_some() { "DIFFERENT" } else { "identical" }
            );
            if let Some(m) = r.mismatch {
                eprintln!("  {m}");
                failed.push(format!("{dp} RC, {name}"));
            }
        }
        if a.array == 0 && !a.bench {
            continue;
        }
        let t = Instant::now();
        crate::note!("building the {dp} Verilog array with Verilator");
        let program = build(Top::Array, dp, &verilog_dir(), &a.build_dir)?;
        crate::note!("  built in {:.1} s", t.elapsed().as_secs_f64());
        let steps = array_stream(dp, a.array.max(1), a.seed, false);
        if a.array > 0 {
            let r = run_array(dp, &program, &steps)?;
            println!(
                "{dp} array, random contexts in three modes: {} cycles ({} RC executions), {} values compared in {:.1} s: {}",
                thousands(r.cycles),
                thousands(r.executed),
                thousands(r.values),
                r.seconds,
                if r.mismatch.is_some() { "DIFFERENT" } else { "identical" }
            );
            if let Some(m) = r.mismatch {
                eprintln!("  {m}");
                failed.push(format!("{dp} array"));
            }
        }
        if a.bench {
            let steps = array_stream(dp, BENCH_CYCLES, a.seed, true);
            let sp = bench_array(dp, &program, &steps, BENCH_REPEAT)?;
            println!(
                "{dp} array speed, {} SIMD cycles of one stream, one thread each: Verilator {:.1} k cycles/s, this model's array {:.2} M cycles/s ({:.0}x)",
                thousands(sp.cycles),
                sp.verilator / 1e3,
                sp.rust / 1e6,
                sp.rust / sp.verilator
            );
        }
    }
    if !failed.is_empty() {
        bail!(
            "the Verilog RC differs from the Rust RC: {}",
            failed.join(", ")
        );
    }
    Ok(())
}
