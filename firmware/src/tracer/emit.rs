//! The two emitters the generator writes its assembly source with: RC
//! context kernels ([`K`]) and TinyRISC code ([`Code`]), and the named
//! values both use in place of numbers ([`Name`]).
//!
//! Neither rewrites text: a kernel's format shifts are written as the
//! assembler constants `Q7`..`Q16` (`Qn = n + X`, `X` the datapath's extra
//! fraction bits, defined in the program's header), its RAM addresses as
//! the RC RAM map's names, and TinyRISC code as one method call per
//! instruction with typed registers.

use std::fmt::{self, Display, Write};

/// A named value of the emitted program: an RC RAM word, a record field,
/// an FB address. Displayed as its name, so `format!("ld r8, [r0 + #{}]",
/// C_ONE)` emits `ld r8, [r0 + #C_ONE]`; the program's header defines the
/// name as `value` with `doc` as its comment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Name {
    pub name: &'static str,
    pub value: u32,
    pub doc: &'static str,
}

impl Name {
    pub const fn new(name: &'static str, value: u32, doc: &'static str) -> Name {
        Name { name, value, doc }
    }
    /// The value as a `usize` (an index into a record or a RAM).
    pub const fn at(self) -> usize {
        self.value as usize
    }
    /// The header line `NAME = value ; doc`.
    pub fn define(&self) -> String {
        define(self.name, self.value, self.doc)
    }
}

impl Display for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name)
    }
}

/// `NAME+offset`, the word `offset` after a named one (displayed `NAME` at
/// offset 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Offset {
    pub base: Name,
    pub offset: u32,
}

impl Offset {
    pub fn value(self) -> u32 {
        self.base.value + self.offset
    }
}

impl Display for Offset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.offset {
            0 => write!(f, "{}", self.base),
            k => write!(f, "{}+{k}", self.base),
        }
    }
}

impl std::ops::Add<u32> for Name {
    type Output = Offset;
    fn add(self, k: u32) -> Offset {
        Offset {
            base: self,
            offset: k,
        }
    }
}

impl std::ops::Add<u32> for Offset {
    type Output = Offset;
    fn add(self, k: u32) -> Offset {
        Offset {
            offset: self.offset + k,
            ..self
        }
    }
}

/// A header line defining `name` as `value`, with a comment.
pub fn define(name: &str, value: impl Display, doc: &str) -> String {
    let head = format!("{name} = {value}");
    if doc.is_empty() {
        head
    } else if head.len() < 24 {
        format!("{head:<24}; {doc}")
    } else {
        format!("{head} ; {doc}")
    }
}

/// Column of a trailing comment.
const NOTE_COL: usize = 40;

fn with_note(mut line: String, note: &str) -> String {
    if note.is_empty() {
        return line;
    }
    let n = line.chars().count();
    if n + 1 < NOTE_COL {
        line.extend(std::iter::repeat_n(' ', NOTE_COL - n));
    } else {
        line.push(' ');
    }
    line.push_str("; ");
    line.push_str(note);
    line
}

/// An RC context kernel: context lines in the assembler's syntax, with
/// comments, and the documentation printed above its label.
#[derive(Clone, Debug, Default)]
pub struct K {
    lines: Vec<String>,
    /// FB words the kernel reads (`fb0` operands): its record's length.
    pub fb_reads: usize,
    /// Contexts (lines that are not comments).
    len: usize,
    doc: Vec<String>,
    /// The kernel's cuts ([`K::cut`]): name, the FB words read before it
    /// and the contexts before it.
    cuts: Vec<(String, usize, usize)>,
    /// The kernel's entries ([`K::entry`]): name, the FB words read
    /// before it.
    entries: Vec<(String, usize)>,
}

/// The marker line of a cut, replaced by its label in [`K::text`].
const CUT_MARK: &str = "\u{0}cut ";
const ENTRY_MARK: &str = "\u{0}entry ";

/// The label of cut `name` of kernel `label` ([`K::cut`]).
pub fn cut_label(label: &str, name: &str) -> String {
    format!("{label}_cut_{name}")
}

/// The label of entry `name` of kernel `label` ([`K::entry`]).
pub fn entry_label(label: &str, name: &str) -> String {
    format!("{label}_from_{name}")
}

