//! The RC context word: 32 bits broadcast to the RCs each cycle.
//!
//! Layout (bit 31 on the left), documented with the operation set in
//! `docs/isa.md`:
//!
//! ```text
//!  31    26 25 24 23 22   19 18  16 15  12 11 10           0
//! +--------+-----+--+-------+------+------+--+--------------+
//! |   op   |guard|we|  rd   | asrc |  ra  |bs|      f       |
//! +--------+-----+--+-------+------+------+--+--------------+
//! ```
//!
//! * `op`    operation (see [`Op`]).
//! * `guard` 0 always, 1 only where the flag F is set, 2 only where F is clear.
//! * `we`    write the result to register `rd` (the output register is always
//!   written by an operation that has a result).
//! * `rd`    destination register; for `CMP` the condition ([`Cond`]).
//! * `asrc`  source of operand A ([`ASrc`]); `ra` is the register or, for the
//!   interconnect sources, the direction / lane index.
//! * `bs`    0: operand B is register `f[3:0]`, `f[8:4]` is the multiplier
//!   shift and `f[9]` selects truncation instead of rounding;
//!   `f[10]` is reserved (0) on the 16-bit chip and bit 5 of the
//!   shift (0..=63) on the 32-bit chip ([`Context::decode_wide`]);
//!   1: operand B is the 11-bit signed immediate `f`.
//!
//! A context word is decoded once ([`Context::decode`]) into a [`Context`];
//! the array executes the decoded form, so 64 RCs never decode 64 times.

use std::fmt;

/// What an operation's operands are, as the assembler writes them (the
/// disassembler, the Surfer decoder and the docs' syntax column follow
/// it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Form {
    /// `nop`, `sleep`, `wake`: no operands, no result.
    None,
    /// `cmp.COND A, B`: sets F, no result.
    Compare,
    /// `st A, [B]`: no result.
    Store,
    /// `ld D, [A + B]`.
    Load,
    /// `op D, A`.
    Unary,
    /// `movb D, B`.
    MoveB,
    /// `op D, A, B`.
    Binary,
    /// `op[.t] D, A, B [, >>SH]`: the multiplier's product, shifted.
    Multiply,
    /// `acc[.t] D [, >>SH]`: the accumulator, shifted.
    AccRead,
    /// `acch D`, `accl D`: a half of the accumulator.
    AccPart,
    /// `ldacc[.t] A [, <<SH]`: the accumulator loaded, no result.
    AccLoad,
}

/// The RC unit an operation runs on (`docs/isa.md`; the Verilog unit
/// files `rc_alu.v`, `rc_shifter.v`, `rc_multiplier.v`, `rc_ram.v`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Unit {
    /// No unit: `nop`.
    None,
    Alu,
    Shifter,
    Multiplier,
    Ram,
    /// The sleep flag.
    Power,
}

/// The operation set from one table: each row's variant, opcode (the `op`
/// field), mnemonic, operand form and unit. Every operation takes one
/// cycle. The enum, [`ALL_OPS`], the mnemonics, the assembler's and the
/// Surfer decoder's operand forms and the Verilog `rc_isa.vh`
/// ([`super::isa_vh`]) all come from it.
macro_rules! rc_ops {
    ($($variant:ident = $code:literal, $mn:literal, $form:ident, $unit:ident;)*) => {
        /// Operations of the RC datapath. The numeric value is the `op` field.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[repr(u8)]
        pub enum Op {
            $($variant = $code,)*
        }

        /// Every operation, in opcode order; the disassembler and docs tests walk it.
        pub const ALL_OPS: &[Op] = &[$(Op::$variant,)*];

        impl Op {
            pub fn mnemonic(self) -> &'static str {
                match self {
                    $(Op::$variant => $mn,)*
                }
            }

            /// Its operands, as the assembler writes them.
            pub fn form(self) -> Form {
                match self {
                    $(Op::$variant => Form::$form,)*
                }
            }

            /// The unit it runs on.
            pub fn unit(self) -> Unit {
                match self {
                    $(Op::$variant => Unit::$unit,)*
                }
            }
        }
    };
}

