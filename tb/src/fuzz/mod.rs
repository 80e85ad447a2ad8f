//! Fuzzing of everything that reads user input: the NFF and TOML scene
//! parsers (through validation, the scene compiler and a tiny reference
//! render), the assembler (through a short run of what it assembled) and the
//! program-image loader (through a short run).
//!
//! Inputs are mutations of valid seeds (bytes flipped, inserted, deleted;
//! numbers replaced by NaN, infinities, huge and tiny values; lines
//! duplicated, dropped, swapped; inputs truncated and spliced) and plain
//! random bytes, and structure-aware inputs ([`structured`]: syntax trees
//! from the `arbitrary` crate, reaching deep nesting, absurd counts and
//! files of megabytes), from a fixed seed, so a run is reproducible. Every input
//! must either be accepted or rejected with an error that names its place;
//! a panic, or an error without a location, is a finding. `cargo-fuzz`
//! needs a nightly toolchain this project does not assume, so this is a
//! mutation fuzzer of our own on stable Rust.

pub mod structured;

use std::panic::{self, AssertUnwindSafe};
use std::path::PathBuf;
use std::time::Instant;

use firmware::asm::{self, Image};
use firmware::scene::{native, nff};
use firmware::scene_image::{compile, CompileOptions};

/// What is fuzzed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Target {
    /// NFF scene parser, validation, scene compiler, 4x4 reference render.
    Nff,
    /// Native TOML scene parser, the same pipeline.
    Toml,
    /// Assembler, then up to 2000 cycles of the program on the chip.
    Asm,
    /// Program-image loader, then up to 2000 cycles on the chip.
    Image,
}

pub const ALL: [Target; 4] = [Target::Nff, Target::Toml, Target::Asm, Target::Image];

impl Target {
    pub fn name(self) -> &'static str {
        match self {
            Target::Nff => "nff",
            Target::Toml => "toml",
            Target::Asm => "asm",
            Target::Image => "image",
        }
    }
}

/// A finding: the input and what went wrong.
#[derive(Debug, Clone)]
pub struct Finding {
    pub input: Vec<u8>,
    pub what: String,
}

#[derive(Debug, Default, Clone)]
pub struct Report {
    pub inputs: u64,
    pub accepted: u64,
    pub rejected: u64,
    pub findings: Vec<Finding>,
    /// The slowest input, in seconds (reported, never asserted).
    pub slowest_s: f64,
    /// Inputs from the structure-aware generator ([`structured`]), and the
    /// largest input of the run, in bytes.
    pub structured: u64,
    pub largest_input: usize,
}

/// Deterministic generator (xorshift64*).
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
}

const NUMBERS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e-308",
    "0",
    "-0",
    "1",
    "-1",
    "1e400",
    "99999999999999999999",
    "4294967296",
    "-2147483649",
    "32768",
    "-32769",
    "0.0000001",
    "65535",
    "0x7fffffff",
    "1.5e",
    "--1",
    "",
    "3.4.5",
    "1e9",
    "-1e9",
];

/// The conformance programs, the assembler's and loader's seeds (embedded:
/// `morphosys fuzz` fuzzes from the same seeds wherever it runs).
pub const CONFORMANCE: &[(&str, &str)] = &[
    (
        "cbcast.s",
        include_str!("../../../firmware/conformance/cbcast.s"),
    ),
    (
        "cbcc.s",
        include_str!("../../../firmware/conformance/cbcc.s"),
    ),
    (
        "cbcr.s",
        include_str!("../../../firmware/conformance/cbcr.s"),
    ),
    ("cut.s", include_str!("../../../firmware/conformance/cut.s")),
    (
        "dbcb.s",
        include_str!("../../../firmware/conformance/dbcb.s"),
    ),
    ("dct.s", include_str!("../../../firmware/conformance/dct.s")),
    (
        "double_buffer.s",
        include_str!("../../../firmware/conformance/double_buffer.s"),
    ),
    (
        "ifelse.s",
        include_str!("../../../firmware/conformance/ifelse.s"),
    ),
    (
        "ldctxt.s",
        include_str!("../../../firmware/conformance/ldctxt.s"),
    ),
    (
        "ldfb.s",
        include_str!("../../../firmware/conformance/ldfb.s"),
    ),
    (
        "lfb_sfb.s",
        include_str!("../../../firmware/conformance/lfb_sfb.s"),
    ),
    (
        "rcrisc.s",
        include_str!("../../../firmware/conformance/rcrisc.s"),
    ),
    (
        "sbcb.s",
        include_str!("../../../firmware/conformance/sbcb.s"),
    ),
    (
        "status.s",
        include_str!("../../../firmware/conformance/status.s"),
    ),
    (
        "stfb.s",
        include_str!("../../../firmware/conformance/stfb.s"),
    ),
    (
        "tinyrisc.s",
        include_str!("../../../firmware/conformance/tinyrisc.s"),
    ),
    (
        "transpose.s",
        include_str!("../../../firmware/conformance/transpose.s"),
    ),
    ("wfb.s", include_str!("../../../firmware/conformance/wfb.s")),
    (
        "wide.s",
        include_str!("../../../firmware/conformance/wide.s"),
    ),
];

