//! The assembler and disassembler for TinyRISC code and RC context words.
//!
//! One source format (see `docs/isa.md`, "Assembler"):
//!
//! * sections `.text` (TinyRISC instructions, default origin 0x0),
//!   `.data` (data, 0x10000) and `.ctx` (RC context words, 0x20000), each
//!   with its own location counter; `.org EXPR` moves the counter of the
//!   current section;
//! * labels `name:`, constants `NAME = EXPR` or `.equ NAME, EXPR`;
//! * expressions with `+ - * / % << >> & | ^ ~`, parentheses, `.` (the
//!   current address), numbers in decimal, `0x` hex, `0b` binary, `'c'`;
//! * data: `.word`, `.half`, `.byte`, `.space N[, FILL]`, `.align N`,
//!   `.ascii "..."`, `.rept N[, VAR]` ... `.endr` (VAR counting 0..N-1 in
//!   the body); `.entry EXPR` (default: `_start`, else the start of
//!   `.text`);
//! * `.datapath 16|32`: the RC datapath the contexts are for (default 16;
//!   32 allows multiplier shifts up to 63, encoded with `f[10]`);
//! * comments from `;` or `//` to the end of the line.
//!
//! The instruction syntax is exactly the disassembly of
//! [`rtl::tinyrisc::Instr`] and [`rtl::rc::context::Context`] (plus a few
//! pseudo-instructions), so what the disassembler prints assembles back to
//! the same word. Errors name `file:line:col` and show the line; the
//! assembler never panics, whatever the input.

mod context;
mod error;
mod expr;
mod image;
mod lexer;
mod macros;
mod tinyrisc;

use std::collections::{BTreeMap, HashMap};

pub use error::{AsmError, AsmErrors};
pub use image::{disassemble_image, Image, Label, Section, Segment};
use lexer::{Tok, Token};

pub const TEXT_ORIGIN: i64 = 0x0;
pub const DATA_ORIGIN: i64 = 0x1_0000;
pub const CTX_ORIGIN: i64 = 0x2_0000;
const MAX_ERRORS: usize = 50;

