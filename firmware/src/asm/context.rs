//! RC context syntax: the disassembly of [`rtl::rc::context::Context`].
//!
//! ```text
//! [(f) | (!f)] op[.cond][.t] operands
//!   A := rN | out | n | s | w | e | qrowK | qcolK | xrowK | xcolK | fbK
//!   B := rN | #EXPR            (immediate -1024..=1023)
//!   D := rN | out              (out: result only to the output register)
//!   add D, A, B [, >>SH]       (and every two-operand op; >>SH only for
//!                               mul/mac/msu; .t = truncate instead of round)
//!   not|mov|abs|neg|clz D, A     movb D, B     cmp.COND A, B
//!   ld D, [A + B]     st A, [B]     acc|acch|accl D [, >>SH]
//!   ldacc A [, <<SH]  nop  sleep  wake
//! ```

use rtl::rc::context::{ASrc, BSrc, Context, Form, Guard, Op, ALL_CONDS, ALL_OPS};

use super::lexer::{Tok, Token};
use super::tinyrisc::register;
use super::{split_operands, Asm, AsmError, LineCtx};

fn asrc(name: &str) -> Option<(ASrc, u8)> {
    if let Some(r) = register(name) {
        return Some((ASrc::Reg, r));
    }
    let idx = |p: &str, max: u8| -> Option<u8> {
        let n = name.strip_prefix(p)?;
        if n.len() != 1 {
            return None;
        }
        let v: u8 = n.parse().ok()?;
        (v <= max).then_some(v)
    };
    Some(match name {
        "out" => (ASrc::Out, 0),
        "n" => (ASrc::Nbr, 0),
        "s" => (ASrc::Nbr, 1),
        "w" => (ASrc::Nbr, 2),
        "e" => (ASrc::Nbr, 3),
        _ => {
            if let Some(k) = idx("qrow", 3) {
                (ASrc::QRow, k)
            } else if let Some(k) = idx("qcol", 3) {
                (ASrc::QCol, k)
            } else if let Some(k) = idx("xrow", 7) {
                (ASrc::XRow, k)
            } else if let Some(k) = idx("xcol", 7) {
                (ASrc::XCol, k)
            } else if let Some(k) = idx("fb", 1) {
                (ASrc::Fb, k)
            } else {
                return None;
            }
        }
    })
}

fn one_ident(toks: &[Token], (a, b): (usize, usize)) -> Option<&str> {
    if b == a + 1 {
        if let Tok::Ident(n) = &toks[a].tok {
            return Some(n);
        }
    }
    None
}

/// Assemble one context line; returns the word.
pub(crate) fn context(asm: &Asm, lc: &LineCtx, i: usize) -> Result<u32, AsmError> {
    let t = lc.toks;
    let (guard, head) = guard_prefix(t, i);
    let Some(Tok::Ident(m)) = t.get(head).map(|x| &x.tok) else {
        return Err(lc.err_at(Some(head), "expected a context"));
    };
    if m == "cut" {
        if guard != Guard::Always {
            return Err(lc.err_at(Some(head), "a `cut` takes no guard"));
        }
        if t.get(head + 1).is_some() {
            return Err(lc.err_at(Some(head + 1), "`cut` takes no operands"));
        }
        return Ok(Context::CUT_WORD);
    }
    let (op, cond, trunc) = mnemonic(lc, head, m)?;
    let base = op.mnemonic();
    let mut ops = split_operands(t, head + 1);
    let (shift, shift_at) = trailing_shift(asm, lc, op, &mut ops)?;
    let o = Operands { asm, lc, t };
    let mut c = Context {
        op,
        guard,
        ..Context::NOP
    };
    o.fill(&mut c, head, &ops, cond)?;
    if !op.has_result() {
        c.we = false;
    }
    if shift != 0 || trunc {
        if matches!(c.b, BSrc::Imm(_)) {
            return Err(lc.err_at(
                shift_at.or(Some(head)),
                "a shift or `.t` needs operand B in a register (the immediate form has no shift field)",
            ));
        }
        if !op.uses_shift() && shift != 0 {
            return Err(lc.err_at(shift_at, format!("`{base}` takes no shift")));
        }
    }
    c.shift = shift;
    c.trunc = trunc;
    c.guard = guard;
    Ok(c.encode())
}

