//! TinyRISC instruction syntax: the disassembly of [`rtl::tinyrisc::Instr`]
//! plus pseudo-instructions.
//!
//! Pseudo-instructions: `li rd, EXPR` / `la rd, EXPR` (one `addi` when the
//! value is known in pass 1 and fits 18 signed bits, else `lui` + `ori`),
//! `mv rd, rs`, `not rd, rs`, `neg rd, rs`, `subi rd, rs, EXPR`,
//! `b L`, `beqz rs, L`, `bnez rs, L`, `bgt a, b, L`, `ble a, b, L`,
//! `bgtu`, `bleu`, `call L`, `ret`.

use rtl::tinyrisc::decode::{Format, Instr, Opcode, IMM18_MAX, IMM18_MIN};

use super::lexer::Tok;
use super::{split_operands, Asm, AsmError, LineCtx};

/// `r0`..`r15`, or the aliases `zero` (r0), `sp` (r14), `lr` (r15).
pub fn register(name: &str) -> Option<u8> {
    match name {
        "zero" => return Some(0),
        "sp" => return Some(14),
        "lr" => return Some(15),
        _ => {}
    }
    let n = name.strip_prefix('r')?;
    if n.is_empty() || n.len() > 2 || (n.len() == 2 && n.starts_with('0')) {
        return None;
    }
    let v: u8 = n.parse().ok()?;
    (v < 16).then_some(v)
}

pub fn is_register(name: &str) -> bool {
    register(name).is_some()
}

struct Ops<'a, 'b> {
    lc: &'a LineCtx<'b>,
    ops: Vec<(usize, usize)>,
    head: usize,
}

impl Ops<'_, '_> {
    fn want(&self, n: usize, syntax: &str) -> Result<(), AsmError> {
        if self.ops.len() != n {
            return Err(self.lc.err_at(
                Some(self.head),
                format!(
                    "expected {n} operand(s): `{syntax}`, found {}",
                    self.ops.len()
                ),
            ));
        }
        Ok(())
    }

    fn reg(&self, k: usize) -> Result<u8, AsmError> {
        let (a, b) = self.ops[k];
        if b == a + 1 {
            if let Tok::Ident(n) = &self.lc.toks[a].tok {
                if let Some(r) = register(n) {
                    return Ok(r);
                }
            }
        }
        Err(self
            .lc
            .err_at(Some(a).filter(|&a| a < b), "expected a register r0..r15"))
    }
}

fn check(lc: &LineCtx, at: usize, v: i64, lo: i64, hi: i64, what: &str) -> Result<i32, AsmError> {
    if (lo..=hi).contains(&v) {
        Ok(v as i32)
    } else {
        Err(lc.err_at(Some(at), format!("{what} {v} out of range {lo}..={hi}")))
    }
}

/// Evaluate operand `k` as an expression (optionally after `#`); 0 in pass 1
/// when still unknown.
fn imm(asm: &Asm, o: &Ops, k: usize) -> Result<(i64, bool), AsmError> {
    let (mut a, b) = o.ops[k];
    if matches!(o.lc.toks.get(a).map(|t| &t.tok), Some(Tok::P("#"))) {
        a += 1;
    }
    Ok(match asm.value(o.lc, a, b)? {
        Some(v) => (v, true),
        None => (0, false),
    })
}

/// `rX`, `EXPR` or `rX + EXPR` (count operands): (c, imm).
fn count(asm: &Asm, o: &Ops, k: usize) -> Result<(u8, i64), AsmError> {
    let (a, b) = o.ops[k];
    if let Some(Tok::Ident(n)) = o.lc.toks.get(a).map(|t| &t.tok) {
        if let Some(r) = register(n) {
            if b == a + 1 {
                return Ok((r, 0));
            }
            if matches!(o.lc.toks.get(a + 1).map(|t| &t.tok), Some(Tok::P("+"))) {
                let v = asm.value(o.lc, a + 2, b)?.unwrap_or(0);
                return Ok((r, v));
            }
            return Err(o
                .lc
                .err_at(Some(a + 1), "expected `rX`, `EXPR` or `rX + EXPR`"));
        }
    }
    let (v, _) = imm(asm, o, k)?;
    Ok((0, v))
}

