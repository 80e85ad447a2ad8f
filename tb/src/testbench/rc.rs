//! The RC testbench: drives a sequence of contexts through one RC of the
//! RTL model, checks every result against the independent reference model
//! ([`super::rc_ref`]) and writes the waveform.
//!
//! The sequence is a fixed directed part (every operation with the edge
//! values i16::MIN, -1, 0, 1, i16::MAX) followed by a pseudo-random part
//! from a fixed seed, so every run is identical.

use std::path::PathBuf;

use anyhow::{bail, Context as _};
use rtl::kernel::{Clocked, Fault, Sim};
use rtl::rc::context::{ASrc, BSrc, Cond, Context, Guard, Op, ALL_CONDS, ALL_OPS};
use rtl::rc::{LaneNames, RcArray};
use rtl::trace::{Probe, TraceConfig, Traced};

use super::rc_ref::{Outcome, RefRc};

/// One stimulus: the context of the cycle and the datum on the RC's
/// external operand input (the frame-buffer / interconnect value).
#[derive(Clone, Copy, Debug)]
pub struct Stim {
    pub ctx: Context,
    pub ext: i16,
}

/// The device under test and its stimulus, as one clocked module.
pub(crate) struct RcBench {
    pub rc: RcArray<1>,
    pub stims: Vec<Stim>,
    pub pc: usize,
}

impl Clocked for RcBench {
    fn eval(&mut self) -> Result<(), Fault> {
        let s = self.stims[self.pc];
        self.rc.set_context(s.ctx.encode(), s.ctx);
        self.rc.ext[0] = s.ext;
        self.rc.eval()
    }

    fn commit(&mut self) {
        self.rc.commit();
        self.pc += 1;
    }
}

impl Traced for RcBench {
    fn trace<P: Probe>(&self, p: &mut P) {
        if p.scope(format_args!("stim")) {
            p.signal("step", 32, rtl::trace::Display::Signed, self.pc as u64);
            p.signal(
                "ext",
                16,
                rtl::trace::Display::Signed,
                self.stims[self.pc].ext as u16 as u64,
            );
            p.end();
        }
        self.rc.trace(p);
    }
}

/// A small deterministic generator (xorshift64*), so the sequence is the
/// same on every machine.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    pub(crate) fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    /// True `percent` times in a hundred.
    pub(crate) fn chance(&mut self, percent: u64) -> bool {
        self.below(100) < percent
    }
    fn val(&mut self) -> i16 {
        const EDGES: [i16; 5] = [i16::MIN, -1, 0, 1, i16::MAX];
        if self.below(3) == 0 {
            EDGES[self.below(5) as usize]
        } else {
            self.next() as i16
        }
    }
}

const EDGES: [i16; 5] = [i16::MIN, -1, 0, 1, i16::MAX];

/// Load `v` into register `r` through the external input (`mov rN, fb0`).
fn load(r: u8, v: i16) -> Stim {
    Stim {
        ctx: Context {
            asrc: ASrc::Fb,
            ra: 0,
            ..Context::rrr(Op::Mov, r, 0, 0)
        },
        ext: v,
    }
}

fn plain(ctx: Context) -> Stim {
    Stim { ctx, ext: 0 }
}

/// The directed part: every operation on every pair of edge values.
fn directed() -> Vec<Stim> {
    let mut s = Vec::new();
    for &x in &EDGES {
        for &y in &EDGES {
            s.push(load(1, x));
            s.push(load(2, y));
            for &op in ALL_OPS {
                match op {
                    Op::Sleep | Op::Wake | Op::Ld | Op::St => continue,
                    Op::Cmp => {
                        for cond in ALL_CONDS {
                            s.push(plain(Context {
                                rd: cond as u8,
                                ..Context::rrr(Op::Cmp, 0, 1, 2)
                            }));
                        }
                    }
                    _ if op.uses_shift() => {
                        for sh in [0, 1, 8, 12, 15, 16, 31] {
                            for trunc in [false, true] {
                                s.push(plain(Context {
                                    shift: sh,
                                    trunc,
                                    ..Context::rrr(op, 3, 1, 2)
                                }));
                            }
                        }
                    }
                    _ => s.push(plain(Context::rrr(op, 3, 1, 2))),
                }
            }
            // Shifts by every amount.
            for n in 0..=17 {
                for op in [Op::Sll, Op::Srl, Op::Sra, Op::Asl] {
                    s.push(plain(Context::rri(op, 4, 1, n)));
                }
            }
        }
    }
    // RAM: store the edge values and read them back.
    for (k, &x) in EDGES.iter().enumerate() {
        s.push(load(5, x));
        s.push(plain(Context::rri(Op::St, 0, 5, 500 + k as i16)));
    }
    for k in 0..5 {
        s.push(plain(Context::rri(Op::Ld, 6, 0, 500 + k)));
    }
    // Guarded execution, sleep and wake.
    s.push(plain(Context {
        rd: Cond::True as u8,
        ..Context::rrr(Op::Cmp, 0, 0, 0)
    }));
    s.push(plain(Context {
        guard: Guard::IfNotF,
        ..Context::rri(Op::Movb, 7, 0, 111)
    }));
    s.push(plain(Context {
        guard: Guard::IfF,
        ..Context::rri(Op::Movb, 7, 0, 222)
    }));
    s.push(plain(Context {
        op: Op::Sleep,
        ..Context::NOP
    }));
    s.push(plain(Context::rri(Op::Movb, 7, 0, 333)));
    s.push(plain(Context {
        op: Op::Wake,
        ..Context::NOP
    }));
    s.push(plain(Context::rri(Op::Movb, 7, 0, 444)));
    s
}