/// Assemble a file from disk.
pub fn assemble_file(path: &std::path::Path) -> Result<Image, String> {
    let bytes = crate::input::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if Image::is_image(&bytes) {
        return Err(format!(
            "{}: this is an assembled image (what `morphosys asm -o` writes), not source; `morphosys run` runs it",
            path.display()
        ));
    }
    let src = String::from_utf8(bytes).map_err(|e| {
        format!(
            "{}: not UTF-8 text (byte {} of the file): not assembly source",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })?;
    assemble(&src, &path.display().to_string()).map_err(|e| e.to_string())
}

/// Assemble `src` (named `file` in messages).
pub fn assemble(src: &str, file: &str) -> Result<Image, AsmErrors> {
    let mut a = Asm {
        file: file.to_string(),
        lines: Vec::new(),
        symbols: HashMap::new(),
        errors: Vec::new(),
        loc: [TEXT_ORIGIN, DATA_ORIGIN, CTX_ORIGIN],
        section: Section::Text,
        pass: 1,
        sizes: HashMap::new(),
        segments: Vec::new(),
        entry: None,
        wide: false,
        pending_equ: Vec::new(),
        labels: Vec::new(),
    };
    let is_mnemonic = |w: &str| tinyrisc::is_mnemonic(w) || context::is_mnemonic(w);
    let expanded = macros::expand(src, file, &is_mnemonic).map_err(|e| AsmErrors(vec![e]))?;
    for l in expanded {
        let mk = |col: usize, msg: String| AsmError {
            file: file.to_string(),
            line: l.no,
            col,
            message: format!("{msg}{}", l.from.as_deref().unwrap_or("")),
            text: l.text.clone(),
        };
        match lexer::lex(&l.text, &mk) {
            Ok(toks) => a.lines.push(Src {
                no: l.no,
                text: l.text,
                toks,
                from: l.from,
            }),
            Err(e) => a.errors.push(e),
        }
    }
    if !a.errors.is_empty() {
        return Err(AsmErrors(a.errors));
    }
    if let Err(e) = a.expand_rept() {
        return Err(AsmErrors(vec![e]));
    }
    a.run_pass(1);
    // Constants that referred to labels defined later.
    for _ in 0..8 {
        let pending = std::mem::take(&mut a.pending_equ);
        for (name, li, toks_from, here) in pending {
            let toks = a.lines[li].toks[toks_from..].to_vec();
            let c = expr::Ctx {
                symbols: &a.symbols,
                here,
                final_pass: false,
            };
            let mut p = expr::Parser::new(&toks);
            match p.expr(&c) {
                Ok(Some(v)) => {
                    a.symbols.insert(name, v);
                }
                _ => a.pending_equ.push((name, li, toks_from, here)),
            }
        }
    }
    if a.errors.is_empty() {
        a.run_pass(2);
    }
    if !a.errors.is_empty() {
        a.errors.truncate(MAX_ERRORS);
        return Err(AsmErrors(a.errors));
    }
    let entry = match a.entry {
        Some(e) => e,
        None => a.symbols.get("_start").copied().unwrap_or(TEXT_ORIGIN),
    } as u32;
    let mut symbols = BTreeMap::new();
    for (k, v) in &a.symbols {
        symbols.insert(k.clone(), *v);
    }
    let mut segs = a.segments;
    segs.retain(|s| !s.data.is_empty());
    segs.sort_by_key(|s| s.addr);
    for w in segs.windows(2) {
        if w[0].addr as u64 + w[0].data.len() as u64 > w[1].addr as u64 {
            return Err(AsmErrors(vec![AsmError {
                file: file.to_string(),
                line: 1,
                col: 1,
                message: format!(
                    "sections overlap: {} bytes at 0x{:x} ({}) run into 0x{:x} ({})",
                    w[0].data.len(),
                    w[0].addr,
                    w[0].section.name(),
                    w[1].addr,
                    w[1].section.name()
                ),
                text: String::new(),
            }]));
        }
    }
    let mut labels = std::mem::take(&mut a.labels);
    labels.sort_by_key(|l| (l.section as u8, l.addr));
    Ok(Image {
        entry,
        segments: segs,
        symbols,
        labels,
    })
}

struct Asm {
    file: String,
    lines: Vec<Src>,
    symbols: HashMap<String, i64>,
    errors: Vec<AsmError>,
    loc: [i64; 3],
    section: Section,
    pass: u8,
    /// Words chosen in pass 1 for size-dependent pseudo-instructions.
    sizes: HashMap<usize, u32>,
    segments: Vec<Segment>,
    entry: Option<i64>,
    /// `.datapath 32`: contexts for the 32-bit chip.
    pub(crate) wide: bool,
    /// (name, line index, first token of the expression, `.` there)
    pending_equ: Vec<(String, usize, usize, i64)>,
    /// The labels defined (pass 1).
    labels: Vec<Label>,
}

/// A source line (after macro expansion): its number in the file, its
/// text, its tokens, and for a line of a macro's body where the macro was
/// used (appended to its errors).
#[derive(Clone, Debug, Default)]
struct Src {
    no: usize,
    text: String,
    toks: Vec<Token>,
    from: Option<String>,
}

/// Context of one line for error reporting and operand parsing.
pub(crate) struct LineCtx<'a> {
    pub file: &'a str,
    pub line: usize,
    pub text: &'a str,
    pub toks: &'a [Token],
}

impl LineCtx<'_> {
    /// An error at token `i` (or at the end of the line).
    pub fn err_at(&self, i: Option<usize>, msg: impl Into<String>) -> AsmError {
        let col = match i.and_then(|i| self.toks.get(i)) {
            Some(t) => t.col,
            None => self.text.chars().count() + 1,
        };
        AsmError {
            file: self.file.to_string(),
            line: self.line,
            col,
            message: msg.into(),
            text: self.text.to_string(),
        }
    }
}

