//! Structure-aware inputs: the `arbitrary` crate turns random bytes into
//! small syntax trees of each input language, printed as text (or image
//! bytes). They are well formed where mutations of the seeds rarely are,
//! and reach what small mutations never do: expressions nested thousands
//! deep, counts of a billion, numbers at every extreme, files of a
//! megabyte and more (entities repeated thousands of times).

use arbitrary::{Arbitrary, Unstructured};

use super::{Rng, Target};

/// A number at one of the extremes a reader must survive.
#[derive(Arbitrary, Debug)]
enum Num {
    Small(i8),
    Frac(i16),
    Big(i32),
    Huge(bool),
    Tiny(bool),
    Nan,
    Inf(bool),
    Zero(bool),
}

impl Num {
    fn text(&self) -> String {
        match self {
            Num::Small(v) => v.to_string(),
            Num::Frac(v) => format!("{}", *v as f64 / 1000.0),
            Num::Big(v) => format!("{v}e3"),
            Num::Huge(neg) => if *neg { "-1e308" } else { "1.7e308" }.into(),
            Num::Tiny(neg) => if *neg { "-5e-324" } else { "1e-300" }.into(),
            Num::Nan => "nan".into(),
            Num::Inf(neg) => if *neg { "-inf" } else { "inf" }.into(),
            Num::Zero(neg) => if *neg { "-0" } else { "0" }.into(),
        }
    }
}

/// A count: few, many, or absurd.
#[derive(Arbitrary, Debug)]
enum Count {
    Few(u8),
    Many(u16),
    Absurd(bool),
}

impl Count {
    /// As written in the input.
    fn text(&self) -> String {
        match self {
            Count::Few(n) => n.to_string(),
            Count::Many(n) => n.to_string(),
            Count::Absurd(b) => if *b {
                "1000000000"
            } else {
                "18446744073709551616"
            }
            .into(),
        }
    }
    /// How many times an entity is repeated: large files, bounded so one
    /// input stays under a few megabytes.
    fn times(&self) -> usize {
        match self {
            Count::Few(n) => *n as usize % 8,
            Count::Many(n) => *n as usize % 2_000,
            Count::Absurd(large) => {
                if *large {
                    60_000
                } else {
                    10_000
                }
            }
        }
    }
}

/// Write an entity `n.times()` over, the input kept under 4 MB.
fn repeat(n: &Count, out: &mut String, mut write: impl FnMut(&mut String)) {
    for _ in 0..n.times() {
        if out.len() > 4 << 20 {
            break;
        }
        write(out);
    }
}

fn nums(v: &[Num]) -> String {
    v.iter().map(Num::text).collect::<Vec<_>>().join(" ")
}

// ---------------------------------------------------------------------------
// NFF

#[derive(Arbitrary, Debug)]
enum NffItem {
    Sphere([Num; 4]),
    Cone([Num; 8]),
    Polygon {
        declared: Count,
        given: u8,
        patch: bool,
        at: [Num; 3],
    },
    Light([Num; 3], Option<[Num; 3]>),
    Material([Num; 8]),
    Background([Num; 3]),
    Repeat(Count, Box<NffItem>),
}

impl NffItem {
    fn write(&self, out: &mut String) {
        match self {
            NffItem::Sphere(v) => out.push_str(&format!("s {}\n", nums(v))),
            NffItem::Cone(v) => out.push_str(&format!("c {}\n", nums(v))),
            NffItem::Polygon {
                declared,
                given,
                patch,
                at,
            } => {
                out.push_str(&format!(
                    "{} {}\n",
                    if *patch { "pp" } else { "p" },
                    declared.text()
                ));
                for k in 0..*given as usize % 64 {
                    let c = (k as f64).sin();
                    out.push_str(&format!("{} {c} {}", at[0].text(), at[1].text()));
                    if *patch {
                        out.push_str(&format!(" 0 0 {}", at[2].text()));
                    }
                    out.push('\n');
                }
            }
            NffItem::Light(p, c) => {
                out.push_str(&format!("l {}", nums(p)));
                if let Some(c) = c {
                    out.push_str(&format!(" {}", nums(c)));
                }
                out.push('\n');
            }
            NffItem::Material(v) => out.push_str(&format!("f {}\n", nums(v))),
            NffItem::Background(v) => out.push_str(&format!("b {}\n", nums(v))),
            NffItem::Repeat(n, item) => repeat(n, out, |out| item.write(out)),
        }
    }
}

