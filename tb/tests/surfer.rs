//! Surfer's instruction decoders: the TOML files under
//! `waves/.surfer/decoders/` are the ones `tb/src/surfer.rs` generates
//! from the opcode tables, and they decode every word of the conformance
//! programs and of the tracer's golden firmware (and a few hundred
//! thousand random legal words) to the project's disassembly.
//!
//! Surfer is not packaged for this machine, and the `instruction-decoder`
//! crate Surfer builds its decoders on is not on crates.io; the decoding
//! here follows that crate's source (v0.1.0, `src/lib.rs`): fields cut
//! from bit 31 down, each slice placed at its `bot` within its field,
//! `VInt` sign-extended from the field's top bit unless the instruction
//! says `unsigned`, list mappings by index, numbers in decimal or `{:#x}`,
//! `$name$` and `%field%` substituted, and the last match kept (formats in
//! name order, instructions in name order).

mod common;
use std::collections::BTreeMap;
use std::path::PathBuf;

use rtl::rc::context::Context;
use rtl::tinyrisc::decode::{disassemble, Instr};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

struct Part {
    ty: String,
    hex: bool,
}

struct Slice {
    field: String,
    top: u32,
    bot: u32,
}

struct Instruction {
    name: String,
    mask: u64,
    matches: u64,
    unsigned: bool,
}

struct Format {
    ty: String,
    repr: BTreeMap<String, String>,
    instructions: Vec<Instruction>,
}

/// One decoder file, read as the instruction-decoder crate reads it.
struct Decoder {
    width: u32,
    parts: BTreeMap<String, Part>,
    types: BTreeMap<String, Vec<Slice>>,
    mappings: BTreeMap<String, Vec<String>>,
    /// In name order (the crate keeps them in a BTreeMap).
    formats: BTreeMap<String, Format>,
}