/// The random part: any operation, source, guard and destination.
fn random(n: usize, seed: u64) -> Vec<Stim> {
    let mut g = Rng(seed | 1);
    let mut s = Vec::with_capacity(n);
    let mut asleep = false;
    for _ in 0..n {
        let mut op = ALL_OPS[g.below(ALL_OPS.len() as u64) as usize];
        // Keep sleeping short: a sleep is followed by a wake soon.
        if op == Op::Sleep && g.below(4) != 0 {
            op = Op::Add;
        }
        if asleep && g.below(4) == 0 {
            op = Op::Wake;
        }
        let guard = [Guard::Always, Guard::Always, Guard::IfF, Guard::IfNotF][g.below(4) as usize];
        let asrc = [ASrc::Reg, ASrc::Reg, ASrc::Out, ASrc::Fb][g.below(4) as usize];
        let mut ctx = Context {
            op,
            guard,
            we: g.below(4) != 0,
            rd: g.below(16) as u8,
            asrc,
            ra: g.below(16) as u8 & if asrc == ASrc::Fb { 1 } else { 15 },
            b: if g.below(2) == 0 {
                BSrc::Reg(g.below(16) as u8)
            } else {
                BSrc::Imm(g.below(2048) as i16 - 1024)
            },
            shift: 0,
            trunc: false,
        };
        if let BSrc::Reg(_) = ctx.b {
            if op.uses_shift() {
                ctx.shift = g.below(32) as u8;
                ctx.trunc = g.below(2) == 0;
            }
        }
        let mut ext = g.val();
        // Memory accesses use in-range addresses (faults have their own tests).
        match op {
            Op::Ld => {
                ctx.asrc = ASrc::Fb;
                ctx.ra = 0;
                ext = g.below(256) as i16;
                ctx.b = BSrc::Imm(g.below(256) as i16);
            }
            Op::St => ctx.b = BSrc::Imm(g.below(512) as i16),
            _ => {}
        }
        if op == Op::Sleep && guard == Guard::Always {
            asleep = true;
        }
        if op == Op::Wake {
            asleep = false;
        }
        s.push(Stim { ctx, ext });
    }
    s
}

/// The full stimulus of the testbench.
pub fn stimulus() -> Vec<Stim> {
    let mut s = directed();
    s.extend(random(3000, 0x4D4F_5250_4853_5953)); // "MORPHSYS"
    s
}

/// Results of a testbench run.
#[derive(Debug)]
pub struct Report {
    pub cycles: u64,
    pub executed: u64,
    pub checks: u64,
    pub mismatches: Vec<String>,
    pub files: Vec<PathBuf>,
}

/// Compare the RTL RC with the reference after a cycle.
fn compare(rc: &RcArray<1>, r: &RefRc, step: usize, stim: &Stim, bad: &mut Vec<String>) -> u64 {
    let mut checks = 0;
    let mut check = |what: String, got: i64, want: i64| {
        checks += 1;
        if got != want && bad.len() < 20 {
            bad.push(format!(
                "step {step} `{}` (ext {}): {what} is {got}, reference says {want}",
                stim.ctx, stim.ext
            ));
        }
    };
    check("out".into(), rc.out[0] as i64, r.out);
    for k in 0..16u8 {
        check(format!("r{k}"), rc.regs.read(k)[0] as i64, r.r[k as usize]);
    }
    check("acc".into(), rc.acc[0] as i64, r.acc);
    let f = rc.flags;
    check("F".into(), (f.f & 1) as i64, r.f as i64);
    check("C".into(), (f.c & 1) as i64, r.c as i64);
    check("V".into(), (f.v & 1) as i64, r.v as i64);
    check("sleep".into(), (f.sleep & 1) as i64, r.sleep as i64);
    checks
}