#[derive(Arbitrary, Debug)]
struct NffScene {
    from: [Num; 3],
    angle: Num,
    resolution: (Count, Count),
    one_line: bool,
    items: Vec<NffItem>,
}

impl NffScene {
    fn text(&self) -> String {
        let mut s = format!(
            "v\nfrom {}\nat 0 0 0\nup 0 1 0\nangle {}\nhither 1\nresolution {} {}\n",
            nums(&self.from),
            self.angle.text(),
            self.resolution.0.text(),
            self.resolution.1.text()
        );
        for i in &self.items {
            i.write(&mut s);
        }
        if self.one_line {
            s = s.replace('\n', " ");
        }
        s
    }
}

// ---------------------------------------------------------------------------
// TOML

#[derive(Arbitrary, Debug)]
enum TomlItem {
    Sphere {
        center: Vec<Num>,
        radius: Num,
        material: bool,
    },
    Box {
        min: [Num; 3],
        max: [Num; 3],
    },
    Polygon {
        vertices: Count,
        at: Num,
    },
    Light {
        position: Vec<Num>,
    },
    Repeat(Count, Box<TomlItem>),
}

fn array(v: &[Num]) -> String {
    format!(
        "[{}]",
        v.iter().map(Num::text).collect::<Vec<_>>().join(", ")
    )
}

impl TomlItem {
    fn write(&self, out: &mut String) {
        match self {
            TomlItem::Sphere {
                center,
                radius,
                material,
            } => out.push_str(&format!(
                "[[object]]\ntype = \"sphere\"\nmaterial = \"{}\"\ncenter = {}\nradius = {}\n",
                if *material { "m" } else { "nope" },
                array(center),
                radius.text()
            )),
            TomlItem::Box { min, max } => out.push_str(&format!(
                "[[object]]\ntype = \"box\"\nmaterial = \"m\"\nmin = {}\nmax = {}\n",
                array(min),
                array(max)
            )),
            TomlItem::Polygon { vertices, at } => {
                out.push_str("[[object]]\ntype = \"polygon\"\nmaterial = \"m\"\nvertices = [");
                for k in 0..vertices.times().min(5000) {
                    out.push_str(&format!("[{}, {k}, 0], ", at.text()));
                }
                out.push_str("]\n");
            }
            TomlItem::Light { position } => {
                out.push_str(&format!("[[light]]\nposition = {}\n", array(position)))
            }
            TomlItem::Repeat(n, item) => repeat(n, out, |out| item.write(out)),
        }
    }
}

#[derive(Arbitrary, Debug)]
struct TomlScene {
    angle: Num,
    items: Vec<TomlItem>,
}

impl TomlScene {
    fn text(&self) -> String {
        let mut s = format!(
            "[camera]\nfrom = [0, 0, 10]\nat = [0, 0, 0]\nup = [0, 1, 0]\nangle = {}\n\
             [material.m]\ncolor = [1, 1, 1]\n",
            self.angle.text()
        );
        for i in &self.items {
            i.write(&mut s);
        }
        s
    }
}

// ---------------------------------------------------------------------------
// Assembly

#[derive(Arbitrary, Debug)]
enum Expr {
    Num(Num),
    Here,
    Label(u8),
    Neg(Box<Expr>),
    Paren(Box<Expr>),
    Binary(Box<Expr>, u8, Box<Expr>),
    /// An operand nested `n` deep in parentheses or unary minus.
    Deep(u16, bool),
}

impl Expr {
    fn text(&self, out: &mut String, budget: &mut usize) {
        if *budget == 0 {
            out.push('1');
            return;
        }
        *budget -= 1;
        match self {
            Expr::Num(n) => out.push_str(&match n {
                Num::Small(v) => v.to_string(),
                Num::Frac(v) => v.to_string(),
                Num::Big(v) => v.to_string(),
                Num::Huge(_) => "0x7fffffffffffffff".into(),
                Num::Tiny(_) => "-9223372036854775808".into(),
                _ => "0".into(),
            }),
            Expr::Here => out.push('.'),
            Expr::Label(k) => out.push_str(&format!("l{}", k % 8)),
            Expr::Neg(e) => {
                out.push('-');
                e.text(out, budget);
            }
            Expr::Paren(e) => {
                out.push('(');
                e.text(out, budget);
                out.push(')');
            }
            Expr::Binary(a, op, b) => {
                a.text(out, budget);
                out.push_str(
                    ["+", "-", "*", "/", "%", "<<", ">>", "&", "|", "^"][*op as usize % 10],
                );
                b.text(out, budget);
            }
            Expr::Deep(n, paren) => {
                let n = *n as usize % 30_000;
                if *paren {
                    out.push_str(&"(".repeat(n));
                    out.push('1');
                    out.push_str(&")".repeat(n));
                } else {
                    out.push_str(&"-".repeat(n));
                    out.push('1');
                }
            }
        }
    }
}

