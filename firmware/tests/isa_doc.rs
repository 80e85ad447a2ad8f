//! `docs/isa.md` is checked against the assembler, the disassembler and the
//! timing defaults: every mnemonic in it assembles and disassembles back to
//! itself, every opcode and RC operation is documented, and the cycle
//! columns are the model's defaults.

use std::collections::HashMap;

use firmware::asm::{assemble, Section};
use rtl::rc::context::{Context, ALL_OPS};
use rtl::tinyrisc::decode::{Instr, Opcode, ALL_OPCODES};
use rtl::tinyrisc::execute::cycles;
use rtl::tinyrisc::RiscTiming;

fn doc() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/isa.md")).unwrap()
}

fn section<'a>(d: &'a str, title: &str) -> &'a str {
    let start = d
        .find(title)
        .unwrap_or_else(|| panic!("no section {title}"));
    let rest = &d[start + title.len()..];
    let end = rest.find("\n## ").unwrap_or(rest.len());
    &rest[..end]
}

fn cells(line: &str) -> Vec<String> {
    line.trim()
        .trim_matches('|')
        .split(" | ")
        .map(|c| c.trim().trim_matches('`').to_string())
        .collect()
}

fn word(src: &str, sec: Section) -> u32 {
    let img = assemble(src, "isa.md").unwrap_or_else(|e| panic!("{e}"));
    let s = img
        .segments
        .iter()
        .find(|s| s.section == sec)
        .expect("one word");
    assert_eq!(s.data.len(), 4, "{src}");
    u32::from_le_bytes([s.data[0], s.data[1], s.data[2], s.data[3]])
}

#[test]
fn every_tinyrisc_row_round_trips_and_states_the_model_cycles() {
    let d = doc();
    let s = section(&d, "## 2. TinyRISC");
    let t = RiscTiming::default();
    let mut seen = Vec::new();
    for line in s.lines().filter(|l| l.starts_with("| 0x")) {
        let c = cells(line);
        let op = u8::from_str_radix(c[0].trim_start_matches("0x"), 16).unwrap();
        let o = Opcode::from_bits(op).unwrap_or_else(|| panic!("{line}"));
        assert_eq!(o.mnemonic(), c[1], "{line}");
        // the example at 0x100: branches are relative to it
        let w = word(&format!(".text\n.org 0x100\n{}\n", c[2]), Section::Text);
        let i = Instr::decode(w).unwrap();
        assert_eq!(i.op, o, "{line}");
        assert_eq!(i.to_string(), c[2], "{line}");
        // cycles: the first number is the (taken) cost
        let n: u32 = c[4].split(' ').next().unwrap().parse().unwrap();
        assert_eq!(n, cycles(&t, o, true), "{line}");
        if c[4].contains("not") {
            let nt: u32 = c[4]
                .split(", ")
                .nth(1)
                .unwrap()
                .split(' ')
                .next()
                .unwrap()
                .parse()
                .unwrap();
            assert_eq!(nt, cycles(&t, o, false), "{line}");
        }
        seen.push(o);
    }
    for o in ALL_OPCODES {
        assert!(seen.contains(o), "{} is not documented", o.mnemonic());
    }
}

#[test]
fn every_context_example_round_trips_and_covers_every_operation() {
    let d = doc();
    let start =
        d.find("```ctx-examples\n").expect("ctx-examples block") + "```ctx-examples\n".len();
    let block = &d[start..start + d[start..].find("```").unwrap()];
    let mut ops = Vec::new();
    for line in block.lines().filter(|l| !l.trim().is_empty()) {
        let w = word(&format!(".ctx\n{line}\n"), Section::Ctx);
        let c = Context::decode(w).unwrap();
        assert_eq!(c.to_string(), line, "round trip");
        ops.push(c.op);
    }
    for o in ALL_OPS {
        assert!(ops.contains(o), "no example of `{}`", o.mnemonic());
    }
    // every mnemonic of the RC operation table has an example
    let rc = section(&d, "## 1. RC context word");
    for line in rc.lines().filter(|l| l.starts_with("| 0x")) {
        let m = cells(line)[1].clone();
        assert!(
            ALL_OPS.iter().any(|o| o.mnemonic() == m && ops.contains(o)),
            "`{m}`"
        );
    }
}

#[test]
fn the_timing_table_matches_the_defaults() {
    let d = doc();
    let s = section(&d, "## 4. Timing");
    // field values from the Debug form of the defaults
    let mut vals: HashMap<String, String> = HashMap::new();
    let dbg = format!("{:?}", rtl::Timing::default());
    for part in dbg.split(['{', '}', ',']) {
        if let Some((k, v)) = part.split_once(':') {
            vals.insert(k.trim().to_string(), v.trim().to_string());
        }
    }
    let mut checked = 0;
    for line in s.lines().filter(|l| l.starts_with("| `")) {
        let c = cells(line);
        let names: Vec<&str> = c[0].split(" / ").map(|n| n.trim_matches('`')).collect();
        let values: Vec<&str> = c[1].split(" / ").collect();
        let prefix = names[0].split('.').next().unwrap();
        for (k, n) in names.iter().enumerate() {
            let field = n.rsplit('.').next().unwrap();
            let _ = prefix;
            // Numbers as they are; the issue model's variant in lower case.
            let want = values[k].trim_matches('`');
            assert!(
                vals.get(field)
                    .is_some_and(|v| v.eq_ignore_ascii_case(want)),
                "{line}: the default is {:?}",
                vals.get(field)
            );
            checked += 1;
        }
    }
    assert!(checked >= 18, "{checked}");
}