rc_ops! {
    Nop    = 0x00, "nop", None, None;
    Add    = 0x01, "add", Binary, Alu;
    Adc    = 0x02, "adc", Binary, Alu;
    Sub    = 0x03, "sub", Binary, Alu;
    Sbc    = 0x04, "sbc", Binary, Alu;
    Rsb    = 0x05, "rsb", Binary, Alu;
    Adds   = 0x06, "adds", Binary, Alu;
    Subs   = 0x07, "subs", Binary, Alu;
    And    = 0x08, "and", Binary, Alu;
    Or     = 0x09, "or", Binary, Alu;
    Xor    = 0x0A, "xor", Binary, Alu;
    Not    = 0x0B, "not", Unary, Alu;
    Mov    = 0x0C, "mov", Unary, Alu;
    Movb   = 0x0D, "movb", MoveB, Alu;
    Min    = 0x0E, "min", Binary, Alu;
    Max    = 0x0F, "max", Binary, Alu;
    Abs    = 0x10, "abs", Unary, Alu;
    Absd   = 0x11, "absd", Binary, Alu;
    Neg    = 0x12, "neg", Unary, Alu;
    Cmp    = 0x13, "cmp", Compare, Alu;
    Sel    = 0x14, "sel", Binary, Alu;
    Clz    = 0x15, "clz", Unary, Alu;
    Sll    = 0x18, "sll", Binary, Shifter;
    Srl    = 0x19, "srl", Binary, Shifter;
    Sra    = 0x1A, "sra", Binary, Shifter;
    Asl    = 0x1B, "asl", Binary, Shifter;
    Mul    = 0x20, "mul", Multiply, Multiplier;
    Mac    = 0x21, "mac", Multiply, Multiplier;
    Msu    = 0x22, "msu", Multiply, Multiplier;
    Acc    = 0x23, "acc", AccRead, Multiplier;
    Acch   = 0x24, "acch", AccPart, Multiplier;
    Accl   = 0x25, "accl", AccPart, Multiplier;
    Ldacc  = 0x26, "ldacc", AccLoad, Multiplier;
    Ld     = 0x28, "ld", Load, Ram;
    St     = 0x29, "st", Store, Ram;
    Sleep  = 0x30, "sleep", None, Power;
    Wake   = 0x31, "wake", None, Power;
}

impl Op {
    pub fn from_bits(v: u8) -> Option<Op> {
        ALL_OPS.iter().copied().find(|o| *o as u8 == v)
    }

    /// Does the operation produce a 16-bit result (written to `out`, and to
    /// `rd` when `we` is set)?
    pub fn has_result(self) -> bool {
        !matches!(
            self.form(),
            Form::None | Form::Compare | Form::Store | Form::AccLoad
        )
    }

    /// Operations that use the multiplier's shift field.
    pub fn uses_shift(self) -> bool {
        matches!(self.form(), Form::Multiply | Form::AccRead | Form::AccLoad)
    }
}

/// Guard: which RCs execute the context.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Guard {
    Always = 0,
    IfF = 1,
    IfNotF = 2,
}

/// Source of operand A.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ASrc {
    /// Register `ra` of the RC's own register file.
    Reg = 0,
    /// The RC's own output register.
    Out = 1,
    /// Output register of a neighbour; `ra[1:0]`: 0 north, 1 south, 2 west, 3 east.
    Nbr = 2,
    /// Horizontal short lane: the RC in the same row and quadrant at quadrant
    /// column `ra[1:0]`.
    QRow = 3,
    /// Vertical short lane: same column and quadrant, quadrant row `ra[1:0]`.
    QCol = 4,
    /// Horizontal express lane: the RC of the same row at column `ra[2:0]`.
    XRow = 5,
    /// Vertical express lane: the RC of the same column at row `ra[2:0]`.
    XCol = 6,
    /// Frame-buffer broadcast datum of set `ra[0]`.
    Fb = 7,
}

impl ASrc {
    fn from_bits(v: u32) -> ASrc {
        match v & 7 {
            0 => ASrc::Reg,
            1 => ASrc::Out,
            2 => ASrc::Nbr,
            3 => ASrc::QRow,
            4 => ASrc::QCol,
            5 => ASrc::XRow,
            6 => ASrc::XCol,
            _ => ASrc::Fb,
        }
    }
}