/// The operation of mnemonic `m` (token `head`) and its suffixes: a
/// `cmp`'s condition, `.t` (truncate) on an operation with a shift.
fn mnemonic(
    lc: &LineCtx,
    head: usize,
    m: &str,
) -> Result<(Op, Option<rtl::rc::context::Cond>, bool), AsmError> {
    let mut parts = m.split('.');
    let base = parts.next().unwrap_or("");
    let Some(op) = ALL_OPS.iter().copied().find(|o| o.mnemonic() == base) else {
        return Err(lc.err_at(
            Some(head),
            format!(
                "unknown RC operation `{base}` (in .ctx: RC contexts; TinyRISC code goes in .text)"
            ),
        ));
    };
    let mut cond = None;
    let mut trunc = false;
    for s in parts {
        if op == Op::Cmp && cond.is_none() {
            match ALL_CONDS.iter().copied().find(|c| c.mnemonic() == s) {
                Some(c) => cond = Some(c),
                None => return Err(lc.err_at(Some(head), format!("unknown condition `.{s}`"))),
            }
        } else if s == "t" && op.uses_shift() && !trunc {
            trunc = true;
        } else {
            return Err(lc.err_at(Some(head), format!("unexpected suffix `.{s}` on `{base}`")));
        }
    }
    if op == Op::Cmp && cond.is_none() {
        return Err(lc.err_at(Some(head), "`cmp` needs a condition: cmp.eq, cmp.lt, ..."));
    }
    Ok((op, cond, trunc))
}

/// The optional trailing `>>SH` (`<<SH` for `ldacc`) of `op`'s operands,
/// taken off `ops`: the shift and its token.
fn trailing_shift(
    asm: &Asm,
    lc: &LineCtx,
    op: Op,
    ops: &mut Vec<(usize, usize)>,
) -> Result<(u8, Option<usize>), AsmError> {
    let t = lc.toks;
    let base = op.mnemonic();
    let Some(&(a, b)) = ops.last() else {
        return Ok((0, None));
    };
    if !matches!(
        t.get(a).map(|x| &x.tok),
        Some(Tok::P(">>")) | Some(Tok::P("<<"))
    ) {
        return Ok((0, None));
    }
    if !op.uses_shift() {
        return Err(lc.err_at(Some(a), format!("`{base}` takes no shift")));
    }
    let left = matches!(t[a].tok, Tok::P("<<"));
    if left != (op == Op::Ldacc) {
        let want = if op == Op::Ldacc { "<<" } else { ">>" };
        return Err(lc.err_at(Some(a), format!("`{base}` shifts with `{want}SH`")));
    }
    let v = asm.value(lc, a + 1, b)?.unwrap_or(0);
    let max = if asm.wide { 63 } else { 31 };
    if !(0..=max).contains(&v) {
        let hint = if asm.wide {
            ""
        } else {
            " (0..=63 after `.datapath 32`)"
        };
        return Err(lc.err_at(
            Some(a + 1),
            format!("shift {v} out of range 0..={max}{hint}"),
        ));
    }
    ops.pop();
    Ok((v as u8, Some(a)))
}

/// One context line's operands: its tokens, where errors point.
struct Operands<'a> {
    asm: &'a Asm,
    lc: &'a LineCtx<'a>,
    t: &'a [Token],
}