impl K {
    pub fn new() -> K {
        K::default()
    }
    /// One context.
    pub fn c(&mut self, s: impl AsRef<str>) -> &mut Self {
        let s = s.as_ref();
        self.fb_reads += s.matches("fb0").count();
        self.lines.push(format!("        {s}"));
        self.len += 1;
        self
    }
    /// A trailing comment on the last context.
    pub fn note(&mut self, s: &str) -> &mut Self {
        if let Some(l) = self.lines.last_mut() {
            *l = with_note(std::mem::take(l), s);
        }
        self
    }
    /// A comment line among the contexts.
    pub fn comment(&mut self, s: &str) -> &mut Self {
        self.lines.push(format!("        ; {s}"));
        self
    }
    /// A line of the documentation printed above the kernel's label.
    pub fn doc(&mut self, s: &str) -> &mut Self {
        for l in s.lines() {
            self.doc.push(l.trim_end().to_string());
        }
        self
    }
    /// `.rept n, var` ... `.endr` around the contexts `body` adds: the
    /// assembler repeats them `n` times with `var` = 0, 1, ..., n - 1.
    pub fn rept(&mut self, n: u32, var: &str, body: impl FnOnce(&mut K)) -> &mut Self {
        let mut inner = K::new();
        body(&mut inner);
        self.lines.push(format!("        .rept {n}, {var}"));
        self.lines.extend(inner.lines);
        self.lines.push("        .endr".into());
        self.fb_reads += n as usize * inner.fb_reads;
        self.len += n as usize * inner.len;
        self
    }
    /// A cut: where the kernel's run may end early, where no awake RC
    /// still has F. Either the kernel holds a `cut` context there, after
    /// which the broadcast unit ends the run itself ([`K::text_with_cuts`]),
    /// or TinyRISC broadcasts the kernel in parts, asks the array (`rcany`)
    /// after each, and runs the rest only if some RC has F ([`K::text`]: no
    /// context, only the label). F at a cut must hold wherever the whole
    /// kernel's F would at its end (the compares after it predicated on F,
    /// or an exact test that F contains), and the contexts after it write
    /// nothing but temporaries where F is clear, so that stopping there
    /// leaves the same state where it matters. The text labels it
    /// `{label}_cut_{name}` and defines `{label}_cut_{name}_fb`, the FB
    /// words of the stream read before it.
    pub fn cut(&mut self, name: &str) -> &mut Self {
        self.lines.push(format!("{CUT_MARK}{name}"));
        self.cuts.push((name.to_string(), self.fb_reads, self.len));
        self
    }
    /// An entry: where a run of the kernel may start, TinyRISC giving it
    /// the stream from there. The text labels it `{label}_from_{name}`
    /// and defines `{label}_from_{name}_fb`, the FB words of the stream
    /// read before it (a run that starts there streams from the kernel's
    /// stream plus that many words).
    pub fn entry(&mut self, name: &str) -> &mut Self {
        self.lines.push(format!("{ENTRY_MARK}{name}"));
        self.entries.push((name.to_string(), self.fb_reads));
        self
    }
    /// The names of the kernel's cuts, in order.
    pub fn cuts(&self) -> impl Iterator<Item = &str> {
        self.cuts.iter().map(|c| c.0.as_str())
    }
    /// Contexts before the first cut (all of them without a cut).
    pub fn first_part(&self) -> usize {
        self.cuts.first().map_or(self.len, |c| c.2)
    }
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Contexts in the kernel, its `cut` contexts not counted (what a
    /// test costs, whichever way its cuts are run).
    pub fn len(&self) -> usize {
        self.len
    }
    /// Context words in the kernel's text: [`K::len`], and with
    /// `cut_contexts` one per cut.
    pub fn words(&self, cut_contexts: bool) -> usize {
        self.len + if cut_contexts { self.cuts.len() } else { 0 }
    }
    /// Append another kernel's contexts.
    pub fn extend(&mut self, other: K) -> &mut Self {
        let (at, len) = (self.fb_reads, self.len);
        self.cuts
            .extend(other.cuts.into_iter().map(|(n, f, c)| (n, at + f, len + c)));
        self.entries
            .extend(other.entries.into_iter().map(|(n, f)| (n, at + f)));
        self.fb_reads += other.fb_reads;
        self.len += other.len;
        self.lines.extend(other.lines);
        self
    }
    /// The kernel as assembly: its documentation, `label:`, the contexts,
    /// `label_end:`; a cut is a label only.
    pub fn text(&self, label: &str) -> String {
        self.text_with_cuts(label, false)
    }
    /// [`K::text`], with `cut_contexts` a `cut` context at each cut (after
    /// its label).
    pub fn text_with_cuts(&self, label: &str, cut_contexts: bool) -> String {
        let mut s = String::new();
        for d in &self.doc {
            if d.is_empty() {
                s.push_str(";\n");
            } else {
                let _ = writeln!(s, "; {d}");
            }
        }
        let _ = writeln!(s, "{label}:");
        for l in &self.lines {
            if let Some(name) = l.strip_prefix(ENTRY_MARK) {
                let _ = writeln!(s, "{}:", entry_label(label, name));
                continue;
            }
            match l.strip_prefix(CUT_MARK) {
                Some(name) => {
                    let _ = writeln!(s, "{}:", cut_label(label, name));
                    if cut_contexts {
                        let _ = writeln!(
                            s,
                            "{}",
                            with_note(
                                "        cut".into(),
                                "the run ends here where no awake RC has F"
                            )
                        );
                    }
                }
                None => {
                    let _ = writeln!(s, "{l}");
                }
            }
        }
        let _ = writeln!(s, "{label}_end:");
        for (name, fb) in &self.entries {
            let _ = writeln!(
                s,
                "{}",
                with_note(
                    format!("{}_fb = {fb}", entry_label(label, name)),
                    "FB words of the stream read before the entry"
                )
            );
        }
        for (name, fb, _) in &self.cuts {
            let c = cut_label(label, name);
            let _ = writeln!(
                s,
                "{}",
                with_note(
                    format!("{c}_fb = {fb}"),
                    "FB words of the stream read before the cut"
                )
            );
        }
        s
    }
}

/// A TinyRISC register.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reg(pub u8);

impl Display for Reg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "r{}", self.0)
    }
}

