//! The chip's timing as a file: `--timing FILE.toml` on `render`, `run`,
//! `bench` and `sweep`, and `morphosys timing`, which prints every field
//! with its default and where the value comes from.
//!
//! Any subset of the fields may be given; the rest keep their defaults.
//! Unknown keys, wrong types and values out of range are refused with the
//! file, line and column.

use std::path::Path;

use anyhow::{anyhow, Result};
use rtl::tinyrisc::{IssueModel, RiscTiming};
use rtl::Timing;
use serde::Deserialize;

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct File {
    clock_hz: Option<u64>,
    issue: Option<String>,
    risc: Option<toml::Table>,
    dma: Option<Dma>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct Dma {
    setup_cycles: Option<u32>,
    bytes_per_cycle: Option<u32>,
}

/// One field: its TOML table (`""` for the top level), key, the default
/// as TOML, and where the value comes from.
struct Field {
    table: &'static str,
    key: &'static str,
    why: &'static str,
}

/// Every field in the order `morphosys timing` prints them: the top
/// level's, TinyRISC's cycle counts (from [`RiscTiming::CYCLES`]), the
/// DMA's.
fn fields() -> Vec<Field> {
    let mut v = vec![
        Field { table: "", key: "clock_hz", why: "unset, each chip's frame rate is quoted at its own clock: the 16-bit chip's is the paper's (\"MorphoSys is designed to be running at 300MHz\", section IX), the 32-bit chip's the lower one its longer path allows (`morphosys cost`); set, every chip at this one; only frames/s and waveform time (300 MHz unset) use it" },
        Field { table: "", key: "issue", why: "ours (docs/isa.md, section 4): \"run\", one instruction streams a run of up to 4095 contexts while TinyRISC goes on; \"instruction\" is the M1 chip's, where TinyRISC issues each context by an instruction and the array waits while it does anything else" },
    ];
    v.extend(RiscTiming::CYCLES.iter().map(|c| Field {
        table: "risc",
        key: c.key,
        why: c.why,
    }));
    v.extend([
        Field {
            table: "dma",
            key: "setup_cycles",
            why: "ours: from a transfer's issue to its first word (an external memory's latency)",
        },
        Field {
            table: "dma",
            key: "bytes_per_cycle",
            why: "ours: a 32-bit external bus, 2 FB words or 1 context word per cycle",
        },
    ]);
    v
}

/// The value of a field in `t`, as TOML.
fn value(t: &Timing, table: &str, key: &str) -> String {
    let n = match (table, key) {
        ("", "clock_hz") => t.clock_hz,
        ("", "issue") => return format!("\"{}\"", t.risc.issue.name()),
        ("dma", "setup_cycles") => t.dma.setup_cycles as u64,
        ("dma", "bytes_per_cycle") => t.dma.bytes_per_cycle as u64,
        ("risc", k) => match RiscTiming::CYCLES.iter().find(|c| c.key == k) {
            Some(c) => (c.get)(&t.risc) as u64,
            None => unreachable!("timing field risc.{k}"),
        },
        _ => unreachable!("timing field {table}.{key}"),
    };
    n.to_string()
}

/// `t` as a commented TOML file (`morphosys timing`): every field, its
/// value, and where it comes from. Read back, it gives `t`.
pub fn to_toml(t: &Timing) -> String {
    let mut s = String::from(
        "# The chip's timing (morphosys timing). Give any subset of these fields to\n\
         # --timing FILE.toml on render, run, bench and sweep; the rest keep these\n\
         # defaults. Cycle counts are per instruction class of TinyRISC; the array\n\
         # executes one context per cycle and the FB supplies one datum per set per\n\
         # cycle whatever the file says (docs/isa.md, section 4).\n",
    );
    let mut table = "";
    for f in fields() {
        if f.table != table {
            table = f.table;
            s.push_str(&format!("\n[{table}]\n"));
        }
        // The clock commented out where it is the default: a file written
        // from the defaults leaves each chip at its own.
        let unset = f.key == "clock_hz" && t.clock_hz == Timing::default().clock_hz;
        s.push_str(&format!(
            "# {}\n{}{} = {}\n",
            f.why,
            if unset { "# " } else { "" },
            f.key,
            value(t, f.table, f.key)
        ));
    }
    s
}

/// `t` as JSON (the render report's `timing`).
pub(crate) fn to_json(t: &Timing) -> serde_json::Value {
    let mut top = serde_json::Map::new();
    for f in fields() {
        let v: serde_json::Value = match (f.table, f.key) {
            ("", "issue") => t.risc.issue.name().into(),
            _ => value(t, f.table, f.key)
                .parse::<u64>()
                .map_or(serde_json::Value::Null, Into::into),
        };
        if f.table.is_empty() {
            top.insert(f.key.into(), v);
        } else {
            top.entry(f.table)
                .or_insert_with(|| serde_json::Value::Object(Default::default()))
                .as_object_mut()
                .map(|m| m.insert(f.key.into(), v));
        }
    }
    serde_json::Value::Object(top)
}

/// 1-based line and column of a byte offset.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// A TOML error as one line, `name:line:col: message`.
pub(crate) fn toml_error(e: &toml::de::Error, text: &str, name: &str) -> anyhow::Error {
    let msg = e.message().trim_end();
    match e.span() {
        Some(sp) => {
            let (l, c) = line_col(text, sp.start);
            anyhow!("{name}:{l}:{c}: {msg}")
        }
        // No position (the parser's nesting limit): the deepest line.
        None => match firmware::scene::native::deepest_line(text) {
            0 => anyhow!("{name}: {msg}"),
            l => anyhow!("{name}:{l}: {msg}"),
        },
    }
}

/// Parse a timing file's text (`name` for the messages).
pub fn parse(text: &str, name: &str) -> Result<Timing> {
    parse_file(text, name).map(|(t, _)| t)
}

/// [`parse`], and whether the file sets the clock (`clock_hz`).
fn parse_file(text: &str, name: &str) -> Result<(Timing, bool)> {
    let f: File = toml::from_str(text).map_err(|e| toml_error(&e, text, name))?;
    let sets_clock = f.clock_hz.is_some();
    // Where a key is written, for the range errors below.
    let at = |table: &str, key: &str| -> String {
        let mut cur = "";
        for (k, line) in text.lines().enumerate() {
            let l = line.trim();
            if let Some(t) = l.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
                cur = if t.trim() == table { table } else { "?" };
                continue;
            }
            if cur == table && l.split('=').next().is_some_and(|k| k.trim() == key) {
                return format!("{name}:{}", k + 1);
            }
        }
        name.to_string()
    };
    let mut t = Timing::default();
    if let Some(c) = f.clock_hz {
        if c == 0 {
            return Err(anyhow!(
                "{}: clock_hz must be at least 1",
                at("", "clock_hz")
            ));
        }
        t.clock_hz = c;
    }
    if let Some(m) = &f.issue {
        t.risc.issue = m
            .parse::<IssueModel>()
            .map_err(|e| anyhow!("{}: {e}", at("", "issue")))?;
    }
    if let Some(r) = f.risc {
        for (key, v) in &r {
            let Some(c) = RiscTiming::CYCLES.iter().find(|c| c.key == key) else {
                let known: Vec<String> = RiscTiming::CYCLES
                    .iter()
                    .map(|c| format!("`{}`", c.key))
                    .collect();
                return Err(anyhow!(
                    "{}: unknown field `{key}` in [risc], expected one of {}",
                    at("risc", key),
                    known.join(", ")
                ));
            };
            match v.as_integer() {
                Some(n @ 1..=1_000_000) => (c.set)(&mut t.risc, n as u32),
                _ => {
                    return Err(anyhow!(
                        "{}: risc.{key} = {v}: a cycle count must be 1..=1000000",
                        at("risc", key)
                    ))
                }
            }
        }
    }
    if let Some(d) = f.dma {
        if let Some(v) = d.setup_cycles {
            if v > 1_000_000 {
                return Err(anyhow!(
                    "{}: dma.setup_cycles = {v}: must be 0..=1000000",
                    at("dma", "setup_cycles")
                ));
            }
            t.dma.setup_cycles = v;
        }
        if let Some(v) = d.bytes_per_cycle {
            if !(1..=4096).contains(&v) {
                return Err(anyhow!(
                    "{}: dma.bytes_per_cycle = {v}: must be 1..=4096",
                    at("dma", "bytes_per_cycle")
                ));
            }
            t.dma.bytes_per_cycle = v;
        }
    }
    Ok((t, sets_clock))
}