impl Decoder {
    fn parse(text: &str) -> Decoder {
        let t: toml::Table = text.parse().expect("the decoder is valid TOML");
        let width = t["width"].as_integer().unwrap() as u32;
        let formats_t = t["formats"].as_table().unwrap();
        let mut parts = BTreeMap::new();
        for p in formats_t["parts"].as_array().unwrap() {
            let p = p.as_array().unwrap();
            assert!(
                p.len() == 3 || p.len() == 4,
                "a part is [name, bits, type(, format)]"
            );
            parts.insert(
                p[0].as_str().unwrap().to_string(),
                Part {
                    ty: p[2].as_str().unwrap().to_string(),
                    hex: p.get(3).and_then(|f| f.as_str()) == Some("hex"),
                },
            );
        }
        let types_t = t["types"].as_table().unwrap();
        let mut types = BTreeMap::new();
        for n in types_t["names"].as_array().unwrap() {
            let n = n.as_str().unwrap();
            let slices: Vec<Slice> = types_t[n]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| Slice {
                    field: s["name"].as_str().unwrap().to_string(),
                    top: s["top"].as_integer().unwrap() as u32,
                    bot: s["bot"].as_integer().unwrap() as u32,
                })
                .collect();
            for s in &slices {
                assert!(
                    parts.contains_key(&s.field),
                    "type {n}: no part {}",
                    s.field
                );
            }
            let bits: u32 = slices.iter().map(|s| s.top - s.bot + 1).sum();
            assert_eq!(bits, width, "type {n} covers {bits} bits");
            types.insert(n.to_string(), slices);
        }
        let mut mappings = BTreeMap::new();
        if let Some(m) = t.get("mappings").and_then(|m| m.as_table()) {
            for n in m["names"].as_array().unwrap() {
                let n = n.as_str().unwrap();
                let list = m[n]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_str().unwrap().to_string())
                    .collect();
                mappings.insert(n.to_string(), list);
            }
        }
        for p in parts.values() {
            let builtin = ["u8", "u16", "u32", "u64", "VInt"].contains(&p.ty.as_str());
            assert!(
                builtin || mappings.contains_key(&p.ty),
                "no mapping {}",
                p.ty
            );
        }
        let mut formats = BTreeMap::new();
        for n in formats_t["names"].as_array().unwrap() {
            let n = n.as_str().unwrap();
            let f = t[n].as_table().unwrap();
            let ty = f["type"].as_str().unwrap().to_string();
            assert!(types.contains_key(&ty), "format {n}: no type {ty}");
            let repr = f["repr"]
                .as_table()
                .unwrap()
                .iter()
                .map(|(k, v)| (k.clone(), v.as_str().unwrap().to_string()))
                .collect();
            // toml::Table iterates in key order, as the crate's does.
            let instructions = f["instructions"]
                .as_table()
                .unwrap()
                .iter()
                .map(|(name, i)| Instruction {
                    name: name.clone(),
                    mask: i["mask"].as_integer().unwrap() as u64,
                    matches: i["match"].as_integer().unwrap() as u64,
                    unsigned: i.get("unsigned").and_then(|u| u.as_bool()) == Some(true),
                })
                .collect();
            formats.insert(
                n.to_string(),
                Format {
                    ty,
                    repr,
                    instructions,
                },
            );
        }
        Decoder {
            width,
            parts,
            types,
            mappings,
            formats,
        }
    }

    /// Every match's text, in the crate's order (it shows the last).
    fn decode_all(&self, w: u64) -> Vec<String> {
        let mut out = Vec::new();
        for f in self.formats.values() {
            for i in &f.instructions {
                if w & i.mask == i.matches {
                    out.push(self.display(f, i, w));
                }
            }
        }
        out
    }

    fn display(&self, f: &Format, i: &Instruction, w: u64) -> String {
        // Fields: each slice's bits, taken from the top of the word down,
        // placed at `bot` within its field and OR-ed together.
        let mut values: BTreeMap<&str, u64> = BTreeMap::new();
        let mut pos = 0;
        let slices = &self.types[&f.ty];
        for s in slices {
            let width = s.top - s.bot + 1;
            let bits = (w >> (self.width - pos - width)) & ((1u64 << width) - 1);
            *values.entry(&s.field).or_default() |= bits << s.bot;
            pos += width;
        }
        let text_of = |field: &str| -> String {
            let v = values[field];
            let part = &self.parts[field];
            match part.ty.as_str() {
                "VInt" if !i.unsigned => {
                    // Sign-extended from the field's top bit.
                    let top = slices
                        .iter()
                        .filter(|s| s.field == field)
                        .map(|s| s.top + 1)
                        .max()
                        .unwrap();
                    let signed = ((v << (64 - top)) as i64) >> (64 - top);
                    if part.hex {
                        if signed < 0 {
                            format!("-{:#x}", -signed)
                        } else {
                            format!("{signed:#x}")
                        }
                    } else {
                        signed.to_string()
                    }
                }
                "u8" | "u16" | "u32" | "u64" | "VInt" => {
                    if part.hex {
                        format!("{v:#x}")
                    } else {
                        v.to_string()
                    }
                }
                mapping => self.mappings[mapping][v as usize].clone(),
            }
        };
        let mut s = f
            .repr
            .get(&i.name)
            .or_else(|| f.repr.get("default"))
            .expect("a repr")
            .replace("$name$", &i.name);
        while let Some(b) = s.find('%') {
            let e = b + 1 + s[b + 1..].find('%').expect("closing %");
            let field = s[b + 1..e].to_string();
            s = s.replace(&format!("%{field}%"), &text_of(&field));
        }
        s
    }

    fn decode(&self, w: u32) -> Option<String> {
        self.decode_all(w as u64).pop()
    }
}

fn decoder(path: &str) -> Decoder {
    let text = std::fs::read_to_string(root().join(path))
        .unwrap_or_else(|e| panic!("{path}: {e} (UPDATE_GOLDEN=1 writes it)"));
    Decoder::parse(&text)
}