/// `EXPR(rB)` or `(rB)`: (offset, base).
fn mem(asm: &Asm, o: &Ops, k: usize) -> Result<(i64, u8), AsmError> {
    let (a, b) = o.ops[k];
    let t = o.lc.toks;
    let ok = b >= a + 3
        && matches!(t[b - 1].tok, Tok::P(")"))
        && matches!(t[b - 3].tok, Tok::P("("))
        && matches!(&t[b - 2].tok, Tok::Ident(n) if register(n).is_some());
    if !ok {
        return Err(o.lc.err_at(Some(a), "expected `OFFSET(rB)`"));
    }
    let base = match &t[b - 2].tok {
        Tok::Ident(n) => register(n).unwrap_or(0),
        _ => 0,
    };
    let off = if b - 3 == a {
        0
    } else {
        asm.value(o.lc, a, b - 3)?.unwrap_or(0)
    };
    Ok((off, base))
}

fn emit(asm: &mut Asm, lc: &LineCtx, head: usize, i: Instr) -> Result<(), AsmError> {
    let w = i.encode().map_err(|e| lc.err_at(Some(head), e.0))?;
    asm.emit(&w.to_le_bytes());
    Ok(())
}

/// Assemble one instruction line of `.text`.
pub(crate) fn instruction(
    asm: &mut Asm,
    lc: &LineCtx,
    li: usize,
    head: usize,
    m: &str,
) -> Result<(), AsmError> {
    let here = asm.here();
    if here % 4 != 0 {
        return Err(lc.err_at(
            Some(head),
            format!("instruction at 0x{here:x}, not 4-aligned (use .align 4)"),
        ));
    }
    let o = Ops {
        lc,
        ops: split_operands(lc.toks, head + 1),
        head,
    };
    if let Some(v) = pseudo(asm, &o, li, m, here)? {
        for i in v {
            if i.op == Opcode::Jal && !(0..1 << 28).contains(&(i.imm as i64)) {
                return Err(lc.err_at(Some(head), "call target out of range"));
            }
            emit(asm, lc, head, i)?;
        }
        return Ok(());
    }
    let Some(op) = Opcode::from_mnemonic(m) else {
        return Err(lc.err_at(
            Some(head),
            format!(
                "unknown instruction `{m}` (in .text: TinyRISC instructions; contexts go in .ctx)"
            ),
        ));
    };
    let i = by_format(asm, &o, op, here)?;
    emit(asm, lc, head, i)
}

/// The branch offset from `pc + 4` (`here + 4`) to operand `k`'s target,
/// in words.
fn branch(asm: &Asm, o: &Ops, here: i64, k: usize) -> Result<i32, AsmError> {
    let lc = o.lc;
    let (t, known) = imm(asm, o, k)?;
    if !known {
        return Ok(0);
    }
    let d = t - (here + 4);
    if d % 4 != 0 {
        return Err(lc.err_at(
            Some(o.ops[k].0),
            format!("branch target 0x{t:x} not 4-aligned"),
        ));
    }
    check(
        lc,
        o.ops[k].0,
        d / 4,
        IMM18_MIN as i64,
        IMM18_MAX as i64,
        "branch distance (words)",
    )
}