#[derive(Arbitrary, Debug)]
enum AsmLine {
    Label(u8),
    Text(u8, u8, u8, Expr),
    Ctx(u8, u8, u8, u8),
    Word(Vec<Expr>),
    Space(Count),
    Repeat(Count, Box<AsmLine>),
}

const MNEMONICS: [&str; 12] = [
    "addi", "li", "lw", "sw", "beq", "j", "ldctxt", "ldfb", "cbcast", "sll", "halt", "nop",
];
const CTX_OPS: [&str; 8] = ["add", "sub", "mul", "mac", "mov", "cmp.lt", "ld", "st"];

impl AsmLine {
    fn write(&self, out: &mut String) {
        let mut budget = 400;
        match self {
            AsmLine::Label(k) => out.push_str(&format!("l{}:\n", k % 8)),
            AsmLine::Text(m, a, b, e) => {
                out.push_str(&format!(
                    ".text\n{} r{}, r{}, ",
                    MNEMONICS[*m as usize % MNEMONICS.len()],
                    a % 20,
                    b % 20
                ));
                e.text(out, &mut budget);
                out.push('\n');
            }
            AsmLine::Ctx(op, a, b, c) => out.push_str(&format!(
                ".ctx\n{} r{}, r{}, r{}\n",
                CTX_OPS[*op as usize % CTX_OPS.len()],
                a % 20,
                b % 20,
                c % 20
            )),
            AsmLine::Word(v) => {
                out.push_str(".data\n.word ");
                for (i, e) in v.iter().enumerate() {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    e.text(out, &mut budget);
                }
                out.push('\n');
            }
            AsmLine::Space(n) => out.push_str(&format!(".data\n.space {}\n", n.text())),
            AsmLine::Repeat(n, line) => repeat(n, out, |out| line.write(out)),
        }
    }
}

#[derive(Arbitrary, Debug)]
struct Program {
    lines: Vec<AsmLine>,
}

// ---------------------------------------------------------------------------
// Program images

#[derive(Arbitrary, Debug)]
struct ImageDoc {
    entry: u32,
    declared: Count,
    segments: Vec<(u32, u8, Count, Vec<u8>)>,
}

impl ImageDoc {
    fn bytes(&self) -> Vec<u8> {
        let mut v = b"MSYSIMG1".to_vec();
        v.extend(self.entry.to_le_bytes());
        let n = match &self.declared {
            Count::Absurd(_) => u32::MAX,
            _ => self.segments.len() as u32,
        };
        v.extend(n.to_le_bytes());
        for (addr, sec, len, data) in &self.segments {
            v.extend(addr.to_le_bytes());
            v.push(sec % 4);
            let len = match len {
                Count::Absurd(_) => u32::MAX,
                _ => data.len() as u32,
            };
            v.extend(len.to_le_bytes());
            v.extend(data);
        }
        v
    }
}

/// One structure-aware input for `t`, from the generator's random bytes.
pub fn input(t: Target, g: &mut Rng) -> Vec<u8> {
    let raw: Vec<u8> = (0..64 + g.below(2048)).map(|_| g.next() as u8).collect();
    let mut u = Unstructured::new(&raw);
    match t {
        Target::Nff => NffScene::arbitrary(&mut u).map(|s| s.text().into_bytes()),
        Target::Toml => TomlScene::arbitrary(&mut u).map(|s| s.text().into_bytes()),
        Target::Asm => Program::arbitrary(&mut u).map(|p| {
            let mut s = String::new();
            for l in &p.lines {
                l.write(&mut s);
            }
            s.into_bytes()
        }),
        Target::Image => ImageDoc::arbitrary(&mut u).map(|d| d.bytes()),
    }
    .unwrap_or_default()
}
