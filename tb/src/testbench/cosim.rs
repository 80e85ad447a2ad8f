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
use rtl::array::{Array, Mode};
use rtl::rc::context::{ASrc, BSrc, Context, Guard, Op, ALL_OPS};
use rtl::rc::{Datapath, LaneNames, RcArray, Word};

use super::rc::Rng;
use crate::cmd_report::thousands;

/// One cycle of the stream: a context word (legal or not), the datum on
/// the external operand input, and the array's lane enable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    pub ctx: u32,
    pub ext: i64,
    pub lane_en: bool,
}

/// The RC testbench's stimulus ([`super::rc::stimulus`], its directed and
/// random parts) as a stream; on the 32-bit RC its data are sign-extended.
pub fn testbench_stream() -> Vec<Step> {
    super::rc::stimulus()
        .iter()
        .map(|s| Step {
            ctx: s.ctx.encode(),
            ext: s.ext as i64,
            lane_en: true,
        })
        .collect()
}

/// `n` random cycles from `seed` for the RC of width `dp`: any operation,
/// guard, operand source, destination, immediate and multiplier shift
/// (0..63 on the 32-bit RC), data at the word's edges, small and random;
/// one word in fifty entirely random (mostly illegal), one `ld` / `st` in
/// five at a random address (mostly a fault); the lane enable off one
/// cycle in twenty; sleeps kept short.
pub fn random_stream(dp: Datapath, n: usize, seed: u64) -> Vec<Step> {
    let bits = dp.bits();
    let mut g = Rng(seed | 1);
    let mut s = Vec::with_capacity(n);
    let mut asleep = false;
    for _ in 0..n {
        let lane_en = !g.chance(5);
        if g.chance(2) {
            s.push(Step {
                ctx: g.next() as u32,
                ext: value(&mut g, bits),
                lane_en,
            });
            continue;
        }
        let mut op = ALL_OPS[g.below(ALL_OPS.len() as u64) as usize];
        if op == Op::Sleep && g.below(4) != 0 {
            op = Op::Mov;
        }
        if asleep && g.below(4) == 0 {
            op = Op::Wake;
        }
        let asrc = match g.below(10) {
            0..=3 => ASrc::Reg,
            4 | 5 => ASrc::Out,
            6 => ASrc::Nbr,
            7 => ASrc::XRow,
            8 => ASrc::QCol,
            _ => ASrc::Fb,
        };
        let ra = g.below(16) as u8;
        let mut ctx = context(&mut g, bits, op, asrc, ra);
        let mut ext = value(&mut g, bits);
        if matches!(op, Op::Ld | Op::St) && !g.chance(20) {
            if let Some(x) = address_in_range(&mut g, &mut ctx) {
                ext = x;
            }
        }
        if op == Op::Sleep && ctx.guard == Guard::Always && lane_en {
            asleep = true;
        }
        if op == Op::Wake {
            asleep = false;
        }
        s.push(Step {
            ctx: ctx.encode(),
            ext,
            lane_en,
        });
    }
    s
}

/// A datum of `bits` bits: at the word's edges, small, or any.
fn value(g: &mut Rng, bits: u32) -> i64 {
    let min = -(1i64 << (bits - 1));
    let max = (1i64 << (bits - 1)) - 1;
    match g.below(6) {
        0 | 1 => [min, -1, 0, 1, max, min + 1, max - 1][g.below(7) as usize],
        2 => g.below(81) as i64 - 40,
        _ => (g.next() as i64) >> (64 - bits),
    }
}

/// A context of `op` with operand A from `asrc` / `ra`, and at random its
/// guard, destination, operand B and multiplier shift (up to 2 `bits`).
fn context(g: &mut Rng, bits: u32, op: Op, asrc: ASrc, ra: u8) -> Context {
    let guard = [Guard::Always, Guard::Always, Guard::IfF, Guard::IfNotF][g.below(4) as usize];
    let b = if g.chance(50) {
        BSrc::Reg(g.below(16) as u8)
    } else {
        BSrc::Imm(g.below(2048) as i16 - 1024)
    };
    let mut ctx = Context {
        op,
        guard,
        we: g.below(4) != 0,
        rd: g.below(16) as u8,
        asrc,
        ra,
        b,
        shift: 0,
        trunc: false,
    };
    if matches!(b, BSrc::Reg(_)) {
        ctx.shift = g.below(2 * bits as u64) as u8;
        ctx.trunc = g.chance(50);
    }
    ctx
}