/// The instructions of pseudo-instruction `m` (line `li`, at `here`), or
/// `None` if `m` is not one.
fn pseudo(
    asm: &mut Asm,
    o: &Ops,
    li: usize,
    m: &str,
    here: i64,
) -> Result<Option<Vec<Instr>>, AsmError> {
    use Opcode::*;
    let lc = o.lc;
    let p2 = asm.pass == 2;
    let branch = |asm: &Asm, k: usize| branch(asm, o, here, k);
    Ok(match m {
        "li" | "la" => {
            o.want(2, "li rd, EXPR")?;
            let rd = o.reg(0)?;
            let (v, known) = imm(asm, o, 1)?;
            let v = if p2 || known {
                check(lc, o.ops[1].0, v, i32::MIN as i64, u32::MAX as i64, "value")? as u32
            } else {
                0
            };
            let words = if asm.pass == 1 {
                let n = if known
                    && (IMM18_MIN as i64..=IMM18_MAX as i64).contains(&(v as i32 as i64))
                {
                    1
                } else {
                    2
                };
                asm.sizes.insert(li, n);
                n
            } else {
                *asm.sizes.get(&li).unwrap_or(&2)
            };
            Some(if words == 1 {
                vec![Instr::new(Addi, rd, 0, 0, v as i32)]
            } else {
                vec![
                    Instr::new(Lui, rd, 0, 0, (v >> 14) as i32),
                    Instr::new(Ori, rd, rd, 0, (v & 0x3FFF) as i32),
                ]
            })
        }
        "mv" => {
            o.want(2, "mv rd, rs")?;
            Some(vec![Instr::new(Add, o.reg(0)?, o.reg(1)?, 0, 0)])
        }
        "not" => {
            o.want(2, "not rd, rs")?;
            Some(vec![Instr::new(Nor, o.reg(0)?, o.reg(1)?, 0, 0)])
        }
        "neg" => {
            o.want(2, "neg rd, rs")?;
            Some(vec![Instr::new(Sub, o.reg(0)?, 0, o.reg(1)?, 0)])
        }
        "subi" => {
            o.want(3, "subi rd, rs, EXPR")?;
            let (v, _) = imm(asm, o, 2)?;
            let v = check(
                lc,
                o.ops[2].0,
                v.wrapping_neg(),
                IMM18_MIN as i64,
                IMM18_MAX as i64,
                "immediate",
            )?;
            Some(vec![Instr::new(Addi, o.reg(0)?, o.reg(1)?, 0, v)])
        }
        "b" => {
            o.want(1, "b LABEL")?;
            Some(vec![Instr::new(Beq, 0, 0, 0, branch(asm, 0)?)])
        }
        "beqz" | "bnez" => {
            o.want(2, "beqz rs, LABEL")?;
            let op = if m == "beqz" { Beq } else { Bne };
            Some(vec![Instr::new(op, o.reg(0)?, 0, 0, branch(asm, 1)?)])
        }
        "bgt" | "ble" | "bgtu" | "bleu" => {
            o.want(3, "bgt ra, rb, LABEL")?;
            let op = match m {
                "bgt" => Blt,
                "ble" => Bge,
                "bgtu" => Bltu,
                _ => Bgeu,
            };
            Some(vec![Instr::new(
                op,
                o.reg(1)?,
                o.reg(0)?,
                0,
                branch(asm, 2)?,
            )])
        }
        "call" => {
            o.want(1, "call LABEL")?;
            let (t, _) = imm(asm, o, 0)?;
            Some(vec![Instr::new(Jal, 0, 0, 0, t as i32)])
        }
        "ret" => {
            o.want(0, "ret")?;
            Some(vec![Instr::new(Jr, 15, 0, 0, 0)])
        }
        _ => None,
    })
}

/// The operands a format takes, as its errors spell them.
fn syntax(f: Format) -> &'static str {
    match f {
        Format::None => "",
        Format::R3 => "rd, rs, rt",
        Format::RIs | Format::RIu => "rd, rs, EXPR",
        Format::LUi => "rd, EXPR",
        Format::Mem => "rt, OFFSET(rs)",
        Format::Br => "ra, rb, LABEL",
        Format::J => "LABEL",
        Format::R1 | Format::Rd => "rd",
        Format::R2 => "rd, rs",
        Format::M2 => "ra, rb, COUNT",
        Format::M1 => "ra, COUNT",
        Format::M3 => "ra, rb, rc, COUNT",
        Format::MI => "ra, OFFSET",
        Format::MRI => "rd, ra, OFFSET",
    }
}