/// Source of operand B.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BSrc {
    Reg(u8),
    Imm(i16),
}

/// Conditions of `CMP` (in the `rd` field). Signed unless marked `u`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Cond {
    Eq = 0,
    Ne = 1,
    Lt = 2,
    Ge = 3,
    Le = 4,
    Gt = 5,
    Ltu = 6,
    Geu = 7,
    Leu = 8,
    Gtu = 9,
    /// Carry/borrow flag set.
    Cs = 10,
    /// Overflow flag set.
    Vs = 11,
    True = 12,
    False = 13,
    /// `A & B != 0`.
    Bit = 14,
    /// `A & B == 0`.
    Nbit = 15,
}

pub const ALL_CONDS: [Cond; 16] = [
    Cond::Eq,
    Cond::Ne,
    Cond::Lt,
    Cond::Ge,
    Cond::Le,
    Cond::Gt,
    Cond::Ltu,
    Cond::Geu,
    Cond::Leu,
    Cond::Gtu,
    Cond::Cs,
    Cond::Vs,
    Cond::True,
    Cond::False,
    Cond::Bit,
    Cond::Nbit,
];

impl Cond {
    pub fn from_bits(v: u8) -> Cond {
        ALL_CONDS[(v & 15) as usize]
    }
    pub fn mnemonic(self) -> &'static str {
        use Cond::*;
        match self {
            Eq => "eq",
            Ne => "ne",
            Lt => "lt",
            Ge => "ge",
            Le => "le",
            Gt => "gt",
            Ltu => "ltu",
            Geu => "geu",
            Leu => "leu",
            Gtu => "gtu",
            Cs => "cs",
            Vs => "vs",
            True => "true",
            False => "false",
            Bit => "bit",
            Nbit => "nbit",
        }
    }
}

/// A decoded context word.
///
/// Aligned to 16 bytes so a copy is one 16-byte move: the broadcast unit
/// stores a context and the array loads it in the same cycle, and a load
/// that spans several smaller stores cannot be forwarded (the array's eval
/// then stalls on it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(align(16))]
pub struct Context {
    pub op: Op,
    pub guard: Guard,
    pub we: bool,
    pub rd: u8,
    pub asrc: ASrc,
    pub ra: u8,
    pub b: BSrc,
    /// Multiplier shift amount, 0..=31 on the 16-bit chip, 0..=63 on the
    /// 32-bit chip (register form only; 0 with an immediate).
    pub shift: u8,
    /// Multiplier result truncated (floor) instead of rounded to nearest.
    pub trunc: bool,
}

/// Why a context word does not decode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    IllegalOp(u8),
    IllegalGuard,
    /// Spare bits of the register form are not zero.
    ReservedBits,
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DecodeError::IllegalOp(o) => write!(f, "illegal RC opcode 0x{o:02x}"),
            DecodeError::IllegalGuard => write!(f, "illegal guard field 3"),
            DecodeError::ReservedBits => write!(
                f,
                "reserved context bit 10 set (a multiplier shift above 31 needs the 32-bit datapath)"
            ),
        }
    }
}

impl std::error::Error for DecodeError {}

impl Context {
    pub const NOP: Context = Context {
        op: Op::Nop,
        guard: Guard::Always,
        we: false,
        rd: 0,
        asrc: ASrc::Reg,
        ra: 0,
        b: BSrc::Reg(0),
        shift: 0,
        trunc: false,
    };

    /// `cut`: a `nop` whose operand B is the immediate 1 and every other
    /// field 0. The RCs execute it as a `nop`; the broadcast unit ends the
    /// run after it where no awake RC has F ([`crate::broadcast`]). Only
    /// this exact word is a cut: any other `nop` is a `nop`.
    pub const CUT: Context = Context {
        b: BSrc::Imm(1),
        ..Context::NOP
    };

    /// The context word of [`Context::CUT`].
    pub const CUT_WORD: u32 = 1 << 11 | 1;

    /// Is this context a [`Context::CUT`]?
    #[inline(always)]
    pub fn is_cut(&self) -> bool {
        *self == Context::CUT
    }