/// Make a `ld` / `st` address a valid one: `ld rd, [fbK + #i]` with the
/// FB datum returned (0..255 each), `st A, [#i]`.
fn address_in_range(g: &mut Rng, ctx: &mut Context) -> Option<i64> {
    ctx.shift = 0;
    ctx.trunc = false;
    if ctx.op == Op::St {
        ctx.b = BSrc::Imm(g.below(512) as i16);
        return None;
    }
    ctx.asrc = ASrc::Fb;
    ctx.ra = g.below(2) as u8;
    ctx.b = BSrc::Imm(g.below(256) as i16);
    Some(g.below(256) as i64)
}

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

/// One cycle of the array's stream: whether a context runs, the broadcast
/// mode, the 8 context words (SIMD: word 0) and the two FB data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ArrayStep {
    pub active: bool,
    pub mode: Mode,
    pub words: [u32; 8],
    pub fb: [i64; 2],
}

/// `n` random cycles of the array from `seed`: one cycle in five in row
/// or column mode, any legal operation with every interconnect source
/// (neighbours, short and express lanes, FB data) often, RAM addresses in
/// range, and in each cycle one lane index per lane bus (two rows of a
/// row-mode group asking one vertical lane for different drivers is a
/// fault of the chip, not a cycle to compare).
///
/// With `simd_only` every cycle is SIMD (as nearly every cycle of the ray
/// tracer is; `tb cosim --bench` times that).
pub fn array_stream(dp: Datapath, n: usize, seed: u64, simd_only: bool) -> Vec<ArrayStep> {
    let bits = dp.bits();
    let mut g = Rng(seed | 1);
    let mut s = Vec::with_capacity(n);
    for _ in 0..n {
        let mode = match g.below(10) {
            _ if simd_only => Mode::Simd,
            0 => Mode::Row,
            1 => Mode::Col,
            _ => Mode::Simd,
        };
        let (kx, kq) = (g.below(8) as u8, g.below(4) as u8);
        let mut fb = [value(&mut g, bits), value(&mut g, bits)];
        let mut words = [0u32; 8];
        for w in words.iter_mut() {
            let mut op = ALL_OPS[g.below(ALL_OPS.len() as u64) as usize];
            // Sleep seldom and wake often: the array stays mostly awake.
            if op == Op::Sleep && g.below(4) != 0 {
                op = Op::Wake;
            }
            let asrc = [
                ASrc::Reg,
                ASrc::Out,
                ASrc::Nbr,
                ASrc::QRow,
                ASrc::QCol,
                ASrc::XRow,
                ASrc::XCol,
                ASrc::Fb,
            ][g.below(8) as usize];
            let ra = match asrc {
                ASrc::Nbr => g.below(4) as u8,
                ASrc::QRow | ASrc::QCol => kq,
                ASrc::XRow | ASrc::XCol => kx,
                ASrc::Fb => g.below(2) as u8,
                _ => g.below(16) as u8,
            };
            let mut ctx = context(&mut g, bits, op, asrc, ra);
            if matches!(op, Op::Ld | Op::St) {
                if let Some(x) = address_in_range(&mut g, &mut ctx) {
                    // both sets small: the group's other loads read them too
                    fb = [x, g.below(256) as i64];
                }
            }
            *w = ctx.encode();
        }
        s.push(ArrayStep {
            active: !g.chance(5),
            mode,
            words,
            fb,
        });
    }
    s
}

/// Run `steps` through the array harness `program` (from [`build`] with
/// [`Top::Array`]) and the Rust array of width `dp`, comparing every RC's
/// `out`, the flag masks and the RCs executed after every cycle, and every
/// register, accumulator and RAM word at the end.
pub fn run_array(dp: Datapath, program: &Path, steps: &[ArrayStep]) -> anyhow::Result<Report> {
    match dp {
        Datapath::W16 => run_array_w::<i16>(program, steps),
        Datapath::W32 => run_array_w::<i32>(program, steps),
    }
}

fn array_input(steps: &[ArrayStep]) -> Vec<u8> {
    let mut input = Vec::with_capacity(steps.len() * 56);
    for s in steps {
        let control = s.active as u32 | (s.mode as u32) << 1;
        input.extend_from_slice(&control.to_le_bytes());
        for w in s.words {
            input.extend_from_slice(&w.to_le_bytes());
        }
        input.extend_from_slice(&0u32.to_le_bytes());
        input.extend_from_slice(&(s.fb[0] as u64).to_le_bytes());
        input.extend_from_slice(&(s.fb[1] as u64).to_le_bytes());
    }
    input
}