pub const R0: Reg = Reg(0);
pub const R1: Reg = Reg(1);
pub const R2: Reg = Reg(2);
pub const R3: Reg = Reg(3);
pub const R4: Reg = Reg(4);
pub const R5: Reg = Reg(5);
pub const R6: Reg = Reg(6);
pub const R7: Reg = Reg(7);
pub const R8: Reg = Reg(8);
pub const R9: Reg = Reg(9);
pub const R10: Reg = Reg(10);
pub const R11: Reg = Reg(11);
pub const R12: Reg = Reg(12);
pub const R13: Reg = Reg(13);
pub const R14: Reg = Reg(14);
pub const R15: Reg = Reg(15);

/// A memory operand `OFFSET(rB)`.
#[derive(Clone, Debug)]
pub struct Mem {
    off: String,
    base: Reg,
}

/// `off(base)`: a load or store operand (main memory for `lw`/`sw`...,
/// FB set 0 words for `lfb`/`sfb`).
pub fn at(off: impl Display, base: Reg) -> Mem {
    Mem {
        off: off.to_string(),
        base,
    }
}

/// `(base)`: the word the register points at (a stack's top, a list's
/// entry).
pub fn deref(base: Reg) -> Mem {
    Mem {
        off: String::new(),
        base,
    }
}

impl Display for Mem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}({})", self.off, self.base)
    }
}

#[derive(Clone, Debug)]
enum Line {
    /// `name:` on a line of its own.
    Label(String),
    /// An instruction at the code column, with a trailing comment.
    Instr(String, String),
    /// A comment line at the code column.
    Comment(String),
    /// A line at column 0 as it is (block comments, constants, data,
    /// directives).
    Raw(String),
    Blank,
}

/// TinyRISC code: labels, instructions (one method per instruction, typed
/// registers; the other operands anything displayable: numbers, names,
/// assembler expressions), comments and blocks of documentation.
#[derive(Clone, Debug, Default)]
pub struct Code {
    lines: Vec<Line>,
}