/// Read a timing file.
pub fn load(path: &Path) -> Result<Timing> {
    load_file(path).map(|(t, _)| t)
}

/// [`load`], and whether the file sets the clock (`clock_hz`: then every
/// chip's frame rate is quoted at it).
pub(crate) fn load_file(path: &Path) -> Result<(Timing, bool)> {
    let text = firmware::input::read_to_string(path)
        .map_err(|e| anyhow!("{}: cannot read the timing file: {e}", path.display()))?;
    parse_file(&text, &path.display().to_string())
}

/// `--timing FILE`, or the defaults.
pub(crate) fn load_or_default(path: Option<&Path>) -> Result<Timing> {
    path.map_or_else(|| Ok(Timing::default()), load)
}

/// [`load_or_default`], and whether a file sets the clock.
pub(crate) fn load_or_default_file(path: Option<&Path>) -> Result<(Timing, bool)> {
    path.map_or_else(|| Ok((Timing::default(), false)), load_file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_printed_defaults_read_back_as_the_defaults() {
        let t = parse(&to_toml(&Timing::default()), "t.toml").unwrap();
        assert_eq!(t.risc, Timing::default().risc);
        assert_eq!(t.dma, Timing::default().dma);
        assert_eq!(t.clock_hz, Timing::default().clock_hz);
    }

    /// Each TinyRISC key sets its own field and no other: the struct's
    /// Debug text names the field with the value the file gave.
    #[test]
    fn every_risc_key_sets_its_own_field() {
        for c in RiscTiming::CYCLES {
            let t = parse(&format!("[risc]\n{} = 777\n", c.key), "t.toml").unwrap();
            let debug = format!("{:?}", t.risc);
            assert!(debug.contains(&format!("{}: 777", c.key)), "{debug}");
            assert_eq!(debug.matches(": 777").count(), 1, "{debug}");
            assert_eq!(value(&t, "risc", c.key), "777");
        }
    }

    #[test]
    fn a_subset_keeps_the_other_defaults() {
        let t = parse("[dma]\nbytes_per_cycle = 8\n", "t.toml").unwrap();
        assert_eq!(t.dma.bytes_per_cycle, 8);
        assert_eq!(t.dma.setup_cycles, 10);
        assert_eq!(t.risc, Timing::default().risc);
        let t = parse("issue = \"instruction\"\n", "t.toml").unwrap();
        assert_eq!(t.risc.issue, IssueModel::Instruction);
    }

    #[test]
    fn bad_files_name_the_line() {
        let e = parse("[risc]\nalu = 1\nbranch_taken = 2\nbrnch = 3\n", "a.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("a.toml:4:"), "{e}");
        assert!(e.contains("brnch"), "{e}");
        let e = parse("[risc]\nstatus = 0\n", "b.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("b.toml:2:"), "{e}");
        let e = parse("[dma]\nsetup_cycles = \"ten\"\n", "c.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.toml:2:"), "{e}");
        let e = parse("issue = \"pipelined\"\n", "d.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("d.toml:1") && e.contains("run or instruction"),
            "{e}"
        );
    }
}

/// `morphosys timing` arguments.
#[derive(clap::Args, Debug)]
pub struct TimingArgs {
    /// Write it here instead of standard output.
    #[arg(long, value_name = "FILE.toml")]
    pub out: Option<std::path::PathBuf>,
    /// The issue model: `run` (ours, the default) or `instruction` (the
    /// M1 chip's: TinyRISC issues each context by an instruction).
    #[arg(long, value_name = "run|instruction", value_parser = clap::builder::PossibleValuesParser::new(["run", "instruction"]))]
    pub issue: Option<String>,
}

/// `morphosys timing`: the chip's timing as TOML, every field with where
/// its value comes from.
pub fn command(a: TimingArgs) -> Result<()> {
    let mut t = Timing::default();
    if let Some(i) = a.issue {
        t.risc.issue = i
            .parse()
            .map_err(|e: String| anyhow::anyhow!("--issue: {e}"))?;
    }
    let text = to_toml(&t);
    match a.out {
        Some(p) => {
            crate::output::Files::new().output(&p, "--out").check()?;
            crate::output::write(&p, text.as_bytes())?;
            crate::note!("wrote {}", p.display());
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
