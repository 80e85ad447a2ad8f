//! TinyRISC instruction encoding, decoding and disassembly.
//!
//! 32-bit words, opcode in bits 31..26; registers are 4-bit fields `a`
//! (25..22), `b` (21..18), `c` (17..14). Formats:
//!
//! ```text
//!  31    26 25  22 21  18 17  14 13                 0
//! +--------+------+------+------+--------------------+
//! |   op   |  a   |  b   |  c   |     0 / imm14      |  R, M
//! +--------+------+------+------+--------------------+
//! |   op   |  a   |  b   |        imm18              |  I, B
//! +--------+------+------+---------------------------+
//! |   op   |            target26                     |  J
//! +--------+-----------------------------------------+
//! ```
//!
//! The all-zero word is not an instruction (running into zeroed memory is
//! an illegal-instruction fault). The disassembly ([`Instr`]'s `Display`)
//! is the canonical assembler syntax: the firmware assembler reads it back.

use std::fmt;

/// Instruction formats, by operand syntax.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// No operands.
    None,
    /// `rd, rs, rt` (a, b, c).
    R3,
    /// `rd, rs, imm` signed imm18.
    RIs,
    /// `rd, rs, imm` unsigned imm18.
    RIu,
    /// `rd, imm` (lui) unsigned imm18.
    LUi,
    /// `rt, imm(rs)` loads and stores, signed imm18.
    Mem,
    /// `ra, rb, target` branch: signed imm18 word offset from pc + 4.
    Br,
    /// `target` absolute (target26 << 2).
    J,
    /// `rs`.
    R1,
    /// `rd, rs`.
    R2,
    /// `rd` (status reads).
    Rd,
    /// `ra, rb, count` (count = rc + imm14): DMA, `sbcb`, `cbcr`, `cbcc`.
    M2,
    /// `ra, count`: `cbcast`.
    M1,
    /// `ra, rb, rc, N[, row|col]`: `dbcb`; imm14 = mode << 12 | N, mode 0
    /// SIMD, 1 row, 2 column (3 illegal), N up to 4095.
    M3,
    /// `ra, imm14`: `wfb`.
    MI,
    /// `rd, ra, imm14`: `rcrisc`.
    MRI,
}

macro_rules! opcodes {
    ($($name:ident = $val:expr, $mn:expr, $fmt:ident;)*) => {
        /// TinyRISC opcodes (the numeric value is bits 31..26).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[repr(u8)]
        pub enum Opcode { $($name = $val,)* }

        /// Every opcode, in numeric order.
        pub const ALL_OPCODES: &[Opcode] = &[$(Opcode::$name,)*];

        impl Opcode {
            pub fn mnemonic(self) -> &'static str {
                match self { $(Opcode::$name => $mn,)* }
            }
            pub fn format(self) -> Format {
                match self { $(Opcode::$name => Format::$fmt,)* }
            }
        }

        const OPCODE_TABLE: [Option<Opcode>; 64] = {
            let mut t = [None; 64];
            $(t[$val] = Some(Opcode::$name);)*
            t
        };
    };
}