/// Real instruction `op` (at `here`), its operands by its format.
fn by_format(asm: &Asm, o: &Ops, op: Opcode, here: i64) -> Result<Instr, AsmError> {
    use Opcode::*;
    let lc = o.lc;
    let branch = |asm: &Asm, k: usize| branch(asm, o, here, k);
    let syntax = syntax(op.format());
    Ok(match op.format() {
        Format::None => {
            o.want(0, syntax)?;
            Instr::new(op, 0, 0, 0, 0)
        }
        Format::R3 => {
            o.want(3, syntax)?;
            Instr::new(op, o.reg(0)?, o.reg(1)?, o.reg(2)?, 0)
        }
        Format::RIs | Format::RIu => {
            o.want(3, syntax)?;
            let (v, _) = imm(asm, o, 2)?;
            let (lo, hi) = if op.format() == Format::RIs {
                (IMM18_MIN as i64, IMM18_MAX as i64)
            } else if matches!(op, Slli | Srli | Srai) {
                (0, 31)
            } else {
                (0, (1 << 18) - 1)
            };
            let v = check(lc, o.ops[2].0, v, lo, hi, "immediate")?;
            Instr::new(op, o.reg(0)?, o.reg(1)?, 0, v)
        }
        Format::LUi => {
            o.want(2, syntax)?;
            let (v, _) = imm(asm, o, 1)?;
            let v = check(lc, o.ops[1].0, v, 0, (1 << 18) - 1, "immediate")?;
            Instr::new(op, o.reg(0)?, 0, 0, v)
        }
        Format::Mem => {
            o.want(2, syntax)?;
            let (off, base) = mem(asm, o, 1)?;
            let off = check(
                lc,
                o.ops[1].0,
                off,
                IMM18_MIN as i64,
                IMM18_MAX as i64,
                "offset",
            )?;
            Instr::new(op, o.reg(0)?, base, 0, off)
        }
        Format::Br => {
            o.want(3, syntax)?;
            Instr::new(op, o.reg(0)?, o.reg(1)?, 0, branch(asm, 2)?)
        }
        Format::J => {
            o.want(1, syntax)?;
            let (t, _) = imm(asm, o, 0)?;
            let t = check(lc, o.ops[0].0, t, 0, (1 << 28) - 4, "jump target")?;
            Instr::new(op, 0, 0, 0, t)
        }
        Format::R1 | Format::Rd => {
            o.want(1, syntax)?;
            Instr::new(op, o.reg(0)?, 0, 0, 0)
        }
        Format::R2 => {
            o.want(2, syntax)?;
            Instr::new(op, o.reg(0)?, o.reg(1)?, 0, 0)
        }
        Format::M2 => {
            o.want(3, syntax)?;
            let (c, n) = count(asm, o, 2)?;
            let n = check(lc, o.ops[2].0, n, 0, (1 << 14) - 1, "count")?;
            Instr::new(op, o.reg(0)?, o.reg(1)?, c, n)
        }
        Format::M1 => {
            o.want(2, syntax)?;
            let (c, n) = count(asm, o, 1)?;
            let n = check(lc, o.ops[1].0, n, 0, (1 << 14) - 1, "count")?;
            Instr::new(op, o.reg(0)?, 0, c, n)
        }
        Format::M3 => {
            let mode = if o.ops.len() == 5 {
                let (a, b) = o.ops[4];
                match (b == a + 1).then(|| &lc.toks[a].tok) {
                    Some(Tok::Ident(n)) if n == "row" => 1,
                    Some(Tok::Ident(n)) if n == "col" => 2,
                    _ => return Err(lc.err_at(Some(a), "expected `row` or `col`")),
                }
            } else {
                o.want(4, "ra, rb, rc, N[, row|col]")?;
                0
            };
            let (v, _) = imm(asm, o, 3)?;
            let n = check(lc, o.ops[3].0, v, 0, 4095, "count")?;
            Instr::new(op, o.reg(0)?, o.reg(1)?, o.reg(2)?, mode << 12 | n)
        }
        Format::MI => {
            o.want(2, syntax)?;
            let (v, _) = imm(asm, o, 1)?;
            let n = check(lc, o.ops[1].0, v, 0, (1 << 14) - 1, "offset")?;
            Instr::new(op, o.reg(0)?, 0, 0, n)
        }
        Format::MRI => {
            o.want(3, syntax)?;
            let (v, _) = imm(asm, o, 2)?;
            let n = check(lc, o.ops[2].0, v, 0, (1 << 14) - 1, "offset")?;
            Instr::new(op, o.reg(0)?, o.reg(1)?, 0, n)
        }
    })
}

/// A TinyRISC instruction or pseudo-instruction's name.
pub(crate) fn is_mnemonic(w: &str) -> bool {
    const PSEUDO: [&str; 15] = [
        "li", "la", "mv", "not", "neg", "subi", "b", "beqz", "bnez", "bgt", "ble", "bgtu", "bleu",
        "call", "ret",
    ];
    PSEUDO.contains(&w) || Opcode::from_mnemonic(w).is_some()
}