/// The disassembler's text, with a branch target `.+12` / `.-4` written as
/// the decoder writes it, `.+4+(8)` / `.+4+(-8)`.
fn tinyrisc_text(w: u32) -> String {
    let text = disassemble(w);
    match Instr::decode(w) {
        Ok(i) if matches!(i.op.format(), rtl::tinyrisc::decode::Format::Br) => {
            let cut = text.rfind(", .").unwrap();
            format!("{}, .+4+({})", &text[..cut], 4 * i.imm)
        }
        _ => text,
    }
}

/// Every TinyRISC and context word of a program.
fn words(img: &firmware::asm::Image) -> (Vec<u32>, Vec<u32>) {
    let (mut text, mut ctx) = (Vec::new(), Vec::new());
    for seg in &img.segments {
        let ws = seg
            .data
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]));
        match seg.section {
            firmware::asm::Section::Text => text.extend(ws),
            firmware::asm::Section::Ctx => ctx.extend(ws),
            firmware::asm::Section::Data => {}
        }
    }
    (text, ctx)
}

const TINYRISC: &str = "waves/.surfer/decoders/tinyrisc/tinyrisc.toml";
const CONTEXT: &str = "waves/.surfer/decoders/rc_context/rc_context.toml";

#[test]
fn the_decoder_files_are_the_generated_ones() {
    let update = std::env::var_os("UPDATE_GOLDEN").is_some();
    for (path, text) in tb::surfer::decoder_files() {
        let path = root().join(path);
        if update {
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, &text).unwrap();
            continue;
        }
        let committed = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (UPDATE_GOLDEN=1 writes it)", path.display()));
        assert!(
            committed == text,
            "{} differs from what tb/src/surfer.rs generates (UPDATE_GOLDEN=1 cargo test -p morphosys-tb --test surfer)",
            path.display()
        );
    }
}

#[test]
fn every_word_of_the_programs_decodes_to_the_disassembly() {
    let tr = decoder(TINYRISC);
    let cx = decoder(CONTEXT);
    let mut programs: Vec<PathBuf> = Vec::new();
    for dir in ["firmware/conformance", "firmware/golden"] {
        for e in std::fs::read_dir(root().join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "s") {
                programs.push(p);
            }
        }
    }
    programs.sort();
    assert!(programs.len() >= 20, "{programs:?}");
    let (mut n_text, mut n_ctx) = (0, 0);
    for p in &programs {
        let img = firmware::asm::assemble_file(p).unwrap();
        let (text, ctx) = words(&img);
        for w in text {
            if Instr::decode(w).is_err() {
                continue; // data in .text: no instruction to show
            }
            assert_eq!(
                tr.decode(w).as_deref(),
                Some(tinyrisc_text(w).as_str()),
                "{}: TinyRISC word {w:#010x}",
                p.display()
            );
            n_text += 1;
        }
        for w in ctx {
            let c = Context::decode_wide(w).unwrap_or_else(|e| panic!("{w:#x}: {e}"));
            assert_eq!(
                cx.decode(w).as_deref(),
                Some(c.to_string().as_str()),
                "{}: context word {w:#010x}",
                p.display()
            );
            n_ctx += 1;
        }
    }
    eprintln!(
        "{} programs: {n_text} TinyRISC words, {n_ctx} context words decoded",
        programs.len()
    );
    assert!(n_text > 1000 && n_ctx > 1000, "{n_text} {n_ctx}");
}