/// A cycle's contexts, decoded (as the chip's context memory holds them).
fn decode_step(s: &ArrayStep, wide: bool) -> anyhow::Result<[Context; 8]> {
    let mut ctx = [Context::NOP; 8];
    for (c, &w) in ctx.iter_mut().zip(&s.words) {
        *c = Context::decode_for(w, wide).map_err(|e| anyhow::anyhow!("word 0x{w:08x}: {e}"))?;
    }
    Ok(ctx)
}

/// One cycle of the Rust array, its contexts decoded.
#[inline]
fn array_cycle<W: Word>(a: &mut Array<W>, s: &ArrayStep, ctx: &[Context; 8]) -> anyhow::Result<()> {
    let fb = [W::wrap(s.fb[0]), W::wrap(s.fb[1])];
    if !s.active {
        a.idle();
        return Ok(());
    }
    if s.mode == Mode::Simd {
        a.drive_simd(s.words[0], &ctx[0], fb);
    } else {
        a.drive_group(s.mode, s.words, *ctx, fb);
    }
    a.step()
        .map_err(|e| anyhow::anyhow!("the Rust array faulted: {e}"))
}

fn run_array_w<W: Word>(program: &Path, steps: &[ArrayStep]) -> anyhow::Result<Report> {
    let t0 = Instant::now();
    let mut from = Harness::start(program, array_input(steps))?;
    let word = |x: W| x.to_i64() as u64 & mask(W::BITS);
    let mut a: Array<W> = Array::new();
    let mut report = Report::default();
    let mut rec = [0u8; 70 * 8];
    for (i, s) in steps.iter().enumerate() {
        let ctx = decode_step(s, W::BITS == 32)?;
        array_cycle(&mut a, s, &ctx).with_context(|| format!("cycle {i}"))?;
        from.read_exact(&mut rec)
            .with_context(|| format!("the Verilog harness stopped before cycle {i}"))?;
        let v = |k: usize| u64::from_le_bytes(rec[8 * k..8 * k + 8].try_into().unwrap());
        report.cycles += 1;
        report.values += 64 + 6;
        let executed = if s.active { a.active_now as u64 } else { 0 };
        report.executed += executed;
        let mut d = Vec::new();
        for k in 0..64 {
            let r = word(a.rc.out[k]);
            if v(k) != r {
                d.push(format!(
                    "{}: out Verilog 0x{:x}, Rust 0x{r:x}",
                    LaneNames::Grid.name(k),
                    v(k)
                ));
            }
        }
        let f = &a.rc.flags;
        for (name, k, r) in [
            ("F", 64, f.f),
            ("C", 65, f.c),
            ("V", 66, f.v),
            ("sleep", 67, f.sleep),
        ] {
            if v(k) != r {
                d.push(format!("{name} mask: Verilog {:016x}, Rust {r:016x}", v(k)));
            }
        }
        if v(68).count_ones() as u64 != executed {
            d.push(format!(
                "RCs executed: Verilog {}, Rust {executed}",
                v(68).count_ones()
            ));
        }
        if v(69) != 0 {
            d.push(format!("Verilog faults {:016x}", v(69)));
        }
        if !d.is_empty() {
            let words: Vec<String> = match s.mode {
                Mode::Simd => vec![describe(s.words[0], W::BITS == 32)],
                _ => s
                    .words
                    .iter()
                    .map(|&w| describe(w, W::BITS == 32))
                    .collect(),
            };
            report.mismatch = Some(format!(
                "first difference at cycle {i}: {:?} mode, {}, fb {:?}{}\n  {}",
                s.mode,
                words.join(" | "),
                s.fb,
                if s.active { "" } else { " (idle)" },
                d.join("\n  ")
            ));
            from.stop();
            report.seconds = t0.elapsed().as_secs_f64();
            return Ok(report);
        }
    }
    // The whole state: registers, accumulators, RAM.
    let mut rest = vec![0u8; (64 * 16 + 64 + 512 * 64) * 8];
    from.read_exact(&mut rest)
        .context("the Verilog harness stopped before its final state")?;
    let v = |k: usize| u64::from_le_bytes(rest[8 * k..8 * k + 8].try_into().unwrap());
    let mut diff = None;
    for i in 0..64 {
        for r in 0..16u8 {
            let got = word(a.rc.regs.read(r)[i]);
            let k = i * 16 + r as usize;
            if v(k) != got && diff.is_none() {
                diff = Some(format!(
                    "{} r{r} at the end: Verilog 0x{:x}, Rust 0x{got:x}",
                    LaneNames::Grid.name(i),
                    v(k)
                ));
            }
        }
        let acc = W::acc_i128(a.rc.acc[i]) as u64 & mask(2 * W::BITS);
        if v(64 * 16 + i) != acc && diff.is_none() {
            diff = Some(format!(
                "{} acc at the end: Verilog 0x{:x}, Rust 0x{acc:x}",
                LaneNames::Grid.name(i),
                v(64 * 16 + i)
            ));
        }
    }
    for addr in 0..512 {
        for i in 0..64 {
            let got = word(a.rc.ram.read(i, addr));
            let k = 64 * 17 + addr * 64 + i;
            if v(k) != got && diff.is_none() {
                diff = Some(format!(
                    "{} RAM word {addr} at the end: Verilog 0x{:x}, Rust 0x{got:x}",
                    LaneNames::Grid.name(i),
                    v(k)
                ));
            }
        }
    }
    report.values += (64 * 17 + 512 * 64) as u64;
    report.mismatch = diff;
    from.finish()?;
    report.seconds = t0.elapsed().as_secs_f64();
    Ok(report)
}