    /// A context with operand A from register `ra`, B from register `rb`,
    /// result to `rd`.
    pub fn rrr(op: Op, rd: u8, ra: u8, rb: u8) -> Context {
        Context {
            op,
            we: op.has_result(),
            rd,
            ra,
            b: BSrc::Reg(rb),
            ..Context::NOP
        }
    }

    /// Operand A from register `ra`, B the immediate `imm` (-1024..=1023).
    pub fn rri(op: Op, rd: u8, ra: u8, imm: i16) -> Context {
        Context {
            op,
            we: op.has_result(),
            rd,
            ra,
            b: BSrc::Imm(imm),
            ..Context::NOP
        }
    }

    /// Decode for the 16-bit chip: `f[10]` of the register form is reserved.
    pub fn decode(w: u32) -> Result<Context, DecodeError> {
        Self::decode_for(w, false)
    }

    /// Decode for the 32-bit chip: `f[10]` of the register form is bit 5 of
    /// the multiplier shift (0..=63).
    pub fn decode_wide(w: u32) -> Result<Context, DecodeError> {
        Self::decode_for(w, true)
    }

    /// Decode for the datapath `wide` (32-bit) or not.
    pub fn decode_for(w: u32, wide: bool) -> Result<Context, DecodeError> {
        let opb = (w >> 26) as u8;
        let op = Op::from_bits(opb).ok_or(DecodeError::IllegalOp(opb))?;
        let guard = match (w >> 24) & 3 {
            0 => Guard::Always,
            1 => Guard::IfF,
            2 => Guard::IfNotF,
            _ => return Err(DecodeError::IllegalGuard),
        };
        let f = w & 0x7FF;
        let (b, shift, trunc) = if w & (1 << 11) != 0 {
            // sign-extend 11 bits
            (BSrc::Imm(((f << 5) as i16) >> 5), 0, false)
        } else {
            if f & (1 << 10) != 0 && !wide {
                return Err(DecodeError::ReservedBits);
            }
            (
                BSrc::Reg((f & 15) as u8),
                ((f >> 4) & 31 | (f >> 5) & 32) as u8,
                f & (1 << 9) != 0,
            )
        };
        Ok(Context {
            op,
            guard,
            we: w & (1 << 23) != 0,
            rd: ((w >> 19) & 15) as u8,
            asrc: ASrc::from_bits(w >> 16),
            ra: ((w >> 12) & 15) as u8,
            b,
            shift,
            trunc,
        })
    }

    /// Encode; panics only on a field out of range, which is a bug in the caller
    /// (the assembler range-checks user input before building a `Context`).
    pub fn encode(&self) -> u32 {
        assert!(self.rd < 16 && self.ra < 16 && self.shift < 64);
        let f = match self.b {
            BSrc::Reg(rb) => {
                assert!(rb < 16);
                let sh = self.shift as u32;
                rb as u32 | (sh & 31) << 4 | (self.trunc as u32) << 9 | (sh >> 5) << 10
            }
            BSrc::Imm(i) => {
                assert!((-1024..=1023).contains(&i), "immediate {i} out of range");
                (1 << 11) | (i as u32 & 0x7FF)
            }
        };
        (self.op as u32) << 26
            | (self.guard as u32) << 24
            | (self.we as u32) << 23
            | (self.rd as u32) << 19
            | (self.asrc as u32) << 16
            | (self.ra as u32) << 12
            | f
    }

    /// Condition of a `CMP`.
    pub fn cond(&self) -> Cond {
        Cond::from_bits(self.rd)
    }
}