#[test]
fn random_legal_words_decode_to_the_disassembly_and_match_one_form() {
    let tr = decoder(TINYRISC);
    let cx = decoder(CONTEXT);
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x as u32
    };
    let (mut legal_text, mut legal_ctx) = (0, 0);
    for k in 0..400_000u32 {
        let mut w = next();
        // Half the words with the low fields zeroed, where the formats
        // that demand zeros (and the counts `8`, `r3`) live.
        if k % 2 == 0 {
            w &= !(0x3FFF >> (k % 14));
        }
        if let Ok(i) = Instr::decode(w) {
            let all = tr.decode_all(w as u64);
            assert_eq!(
                all.last(),
                Some(&tinyrisc_text(w)),
                "TinyRISC {w:#010x}: {all:?}"
            );
            // Only the count operand's forms overlap (the last one shown).
            let counted = matches!(
                i.op.format(),
                rtl::tinyrisc::decode::Format::M1 | rtl::tinyrisc::decode::Format::M2
            );
            assert!(all.len() == 1 || counted, "TinyRISC {w:#010x}: {all:?}");
            legal_text += 1;
        }
        if let Ok(c) = Context::decode_wide(w) {
            let all = cx.decode_all(w as u64);
            assert_eq!(all, [c.to_string()], "context {w:#010x}");
            legal_ctx += 1;
        }
    }
    assert!(
        legal_text > 50_000 && legal_ctx > 50_000,
        "{legal_text} {legal_ctx}"
    );
}

/// The decoding rules above, on a decoder made up here (so that a misread
/// of the format shows up as a failure of this test, not as agreement).
#[test]
fn the_reader_follows_the_format() {
    let d = Decoder::parse(
        r#"
set = "t"
width = 32
[formats]
names = ["f"]
parts = [["op", 8, "u8"], ["r", 4, "R"], ["imm", 20, "VInt"], ["h", 20, "u32", "hex"]]
[types]
names = ["t"]
[[types.t]]
name = "op"
top = 7
bot = 0
[[types.t]]
name = "r"
top = 3
bot = 0
[[types.t]]
name = "imm"
top = 21
bot = 2
[mappings]
names = ["R"]
R = ["zero", "one", "two", "three", "4", "5", "6", "7", "8", "9", "10", "11", "12", "13", "14", "15"]
[f]
type = "t"
[f.repr]
default = "$name$ %r%, %imm%"
[f.instructions.go]
mask = 0xff000000
match = 0x12000000
[f.instructions.up]
mask = 0xff000000
match = 0x13000000
unsigned = true
"#,
    );
    // op 0x12, r 2, imm field all ones: -1 words, shown as bytes (-4).
    assert_eq!(d.decode(0x122F_FFFF).as_deref(), Some("go two, -4"));
    assert_eq!(d.decode(0x132F_FFFF).as_deref(), Some("up two, 4194300"));
    assert_eq!(d.decode(0x1400_0000), None);
}

/// A render's waveform comes with Surfer decoders of the PC and the
/// broadcast unit's context address (`.surfer/decoders/<stem>.code_labels/`
/// and `<stem>.context_labels/` beside it): read as the crate reads them,
/// they name every value the GTKWave filters name, with the same text
/// (which `waveforms.rs` checks against the assembler's symbols).
#[test]
fn a_render_waveform_comes_with_surfer_decoders_of_its_labels() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (ok, _, err) = common::morphosys(
        d,
        &[
            "render",
            "--size",
            "16x16",
            "--vcd",
            "w.vcd",
            "--trace-cycles",
            "3000",
        ],
    );
    assert!(ok, "{err}");
    for (name, width) in [("code_labels", 32), ("context_labels", 13)] {
        let file = d.join(format!(".surfer/decoders/w.{name}/{name}.toml"));
        let dec = Decoder::parse(
            &std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display())),
        );
        assert_eq!(dec.width, width, "{name}");
        let filter = std::fs::read_to_string(d.join(format!("w.{name}.txt"))).unwrap();
        let mut named = 0;
        for line in filter.lines().filter(|l| !l.starts_with('#')) {
            let (value, text) = line.split_once(' ').unwrap();
            let v = u64::from_str_radix(value, 16).unwrap();
            assert_eq!(
                dec.decode_all(v),
                vec![text.to_string()],
                "{name}: {value} decodes to one text, the filter's"
            );
            named += 1;
        }
        assert!(named >= 3, "{name}: {filter}");
        if name == "code_labels" {
            // No PC is odd: left as hex.
            assert!(dec.decode_all(0x7ff).is_empty());
        }
    }
}
