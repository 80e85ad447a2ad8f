//! The assembled program: segments of main memory, an entry point, the
//! symbols; a small binary file format for `morphosys asm -o`, and the
//! disassembler that lists an image.
//!
//! File format (little-endian): magic `MSYSIMG1`, entry `u32`, segment count
//! `u32`, then per segment: address `u32`, section `u8` (0 text, 1 data,
//! 2 ctx), length `u32`, bytes.

use std::collections::BTreeMap;
use std::fmt::Write;

use rtl::rc::context::Context;
use rtl::tinyrisc::decode::disassemble;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Section {
    Text = 0,
    Data = 1,
    Ctx = 2,
}

impl Section {
    pub fn name(self) -> &'static str {
        match self {
            Section::Text => ".text",
            Section::Data => ".data",
            Section::Ctx => ".ctx",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Segment {
    pub addr: u32,
    pub section: Section,
    pub data: Vec<u8>,
}

#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct Image {
    pub entry: u32,
    pub segments: Vec<Segment>,
    pub symbols: BTreeMap<String, i64>,
    /// The labels (`name:`, not constants), with their sections, in
    /// address order: what a waveform or a profile names an address by.
    /// Not kept in the image file.
    pub labels: Vec<Label>,
}

/// A label of the source: its name, its section and its address.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Label {
    pub addr: u32,
    pub section: Section,
    pub name: String,
}

const MAGIC: &[u8; 8] = b"MSYSIMG1";

impl Image {
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut v = MAGIC.to_vec();
        v.extend(self.entry.to_le_bytes());
        v.extend((self.segments.len() as u32).to_le_bytes());
        for s in &self.segments {
            v.extend(s.addr.to_le_bytes());
            v.push(s.section as u8);
            v.extend((s.data.len() as u32).to_le_bytes());
            v.extend(&s.data);
        }
        v
    }

    /// Is this an image file (rather than assembly source)?
    pub fn is_image(bytes: &[u8]) -> bool {
        bytes.starts_with(MAGIC)
    }

    pub fn from_bytes(b: &[u8]) -> Result<Image, String> {
        let bad = || "not a morphosys image (truncated or corrupt)".to_string();
        if !Self::is_image(b) {
            return Err("not a morphosys image (no MSYSIMG1 header)".into());
        }
        let mut p = 8usize;
        let u32_at = |p: &mut usize| -> Result<u32, String> {
            let s = b.get(*p..*p + 4).ok_or_else(bad)?;
            *p += 4;
            Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
        };
        let entry = u32_at(&mut p)?;
        let n = u32_at(&mut p)?;
        let mut segments = Vec::new();
        for _ in 0..n {
            let addr = u32_at(&mut p)?;
            let sec = match b.get(p) {
                Some(0) => Section::Text,
                Some(1) => Section::Data,
                Some(2) => Section::Ctx,
                _ => return Err(bad()),
            };
            p += 1;
            let len = u32_at(&mut p)? as usize;
            let data = b
                .get(p..p.checked_add(len).ok_or_else(bad)?)
                .ok_or_else(bad)?
                .to_vec();
            p += len;
            segments.push(Segment {
                addr,
                section: sec,
                data,
            });
        }
        Ok(Image {
            entry,
            segments,
            symbols: BTreeMap::new(),
            labels: Vec::new(),
        })
    }

    /// Copy the segments into a chip's main memory and set its entry.
    pub fn load<W: rtl::rc::Word>(&self, chip: &mut rtl::Chip<W>) -> Result<(), rtl::Fault> {
        for s in &self.segments {
            chip.load(s.addr, &s.data)?;
        }
        chip.set_entry(self.entry);
        Ok(())
    }

    /// The address of a symbol.
    pub fn symbol(&self, name: &str) -> Option<i64> {
        self.symbols.get(name).copied()
    }

    /// The labels a waveform names addresses by: the code labels (byte
    /// addresses) and the context labels as context-memory indices, the
    /// context words at main-memory address `ctx_base` being loaded into
    /// context 0 (the `.ctx` label `k_x: ` at `ctx_base + 4 i` names
    /// context i).
    pub fn trace_labels(&self, ctx_base: u32) -> rtl::trace::Labels {
        rtl::trace::Labels {
            code: self
                .labels_in(Section::Text)
                .map(|l| (l.addr, l.name.clone()))
                .collect(),
            context: self
                .labels_in(Section::Ctx)
                .filter(|l| l.addr >= ctx_base && (l.addr - ctx_base).is_multiple_of(4))
                .map(|l| ((l.addr - ctx_base) / 4, l.name.clone()))
                .collect(),
        }
    }

    /// The lowest address of the `.ctx` segments (where a program that
    /// loads its contexts whole starts them).
    pub fn ctx_base(&self) -> Option<u32> {
        self.segments
            .iter()
            .filter(|s| s.section == Section::Ctx)
            .map(|s| s.addr)
            .min()
    }

    /// The labels of one section, in address order.
    pub fn labels_in(&self, section: Section) -> impl Iterator<Item = &Label> {
        self.labels.iter().filter(move |l| l.section == section)
    }

    /// `label+offset` for an address of `section` (the nearest label at or
    /// before it; `label` alone at the label), or `None` before the
    /// section's first label.
    pub fn locate(&self, section: Section, addr: u32) -> Option<String> {
        let l = self
            .labels_in(section)
            .take_while(|l| l.addr <= addr)
            .last()?;
        Some(match addr - l.addr {
            0 => l.name.clone(),
            d => format!("{}+{d}", l.name),
        })
    }
}

/// A listing: address, word and disassembly of every word of `.text` and
/// `.ctx`, and the data of `.data`.
pub fn disassemble_image(img: &Image) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "; entry 0x{:08x}", img.entry);
    for seg in &img.segments {
        let _ = writeln!(s, "{}\n.org 0x{:x}", seg.section.name(), seg.addr);
        match seg.section {
            Section::Data => {
                for (k, chunk) in seg.data.chunks(16).enumerate() {
                    let bytes: Vec<String> = chunk.iter().map(|b| format!("0x{b:02x}")).collect();
                    let _ = writeln!(
                        s,
                        "    .byte {:<80} ; {:08x}",
                        bytes.join(", "),
                        seg.addr as usize + 16 * k
                    );
                }
            }
            _ => {
                let mut k = 0;
                while k + 4 <= seg.data.len() {
                    let w = u32::from_le_bytes([
                        seg.data[k],
                        seg.data[k + 1],
                        seg.data[k + 2],
                        seg.data[k + 3],
                    ]);
                    let text = if seg.section == Section::Text {
                        disassemble(w)
                    } else {
                        match Context::decode(w) {
                            Ok(c) => c.to_string(),
                            Err(_) => format!(".word 0x{w:08x}"),
                        }
                    };
                    let _ = writeln!(s, "    {text:<40} ; {:08x}: {w:08x}", seg.addr as usize + k);
                    k += 4;
                }
                if k < seg.data.len() {
                    let bytes: Vec<String> =
                        seg.data[k..].iter().map(|b| format!("0x{b:02x}")).collect();
                    let _ = writeln!(s, "    .byte {}", bytes.join(", "));
                }
            }
        }
    }
    s
}