opcodes! {
    Nop = 0x01, "nop", None;
    Halt = 0x02, "halt", None;
    Rdcyc = 0x03, "rdcyc", Rd;
    Add = 0x04, "add", R3;
    Sub = 0x05, "sub", R3;
    And = 0x06, "and", R3;
    Or = 0x07, "or", R3;
    Xor = 0x08, "xor", R3;
    Nor = 0x09, "nor", R3;
    Sll = 0x0A, "sll", R3;
    Srl = 0x0B, "srl", R3;
    Sra = 0x0C, "sra", R3;
    Slt = 0x0D, "slt", R3;
    Sltu = 0x0E, "sltu", R3;
    Mul = 0x0F, "mul", R3;
    Addi = 0x10, "addi", RIs;
    Andi = 0x11, "andi", RIu;
    Ori = 0x12, "ori", RIu;
    Xori = 0x13, "xori", RIu;
    Slti = 0x14, "slti", RIs;
    Sltiu = 0x15, "sltiu", RIs;
    Slli = 0x16, "slli", RIu;
    Srli = 0x17, "srli", RIu;
    Srai = 0x18, "srai", RIu;
    Lui = 0x19, "lui", LUi;
    Lw = 0x1A, "lw", Mem;
    Lh = 0x1B, "lh", Mem;
    Lhu = 0x1C, "lhu", Mem;
    Lb = 0x1D, "lb", Mem;
    Lbu = 0x1E, "lbu", Mem;
    Sw = 0x1F, "sw", Mem;
    Sh = 0x20, "sh", Mem;
    Sb = 0x21, "sb", Mem;
    Beq = 0x22, "beq", Br;
    Bne = 0x23, "bne", Br;
    Blt = 0x24, "blt", Br;
    Bge = 0x25, "bge", Br;
    Bltu = 0x26, "bltu", Br;
    Bgeu = 0x27, "bgeu", Br;
    J = 0x28, "j", J;
    Jal = 0x29, "jal", J;
    Jr = 0x2A, "jr", R1;
    Jalr = 0x2B, "jalr", R2;
    Rcsl = 0x2C, "rcsl", Rd;
    Rcsh = 0x2D, "rcsh", Rd;
    Lfb = 0x2E, "lfb", Mem;
    Sfb = 0x2F, "sfb", Mem;
    Ldctxt = 0x30, "ldctxt", M2;
    Ldfb = 0x31, "ldfb", M2;
    Stfb = 0x32, "stfb", M2;
    Dwait = 0x33, "dwait", None;
    Cbcast = 0x34, "cbcast", M1;
    Sbcb = 0x35, "sbcb", M2;
    Dbcb = 0x36, "dbcb", M3;
    Cbcr = 0x37, "cbcr", M2;
    Cbcc = 0x38, "cbcc", M2;
    Wfb = 0x39, "wfb", MI;
    Rcrisc = 0x3A, "rcrisc", MRI;
    Rcany = 0x3B, "rcany", Rd;
    Rcall = 0x3C, "rcall", Rd;
    Rcfl = 0x3D, "rcfl", Rd;
    Rcfh = 0x3E, "rcfh", Rd;
    Rcst = 0x3F, "rcst", Rd;
}

impl Opcode {
    pub fn from_bits(v: u8) -> Option<Opcode> {
        OPCODE_TABLE[(v & 63) as usize]
    }

    pub fn from_mnemonic(s: &str) -> Option<Opcode> {
        ALL_OPCODES.iter().copied().find(|o| o.mnemonic() == s)
    }
}

pub const IMM18_MIN: i32 = -(1 << 17);
pub const IMM18_MAX: i32 = (1 << 17) - 1;
pub(crate) const UIMM18_MAX: i32 = (1 << 18) - 1;
pub(crate) const IMM14_MAX: i32 = (1 << 14) - 1;

/// A decoded instruction. `imm` holds the value the format gives it:
/// sign- or zero-extended immediate, the branch word offset, the jump
/// target byte address, or imm14.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Instr {
    pub op: Opcode,
    pub a: u8,
    pub b: u8,
    pub c: u8,
    pub imm: i32,
}

/// Why a word is not an instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IllegalInstruction(pub u32);

impl fmt::Display for IllegalInstruction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "illegal instruction 0x{:08x}", self.0)
    }
}

/// Why an instruction cannot be encoded (the assembler reports it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EncodeError(pub String);

impl Instr {
    pub fn new(op: Opcode, a: u8, b: u8, c: u8, imm: i32) -> Instr {
        Instr { op, a, b, c, imm }
    }