/// A context word in disassembly, or what is wrong with it.
fn describe(w: u32, wide: bool) -> String {
    match Context::decode_for(w, wide) {
        Ok(c) => format!("`{c}`"),
        Err(e) => format!("0x{w:08x} ({e})"),
    }
}

/// The speed of the Verilated array and of the Rust array on the same
/// stream, in array cycles per second.
#[derive(Clone, Copy, Debug)]
pub struct Speeds {
    pub cycles: u64,
    pub verilator: f64,
    pub rust: f64,
}

/// Run `steps` `repeat` times through the Verilated array (`program`, its
/// `--bench` mode: the stream in memory, nothing compared) and through the
/// Rust array of width `dp`, each timed alone on one thread.
pub fn bench_array(
    dp: Datapath,
    program: &Path,
    steps: &[ArrayStep],
    repeat: u32,
) -> anyhow::Result<Speeds> {
    let mut child = Command::new(program)
        .arg("--bench")
        .arg(repeat.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .with_context(|| format!("cannot run {}", program.display()))?;
    child
        .stdin
        .take()
        .expect("piped")
        .write_all(&array_input(steps))
        .context("writing the stream to the Verilog harness")?;
    let out = child.wait_with_output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let mut it = text.split_whitespace();
    let (Some(n), Some(secs)) = (
        it.next().and_then(|x| x.parse::<u64>().ok()),
        it.next().and_then(|x| x.parse::<f64>().ok()),
    ) else {
        bail!("the Verilog harness's bench printed `{}`", text.trim());
    };
    let rust = match dp {
        Datapath::W16 => time_rust::<i16>(steps, repeat)?,
        Datapath::W32 => time_rust::<i32>(steps, repeat)?,
    };
    Ok(Speeds {
        cycles: n,
        verilator: n as f64 / secs,
        rust: n as f64 / rust,
    })
}

fn time_rust<W: Word>(steps: &[ArrayStep], repeat: u32) -> anyhow::Result<f64> {
    let decoded = steps
        .iter()
        .map(|s| decode_step(s, W::BITS == 32))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut a: Array<W> = Array::new();
    let t = Instant::now();
    for _ in 0..repeat {
        for (s, c) in steps.iter().zip(&decoded) {
            array_cycle(&mut a, s, c)?;
        }
    }
    let secs = t.elapsed().as_secs_f64();
    std::hint::black_box(&a.rc.out);
    Ok(secs)
}

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
    /// Random context cycles after the RC testbench's stream, per width.
    #[arg(long, value_name = "N", default_value_t = 1_000_000)]
    pub random: usize,
    /// Seed of the random stream.
    #[arg(long, value_name = "SEED", default_value_t = SEED, value_parser = parse_seed)]
    pub seed: u64,
    /// Random cycles of the 8x8 array (the Verilog array with its
    /// interconnect against the Rust array, all three broadcast modes),
    /// per width; 0 leaves the array out.
    #[arg(long, value_name = "N", default_value_t = 100_000)]
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