/// The valid inputs mutations start from (embedded in the binary).
pub fn seeds(t: Target) -> Vec<Vec<u8>> {
    match t {
        Target::Nff => {
            let mut v = vec![
                include_bytes!("../../../scenes/spd/jacks-1.nff").to_vec(),
                include_bytes!("../../../scenes/spd/tetra-1.nff").to_vec(),
            ];
            // The head of balls: every entity kind in a few lines.
            let balls = firmware::scene::spd::generate("balls", 1).unwrap_or_default();
            let head: Vec<u8> = balls
                .lines()
                .take(60)
                .flat_map(|l| l.bytes().chain(std::iter::once(b'\n')))
                .collect();
            v.push(head);
            v.push(
                b"v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 8 8\n\
                  b 0 0 0\nl 1 1 1\nf 1 0 0 0.5 0.5 3 0 1\ns 0 0 0 1\n\
                  c 0 0 0 1 0 1 0 0.5\np 3\n0 0 0\n1 0 0\n0 1 0\npp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n"
                    .to_vec(),
            );
            v
        }
        Target::Toml => vec![include_bytes!("../../../scenes/default.toml").to_vec()],
        Target::Asm => CONFORMANCE
            .iter()
            .map(|(_, s)| s.as_bytes().to_vec())
            .collect(),
        Target::Image => CONFORMANCE
            .iter()
            .filter_map(|(name, s)| asm::assemble(s, name).ok())
            .map(|img| img.to_bytes())
            .collect(),
    }
}

/// One mutation of `x` (possibly spliced with `other`).
pub(crate) fn mutate(g: &mut Rng, x: &[u8], other: &[u8]) -> Vec<u8> {
    let mut v = x.to_vec();
    let rounds = 1 + g.below(4);
    for _ in 0..rounds {
        match g.below(10) {
            0 if !v.is_empty() => {
                let i = g.below(v.len());
                v[i] ^= 1 << g.below(8);
            }
            1 => {
                let i = g.below(v.len() + 1);
                v.insert(i, g.next() as u8);
            }
            2 if !v.is_empty() => {
                let i = g.below(v.len());
                let n = 1 + g.below(16.min(v.len() - i));
                v.drain(i..i + n);
            }
            3 | 4 => {
                // Replace a number-looking token.
                let s = String::from_utf8_lossy(&v).into_owned();
                let toks: Vec<(usize, usize)> = token_spans(&s);
                if !toks.is_empty() {
                    let (a, b) = toks[g.below(toks.len())];
                    let rep = NUMBERS[g.below(NUMBERS.len())];
                    let mut out = s[..a].to_string();
                    out.push_str(rep);
                    out.push_str(&s[b..]);
                    v = out.into_bytes();
                }
            }
            5 => {
                // Duplicate, drop or swap lines.
                let mut lines: Vec<Vec<u8>> =
                    v.split(|b| *b == b'\n').map(|l| l.to_vec()).collect();
                if !lines.is_empty() {
                    let i = g.below(lines.len());
                    let j = g.below(lines.len());
                    match g.below(3) {
                        0 => {
                            let l = lines[i].clone();
                            lines.insert(j, l);
                        }
                        1 => {
                            lines.remove(i);
                        }
                        _ => lines.swap(i, j),
                    }
                }
                v = lines.join(&b'\n');
            }
            6 if !v.is_empty() => {
                let n = g.below(v.len());
                v.truncate(n);
            }
            7 if !other.is_empty() => {
                let i = g.below(v.len() + 1);
                let a = g.below(other.len());
                let b = a + g.below(other.len() - a + 1);
                v.splice(i..i, other[a..b].iter().copied());
            }
            8 => {
                // Repeat a chunk many times (size and count limits).
                if !v.is_empty() {
                    let a = g.below(v.len());
                    let b = (a + 1 + g.below(32)).min(v.len());
                    let chunk = v[a..b].to_vec();
                    for _ in 0..g.below(64) {
                        v.splice(a..a, chunk.iter().copied());
                    }
                }
            }
            _ => {
                if !v.is_empty() {
                    let i = g.below(v.len());
                    v[i] = [
                        b'\n', b' ', b'#', b'-', b'.', b'e', b'[', b']', b'"', b'=', 0, 0xFF,
                    ][g.below(12)];
                }
            }
        }
    }
    v
}