    pub fn decode(w: u32) -> Result<Instr, IllegalInstruction> {
        let op = Opcode::from_bits((w >> 26) as u8).ok_or(IllegalInstruction(w))?;
        let a = ((w >> 22) & 15) as u8;
        let b = ((w >> 18) & 15) as u8;
        let c = ((w >> 14) & 15) as u8;
        let i18 = w & 0x3FFFF;
        let s18 = ((i18 << 14) as i32) >> 14;
        let i14 = (w & 0x3FFF) as i32;
        let ins = |a, b, c, imm| Ok(Instr { op, a, b, c, imm });
        let zero = |mask: u32| {
            if w & mask != 0 {
                Err(IllegalInstruction(w))
            } else {
                Ok(())
            }
        };
        match op.format() {
            Format::None => {
                zero(0x03FF_FFFF)?;
                ins(0, 0, 0, 0)
            }
            Format::R3 => {
                zero(0x3FFF)?;
                ins(a, b, c, 0)
            }
            Format::RIs | Format::Mem | Format::Br => ins(a, b, 0, s18),
            Format::RIu => ins(a, b, 0, i18 as i32),
            Format::LUi => {
                zero(0xF << 18)?;
                ins(a, 0, 0, i18 as i32)
            }
            Format::J => ins(0, 0, 0, ((w & 0x03FF_FFFF) << 2) as i32),
            Format::R1 | Format::Rd => {
                zero(0x003F_FFFF)?;
                ins(a, 0, 0, 0)
            }
            Format::R2 => {
                zero(0x0003_FFFF)?;
                ins(a, b, 0, 0)
            }
            Format::M2 => ins(a, b, c, i14),
            Format::M3 => {
                if i14 >> 12 == 3 {
                    return Err(IllegalInstruction(w));
                }
                ins(a, b, c, i14)
            }
            Format::M1 => {
                zero(0xF << 18)?;
                ins(a, 0, c, i14)
            }
            Format::MI => {
                zero(0xFF << 14)?;
                ins(a, 0, 0, i14)
            }
            Format::MRI => {
                zero(0xF << 14)?;
                ins(a, b, 0, i14)
            }
        }
    }

    /// Encode, checking every field's range.
    pub fn encode(&self) -> Result<u32, EncodeError> {
        let r = |v: u8| -> Result<u32, EncodeError> {
            if v < 16 {
                Ok(v as u32)
            } else {
                Err(EncodeError(format!(
                    "register r{v} does not exist (r0..r15)"
                )))
            }
        };
        let range = |v: i32, lo: i32, hi: i32, what: &str| -> Result<u32, EncodeError> {
            if (lo..=hi).contains(&v) {
                Ok(v as u32)
            } else {
                Err(EncodeError(format!("{what} {v} out of range {lo}..={hi}")))
            }
        };
        let (a, b, c) = (r(self.a)? << 22, r(self.b)? << 18, r(self.c)? << 14);
        let op = (self.op as u32) << 26;
        let w = match self.op.format() {
            Format::None => op,
            Format::R3 => op | a | b | c,
            Format::RIs | Format::Mem => {
                op | a | b | (range(self.imm, IMM18_MIN, IMM18_MAX, "immediate")? & 0x3FFFF)
            }
            Format::Br => {
                op | a
                    | b
                    | (range(self.imm, IMM18_MIN, IMM18_MAX, "branch offset (words)")? & 0x3FFFF)
            }
            Format::RIu => op | a | b | range(self.imm, 0, UIMM18_MAX, "unsigned immediate")?,
            Format::LUi => op | a | range(self.imm, 0, UIMM18_MAX, "unsigned immediate")?,
            Format::J => {
                let t = self.imm as u32;
                if t & 3 != 0 || t >= 1 << 28 {
                    return Err(EncodeError(format!(
                        "jump target 0x{t:x} not a word address below 0x10000000"
                    )));
                }
                op | t >> 2
            }
            Format::R1 | Format::Rd => op | a,
            Format::R2 => op | a | b,
            Format::M2 => op | a | b | c | range(self.imm, 0, IMM14_MAX, "count")?,
            Format::M3 => op | a | b | c | range(self.imm, 0, (2 << 12) | 4095, "mode/count")?,
            Format::M1 => op | a | c | range(self.imm, 0, IMM14_MAX, "count")?,
            Format::MI => op | a | range(self.imm, 0, IMM14_MAX, "offset")?,
            Format::MRI => op | a | b | range(self.imm, 0, IMM14_MAX, "lane offset")?,
        };
        Ok(w)
    }

    /// Count operand `rc + imm14` as written.
    fn count(&self) -> String {
        match (self.c, self.imm) {
            (0, i) => format!("{i}"),
            (c, 0) => format!("r{c}"),
            (c, i) => format!("r{c}+{i}"),
        }
    }
}