macro_rules! r3 {
    ($($m:ident),*) => {$(
        #[doc = concat!("`", stringify!($m), " rd, rs, rt`")]
        pub fn $m(&mut self, rd: Reg, rs: Reg, rt: Reg) -> &mut Self {
            self.i(format!(concat!(stringify!($m), " {}, {}, {}"), rd, rs, rt))
        }
    )*};
}
macro_rules! ri {
    ($($m:ident),*) => {$(
        #[doc = concat!("`", stringify!($m), " rd, rs, IMM`")]
        pub fn $m(&mut self, rd: Reg, rs: Reg, imm: impl Display) -> &mut Self {
            self.i(format!(concat!(stringify!($m), " {}, {}, {}"), rd, rs, imm))
        }
    )*};
}
macro_rules! mem {
    ($($m:ident),*) => {$(
        #[doc = concat!("`", stringify!($m), " rt, OFFSET(rs)`")]
        pub fn $m(&mut self, rt: Reg, m: Mem) -> &mut Self {
            self.i(format!(concat!(stringify!($m), " {}, {}"), rt, m))
        }
    )*};
}
macro_rules! br2 {
    ($($m:ident),*) => {$(
        #[doc = concat!("`", stringify!($m), " ra, rb, LABEL`")]
        pub fn $m(&mut self, ra: Reg, rb: Reg, label: impl Display) -> &mut Self {
            self.i(format!(concat!(stringify!($m), " {}, {}, {}"), ra, rb, label))
        }
    )*};
}
macro_rules! br1 {
    ($($m:ident),*) => {$(
        #[doc = concat!("`", stringify!($m), " rs, LABEL`")]
        pub fn $m(&mut self, rs: Reg, label: impl Display) -> &mut Self {
            self.i(format!(concat!(stringify!($m), " {}, {}"), rs, label))
        }
    )*};
}
macro_rules! rd {
    ($($m:ident),*) => {$(
        #[doc = concat!("`", stringify!($m), " rd`")]
        pub fn $m(&mut self, rd: Reg) -> &mut Self {
            self.i(format!(concat!(stringify!($m), " {}"), rd))
        }
    )*};
}
macro_rules! none {
    ($($m:ident),*) => {$(
        #[doc = concat!("`", stringify!($m), "`")]
        pub fn $m(&mut self) -> &mut Self {
            self.i(stringify!($m))
        }
    )*};
}
macro_rules! rrn {
    ($($m:ident),*) => {$(
        #[doc = concat!("`", stringify!($m), " ra, rb, COUNT`")]
        pub fn $m(&mut self, ra: Reg, rb: Reg, count: impl Display) -> &mut Self {
            self.i(format!(concat!(stringify!($m), " {}, {}, {}"), ra, rb, count))
        }
    )*};
}

impl Code {
    pub fn new() -> Code {
        Code::default()
    }

    /// No line yet.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// One instruction, as the assembler reads it.
    fn i(&mut self, text: impl Into<String>) -> &mut Self {
        self.lines.push(Line::Instr(text.into(), String::new()));
        self
    }
    /// A trailing comment on the last instruction.
    pub fn c(&mut self, note: impl Into<String>) -> &mut Self {
        if let Some(Line::Instr(_, n)) = self.lines.last_mut() {
            *n = note.into();
        }
        self
    }
    /// `name:` on a line of its own.
    pub fn label(&mut self, name: impl Display) -> &mut Self {
        self.lines.push(Line::Label(name.to_string()));
        self
    }
    /// A comment line at the code's indentation.
    pub fn comment(&mut self, text: impl Display) -> &mut Self {
        for l in text.to_string().lines() {
            self.lines.push(Line::Comment(l.to_string()));
        }
        self
    }
    /// A block of documentation at column 0 (`; ` before each line), after
    /// an empty line: the head of a routine.
    pub fn doc(&mut self, text: &str) -> &mut Self {
        if !matches!(self.lines.last(), None | Some(Line::Blank)) {
            self.lines.push(Line::Blank);
        }
        for l in text.lines() {
            let l = l.trim_end();
            self.lines.push(Line::Raw(if l.is_empty() {
                ";".into()
            } else {
                format!("; {l}")
            }));
        }
        self
    }
    /// A line at column 0 as it is (a directive, a constant, data).
    pub fn raw(&mut self, text: impl Into<String>) -> &mut Self {
        self.lines.push(Line::Raw(text.into()));
        self
    }
    /// An instruction (or a macro's body line) written out, at the code's
    /// indentation.
    pub fn line(&mut self, text: impl Into<String>) -> &mut Self {
        self.i(text)
    }
    /// A directive at the code's indentation (`.text`, `.rept N, i`...).
    pub fn directive(&mut self, text: impl Display) -> &mut Self {
        self.lines
            .push(Line::Instr(text.to_string(), String::new()));
        self
    }
    pub fn blank(&mut self) -> &mut Self {
        self.lines.push(Line::Blank);
        self
    }
    /// Append another piece of code.
    pub fn extend(&mut self, other: Code) -> &mut Self {
        self.lines.extend(other.lines);
        self
    }