/// Run the testbench; trace into `trace` if given.
pub fn run(trace: Option<TraceConfig>) -> anyhow::Result<Report> {
    let stims = stimulus();
    let n = stims.len();
    let mut sim = Sim::new(RcBench {
        rc: RcArray::new(LaneNames::Single),
        stims: stims.clone(),
        pc: 0,
    });
    if let Some(cfg) = trace {
        let path = cfg.path.clone();
        sim.trace(cfg, "tb")
            .with_context(|| format!("cannot write waveform {}", path.display()))?;
    }
    let mut reference = RefRc::default();
    let mut report = Report {
        cycles: 0,
        executed: 0,
        checks: 0,
        mismatches: Vec::new(),
        files: Vec::new(),
    };
    for (i, stim) in stims.iter().enumerate().take(n) {
        let outcome = reference.step(&stim.ctx, stim.ext as i64);
        let stepped = sim.step();
        match (outcome, stepped) {
            (Outcome::Fault(addr), Err(e)) => {
                report.mismatches.push(format!(
                    "step {i}: both fault on address {addr} ({e}); the testbench should not fault"
                ));
                break;
            }
            (Outcome::Fault(addr), Ok(())) => {
                report.mismatches.push(format!(
                    "step {i} `{}`: reference faults on address {addr}, RTL does not",
                    stim.ctx
                ));
                break;
            }
            (_, Err(e)) => {
                report
                    .mismatches
                    .push(format!("step {i} `{}`: RTL faulted: {e}", stim.ctx));
                break;
            }
            (o, Ok(())) => {
                if let Outcome::Executed = o {
                    report.executed += 1;
                }
            }
        }
        report.checks += compare(&sim.top.rc, &reference, i, stim, &mut report.mismatches);
    }
    // Finally the whole RAM.
    for addr in 0..512 {
        report.checks += 1;
        let got = sim.top.rc.ram.read(0, addr) as i64;
        if got != reference.ram[addr] && report.mismatches.len() < 20 {
            report.mismatches.push(format!(
                "RAM[{addr}] is {got}, reference says {}",
                reference.ram[addr]
            ));
        }
    }
    report.cycles = sim.cycle();
    report.files = sim.finish_trace().context("cannot finish waveform")?;
    Ok(report)
}

/// `morphosys tb rc`.
pub fn command(
    vcd: Option<PathBuf>,
    window: crate::cli::TraceWindow,
    json: Option<PathBuf>,
) -> anyhow::Result<()> {
    let path = vcd.unwrap_or_else(|| PathBuf::from("waves/rc.vcd"));
    // The waveform's folder is made (waves/ by default), as the tracer would.
    if let Some(d) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(d).with_context(|| format!("--vcd {}", path.display()))?;
    }
    let mut files = crate::output::Files::new();
    files.waveform(&path, "--vcd");
    if let Some(j) = &json {
        files.output(j, "--json");
    }
    files.check()?;
    let mut cfg = window.config(path);
    cfg.budget_cycles = Some(stimulus().len() as u64);
    let r = run(Some(cfg))?;
    println!(
        "rc testbench: {} cycles, {} contexts executed, {} values checked against the reference model",
        r.cycles, r.executed, r.checks
    );
    for f in &r.files {
        crate::note!("  wrote {}", f.display());
    }
    if let Some(v) = r
        .files
        .iter()
        .find(|f| f.extension().is_some_and(|e| e == "gtkw"))
    {
        println!("  view:  gtkwave {}", v.display());
    }
    if let Some(j) = &json {
        let v = serde_json::json!({
            "testbench": "rc",
            "cycles": r.cycles,
            "contexts_executed": r.executed,
            "values_checked": r.checks,
            "mismatches": r.mismatches,
            "pass": r.mismatches.is_empty(),
            "files": r.files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>(),
        });
        crate::output::write(j, (serde_json::to_string_pretty(&v)? + "\n").as_bytes())?;
        crate::note!("  wrote {}", j.display());
    }
    if !r.mismatches.is_empty() {
        for m in &r.mismatches {
            eprintln!("  MISMATCH {m}");
        }
        bail!("rc testbench failed: {} mismatches", r.mismatches.len());
    }
    println!("  PASS");
    Ok(())
}

/// `morphosys tb rc` arguments.
#[derive(clap::Args, Debug)]
pub struct RcArgs {
    /// Write the waveform here: VCD, or FST where the path ends in
    /// `.fst` (a GTKWave `.gtkw` save file and the translate filters go
    /// beside it).
    #[arg(long, value_name = "PATH")]
    pub vcd: Option<PathBuf>,
    #[command(flatten)]
    pub window: crate::cli::TraceWindow,
    /// Write the result (cycles, contexts, values checked, mismatches)
    /// as JSON here.
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
}