impl fmt::Display for Context {
    /// The disassembly; the assembler of the firmware crate reads it back.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_cut() {
            return write!(f, "cut");
        }
        match self.guard {
            Guard::Always => {}
            Guard::IfF => write!(f, "(f) ")?,
            Guard::IfNotF => write!(f, "(!f) ")?,
        }
        write!(f, "{}", self.op.mnemonic())?;
        if self.op.form() == Form::Compare {
            write!(f, ".{}", self.cond().mnemonic())?;
        }
        if self.op.uses_shift() && self.trunc {
            write!(f, ".t")?;
        }
        let a = match self.asrc {
            ASrc::Reg => format!("r{}", self.ra),
            ASrc::Out => "out".to_string(),
            ASrc::Nbr => ["n", "s", "w", "e"][(self.ra & 3) as usize].to_string(),
            ASrc::QRow => format!("qrow{}", self.ra & 3),
            ASrc::QCol => format!("qcol{}", self.ra & 3),
            ASrc::XRow => format!("xrow{}", self.ra & 7),
            ASrc::XCol => format!("xcol{}", self.ra & 7),
            ASrc::Fb => format!("fb{}", self.ra & 1),
        };
        let b = match self.b {
            BSrc::Reg(r) => format!("r{r}"),
            BSrc::Imm(i) => format!("#{i}"),
        };
        let d = if self.we {
            format!("r{}", self.rd)
        } else {
            "out".to_string()
        };
        let sh = if self.op.uses_shift() && self.shift != 0 {
            format!(", >>{}", self.shift)
        } else {
            String::new()
        };
        match self.op.form() {
            Form::None => Ok(()),
            Form::Compare => write!(f, " {a}, {b}"),
            Form::Store => write!(f, " {a}, [{b}]"),
            Form::Load => write!(f, " {d}, [{a} + {b}]"),
            Form::Unary => write!(f, " {d}, {a}"),
            Form::MoveB => write!(f, " {d}, {b}"),
            Form::AccRead | Form::AccPart => write!(f, " {d}{sh}"),
            Form::AccLoad if self.shift != 0 => write!(f, " {a}, <<{}", self.shift),
            Form::AccLoad => write!(f, " {a}"),
            Form::Binary | Form::Multiply => write!(f, " {d}, {a}, {b}{sh}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cut_is_one_nop_word() {
        assert_eq!(Context::CUT.encode(), Context::CUT_WORD);
        assert_eq!(Context::decode(Context::CUT_WORD), Ok(Context::CUT));
        assert_eq!(Context::CUT.to_string(), "cut");
        // a nop with another immediate, or guarded, is no cut
        for w in [1 << 11 | 2, 1 << 24 | 1 << 11 | 1, 0] {
            let c = Context::decode(w).unwrap();
            assert_eq!(c.op, Op::Nop);
            assert!(!c.is_cut(), "{w:#x}");
        }
    }

    #[test]
    fn every_op_round_trips_through_its_encoding() {
        for &op in ALL_OPS {
            for (asrc, ra) in [(ASrc::Reg, 3), (ASrc::Nbr, 2), (ASrc::Fb, 1)] {
                for b in [BSrc::Reg(7), BSrc::Imm(-1024), BSrc::Imm(1023)] {
                    let c = Context {
                        op,
                        guard: Guard::IfNotF,
                        we: true,
                        rd: 9,
                        asrc,
                        ra,
                        b,
                        shift: if matches!(b, BSrc::Reg(_)) { 12 } else { 0 },
                        trunc: matches!(b, BSrc::Reg(_)),
                    };
                    assert_eq!(Context::decode(c.encode()), Ok(c), "{op:?}");
                }
            }
        }
    }

    #[test]
    fn illegal_words_are_refused() {
        assert_eq!(
            Context::decode(0x3F << 26),
            Err(DecodeError::IllegalOp(0x3F))
        );
        assert_eq!(Context::decode(3 << 24), Err(DecodeError::IllegalGuard));
        assert_eq!(Context::decode(1 << 10), Err(DecodeError::ReservedBits));
    }

    #[test]
    fn the_wide_decode_reads_bit_10_as_bit_5_of_the_shift() {
        for sh in 0..64u8 {
            let c = Context {
                shift: sh,
                trunc: sh % 3 == 0,
                ..Context::rrr(Op::Mac, 4, 5, 6)
            };
            let w = c.encode();
            assert_eq!(w >> 10 & 1, (sh >= 32) as u32);
            assert_eq!(Context::decode_wide(w), Ok(c));
            if sh < 32 {
                assert_eq!(Context::decode(w), Ok(c));
            } else {
                assert_eq!(Context::decode(w), Err(DecodeError::ReservedBits));
            }
        }
        // the immediate form is the same on both chips
        let c = Context::rri(Op::Add, 1, 2, -1024);
        assert_eq!(Context::decode_wide(c.encode()), Ok(c));
    }
}