impl fmt::Display for Instr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = self.op.mnemonic();
        let (a, b, c, i) = (self.a, self.b, self.c, self.imm);
        match self.op.format() {
            Format::None => write!(f, "{m}"),
            Format::R3 => write!(f, "{m} r{a}, r{b}, r{c}"),
            Format::RIs | Format::RIu => write!(f, "{m} r{a}, r{b}, {i}"),
            Format::LUi => write!(f, "{m} r{a}, {i}"),
            Format::Mem => write!(f, "{m} r{a}, {i}(r{b})"),
            Format::Br => {
                let d = 4 + 4 * i as i64;
                if d >= 0 {
                    write!(f, "{m} r{a}, r{b}, .+{d}")
                } else {
                    write!(f, "{m} r{a}, r{b}, .{d}")
                }
            }
            Format::J => write!(f, "{m} 0x{:x}", i as u32),
            Format::R1 | Format::Rd => write!(f, "{m} r{a}"),
            Format::R2 => write!(f, "{m} r{a}, r{b}"),
            Format::M2 => write!(f, "{m} r{a}, r{b}, {}", self.count()),
            Format::M1 => write!(f, "{m} r{a}, {}", self.count()),
            Format::M3 => {
                let mode = ["", ", row", ", col", ", ?"][(i >> 12 & 3) as usize];
                write!(f, "{m} r{a}, r{b}, r{c}, {}{mode}", i & 4095)
            }
            Format::MI => write!(f, "{m} r{a}, {i}"),
            Format::MRI => write!(f, "{m} r{a}, r{b}, {i}"),
        }
    }
}

/// Disassemble a word: the instruction, or `.word 0x...` when illegal.
pub fn disassemble(w: u32) -> String {
    match Instr::decode(w) {
        Ok(i) => i.to_string(),
        Err(_) => format!(".word 0x{w:08x}"),
    }
}

fn instr_text(v: u64) -> Option<String> {
    Instr::decode(v as u32).ok().map(|i| i.to_string())
}

/// Translate filter for waveforms: instruction word to its disassembly.
pub(crate) static INSTR_FILTER: crate::trace::Filter = crate::trace::Filter {
    name: "tinyrisc_instr",
    text: instr_text,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_opcode_round_trips() {
        for &op in ALL_OPCODES {
            let i = match op.format() {
                Format::None => Instr::new(op, 0, 0, 0, 0),
                Format::R3 => Instr::new(op, 1, 2, 15, 0),
                Format::RIs | Format::Mem | Format::Br => Instr::new(op, 3, 4, 0, -7),
                Format::RIu => Instr::new(op, 3, 4, 0, UIMM18_MAX),
                Format::LUi => Instr::new(op, 5, 0, 0, 0x2ABCD),
                Format::J => Instr::new(op, 0, 0, 0, 0x0FFF_FFFC),
                Format::R1 | Format::Rd => Instr::new(op, 9, 0, 0, 0),
                Format::R2 => Instr::new(op, 9, 10, 0, 0),
                Format::M2 => Instr::new(op, 1, 2, 3, IMM14_MAX),
                Format::M3 => Instr::new(op, 1, 2, 3, 2 << 12 | 4095),
                Format::M1 => Instr::new(op, 1, 0, 3, 17),
                Format::MI => Instr::new(op, 6, 0, 0, 64),
                Format::MRI => Instr::new(op, 6, 7, 0, 63),
            };
            let w = i.encode().unwrap();
            assert_eq!(Instr::decode(w), Ok(i), "{op:?}");
            assert_eq!((w >> 26) as u8, op as u8);
        }
    }

    #[test]
    fn illegal_words_and_fields() {
        assert!(Instr::decode(0).is_err());
        assert!(Instr::decode((Opcode::Rcst as u32) << 26 | 1).is_err());
        assert!(Instr::decode((Opcode::Add as u32) << 26 | 1).is_err());
        assert!(Instr::new(Opcode::Addi, 1, 1, 0, 1 << 17).encode().is_err());
        assert!(Instr::new(Opcode::Andi, 1, 1, 0, -1).encode().is_err());
        assert!(Instr::new(Opcode::J, 0, 0, 0, 2).encode().is_err());
    }

    #[test]
    fn disassembly_is_canonical() {
        assert_eq!(
            Instr::new(Opcode::Beq, 1, 2, 0, -2).to_string(),
            "beq r1, r2, .-4"
        );
        assert_eq!(
            Instr::new(Opcode::Lw, 1, 2, 0, -8).to_string(),
            "lw r1, -8(r2)"
        );
        assert_eq!(
            Instr::new(Opcode::Ldfb, 1, 2, 3, 4).to_string(),
            "ldfb r1, r2, r3+4"
        );
        assert_eq!(
            Instr::new(Opcode::Cbcast, 1, 0, 0, 9).to_string(),
            "cbcast r1, 9"
        );
        assert_eq!(disassemble(0), ".word 0x00000000");
    }
}