impl Operands<'_> {
    /// The context's operands by its operation's [`Form`] (`ops`: their
    /// token ranges; `head`: the mnemonic's token).
    fn fill(
        &self,
        c: &mut Context,
        head: usize,
        ops: &[(usize, usize)],
        cond: Option<rtl::rc::context::Cond>,
    ) -> Result<(), AsmError> {
        let base = c.op.mnemonic();
        let want = |n: usize, syn: &str| -> Result<(), AsmError> {
            if ops.len() != n {
                Err(self.lc.err_at(Some(head), format!("`{base}` takes {syn}")))
            } else {
                Ok(())
            }
        };
        match c.op.form() {
            Form::None => want(0, "no operands")?,
            Form::Compare => {
                want(2, "`A, B`")?;
                (c.asrc, c.ra) = self.a(ops[0])?;
                c.b = self.b(ops[1])?;
                c.rd = cond.map_or(0, |x| x as u8);
            }
            Form::Store => {
                want(2, "`A, [B]`")?;
                (c.asrc, c.ra) = self.a(ops[0])?;
                c.b = self.b(self.bracket(ops[1], "expected `[B]`")?)?;
            }
            Form::Load => {
                want(2, "`D, [A + B]`")?;
                (c.we, c.rd) = self.d(ops[0])?;
                let inner = self.bracket(ops[1], "expected `[A + B]`")?;
                let plus = (inner.0..inner.1).find(|&x| matches!(self.t[x].tok, Tok::P("+")));
                let Some(p) = plus else {
                    return Err(self.lc.err_at(Some(inner.0), "expected `[A + B]`"));
                };
                (c.asrc, c.ra) = self.a((inner.0, p))?;
                c.b = self.b((p + 1, inner.1))?;
            }
            Form::Unary => {
                want(2, "`D, A`")?;
                (c.we, c.rd) = self.d(ops[0])?;
                (c.asrc, c.ra) = self.a(ops[1])?;
            }
            Form::MoveB => {
                want(2, "`D, B`")?;
                (c.we, c.rd) = self.d(ops[0])?;
                c.b = self.b(ops[1])?;
            }
            Form::AccRead | Form::AccPart => {
                want(1, "`D`")?;
                (c.we, c.rd) = self.d(ops[0])?;
            }
            Form::AccLoad => {
                want(1, "`A`")?;
                (c.asrc, c.ra) = self.a(ops[0])?;
            }
            Form::Binary | Form::Multiply => {
                want(3, "`D, A, B`")?;
                (c.we, c.rd) = self.d(ops[0])?;
                (c.asrc, c.ra) = self.a(ops[1])?;
                c.b = self.b(ops[2])?;
            }
        }
        Ok(())
    }

    /// Operand A.
    fn a(&self, k: (usize, usize)) -> Result<(ASrc, u8), AsmError> {
        one_ident(self.t, k).and_then(asrc).ok_or_else(|| {
            self.lc.err_at(
                Some(k.0).filter(|&x| x < k.1),
                "expected operand A: rN, out, n, s, w, e, qrowK, qcolK, xrowK, xcolK or fbK",
            )
        })
    }

    /// Operand B: a register or `#EXPR`.
    fn b(&self, k: (usize, usize)) -> Result<BSrc, AsmError> {
        let (t, lc) = (self.t, self.lc);
        if let Some(r) = one_ident(t, k).and_then(register) {
            return Ok(BSrc::Reg(r));
        }
        if matches!(t.get(k.0).map(|x| &x.tok), Some(Tok::P("#"))) && k.1 > k.0 + 1 {
            let v = self.asm.value(lc, k.0 + 1, k.1)?.unwrap_or(0);
            if !(-1024..=1023).contains(&v) {
                return Err(lc.err_at(
                    Some(k.0 + 1),
                    format!("immediate {v} out of range -1024..=1023"),
                ));
            }
            return Ok(BSrc::Imm(v as i16));
        }
        Err(lc.err_at(
            Some(k.0).filter(|&x| x < k.1),
            "expected operand B: rN or #EXPR",
        ))
    }

    /// The destination: a register (written) or `out`.
    fn d(&self, k: (usize, usize)) -> Result<(bool, u8), AsmError> {
        match one_ident(self.t, k) {
            Some("out") => Ok((false, 0)),
            Some(n) if register(n).is_some() => Ok((true, register(n).unwrap_or(0))),
            _ => Err(self.lc.err_at(
                Some(k.0).filter(|&x| x < k.1),
                "expected destination: rN or out",
            )),
        }
    }

    /// `[X]` or `[X + Y]`: the range inside the brackets, or `what`.
    fn bracket(&self, k: (usize, usize), what: &str) -> Result<(usize, usize), AsmError> {
        let t = self.t;
        if k.1 >= k.0 + 2
            && matches!(t[k.0].tok, Tok::P("["))
            && matches!(t[k.1 - 1].tok, Tok::P("]"))
        {
            Ok((k.0 + 1, k.1 - 1))
        } else {
            Err(self.lc.err_at(Some(k.0), what))
        }
    }
}

/// The guard prefix `(f)` / `(!f)`: returns the guard and the index of the
/// mnemonic.
pub(crate) fn guard_prefix(t: &[Token], i: usize) -> (Guard, usize) {
    let is = |k: usize, p: &str| matches!(t.get(k).map(|x| &x.tok), Some(Tok::P(q)) if *q == p);
    let id = |k: usize, s: &str| matches!(t.get(k).map(|x| &x.tok), Some(Tok::Ident(n)) if n == s);
    if is(i, "(") && id(i + 1, "f") && is(i + 2, ")") {
        (Guard::IfF, i + 3)
    } else if is(i, "(") && is(i + 1, "!") && id(i + 2, "f") && is(i + 3, ")") {
        (Guard::IfNotF, i + 4)
    } else {
        (Guard::Always, i)
    }
}

/// An RC operation's name (with or without its suffixes).
pub(crate) fn is_mnemonic(w: &str) -> bool {
    let base = w.split('.').next().unwrap_or("");
    w == "cut" || ALL_OPS.iter().any(|o| o.mnemonic() == base)
}