    /// Define the assembler macro `name` with `params` (comma-separated,
    /// used as `\\P` in the body) and the documentation `doc`.
    pub fn define_macro(&mut self, name: &str, params: &str, doc: &str, body: Code) -> &mut Self {
        self.doc(doc);
        self.raw(if params.is_empty() {
            format!(".macro {name}")
        } else {
            format!(".macro {name} {params}")
        });
        self.lines.extend(body.lines);
        self.raw(".endm")
    }

    /// A use of the macro `name` with its arguments.
    pub fn m(&mut self, name: &str, args: impl Display) -> &mut Self {
        let args = args.to_string();
        self.i(if args.is_empty() {
            name.to_string()
        } else {
            format!("{name} {args}")
        })
    }

    r3!(add, sub, and, or, xor, nor, sll, srl, sra, slt, sltu, mul);
    ri!(addi, andi, ori, xori, slti, sltiu, slli, srli, srai);
    mem!(lw, lh, lhu, lb, lbu, sw, sh, sb, lfb, sfb);
    br2!(beq, bne, blt, bge, bltu, bgeu);
    br1!(beqz, bnez);
    rd!(rdcyc, rcsl, rcsh, rcany, rcall, rcfl, rcfh, rcst);
    none!(nop, halt, dwait, ret);
    rrn!(ldctxt, ldfb, stfb, sbcb, cbcr, cbcc);

    /// `li rd, VALUE` (one instruction when the value is known where it is
    /// used and fits 18 bits, else two).
    pub fn li(&mut self, rd: Reg, v: impl Display) -> &mut Self {
        self.i(format!("li {rd}, {v}"))
    }
    /// `mv rd, rs`
    pub fn mv(&mut self, rd: Reg, rs: Reg) -> &mut Self {
        self.i(format!("mv {rd}, {rs}"))
    }
    /// `j LABEL`
    pub fn j(&mut self, label: impl Display) -> &mut Self {
        self.i(format!("j {label}"))
    }
    /// `jal LABEL`
    pub fn jal(&mut self, label: impl Display) -> &mut Self {
        self.i(format!("jal {label}"))
    }
    /// `cbcast ra, COUNT`
    pub fn cbcast(&mut self, ra: Reg, count: impl Display) -> &mut Self {
        self.i(format!("cbcast {ra}, {count}"))
    }
    /// `wfb ra, OFFSET`
    pub fn wfb(&mut self, ra: Reg, off: impl Display) -> &mut Self {
        self.i(format!("wfb {ra}, {off}"))
    }

    /// The code as assembly text.
    pub fn text(&self) -> String {
        let mut s = String::new();
        for l in &self.lines {
            match l {
                Line::Label(n) => {
                    let _ = writeln!(s, "{n}:");
                }
                Line::Instr(t, n) => {
                    let _ = writeln!(s, "{}", with_note(format!("        {t}"), n));
                }
                Line::Comment(t) => {
                    let _ = writeln!(s, "        ; {t}");
                }
                Line::Raw(t) => {
                    let _ = writeln!(s, "{t}");
                }
                Line::Blank => s.push('\n'),
            }
        }
        s
    }
}