/// Operands: token index ranges split at top-level commas.
pub(crate) fn split_operands(toks: &[Token], from: usize) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    if from >= toks.len() {
        return out;
    }
    let mut depth = 0i32;
    let mut start = from;
    for (i, t) in toks.iter().enumerate().skip(from) {
        match t.tok {
            Tok::P("(") | Tok::P("[") => depth += 1,
            Tok::P(")") | Tok::P("]") => depth -= 1,
            Tok::P(",") if depth == 0 => {
                out.push((start, i));
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push((start, toks.len()));
    out
}

impl Asm {
    /// Expand `.rept N` ... `.endr` (N a constant expression of numbers and
    /// constants defined above with `=`; no nesting).
    fn expand_rept(&mut self) -> Result<(), AsmError> {
        let is = |toks: &[Token], d: &str| matches!(toks.first().map(|t| &t.tok), Some(Tok::Ident(n)) if n == d);
        if !self.lines.iter().any(|l| is(&l.toks, ".rept")) {
            return Ok(());
        }
        let mut lines = std::mem::take(&mut self.lines);
        let mut out = Vec::with_capacity(lines.len());
        let mut consts: HashMap<String, i64> = HashMap::new();
        let mut k = 0;
        while k < lines.len() {
            let Src {
                no,
                text,
                toks,
                from,
            } = &lines[k];
            let lc = LineCtx {
                file: &self.file,
                line: *no,
                text,
                toks,
            };
            // track simple constants so .rept counts can use them
            if toks.len() > 2 {
                if let (Tok::Ident(n), Tok::P("=")) = (&toks[0].tok, &toks[1].tok) {
                    let c = expr::Ctx {
                        symbols: &consts,
                        here: 0,
                        final_pass: false,
                    };
                    if let Ok(Some(v)) = expr::Parser::new(&toks[2..]).expr(&c) {
                        consts.insert(n.clone(), v);
                    }
                }
            }
            let note = |mut e: AsmError| {
                e.message.push_str(from.as_deref().unwrap_or(""));
                e
            };
            if is(toks, ".endr") {
                return Err(note(lc.err_at(Some(0), "`.endr` without `.rept`")));
            }
            if !is(toks, ".rept") {
                out.push(std::mem::take(&mut lines[k]));
                k += 1;
                continue;
            }
            let c = expr::Ctx {
                symbols: &consts,
                here: 0,
                final_pass: true,
            };
            let mut p = expr::Parser::new(&toks[1..]);
            let n = match p.expr(&c) {
                Ok(Some(n)) if (0..=65536).contains(&n) => n,
                _ => {
                    return Err(note(
                        lc.err_at(Some(1), "`.rept N` needs a count 0..=65536 known here"),
                    ))
                }
            };
            // `.rept N, VAR`: VAR stands for 0, 1, ..., N - 1 in the body.
            let var = match &toks[p.pos + 1..] {
                [] => None,
                [comma, name] if comma.tok == Tok::P(",") => match &name.tok {
                    Tok::Ident(v) if !v.starts_with('.') && !tinyrisc::is_register(v) => {
                        Some(v.clone())
                    }
                    _ => {
                        return Err(note(lc.err_at(
                            Some(p.pos + 3),
                            "`.rept N, VAR`: VAR must be a name (not a register or directive)",
                        )))
                    }
                },
                _ => {
                    return Err(note(lc.err_at(
                        Some(p.pos + 1),
                        "expected `.rept N` or `.rept N, VAR` (VAR counts 0..N-1 in the body)",
                    )))
                }
            };
            let end = (k + 1..lines.len())
                .find(|&j| is(&lines[j].toks, ".endr") || is(&lines[j].toks, ".rept"));
            let Some(end) = end.filter(|&j| is(&lines[j].toks, ".endr")) else {
                return Err(note(lc.err_at(
                    Some(0),
                    "`.rept` without `.endr` (nesting is not supported)",
                )));
            };
            for i in 0..n {
                for l in &lines[k + 1..end] {
                    let toks = match &var {
                        Some(v) => l
                            .toks
                            .iter()
                            .map(|t| match &t.tok {
                                Tok::Ident(x) if x == v => Token {
                                    tok: Tok::Int(i),
                                    col: t.col,
                                },
                                _ => t.clone(),
                            })
                            .collect(),
                        None => l.toks.clone(),
                    };
                    out.push(Src {
                        no: l.no,
                        text: l.text.clone(),
                        toks,
                        from: l.from.clone(),
                    });
                }
            }
            k = end + 1;
        }
        self.lines = out;
        Ok(())
    }

    fn run_pass(&mut self, pass: u8) {
        self.pass = pass;
        self.loc = [TEXT_ORIGIN, DATA_ORIGIN, CTX_ORIGIN];
        self.section = Section::Text;
        self.wide = false;
        // The lines out of `self` while a pass reads them (no line is
        // changed by a pass), so that each is read in place.
        let lines = std::mem::take(&mut self.lines);
        let file = std::mem::take(&mut self.file);
        for (li, l) in lines.iter().enumerate() {
            if self.errors.len() >= MAX_ERRORS {
                break;
            }
            if let Err(mut e) = self.line(&file, li, l) {
                e.message.push_str(l.from.as_deref().unwrap_or(""));
                self.errors.push(e);
            }
        }
        self.lines = lines;
        self.file = file;
    }

    fn here(&self) -> i64 {
        self.loc[self.section as usize]
    }

    fn eval(
        &self,
        lc: &LineCtx,
        from: usize,
        to: usize,
        final_pass: bool,
    ) -> Result<Option<i64>, AsmError> {
        if from >= to {
            return Err(lc.err_at(
                Some(from).filter(|&f| f < lc.toks.len()),
                "expected an expression",
            ));
        }
        let c = expr::Ctx {
            symbols: &self.symbols,
            here: self.here(),
            final_pass,
        };
        let mut p = expr::Parser::new(&lc.toks[from..to]);
        let v = p
            .expr(&c)
            .map_err(|e| lc.err_at(e.at.map(|a| a + from).or(Some(to)), e.msg))?;
        if p.pos + from < to {
            return Err(lc.err_at(
                Some(p.pos + from),
                format!(
                    "unexpected {} in expression",
                    expr::show(&lc.toks[p.pos + from].tok)
                ),
            ));
        }
        Ok(v)
    }

    /// Evaluate: must be known in pass 2; in pass 1 unknown gives `None`.
    pub(crate) fn value(
        &self,
        lc: &LineCtx,
        from: usize,
        to: usize,
    ) -> Result<Option<i64>, AsmError> {
        self.eval(lc, from, to, self.pass == 2)
    }

    /// Evaluate an expression that must be known in pass 1 (sizes).
    fn value_now(&self, lc: &LineCtx, from: usize, to: usize, what: &str) -> Result<i64, AsmError> {
        match self.eval(lc, from, to, true) {
            Ok(Some(v)) => Ok(v),
            Ok(None) => Err(lc.err_at(
                Some(from),
                format!("{what} must be known here (no forward references)"),
            )),
            Err(e) if self.pass == 1 && e.message.starts_with("undefined symbol") => Err(lc
                .err_at(
                    Some(from),
                    format!("{what} must be known here: {}", e.message),
                )),
            Err(e) => Err(e),
        }
    }

    fn define(&mut self, lc: &LineCtx, at: usize, name: &str, v: i64) -> Result<(), AsmError> {
        if tinyrisc::is_register(name) {
            return Err(lc.err_at(Some(at), format!("`{name}` is a register name")));
        }
        if self.pass == 1 {
            if self.symbols.contains_key(name) {
                return Err(lc.err_at(Some(at), format!("`{name}` is defined twice")));
            }
            self.symbols.insert(name.to_string(), v);
        }
        Ok(())
    }

    pub(crate) fn emit(&mut self, bytes: &[u8]) {
        let here = self.here();
        if self.pass == 2 {
            let sec = self.section;
            match self.segments.iter_mut().rev().find(|s| s.section == sec) {
                Some(s) if s.addr as i64 + s.data.len() as i64 == here => {
                    s.data.extend_from_slice(bytes)
                }
                _ => self.segments.push(Segment {
                    addr: here as u32,
                    section: sec,
                    data: bytes.to_vec(),
                }),
            }
        }
        self.loc[self.section as usize] = here + bytes.len() as i64;
    }

    fn line(&mut self, file: &str, li: usize, l: &Src) -> Result<(), AsmError> {
        let (no, text, toks) = (l.no, &l.text, &l.toks);
        let lc = LineCtx {
            file,
            line: no,
            text,
            toks,
        };
        let mut i = 0;
        // labels
        while i + 1 < toks.len() {
            match (&toks[i].tok, &toks[i + 1].tok) {
                (Tok::Ident(name), Tok::P(":")) if !name.starts_with('.') => {
                    let here = self.here();
                    self.define(&lc, i, name, here)?;
                    if self.pass == 1 && (0..=u32::MAX as i64).contains(&here) {
                        self.labels.push(Label {
                            addr: here as u32,
                            section: self.section,
                            name: name.clone(),
                        });
                    }
                    i += 2;
                }
                _ => break,
            }
        }
        if i >= toks.len() {
            return Ok(());
        }
        if self.section == Section::Ctx && matches!(toks[i].tok, Tok::P("(")) {
            let loc = self.here();
            if loc % 4 != 0 {
                return Err(lc.err_at(Some(i), "context word at an address that is not 4-aligned"));
            }
            let w = context::context(self, &lc, i)?;
            self.emit(&w.to_le_bytes());
            return Ok(());
        }
        let Tok::Ident(head) = &toks[i].tok else {
            return Err(lc.err_at(
                Some(i),
                format!(
                    "expected a label, instruction or directive, found {}",
                    expr::show(&toks[i].tok)
                ),
            ));
        };
        // NAME = EXPR
        if matches!(toks.get(i + 1).map(|t| &t.tok), Some(Tok::P("="))) {
            return self.equ(&lc, li, i, head, i + 2);
        }
        let head = head.clone();
        let loc = self.here();
        if !(0..=u32::MAX as i64).contains(&loc) {
            return Err(lc.err_at(
                Some(i),
                format!("address 0x{loc:x} outside the 32-bit address space"),
            ));
        }
        if head.starts_with('.') {
            return self.directive(&lc, li, i, &head);
        }
        match self.section {
            Section::Text => tinyrisc::instruction(self, &lc, li, i, &head),
            Section::Ctx => {
                if loc % 4 != 0 {
                    return Err(lc.err_at(Some(i), "context word at an address that is not 4-aligned"));
                }
                let w = context::context(self, &lc, i)?;
                self.emit(&w.to_le_bytes());
                Ok(())
            }
            Section::Data => Err(lc.err_at(
                Some(i),
                format!("`{head}`: only data directives (.word, .half, .byte, ...) in .data; instructions go in .text, contexts in .ctx"),
            )),
        }
    }

    fn equ(
        &mut self,
        lc: &LineCtx,
        li: usize,
        at: usize,
        name: &str,
        from: usize,
    ) -> Result<(), AsmError> {
        let v = self.eval(lc, from, lc.toks.len(), self.pass == 2)?;
        if self.pass == 1 {
            match v {
                Some(v) => self.define(lc, at, name, v)?,
                None => {
                    if self.pending_equ.iter().any(|p| p.0 == name)
                        || self.symbols.contains_key(name)
                    {
                        return Err(lc.err_at(Some(at), format!("`{name}` is defined twice")));
                    }
                    self.pending_equ
                        .push((name.to_string(), li, from, self.here()));
                }
            }
        } else if !self.symbols.contains_key(name) {
            if let Some(v) = v {
                self.symbols.insert(name.to_string(), v);
            }
        }
        Ok(())
    }

    /// `.space N[, FILL]` (operands `ops`; the directive's token `i`).
    fn space(&mut self, lc: &LineCtx, i: usize, ops: &[(usize, usize)]) -> Result<(), AsmError> {
        let nops = ops.len();
        if nops != 1 && nops != 2 {
            return Err(lc.err_at(Some(i), "`.space N[, FILL]` takes 1 or 2 operands"));
        }
        let n = self.value_now(lc, ops[0].0, ops[0].1, "the size")?;
        if !(0..=1 << 26).contains(&n) {
            return Err(lc.err_at(
                Some(ops[0].0),
                format!(".space {n}: size outside 0..=64 MiB"),
            ));
        }
        let fill = if nops == 2 {
            self.value(lc, ops[1].0, ops[1].1)?.unwrap_or(0) as u8
        } else {
            0
        };
        self.emit(&vec![fill; n as usize]);
        Ok(())
    }

    /// `.word`, `.half` or `.byte` (`d`) and its values, each checked to
    /// fit.
    fn values(
        &mut self,
        lc: &LineCtx,
        i: usize,
        d: &str,
        ops: &[(usize, usize)],
    ) -> Result<(), AsmError> {
        if ops.is_empty() {
            return Err(lc.err_at(Some(i), format!("`{d}` needs at least one value")));
        }
        let (size, lo, hi) = match d {
            ".word" => (4usize, i32::MIN as i64, u32::MAX as i64),
            ".half" => (2, i16::MIN as i64, u16::MAX as i64),
            _ => (1, i8::MIN as i64, u8::MAX as i64),
        };
        for &(a, b) in ops {
            let v = self.value(lc, a, b)?.unwrap_or(0);
            if !(lo..=hi).contains(&v) {
                return Err(lc.err_at(
                    Some(a),
                    format!("value {v} does not fit in {d} ({lo}..={hi})"),
                ));
            }
            self.emit(&(v as u32).to_le_bytes()[..size]);
        }
        Ok(())
    }

    fn directive(&mut self, lc: &LineCtx, li: usize, i: usize, d: &str) -> Result<(), AsmError> {
        let ops = split_operands(lc.toks, i + 1);
        let nops = ops.len();
        let want = |n: usize| -> Result<(), AsmError> {
            if nops != n {
                Err(lc.err_at(Some(i), format!("`{d}` takes {n} operand(s), found {nops}")))
            } else {
                Ok(())
            }
        };
        match d {
            ".text" | ".data" | ".ctx" => {
                want(0)?;
                self.section = match d {
                    ".text" => Section::Text,
                    ".data" => Section::Data,
                    _ => Section::Ctx,
                };
            }
            ".org" => {
                want(1)?;
                let v = self.value_now(lc, ops[0].0, ops[0].1, "the .org address")?;
                if !(0..=u32::MAX as i64).contains(&v) {
                    return Err(lc.err_at(
                        Some(ops[0].0),
                        format!(".org 0x{v:x} outside the 32-bit address space"),
                    ));
                }
                self.loc[self.section as usize] = v;
            }
            ".align" => {
                want(1)?;
                let n = self.value_now(lc, ops[0].0, ops[0].1, "the alignment")?;
                if !(1..=1 << 20).contains(&n) || n & (n - 1) != 0 {
                    return Err(lc.err_at(
                        Some(ops[0].0),
                        format!(".align {n}: use a power of two up to 2^20"),
                    ));
                }
                let here = self.here();
                let pad = (n - here.rem_euclid(n)) % n;
                self.emit(&vec![0u8; pad as usize]);
            }
            ".space" => self.space(lc, i, &ops)?,
            ".word" | ".half" | ".byte" => self.values(lc, i, d, &ops)?,
            ".ascii" => {
                want(1)?;
                match lc.toks[ops[0].0..ops[0].1].first().map(|t| &t.tok) {
                    Some(Tok::Str(s)) if ops[0].1 - ops[0].0 == 1 => {
                        let b = s.clone().into_bytes();
                        self.emit(&b);
                    }
                    _ => return Err(lc.err_at(Some(ops[0].0), "`.ascii` takes one string")),
                }
            }
            ".equ" | ".set" => {
                want(2)?;
                match &lc.toks[ops[0].0].tok {
                    Tok::Ident(n) if ops[0].1 - ops[0].0 == 1 => {
                        let n = n.clone();
                        return self.equ(lc, li, ops[0].0, &n, ops[1].0);
                    }
                    _ => return Err(lc.err_at(Some(ops[0].0), "`.equ NAME, EXPR` needs a name")),
                }
            }
            ".entry" => {
                want(1)?;
                if let Some(v) = self.value(lc, ops[0].0, ops[0].1)? {
                    self.entry = Some(v);
                }
            }
            ".datapath" => {
                want(1)?;
                match self.value_now(lc, ops[0].0, ops[0].1, "the datapath width")? {
                    16 => self.wide = false,
                    32 => self.wide = true,
                    v => {
                        return Err(
                            lc.err_at(Some(ops[0].0), format!("datapath {v}: 16 or 32 bits"))
                        )
                    }
                }
            }
            ".global" | ".globl" => {}
            _ => return Err(lc.err_at(Some(i), format!("unknown directive `{d}`"))),
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