fn token_spans(s: &str) -> Vec<(usize, usize)> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() || (b[i] == b'-' && i + 1 < b.len() && b[i + 1].is_ascii_digit()) {
            let a = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'.' || b[i] == b'-') {
                i += 1;
            }
            out.push((a, i));
        } else {
            i += 1;
        }
    }
    out
}

/// Does an error message name the place in the input?
fn has_location(msg: &str, file: &str) -> bool {
    msg.contains(file)
}

/// Run one input through a target: `Ok(true)` accepted, `Ok(false)`
/// rejected with a located error, `Err` a finding (without the panic case,
/// which the caller catches).
pub fn check(t: Target, input: &[u8]) -> Result<bool, String> {
    const FILE: &str = "fuzz-input";
    match t {
        Target::Nff | Target::Toml => {
            let text = String::from_utf8_lossy(input);
            let parsed = if t == Target::Nff {
                nff::parse(&text, FILE)
            } else {
                native::parse(&text, FILE)
            };
            let scene = match parsed.and_then(|s| s.validate().map(|_| s)) {
                Ok(s) => s,
                Err(e) => {
                    let m = e.to_string();
                    return if has_location(&m, FILE) {
                        Ok(false)
                    } else {
                        Err(format!("error without location: {m}"))
                    };
                }
            };
            match compile(&scene, &CompileOptions::default()) {
                Ok(_) => {}
                Err(e) => {
                    let m = e.to_string();
                    if !has_location(&m, FILE) {
                        return Err(format!("compile error without location: {m}"));
                    }
                }
            }
            let opt = crate::reference::Options {
                width: 4,
                height: 4,
                max_depth: 3,
                corners: false,
                progress: false,
            };
            let img = crate::reference::render(&scene, &opt);
            let _ = img;
            Ok(true)
        }
        Target::Asm => {
            let text = String::from_utf8_lossy(input);
            match asm::assemble(&text, FILE) {
                Ok(img) => {
                    run_briefly(&img);
                    Ok(true)
                }
                Err(e) => {
                    let m = e.to_string();
                    if has_location(&m, FILE) {
                        Ok(false)
                    } else {
                        Err(format!("assembler error without location: {m}"))
                    }
                }
            }
        }
        Target::Image => match Image::from_bytes(input) {
            Ok(img) => {
                run_briefly(&img);
                Ok(true)
            }
            Err(m) if !m.is_empty() => Ok(false),
            Err(_) => Err("empty image error".into()),
        },
    }
}

fn run_briefly(img: &Image) {
    let mut chip = rtl::Chip::new(rtl::Timing::default(), crate::cmd_run::DEFAULT_MEMORY);
    if img.load(&mut chip).is_err() {
        return;
    }
    let mut sim = rtl::Sim::new(chip);
    let _ = rtl::chip::run_to_halt(&mut sim, 2000);
}

/// Run `count` inputs of target `t` from `seed`; `tick` is called after
/// each input (for a progress bar).
pub fn run(t: Target, count: u64, seed: u64, mut tick: impl FnMut(u64)) -> Report {
    let seeds = seeds(t);
    let mut g = Rng::new(seed ^ t as u64);
    let mut rep = Report::default();
    let prev = panic::take_hook();
    panic::set_hook(Box::new(|_| {}));
    for k in 0..count {
        let pick = g.below(10);
        let input = if seeds.is_empty() || pick == 0 {
            let n = g.below(512);
            (0..n).map(|_| g.next() as u8).collect()
        } else if pick <= 2 {
            rep.structured += 1;
            structured::input(t, &mut g)
        } else {
            let a = &seeds[g.below(seeds.len())];
            let b = &seeds[g.below(seeds.len())];
            mutate(&mut g, a, b)
        };
        let t0 = Instant::now();
        let r = panic::catch_unwind(AssertUnwindSafe(|| check(t, &input)));
        rep.slowest_s = rep.slowest_s.max(t0.elapsed().as_secs_f64());
        rep.inputs += 1;
        rep.largest_input = rep.largest_input.max(input.len());
        match r {
            Ok(Ok(true)) => rep.accepted += 1,
            Ok(Ok(false)) => rep.rejected += 1,
            Ok(Err(what)) => rep.findings.push(Finding { input, what }),
            Err(p) => {
                let what = p
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_else(|| "panic".into());
                rep.findings.push(Finding {
                    input,
                    what: format!("panic: {what}"),
                });
            }
        }
        tick(k);
    }
    panic::set_hook(prev);
    rep
}

/// The regression corpus kept under `tb/tests/fuzz_corpus/<target>/`.
pub fn corpus_dir(t: Target) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_corpus")
        .join(t.name())
}
