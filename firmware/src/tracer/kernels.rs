//! The RC context kernels of the ray tracer, emitted as assembly text.
//!
//! Register convention in every RC (the "ray registers" live across
//! kernels, the rest are temporaries of one kernel):
//!
//! | reg | holds |
//! |---|---|
//! | r0 | 0 (set once at start) |
//! | r1..r3 | ray origin, scene format `Qm.n` |
//! | r4..r6 | ray direction, unit, Q1.14 |
//! | r7 | `tbest`: distance to the closest hit so far (scene format), 32767 = none |
//! | r8..r15 | temporaries |
//!
//! Each kernel reads its object's record from one FB stream (set 0) in
//! exactly the order its contexts read `fb0`; the record writers in
//! [`super::layout`] follow the same order, and a test checks that every
//! kernel reads exactly as many words as its record holds.
//!
//! Arithmetic never wraps silently: differences of coordinates fit by the
//! two guard bits of the scene format, products go through the 32-bit
//! accumulator and are saturated when scaled back to 16 bits, and a
//! saturated value always fails the test it feeds (a saturated
//! perpendicular distance is a miss, a saturated `t` is beyond `tbest`).

use std::cell::Cell;
use std::fmt::Write;

use rtl::rc::Datapath;

thread_local! {
    static EXTRA: Cell<u32> = const { Cell::new(0) };
}

/// Extra fraction bits of every fixed-point format on the datapath the
/// kernels are being generated for: 0 on the 16-bit chip, 16 on the 32-bit
/// chip (Q1.14 directions become Q1.30, Q3.12 colours Q3.28, the scene
/// format gains 16 fraction bits, the tables' fixed points follow). Every
/// format-dependent constant of a kernel is its 16-bit value plus these
/// bits, written [`K::cq`] (a line's shifts and immediates) or [`q`];
/// counts of integer bits (`clz` normalisations, halvings) do not change.
pub fn extra_bits() -> u32 {
    EXTRA.with(|e| e.get())
}

/// Generate kernels for `datapath` inside `f` (the generator sets this once
/// per build; the default is the 16-bit chip).
pub fn with_datapath<R>(datapath: Datapath, f: impl FnOnce() -> R) -> R {
    let x = datapath.bits() - 16;
    let old = EXTRA.with(|e| e.replace(x));
    let r = f();
    EXTRA.with(|e| e.set(old));
    r
}

/// A format constant: its 16-bit value plus [`extra_bits`].
pub fn q(n: u32) -> u32 {
    n + extra_bits()
}

/// RC RAM map (word addresses, 0..511).
pub mod ram {
    /// Reciprocal square root table, 128 words (index `X >> 8`, X in Q.11).
    pub const RSQ: u32 = 0;
    /// Reciprocal table, 128 words (index bits 13..7 of a normalised divisor).
    pub const RCP: u32 = 128;
    pub const C_ONE: u32 = 256;
    pub const C_INF: u32 = 257;
    pub const LANE_ROW: u32 = 258;
    pub const LANE_COL: u32 = 259;
    pub const LANE_ACT: u32 = 260;
    /// The "vector" of the paper's Fig. 7: closest hit of the current pass.
    pub const HIT_OBJ: u32 = 261;
    pub const HIT_MAT: u32 = 262;
    pub const HIT_N: u32 = 263; // 3
    /// `tbest` at the start of the pass (a hit is `tbest < PASS_T0`).
    pub const PASS_T0: u32 = 266;
    /// Shading state of the current recursion level.
    pub const SH_P: u32 = 267; // 3, hit point offset off the surface
    pub const SH_N: u32 = 270; // 3
    pub const SH_MAT: u32 = 273;
    pub const SH_D: u32 = 274; // 3, direction of the ray that hit
    pub const ACT: u32 = 277;
    pub const COL: u32 = 278; // 3, colour of this level, Q3.12
    pub const OUT_OBJ: u32 = 281;
    pub const SH_KS: u32 = 282;
    pub const SH_NL: u32 = 283;
    pub const SH_RV: u32 = 284;
    pub const LIT: u32 = 285;
    pub const TMP0: u32 = 286;
    pub const TMP1: u32 = 287;
    pub const TMP2: u32 = 288;
    pub const TMP3: u32 = 289;
    pub const TMP4: u32 = 290;
    /// Two more temporaries of one kernel (the cylinder's), sharing the
    /// cone kernel's words.
    pub const TMP5: u32 = CONE_TMP;
    pub const TMP6: u32 = CONE_TMP + 1;
    /// The cone kernel's frame values and zoom (8 words, temporaries of
    /// that kernel).
    pub const CONE_TMP: u32 = 291;
    /// The local stack: 4 words (colour r, g, b and reflection weight) per
    /// recursion level.
    pub const STACK: u32 = 300;
    pub const STACK_FRAME: u32 = 4;
    /// Streamed layout: number of unordered BSP subtrees the ray is in
    /// whose visiting order goes against its direction (it may only sleep
    /// at a leaf when this is 0).
    pub const UNORD: u32 = 340;
    /// Smooth triangles ([`super::smooth_triangle`]): the interpolated
    /// shading normal of the closest smooth triangle hit so far and its
    /// object id (it is the hit's shading normal when the id is the hit's),
    /// and the geometric normal of the hit being shaded.
    pub const HIT_NS: u32 = 341; // 3
    pub const HIT_NS_OBJ: u32 = 344;
    pub const SH_NG: u32 = 345; // 3
    /// Two-sided (transmitting) objects: the id of the closest one hit
    /// from its back so far (-1: none), and whether the hit being shaded
    /// is such a back hit (the ray leaves the object).
    pub const HIT_BACK_OBJ: u32 = 348;
    pub const SH_BACK: u32 = 349;
    /// The refraction stack: per recursion level, the refracted ray's
    /// origin (3), direction (3) and weight T (0: none), set up before the
    /// level's reflection and traced after it.
    pub const REFR: u32 = 350;
    pub const REFR_FRAME: u32 = 7;
    /// Two-sided planar objects: the object the current rays leave (-1:
    /// none, eye rays), which they do not hit again; per recursion level
    /// the one the refracted ray leaves.
    pub const ORIG_OBJ: u32 = 299;
    pub const ORIG_STACK: u32 = 480; // 8
    /// Packet traversal ([`super::super::Traversal::Packet`]): 1 while the
    /// ray takes part in the current pass (it may be woken at a pop).
    pub const P_ALIVE: u32 = 400;
    /// Per axis, the direction's reciprocal as a shift `z - 1` and a signed
    /// mantissa `R`, and the widening `dt` of a plane in `t` (see
    /// [`super::pk_init`]).
    pub const P_Z: u32 = 403; // 3
    pub const P_R: u32 = 406; // 3
    pub const P_DT: u32 = 409; // 3
    /// The interval stack: one slot per BSP depth (the far child of the
    /// node at depth d is pushed into slot d), words `tmax, tmin`.
    pub const P_SLOT: u32 = 416; // 2 x 32
    pub const P_SLOTS: u32 = crate::scene_image::MAX_BSP_DEPTH;
}

/// Offset of a spawned ray's origin along the normal, in LSBs. Default 0:
/// every kernel is one-sided and its primitive convex (or planar), so a ray
/// leaving the surface it starts on cannot hit that surface again however
/// the hit point was rounded (the sphere's near root and a plane's
/// back face are rejected), while an offset of a few LSB pushes the origin
/// of a shadow ray off a small sphere into the neighbour it touches, whose
/// kernel then rejects it (balls-4: 3 LSB cost 2 dB).
pub const EPS_LSB: i32 = 0;
/// Tolerance of the barycentric / rectangle / disc inside tests, Q.14.
pub const INSIDE_TOL: i32 = 2;

/// Entries of the reciprocal and reciprocal square root tables by default.
pub const TABLE_ENTRIES: u32 = 128;
/// Table sizes the RC RAM map has room for (each table has a 128-word
/// slot; two of 256 would fill the whole 512-word RAM).
pub const TABLE_SIZES: [u32; 4] = [16, 32, 64, 128];

/// How the kernels approximate reciprocals and reciprocal square roots:
/// table entries ([`TABLE_SIZES`]) and Newton-Raphson steps after the
/// lookup. A plain `u32` is that many steps with the default table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Approx {
    pub newton_steps: u32,
    pub table_entries: u32,
}

impl From<u32> for Approx {
    fn from(newton_steps: u32) -> Approx {
        Approx {
            newton_steps,
            table_entries: TABLE_ENTRIES,
        }
    }
}

impl Approx {
    /// Right shift of the table index against the 128-entry table.
    fn coarse(self) -> u32 {
        (TABLE_ENTRIES / self.table_entries.clamp(1, TABLE_ENTRIES)).trailing_zeros()
    }
}

/// An emitter of context lines.
#[derive(Default)]
pub struct K {
    pub lines: Vec<String>,
    /// FB words read (for the record-length check).
    pub fb_reads: usize,
}

impl K {
    pub fn c(&mut self, s: impl AsRef<str>) -> &mut Self {
        let s = s.as_ref();
        self.fb_reads += s.matches("fb0").count();
        self.lines.push(format!("        {s}"));
        self
    }
    /// A context line whose shift amounts (`>>N`, `<<N`) and immediates
    /// (`#N`) are fraction counts of the 16-bit formats: each gets the
    /// datapath's [`extra_bits`] (none on the 16-bit chip).
    pub fn cq(&mut self, s: impl AsRef<str>) -> &mut Self {
        let x = extra_bits();
        let s = s.as_ref();
        if x == 0 {
            return self.c(s);
        }
        let mut out = String::with_capacity(s.len() + 4);
        let mut rest = s;
        while let Some(i) = rest.find(|c: char| c.is_ascii_digit()) {
            let (head, tail) = rest.split_at(i);
            let n = tail
                .find(|c: char| !c.is_ascii_digit())
                .unwrap_or(tail.len());
            let marked = head.ends_with(">>") || head.ends_with("<<") || head.ends_with('#');
            out.push_str(head);
            match tail[..n].parse::<u32>() {
                Ok(v) if marked => out.push_str(&(v + x).to_string()),
                _ => out.push_str(&tail[..n]),
            }
            rest = &tail[n..];
        }
        out.push_str(rest);
        self.c(out)
    }
    pub fn comment(&mut self, s: &str) -> &mut Self {
        self.lines.push(format!("        ; {s}"));
        self
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    pub fn len(&self) -> usize {
        self.lines
            .iter()
            .filter(|l| !l.trim_start().starts_with(';'))
            .count()
    }
    pub fn text(&self, label: &str) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "{label}:");
        for l in &self.lines {
            let _ = writeln!(s, "{l}");
        }
        let _ = writeln!(s, "{label}_end:");
        s
    }
}

fn r(k: u8) -> String {
    format!("r{k}")
}

/// Normalise the vector in registers `v` in place to a unit Q1.14 vector;
/// with `len`, also its length (in the input's units) into `t[0]`.
/// Temporaries `t` (5 registers). Method: halve (so the largest component
/// is below 2^14), shift left by `clz(max) - 2` (largest component in
/// [2^13, 2^14)), `X = |v'|^2 >> 15` in Q.11 (range [1, 12)), reciprocal
/// square root from the RSQ table (index X >> 8) and two Newton-Raphson
/// steps `y += y (1 - X y^2) / 2`.
pub fn normalize(k: &mut K, v: [u8; 3], t: [u8; 5], len: bool, nr: impl Into<Approx>) {
    let nr: Approx = nr.into();
    let [a, b, c] = v.map(r);
    let [t0, t1, t2, t3, t4] = t.map(r);
    k.comment("normalize");
    for x in [&a, &b, &c] {
        k.c(format!("sra {x}, {x}, #1"));
    }
    k.c(format!("abs {t0}, {a}"))
        .c(format!("abs {t1}, {b}"))
        .c(format!("max {t0}, {t0}, {t1}"))
        .c(format!("abs {t1}, {c}"))
        .c(format!("max {t0}, {t0}, {t1}"))
        .c(format!("clz {t0}, {t0}"))
        .c(format!("sub {t0}, {t0}, #2")); // t0 = sh
    for x in [&a, &b, &c] {
        k.c(format!("sll {x}, {x}, {t0}"));
    }
    k.c(format!("mul out, {a}, {a}"))
        .c(format!("mac out, {b}, {b}"))
        .cq(format!("mac {t1}, {c}, {c}, >>15")) // X, Q.11
        .c(format!("srl {t2}, {t1}, #{}", q(8) + nr.coarse()))
        .c(format!("ld {t2}, [{t2} + #{}]", ram::RSQ)) // y
        .c(format!("ld {t4}, [r0 + #{}]", ram::C_ONE));
    for _ in 0..nr.newton_steps {
        k.cq(format!("mul {t3}, {t2}, {t2}, >>14"))
            .cq(format!("mul {t3}, {t3}, {t1}, >>11"))
            .c(format!("sub {t3}, {t3}, {t4}"))
            .cq(format!("ldacc {t2}, <<15"))
            .cq(format!("msu {t2}, {t2}, {t3}, >>15"));
    }
    if len {
        // |v'| = X * y in units of v' (>> 12), then undo the shifts.
        k.cq(format!("mul {t1}, {t1}, {t2}, >>12"))
            .c(format!("sra {t1}, {t1}, {t0}"))
            .c(format!("adds {t0}, {t1}, {t1}"));
    }
    for x in [&a, &b, &c] {
        k.cq(format!("mul {x}, {x}, {t2}, >>13"));
    }
}

/// `out = sqrt(s)` for `s` in Q.14 (0, 1], result Q.14. Method: clamp to
/// 16383, shift left by an odd `e = (clz(s) - 2) | 1` so that `X = s << e`
/// is in [2^13, 2^15), reciprocal square root of X (Q.11) from the RSQ
/// table and two Newton-Raphson steps, `sqrt(X) = X * y` (Q.12), then
/// shift right by `(e - 1) / 2` (since `s = X 2^-(3 + e)` in Q.11 units). Clobbers `t` (4 registers); `s` is kept.
pub fn sqrt_q14(k: &mut K, s: u8, out: u8, t: [u8; 4], nr: impl Into<Approx>) {
    let nr: Approx = nr.into();
    let (s, o) = (r(s), r(out));
    let [e, x, y, w] = t.map(r);
    k.comment("sqrt");
    k.c(format!("ld {w}, [r0 + #{}]", ram::C_ONE))
        .c(format!("add {w}, {w}, #-1"))
        .c(format!("min {o}, {s}, {w}"))
        .c(format!("clz {e}, {o}"))
        .c(format!("sub {e}, {e}, #2"))
        .c(format!("or {e}, {e}, #1"))
        .c(format!("sll {x}, {o}, {e}"))
        .c(format!("srl {y}, {x}, #{}", q(8) + nr.coarse()))
        .c(format!("ld {y}, [{y} + #{}]", ram::RSQ))
        .c(format!("ld {w}, [r0 + #{}]", ram::C_ONE));
    for _ in 0..nr.newton_steps {
        k.cq(format!("mul {o}, {y}, {y}, >>14"))
            .cq(format!("mul {o}, {o}, {x}, >>11"))
            .c(format!("sub {o}, {o}, {w}"))
            .cq(format!("ldacc {y}, <<15"))
            .cq(format!("msu {y}, {y}, {o}, >>15"));
    }
    k.cq(format!("mul {o}, {x}, {y}, >>13")) // sqrt(X) in Q.12
        .c(format!("sub {e}, {e}, #1"))
        .c(format!("sra {e}, {e}, #1"))
        .c(format!("sra {o}, {o}, {e}"));
}

/// `q = num * 2^14 / den` for `num >= 0`, `den` in (0, 16384] (Q.14), the
/// caller having checked that the quotient is below 32768. Method:
/// normalise `den` by `clz` into [2^14, 2^15), reciprocal `2^29 / den'` from
/// the RCP table (index bits 13..7) and two Newton-Raphson steps
/// `r -= r (den' r / 2^29 - 1)`, then `q = (num * r) >> (15 - sh)` from the
/// two accumulator halves. Result into `num`'s register `out`; clobbers `t`.
pub fn divide(k: &mut K, num: u8, den: u8, out: u8, t: [u8; 5], nr: impl Into<Approx>) {
    let nr: Approx = nr.into();
    let (n, d, o) = (r(num), r(den), r(out));
    let [sh, dn, rc, w, one] = t.map(r);
    k.comment("divide");
    k.c(format!("clz {sh}, {d}"))
        .c(format!("sub {sh}, {sh}, #1"))
        .c(format!("sll {dn}, {d}, {sh}"))
        .c(format!("srl {rc}, {dn}, #{}", q(7) + nr.coarse()))
        .c(format!("and {rc}, {rc}, #{}", nr.table_entries - 1))
        .c(format!("ld {rc}, [{rc} + #{}]", ram::RCP))
        .c(format!("ld {one}, [r0 + #{}]", ram::C_ONE));
    for _ in 0..nr.newton_steps {
        k.cq(format!("mul {w}, {dn}, {rc}, >>15"))
            .c(format!("sub {w}, {w}, {one}"))
            .cq(format!("ldacc {rc}, <<14"))
            .cq(format!("msu {rc}, {rc}, {w}, >>14"));
    }
    k.c(format!("mul out, {n}, {rc}"))
        .c(format!("acch {w}"))
        .c(format!("accl {dn}"))
        .c(format!("add {one}, {sh}, #1"))
        .c(format!("sll {w}, {w}, {one}"))
        .cq(format!("rsb {one}, {sh}, #15"))
        .c(format!("srl {dn}, {dn}, {one}"))
        .c(format!("or {o}, {w}, {dn}"));
}

/// [`divide`] with one more bit of range: `q = num * 2^13 / den` for `num >= 0`,
/// `den` in (0, 32767], the caller having checked `num < 4 den`.
pub fn divide_q13(k: &mut K, num: u8, den: u8, out: u8, t: [u8; 5], nr: impl Into<Approx>) {
    let nr: Approx = nr.into();
    let (n, d, o) = (r(num), r(den), r(out));
    let [sh, dn, rc, w, one] = t.map(r);
    k.comment("divide (Q.13 quotient)");
    k.c(format!("clz {sh}, {d}"))
        .c(format!("sub {sh}, {sh}, #1"))
        .c(format!("sll {dn}, {d}, {sh}"))
        .c(format!("srl {rc}, {dn}, #{}", q(7) + nr.coarse()))
        .c(format!("and {rc}, {rc}, #{}", nr.table_entries - 1))
        .c(format!("ld {rc}, [{rc} + #{}]", ram::RCP))
        .c(format!("ld {one}, [r0 + #{}]", ram::C_ONE));
    for _ in 0..nr.newton_steps {
        k.cq(format!("mul {w}, {dn}, {rc}, >>15"))
            .c(format!("sub {w}, {w}, {one}"))
            .cq(format!("ldacc {rc}, <<14"))
            .cq(format!("msu {rc}, {rc}, {w}, >>14"));
    }
    k.c(format!("mul out, {n}, {rc}"))
        .c(format!("acch {w}"))
        .c(format!("accl {dn}"))
        .c(format!("sll {w}, {w}, {sh}"))
        .cq(format!("rsb {one}, {sh}, #16"))
        .c(format!("srl {dn}, {dn}, {one}"))
        .c(format!("or {o}, {w}, {dn}"));
}

/// `x^n` for `x` in Q.14 [0, 1] by square-and-multiply: `out = base^n`.
pub fn pow_q14(k: &mut K, base: u8, out: u8, tmp: u8, n: u32) {
    let (b, o, t) = (r(base), r(out), r(tmp));
    k.comment(&format!("pow ^{n}"));
    k.c(format!("ld {o}, [r0 + #{}]", ram::C_ONE));
    if n == 0 {
        return;
    }
    k.c(format!("mov {t}, {b}"));
    let mut e = n;
    loop {
        if e & 1 == 1 {
            k.cq(format!("mul {o}, {o}, {t}, >>14"));
        }
        e >>= 1;
        if e == 0 {
            break;
        }
        k.cq(format!("mul {t}, {t}, {t}, >>14"));
    }
}

/// Store the candidate hit's normal (three words streamed), object and
/// material (streamed) where F is set; `t` becomes `tbest`.
fn commit_streamed_normal(k: &mut K, t: u8) {
    k.c(format!("(f) mov r7, r{t}"));
    for i in 0..3 {
        k.c(format!("(f) st fb0, [#{}]", ram::HIT_N + i));
    }
    k.c(format!("(f) st fb0, [#{}]", ram::HIT_OBJ))
        .c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
}

/// Sphere. Record (8 words): `c.xyz, r, invr, sg, obj, mat`.
/// `invr = 2^(14+ks) / r` (scene LSBs); `sg` = +16384 for a sphere seen from
/// outside, -16384 for NFF's inside-visible sphere.
///
/// Perpendicular method: `b = (c - o).d`, `p = (c - o) - b d` kept with
/// `ep` extra fraction bits (it saturates only beyond twice the largest
/// radius, which is a miss), only `p / r` is squared: `s = 1 - |p / r|^2`,
/// `t = b - sg r sqrt(s)`, and the normal follows without the hit point:
/// `n = -(sg p / r + sqrt(s) d)`.
pub fn sphere(ks: u32, ep: u32, nr: impl Into<Approx>) -> K {
    let nr: Approx = nr.into();
    sphere_with(ks, ep, nr, false, true)
}

/// [`sphere`], with `fine`: spheres a few LSB across, whose rounded centre
/// and radius would move their silhouettes and shadows by a sizeable part
/// of their size. The record (11 words: `c.xyz, cl.xyz, r, invr, sg, obj,
/// mat`) adds the centre's rounding remainder `cl` in units of 2^-14 LSB
/// and holds `r` with `ep` extra fraction bits; the perpendicular vector is
/// formed in the accumulator from the unrounded centre and the unrounded
/// `b` (its remainder below 1 LSB, read back with `accl`, is subtracted
/// along `d` as well): `p = (c - o) + cl - b d` to 2^-ep LSB.
///
/// `perp` (fine normals, [`super::Normals`]): `p` is made perpendicular
/// to `d` instead ([`perpendicular_to`], which also takes out what `b`'s
/// rounding left along `d`, so the fine record needs no remainder of `b`).
pub fn sphere_with(ks: u32, ep: u32, nr: impl Into<Approx>, fine: bool, perp: bool) -> K {
    sphere_sides(ks, ep, nr, fine, perp, false)
}

/// A ray starting on a transmitting sphere ignores its roots closer than
/// this (LSB of the 16-bit chip's scene format; the same distance on the
/// 32-bit chip): its own surface, however the start point was rounded (the
/// sphere's `t` errs by up to 5 LSB, `tb/tests/kernels.rs`; the reference
/// nudges the start off the surface instead). Planar kernels skip the
/// object the ray leaves by its id instead (`ram::ORIG_OBJ`).
pub const SELF_LSB: i32 = 8;

/// The sphere of a transmitting material, visible from both sides (the
/// reference's rule): where the near root is not ahead of the ray (by
/// more than [`SELF_LSB`]) the far root, with the normal turned to the
/// ray; a hit on the far side records the object in `ram::HIT_BACK_OBJ`.
/// The record is the sphere's ([`sphere_with`]).
pub fn sphere_two_sided(ks: u32, ep: u32, nr: impl Into<Approx>, fine: bool, perp: bool) -> K {
    sphere_sides(ks, ep, nr, fine, perp, true)
}

/// Remove from the vector in registers `p` its component along the unit
/// vector in registers `d` (the ray direction r4..r6, or the cylinder's 2D
/// direction): `p -= (p.d) d`, with `t` a temporary. The perpendicular
/// vector `(c - o) - b d` of the sphere and cylinder tests is
/// perpendicular to `d` only in exact arithmetic: `b` is rounded to an
/// LSB and the Q1.14 direction is not quite unit (`|d|^2 - 1` of a few
/// 2^-14), and the distance `b` multiplies that. Far from the eye (`b`
/// thousands of LSB) the leftover along `d` reaches an LSB or more, and
/// divided by a radius of a few dozen LSB it tilts the normal by a
/// hundredth of a radian, which a Phong highlight or a reflection shows.
fn perpendicular_to(k: &mut K, p: &[u8], d: &[u8], t: u8) {
    let n = p.len();
    for (i, (x, e)) in p.iter().zip(d).enumerate() {
        match i {
            0 => k.c(format!("mul out, r{x}, r{e}")),
            _ if i + 1 < n => k.c(format!("mac out, r{x}, r{e}")),
            _ => k.cq(format!("mac r{t}, r{x}, r{e}, >>14")),
        };
    }
    for (x, e) in p.iter().zip(d) {
        k.cq(format!("ldacc r{x}, <<14"))
            .cq(format!("msu r{x}, r{t}, r{e}, >>14"));
    }
}

fn sphere_sides(ks: u32, ep: u32, nr: impl Into<Approx>, fine: bool, perp: bool, two: bool) -> K {
    let nr: Approx = nr.into();
    let mut k = K::default();
    k.comment("sphere: oc = c - o");
    k.c("sub r8, fb0, r1")
        .c("sub r9, fb0, r2")
        .c("sub r10, fb0, r3");
    k.c("mul out, r8, r4")
        .c("mac out, r9, r5")
        .cq("mac r11, r10, r6, >>14"); // b
    if fine && !perp {
        // b's remainder: the accumulator minus round(b) 2^14, below 2^13
        // in magnitude, so its low half is exact (the wrap is intended).
        k.c("accl r12")
            .cq("sll r14, r11, #14")
            .c("sub r12, r12, r14");
    }
    for (x, d) in [(8, 4), (9, 5), (10, 6)] {
        if fine && !perp {
            k.cq(format!("mul r13, r12, r{d}, >>14"))
                .cq(format!("ldacc r{x}, <<14"))
                .c("mac out, fb0, #1")
                .c("msu out, r13, #1");
        } else {
            k.cq(format!("ldacc r{x}, <<14"));
            if fine {
                k.c("mac out, fb0, #1");
            }
        }
        k.c(format!("msu r{x}, r11, r{d}, >>{}", q(14) - ep));
    }
    if perp {
        perpendicular_to(&mut k, &[8, 9, 10], &[4, 5, 6], 12);
    }
    let er = if fine { ep } else { 0 };
    k.c("mov r12, fb0").c("mov r13, fb0"); // r, invr
    for (i, x) in [8, 9, 10].into_iter().enumerate() {
        k.c(format!("mul r{x}, r{x}, r13, >>{}", ks + ep))
            .c(format!("st r{x}, [#{}]", ram::TMP0 + i as u32));
    }
    k.c(format!("ld r14, [r0 + #{}]", ram::C_ONE))
        .cq("ldacc r14, <<14")
        .c("msu out, r8, r8")
        .c("msu out, r9, r9")
        .cq("msu r15, r10, r10, >>14")
        .c("cmp.gt r15, #0");
    sqrt_q14(&mut k, 15, 8, [9, 10, 13, 14], nr);
    if two {
        k.c(format!("mul r9, r12, r8, >>{}", q(14) + er)) // h
            .c("mov r10, fb0") // sg
            .cq("mul r14, r9, r10, >>14")
            .c("sub r9, r11, r14") // t1 = b - sg h
            .c("movb r15, #0")
            .c("(f) movb r15, #1")
            .c("movb r12, #0")
            .c(format!("movb r13, #{SELF_LSB}"));
        if extra_bits() > 0 {
            // the margin in LSB of the 16-bit chip's format
            k.c(format!("sll r13, r13, #{}", extra_bits()));
        }
        k.c("cmp.le r9, r13")
            .c("(f) add r9, r11, r14") // t2 = b + sg h
            .c("(f) neg r10, r10")
            .c("(f) movb r12, #1")
            .c(format!("st r12, [#{}]", ram::TMP3))
            .c("cmp.ne r15, #0")
            .c("(f) cmp.gt r9, r13")
            .c("(f) cmp.lt r9, r7");
    } else {
        k.c(format!("mul r9, r12, r8, >>{}", q(14) + er)) // h
            .c("mov r10, fb0") // sg
            .cq("mul r9, r9, r10, >>14")
            .c("sub r9, r11, r9") // t
            .c("(f) cmp.gt r9, #0")
            .c("(f) cmp.lt r9, r7");
    }
    k.comment("normal = -(sg p/r + sqrt(s) d)");
    for (i, (x, d)) in [(11, 4), (12, 5), (13, 6)].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::TMP0 + i as u32))
            .c(format!("mul out, r8, r{d}"))
            .cq(format!("mac r{x}, r10, r{x}, >>14"))
            .c(format!("neg r{x}, r{x}"));
    }
    k.c("(f) mov r7, r9");
    for (i, x) in [11, 12, 13].into_iter().enumerate() {
        k.c(format!("(f) st r{x}, [#{}]", ram::HIT_N + i as u32));
    }
    if two {
        // HIT_BACK_OBJ = obj where the far side was hit, else -1.
        k.c("mov r8, fb0")
            .c(format!("(f) st r8, [#{}]", ram::HIT_OBJ))
            .c(format!("ld r9, [r0 + #{}]", ram::TMP3))
            .c("neg r9, r9")
            .c("add r13, r8, #1")
            .c("and r13, r13, r9")
            .c("sub r13, r13, #1")
            .c(format!("(f) st r13, [#{}]", ram::HIT_BACK_OBJ));
    } else {
        k.c(format!("(f) st fb0, [#{}]", ram::HIT_OBJ));
    }
    k.c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
    k
}

/// Which inside test a planar kernel ends with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inside {
    /// Barycentric: u >= 0, w >= 0, u + w <= 1.
    Triangle,
    /// 0 <= u <= 1, 0 <= w <= 1.
    Rectangle,
    /// u^2 + w^2 <= 1 (a cylinder's end cap).
    Disc,
}

/// The ray-plane part shared by the planar and polygon kernels: reads the
/// plane normal and a vertex from FB set 0, and leaves `t = num / den` in
/// r9 with F set where the plane is hit in front, closer than `tbest`.
fn plane_hit(k: &mut K, nr: impl Into<Approx>) {
    plane_hit_sides(k, nr, false)
}

/// [`plane_hit`]; `two`: both sides (a transmitting object, the
/// reference's rule): where the plane is seen from its back, `den` and
/// `num` change sign (`ram::TMP3` = 1: a back hit). A ray leaving the
/// object does not hit it again ([`commit_streamed_normal_two`] compares
/// the object with `ram::ORIG_OBJ`; a distance margin would also drop the
/// hits of rays starting near an edge on the next face).
fn plane_hit_sides(k: &mut K, nr: impl Into<Approx>, two: bool) {
    let nr: Approx = nr.into();
    k.c("mov r8, fb0").c("mov r9, fb0").c("mov r10, fb0");
    k.c("mul out, r8, r4")
        .c("mac out, r9, r5")
        .cq("mac r11, r10, r6, >>14");
    k.c("sub r12, fb0, r1")
        .c("sub r13, fb0, r2")
        .c("sub r14, fb0, r3");
    k.c("mul out, r8, r12")
        .c("mac out, r9, r13")
        .cq("mac r15, r10, r14, >>14");
    k.c("neg r11, r11").c("neg r15, r15");
    if two {
        // the back: den and num change sign, TMP3 = 1
        k.c("movb r12, #0")
            .c("cmp.lt r11, #0")
            .c("(f) movb r12, #1")
            .c("(f) neg r11, r11")
            .c("(f) neg r15, r15")
            .c(format!("st r12, [#{}]", ram::TMP3));
    }
    k.c("cmp.gt r11, #0")
        .c("(f) cmp.gt r15, #0")
        .cq("ldacc r15, <<14")
        .c("msu out, r7, r11")
        .c("acch r8")
        .c("(f) cmp.lt r8, #0");
    divide(k, 15, 11, 9, [8, 10, 12, 13, 14], nr);
}

/// [`commit_streamed_normal`] of a two-sided kernel: the streamed normal
/// turned where the back was hit (`ram::TMP3`), and `ram::HIT_BACK_OBJ`.
fn commit_streamed_normal_two(k: &mut K, t: u8) {
    k.c(format!("ld r12, [r0 + #{}]", ram::TMP3))
        .c("movb r14, #1")
        .c("sub r14, r14, r12")
        .c("sub r14, r14, r12") // 1 - 2 back
        .c("mul r10, fb0, r14")
        .c("mul r11, fb0, r14")
        .c("mul r13, fb0, r14")
        .c("mov r8, fb0")
        .c(format!("ld r15, [r0 + #{}]", ram::ORIG_OBJ))
        .c("(f) cmp.ne r8, r15")
        .c(format!("(f) mov r7, r{t}"));
    for (i, x) in [10, 11, 13].into_iter().enumerate() {
        k.c(format!("(f) st r{x}, [#{}]", ram::HIT_N + i as u32));
    }
    k.c(format!("(f) st r8, [#{}]", ram::HIT_OBJ))
        .c("neg r12, r12")
        .c("add r13, r8, #1")
        .c("and r13, r13, r12")
        .c("sub r13, r13, #1")
        .c(format!("(f) st r13, [#{}]", ram::HIT_BACK_OBJ))
        .c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
}

/// A one-sided planar primitive. Record (20 words):
/// `n.xyz (Q1.14), v0.xyz, v0.xyz, eu.xyz, ew.xyz, n.xyz, obj, mat`, where
/// `u = (P - v0).eu`, `w = (P - v0).ew` (scaled by 2^kt) are the
/// barycentric or edge coordinates in Q.14.
///
/// `den = -n.d > 0` (front face), `num = -n.(v0 - o) > 0`; the test
/// `num 2^14 < tbest den` is done in the 32-bit accumulator before the
/// division, so the quotient always fits.
pub fn planar(inside: Inside, kt: u32, nr: impl Into<Approx>) -> K {
    planar_sides(inside, kt, nr, false)
}

/// [`planar`] for a transmitting object: both sides ([`plane_hit_sides`]),
/// the normal turned to the ray, back hits recorded.
pub fn planar_two_sided(inside: Inside, kt: u32, nr: impl Into<Approx>) -> K {
    planar_sides(inside, kt, nr, true)
}

fn planar_sides(inside: Inside, kt: u32, nr: impl Into<Approx>, two: bool) -> K {
    let nr: Approx = nr.into();
    let mut k = K::default();
    k.comment("planar: den = n.d, num = n.(v0 - o)");
    plane_hit_sides(&mut k, nr, two);
    inside_test(&mut k, inside, kt);
    if two {
        commit_streamed_normal_two(&mut k, 9);
    } else {
        commit_streamed_normal(&mut k, 9);
    }
    k
}

/// After [`plane_hit`]: the hit point relative to `v0` (the stream's
/// `v0.xyz`), its coordinates `u` (r13), `w` (r14) along the record's dual
/// edge vectors (scaled by `2^kt`), and F kept only where they are inside
/// the primitive (`u + w` in r15 for a triangle), with a tolerance of
/// [`INSIDE_TOL`].
fn inside_test(k: &mut K, inside: Inside, kt: u32) {
    k.comment("P - v0");
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        let x = 10 + i;
        k.cq(format!("ldacc r{o}, <<14"))
            .cq(format!("mac r{x}, r9, r{d}, >>14"))
            .c(format!("rsb r{x}, fb0, r{x}"));
    }
    k.c("mul out, fb0, r10")
        .c("mac out, fb0, r11")
        .c(format!("mac r13, fb0, r12, >>{kt}"));
    k.c("mul out, fb0, r10")
        .c("mac out, fb0, r11")
        .c(format!("mac r14, fb0, r12, >>{kt}"));
    k.c(format!("ld r8, [r0 + #{}]", ram::C_ONE))
        .c(format!("add r8, r8, #{INSIDE_TOL}"));
    match inside {
        Inside::Triangle => {
            k.c(format!("(f) cmp.ge r13, #-{INSIDE_TOL}"))
                .c(format!("(f) cmp.ge r14, #-{INSIDE_TOL}"))
                .c("adds r15, r13, r14")
                .c("(f) cmp.le r15, r8");
        }
        Inside::Rectangle => {
            k.c(format!("(f) cmp.ge r13, #-{INSIDE_TOL}"))
                .c(format!("(f) cmp.ge r14, #-{INSIDE_TOL}"))
                .c("(f) cmp.le r13, r8")
                .c("(f) cmp.le r14, r8");
        }
        Inside::Disc => {
            k.c("mul out, r13, r13")
                .cq("mac r15, r14, r14, >>14")
                .c("(f) cmp.le r15, r8");
        }
    }
}

/// The smooth triangle's shading normal: with `u` (r13), `w` (r14), `u + w`
/// (r15) from [`inside_test`], the streamed unit vertex normals weighted by
/// `(1 - u - w, u, w)` into r10..r12, normalised (clobbers r8, r9, r13..r15).
fn interpolate_normal(k: &mut K, nr: Approx) {
    k.c(format!("ld r8, [r0 + #{}]", ram::C_ONE))
        .c("sub r8, r8, r15");
    for x in [10, 11, 12] {
        k.c("mul out, fb0, r8")
            .c("mac out, fb0, r13")
            .cq(format!("mac r{x}, fb0, r14, >>14"));
    }
    normalize(k, [10, 11, 12], [9, 8, 13, 14, 15], false, nr);
}

/// A triangle with vertex normals (NFF `pp`), shaded smoothly as the
/// reference shades it: the planar test of [`planar`] (the same first 15
/// record words), then at the hit the unit vertex normals, streamed per
/// axis (`n0.a, n1.a, n2.a`, Q1.14), weighted by the barycentric
/// coordinates `(1 - u - w, u, w)` in the accumulator and normalised into
/// `ram::HIT_NS` (with the object id in `ram::HIT_NS_OBJ`); the face
/// normal goes to `ram::HIT_N` as every kernel's does ([`post_smooth`]
/// picks the shading normal). Record ([`super::layout::SMOOTH_WORDS`], 29
/// words): `n.xyz, v0.xyz, v0.xyz, eu.xyz, ew.xyz, (n0, n1, n2).x, .y, .z,
/// n.xyz, obj, mat`.
pub fn smooth_triangle(kt: u32, nr: impl Into<Approx>) -> K {
    let nr: Approx = nr.into();
    let mut k = K::default();
    k.comment("smooth triangle: den = n.d, num = n.(v0 - o)");
    plane_hit(&mut k, nr);
    inside_test(&mut k, Inside::Triangle, kt);
    k.comment("Ns = (1 - u - w) n0 + u n1 + w n2, normalised");
    k.c("(f) mov r7, r9");
    interpolate_normal(&mut k, nr);
    for (i, x) in [10, 11, 12].into_iter().enumerate() {
        k.c(format!("(f) st r{x}, [#{}]", ram::HIT_NS + i as u32));
    }
    for i in 0..3 {
        k.c(format!("(f) st fb0, [#{}]", ram::HIT_N + i));
    }
    k.c("mov r8, fb0")
        .c(format!("(f) st r8, [#{}]", ram::HIT_OBJ))
        .c(format!("(f) st r8, [#{}]", ram::HIT_NS_OBJ))
        .c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
    k
}

/// [`smooth_triangle`] of a transmitting material: both sides (as
/// [`planar_two_sided`]: the plane seen from its back, the triangle the ray
/// leaves skipped), both normals turned to the ray on a back hit. The
/// record is the smooth triangle's.
pub fn smooth_triangle_two_sided(kt: u32, nr: impl Into<Approx>) -> K {
    let nr: Approx = nr.into();
    let mut k = K::default();
    k.comment("smooth triangle, two-sided: den = n.d, num = n.(v0 - o)");
    plane_hit_sides(&mut k, nr, true);
    inside_test(&mut k, Inside::Triangle, kt);
    k.comment("Ns = (1 - u - w) n0 + u n1 + w n2, normalised");
    k.c(format!("st r9, [#{}]", ram::TMP4));
    interpolate_normal(&mut k, nr);
    k.comment("turned to the ray on a back hit; the face normal, obj");
    k.c(format!("ld r15, [r0 + #{}]", ram::TMP3))
        .c("movb r14, #1")
        .c("sub r14, r14, r15")
        .c("sub r14, r14, r15"); // 1 - 2 back
    for x in [10, 11, 12] {
        k.c(format!("mul r{x}, r{x}, r14"));
    }
    k.c("mul r8, fb0, r14")
        .c("mul r9, fb0, r14")
        .c("mul r13, fb0, r14")
        .c(format!("st r13, [#{}]", ram::TMP2))
        .c("mov r13, fb0")
        .c(format!("ld r14, [r0 + #{}]", ram::ORIG_OBJ))
        .c("(f) cmp.ne r13, r14")
        .c(format!("ld r14, [r0 + #{}]", ram::TMP4))
        .c("(f) mov r7, r14");
    for (i, x) in [10, 11, 12].into_iter().enumerate() {
        k.c(format!("(f) st r{x}, [#{}]", ram::HIT_NS + i as u32));
    }
    k.c(format!("(f) st r8, [#{}]", ram::HIT_N))
        .c(format!("(f) st r9, [#{}]", ram::HIT_N + 1))
        .c(format!("ld r8, [r0 + #{}]", ram::TMP2))
        .c(format!("(f) st r8, [#{}]", ram::HIT_N + 2))
        .c(format!("(f) st r13, [#{}]", ram::HIT_OBJ))
        .c(format!("(f) st r13, [#{}]", ram::HIT_NS_OBJ))
        .c("neg r15, r15")
        .c("add r14, r13, #1")
        .c("and r14, r14, r15")
        .c("sub r14, r14, #1")
        .c(format!("(f) st r14, [#{}]", ram::HIT_BACK_OBJ))
        .c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
    k
}

/// [`post`] for scenes with smooth triangles: the geometric normal is kept
/// in `ram::SH_NG` (for [`reflect_setup_smooth`]) and the shading normal
/// `SH_N` becomes the interpolated one where the hit is a smooth triangle
/// (`HIT_NS_OBJ` = the hit's id) and it lies on the face's side (the
/// reference's rule: otherwise the face normal).
pub fn post_smooth(level0: bool, materials: usize, eps: i32) -> K {
    let mut k = post(level0, materials, eps);
    smooth_normal(&mut k);
    k
}

/// [`post`] with the extensions the scene's types need: smooth triangles
/// ([`post_smooth`]) and refraction (whether the hit is on an object's
/// back, `ram::SH_BACK`, for the index of refraction).
pub fn post_ext(level0: bool, materials: usize, eps: i32, smooth: bool, refract: bool) -> K {
    let mut k = post(level0, materials, eps);
    if smooth {
        smooth_normal(&mut k);
    }
    if refract {
        k.c(format!("ld r8, [r0 + #{}]", ram::HIT_BACK_OBJ))
            .c(format!("ld r9, [r0 + #{}]", ram::HIT_OBJ))
            .c("movb r10, #0")
            .c("cmp.eq r8, r9")
            .c("(f) movb r10, #1")
            .c(format!("st r10, [#{}]", ram::SH_BACK))
            // the rays this hit spawns leave its object
            .c(format!("ld r8, [r0 + #{}]", ram::ACT))
            .c("cmp.eq r8, #0")
            .c("(f) movb r9, #-1")
            .c(format!("st r9, [#{}]", ram::ORIG_OBJ));
    }
    k
}

/// [`eye`] for scenes with two-sided planar objects: eye rays leave no
/// object (`ram::ORIG_OBJ` = -1).
pub fn eye_ext(kd: u32, nr: impl Into<Approx>, refract: bool) -> K {
    let mut k = eye(kd, nr);
    if refract {
        k.c(format!("st r8, [#{}]", ram::ORIG_OBJ));
    }
    k
}

fn smooth_normal(k: &mut K) {
    for i in 0..3 {
        k.c(format!("ld r{}, [r0 + #{}]", 8 + i, ram::HIT_N + i))
            .c(format!("st r{}, [#{}]", 8 + i, ram::SH_NG + i))
            .c(format!("ld r{}, [r0 + #{}]", 11 + i, ram::HIT_NS + i));
    }
    k.c("mul out, r8, r11")
        .c("mac out, r9, r12")
        .cq("mac r14, r10, r13, >>14")
        .c(format!("ld r15, [r0 + #{}]", ram::HIT_NS_OBJ))
        .c(format!("ld r8, [r0 + #{}]", ram::HIT_OBJ))
        .c("cmp.eq r15, r8")
        .c("(f) cmp.gt r14, #0");
    for i in 0..3 {
        k.c(format!("(f) st r{}, [#{}]", 11 + i, ram::SH_N + i));
    }
}

/// Axis-aligned box, visible from outside (slab method, one section per
/// axis). Record (24 words): per axis `a` (b, c the two others):
/// `min_a, max_a, min_b - 1, max_b + 1, min_c - 1, max_c + 1, obj, mat`.
/// Each RC picks the face of axis `a` that faces its ray with `sel`
/// (`max_a` where `d_a < 0`), `t = |c - o_a| / |d_a|` by [`divide`] after the
/// accumulator test, and accepts it where the hit point lies within the
/// other two slabs; the normal is `-sign(d_a)` along `a`.
pub fn aabox(nr: impl Into<Approx>) -> K {
    let nr: Approx = nr.into();
    let mut k = K::default();
    aabox_faces(&mut k, nr, false);
    k
}

/// The box of a transmitting material, visible from both sides: the
/// entry faces of [`aabox`] (skipping the box a ray leaves,
/// `ram::ORIG_OBJ`: a ray starting on a convex box cannot enter it again),
/// then the exit faces (the face each axis's direction leads to, more
/// than [`SELF_LSB`] ahead; a back hit, the normal turned to the ray).
/// Record: the box's, twice (48 words).
pub fn aabox_two_sided(nr: impl Into<Approx>) -> K {
    let nr: Approx = nr.into();
    let mut k = K::default();
    aabox_faces(&mut k, nr, true);
    k
}

/// The per-axis sections of the box kernels; `two`: entry faces skipping
/// `ORIG_OBJ`, then exit faces.
fn aabox_faces(k: &mut K, nr: Approx, two: bool) {
    for a in 0..3u32 {
        box_face(k, nr, a, two, false);
    }
    if two {
        for a in 0..3u32 {
            box_face(k, nr, a, true, true);
        }
    }
}

fn box_face(k: &mut K, nr: Approx, a: u32, two: bool, exit: bool) {
    {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        let (oa, da) = (1 + a, 4 + a);
        k.comment(&match (two, exit) {
            (false, _) => format!("box: faces across axis {a}"),
            (true, false) => format!("box: entry faces across axis {a}"),
            (true, true) => format!("box: exit faces across axis {a}"),
        });
        // F: the max face is the one (entry: d_a < 0; exit: d_a > 0).
        k.c(format!("cmp.{} r{da}, #0", if exit { "gt" } else { "lt" }))
            .c(format!("ld r15, [r0 + #{}]", ram::C_ONE))
            .c(if exit {
                "(f) neg r15, r15"
            } else {
                "(!f) neg r15, r15"
            })
            .c(format!("st r15, [#{}]", ram::TMP0))
            .c("mov r8, fb0")
            .c("sel r8, fb0, r8")
            .c(format!("sub r8, r8, r{oa}"))
            .c(if exit {
                "(!f) neg r8, r8"
            } else {
                "(f) neg r8, r8"
            })
            .c(format!("abs r9, r{da}"));
        k.c("cmp.gt r9, #0")
            .c("(f) cmp.gt r8, #0")
            .cq("ldacc r8, <<14")
            .c("msu out, r7, r9")
            .c("acch r10")
            .c("(f) cmp.lt r10, #0");
        divide(k, 8, 9, 11, [10, 12, 13, 14, 15], nr);
        if exit {
            // more than SELF_LSB ahead along the ray (not along the axis:
            // a grazing ray may start within an LSB of the face's plane)
            k.c(format!("movb r14, #{SELF_LSB}"));
            if extra_bits() > 0 {
                k.c(format!("sll r14, r14, #{}", extra_bits()));
            }
            k.c("(f) cmp.gt r11, r14");
        }
        k.cq(format!("ldacc r{}, <<14", 1 + b))
            .cq(format!("mac r12, r11, r{}, >>14", 4 + b))
            .cq(format!("ldacc r{}, <<14", 1 + c))
            .cq(format!("mac r13, r11, r{}, >>14", 4 + c))
            .c("(f) cmp.le fb0, r12")
            .c("(f) cmp.ge fb0, r12")
            .c("(f) cmp.le fb0, r13")
            .c("(f) cmp.ge fb0, r13");
        if two {
            k.c("mov r8, fb0");
            if !exit {
                k.c(format!("ld r14, [r0 + #{}]", ram::ORIG_OBJ))
                    .c("(f) cmp.ne r8, r14");
            }
        }
        k.c("(f) mov r7, r11")
            .c(format!("ld r15, [r0 + #{}]", ram::TMP0))
            .c(format!("(f) st r15, [#{}]", ram::HIT_N + a))
            .c(format!("(f) st r0, [#{}]", ram::HIT_N + b))
            .c(format!("(f) st r0, [#{}]", ram::HIT_N + c));
        if two {
            // HIT_BACK_OBJ: the box on an exit face, else -1.
            k.c(format!("(f) st r8, [#{}]", ram::HIT_OBJ));
            if exit {
                k.c(format!("(f) st r8, [#{}]", ram::HIT_BACK_OBJ));
            } else {
                k.c("movb r9, #-1")
                    .c(format!("(f) st r9, [#{}]", ram::HIT_BACK_OBJ));
            }
        } else {
            k.c(format!("(f) st fb0, [#{}]", ram::HIT_OBJ));
        }
        k.c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
    }
}

/// Polygon, convex or concave (even-odd rule, as the reference), by the
/// crossing test in exact integer arithmetic: three runs.
///
/// Head (15 words: `n.xyz, v0.xyz, v0.xyz, U.xyz, V.xyz`): the plane test
/// and division of [`planar`], then `v0 - P` (saturating) projected on the
/// plane of the two axes `U`, `V` (unit axis vectors, the normal's
/// dominant axis dropped; a dot product with an axis vector is exact):
/// `-px`, `-py`; the validity kept in RAM, the parity cleared.
///
/// Edge (5 words per edge `(xi, yi) -> (xj, yj)`, vertices relative to
/// `v0` in the scene format: `xi, yi, yj, s ey, s ex` with `e = vj - vi`
/// and `s = sign(ey)`; horizontal edges are left out, they never cross):
/// the parity flips where the edge straddles the point's row
/// (`(yi > py) != (yj > py)`, half-open, so a vertex is counted once) and
/// crosses it to the right of the point, `s ((xi - px) ey - ex (yi - py)) >
/// 0` (the differences by saturating adds of `-px`, `-py`). The products are exact in the 32-bit accumulator and the sign of
/// their difference survives saturation, so no point on a shared edge or
/// near a vertex is counted twice or not at all: no cracks, however thin
/// the polygon's parts (a fan of triangles from `v0` would need the duals
/// of slivers, and their rounding flips points near every diagonal).
///
/// Tail (5 words: `n.xyz, obj, mat`): commit where valid and the parity
/// is odd.
pub fn polygon_head(nr: impl Into<Approx>) -> K {
    polygon_head_sides(nr, false)
}

/// [`polygon_head`] for a transmitting polygon: both sides
/// ([`plane_hit_sides`]); its tail is [`polygon_tail_two_sided`].
pub fn polygon_head_two_sided(nr: impl Into<Approx>) -> K {
    polygon_head_sides(nr, true)
}

fn polygon_head_sides(nr: impl Into<Approx>, two: bool) -> K {
    let nr: Approx = nr.into();
    let mut k = K::default();
    k.comment("polygon head: the plane");
    plane_hit_sides(&mut k, nr, two);
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        let x = 10 + i;
        k.cq(format!("ldacc r{o}, <<14"))
            .cq(format!("mac r{x}, r9, r{d}, >>14"))
            .c(format!("subs r{x}, fb0, r{x}"));
    }
    k.c("movb r15, #0")
        .c("(f) movb r15, #1")
        .c(format!("st r15, [#{}]", ram::TMP0));
    k.comment("v0 - P on the plane of U, V: -px in r10, -py in r11");
    k.c("mul out, fb0, r10")
        .c("mac out, fb0, r11")
        .cq("mac r13, fb0, r12, >>14");
    k.c("mul out, fb0, r10")
        .c("mac out, fb0, r11")
        .cq("mac r11, fb0, r12, >>14")
        .c("mov r10, r13")
        .c("movb r8, #0");
    k
}

pub fn polygon_edge() -> K {
    let mut k = K::default();
    k.c("adds r12, fb0, r10")
        .c("adds r13, fb0, r11")
        .c("adds r14, fb0, r11")
        .c("movb r15, #0")
        .c("cmp.gt r13, #0")
        .c("(f) movb r15, #1")
        .c("cmp.gt r14, #0")
        .c("(f) xor r15, r15, #1")
        .c("mov r14, fb0")
        .c("mul out, r12, r14")
        .c("msu r13, fb0, r13")
        .c("cmp.ne r15, #0")
        .c("(f) cmp.gt r13, #0")
        .c("(f) xor r8, r8, #1");
    k
}

pub fn polygon_tail() -> K {
    let mut k = K::default();
    k.c(format!("ld r13, [r0 + #{}]", ram::TMP0))
        .c("cmp.ne r13, #0")
        .c("(f) cmp.ne r8, #0");
    commit_streamed_normal(&mut k, 9);
    k
}

/// [`polygon_tail`] of a transmitting polygon: the normal turned where
/// the back was hit.
pub fn polygon_tail_two_sided() -> K {
    let mut k = K::default();
    k.c(format!("ld r13, [r0 + #{}]", ram::TMP0))
        .c("cmp.ne r13, #0")
        .c("(f) cmp.ne r8, #0");
    commit_streamed_normal_two(&mut k, 9);
    k
}

/// The end of a curved body kernel: where F, the streamed object id and
/// material; for one side of a transmitting body (`back`: the inside run)
/// also `ram::HIT_BACK_OBJ` (the id on the inside, -1 outside). Clobbers r8.
fn commit_obj_mat(k: &mut K, back: Option<bool>) {
    match back {
        None => {
            k.c(format!("(f) st fb0, [#{}]", ram::HIT_OBJ));
        }
        Some(b) => {
            k.c("mov r8, fb0")
                .c(format!("(f) st r8, [#{}]", ram::HIT_OBJ));
            if !b {
                k.c("movb r8, #-1");
            }
            k.c(format!("(f) st r8, [#{}]", ram::HIT_BACK_OBJ));
        }
    }
    k.c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
}

/// Open cylinder body (the caps are [`Inside::Disc`] planar records).
/// Record (36 words): `B.xyz, e1.xyz, b1, e2.xyz, b2, e1.xyz, e2.xyz, invr,
/// r, sg, B.xyz, a.xyz, H+2, sg, (e1, e2) x, (e1, e2) y, (e1, e2) z, obj,
/// mat` (e1, e2, a an orthonormal frame, a along the axis, B the base
/// centre rounded to the LSB and `b1`, `b2` what the rounding left of it
/// along e1 and e2 in 2^-14 LSB, H the height, scene units; `r` with `ep`
/// extra fraction bits, `invr = 2^(14+ks) / r` of the unrounded radius).
/// The perpendicular vector keeps `ep` extra fraction bits, as the
/// sphere's, formed from the unrounded `(B - o).e1`, `(B - o).e2` (the
/// rounding remainders of the projections and of B added back in the
/// accumulator) and made perpendicular to the 2D direction; the normal
/// follows from it without the hit point.
///
/// In the plane across the axis the ray is a 2D ray: its direction
/// `d2 = (d.e1, d.e2)` is normalised (`|d2|` kept), the 2D problem is the
/// sphere's perpendicular method, and `t = tau / |d2|` by [`divide`].
///
/// Without `fine` (coarse normals, [`super::Normals`]) the record has
/// no `b1`, `b2` (34 words), `r` is rounded to the LSB and `invr` is of
/// that, and the perpendicular vector is formed from the rounded
/// projections and left as it comes.
pub fn cylinder(ks: u32, ep: u32, nr: impl Into<Approx>, fine: bool) -> K {
    cylinder_sides(ks, ep, nr, None, fine)
}

/// The body of a transmitting cylinder, one side per run: its record holds
/// the body twice, with `sg` and `-sg` (the far root, normal turned
/// inwards), so the two runs together test both sides; `back` says which
/// run this is (recorded in `ram::HIT_BACK_OBJ`). Both accept a root only
/// more than [`SELF_LSB`] ahead along the ray (a ray starting on the
/// surface, however rounded, does not hit it there again).
pub fn cylinder_side(ks: u32, ep: u32, nr: impl Into<Approx>, back: bool, fine: bool) -> K {
    cylinder_sides(ks, ep, nr, Some(back), fine)
}

fn cylinder_sides(ks: u32, ep: u32, nr: impl Into<Approx>, back: Option<bool>, fine: bool) -> K {
    let nr: Approx = nr.into();
    let mut k = K::default();
    k.comment("cylinder: oc = B - o, projected on e1, e2");
    k.c("sub r8, fb0, r1")
        .c("sub r9, fb0, r2")
        .c("sub r10, fb0, r3");
    // oc2 = (oc.e1, oc.e2) rounded to LSB, and what the rounding left (in
    // 2^-14 LSB, the accumulator's low half minus the rounded value's, exact
    // below 2^13): added back when the perpendicular vector is formed, whose
    // half-LSB error over a radius of a few dozen LSB would tilt the normal.
    for (x, rem, t, at) in [(11, 14, 15, ram::TMP5), (12, 15, 13, ram::TMP6)] {
        k.c("mul out, fb0, r8")
            .c("mac out, fb0, r9")
            .cq(format!("mac r{x}, fb0, r10, >>14"));
        if fine {
            k.c(format!("accl r{rem}"))
                .cq(format!("sll r{t}, r{x}, #14"))
                .c(format!("sub r{rem}, r{rem}, r{t}"))
                .c(format!("add r{rem}, fb0, r{rem}"))
                .c(format!("st r{rem}, [#{at}]"));
        }
    }
    k.c(format!("st r11, [#{}]", ram::TMP0))
        .c(format!("st r12, [#{}]", ram::TMP1));
    k.c("mul out, fb0, r4")
        .c("mac out, fb0, r5")
        .cq("mac r8, fb0, r6, >>14");
    k.c("mul out, fb0, r4")
        .c("mac out, fb0, r5")
        .cq("mac r9, fb0, r6, >>14");
    k.c("movb r10, #0");
    normalize(&mut k, [8, 9, 10], [11, 12, 13, 14, 15], true, nr);
    k.c("mov r10, r11") // |d2|, Q.14
        .c(format!("st r8, [#{}]", ram::TMP2))
        .c(format!("st r9, [#{}]", ram::TMP3));
    k.c(format!("ld r11, [r0 + #{}]", ram::TMP0))
        .c(format!("ld r12, [r0 + #{}]", ram::TMP1));
    k.cq("mul out, r11, r8").cq("mac r13, r12, r9, >>14"); // b
    if fine {
        k.c(format!("ld r14, [r0 + #{}]", ram::TMP5))
            .c(format!("ld r15, [r0 + #{}]", ram::TMP6));
    }
    for (x, rem, d) in [(11, 14, 8), (12, 15, 9)] {
        k.cq(format!("ldacc r{x}, <<14"));
        if fine {
            k.c(format!("mac out, r{rem}, #1"));
        }
        k.c(format!("msu r{x}, r13, r{d}, >>{}", q(14) - ep));
    }
    if fine {
        // p2 perpendicular to the 2D direction d2n
        perpendicular_to(&mut k, &[11, 12], &[8, 9], 14);
    }
    k.c("mov r14, fb0")
        .c(format!("mul r11, r11, r14, >>{}", ks + ep))
        .c(format!("mul r12, r12, r14, >>{}", ks + ep))
        .c(format!("st r11, [#{}]", ram::TMP0))
        .c(format!("st r12, [#{}]", ram::TMP1));
    k.c(format!("ld r14, [r0 + #{}]", ram::C_ONE))
        .cq("ldacc r14, <<14")
        .c("msu out, r11, r11")
        .cq("msu r15, r12, r12, >>14")
        .c("cmp.gt r15, #0")
        .c("(f) cmp.gt r10, #0");
    sqrt_q14(&mut k, 15, 8, [9, 11, 12, 14], nr);
    k.c(format!("st r8, [#{}]", ram::TMP4));
    let er = if fine { ep } else { 0 };
    k.c("mov r9, fb0")
        .c(format!("mul r9, r9, r8, >>{}", q(14) + er)) // h
        .c("mov r11, fb0")
        .cq("mul r9, r9, r11, >>14")
        .c("sub r9, r13, r9") // tau
        .c("(f) cmp.gt r9, #0")
        .cq("ldacc r9, <<14")
        .c("msu out, r7, r10")
        .c("acch r11")
        .c("(f) cmp.lt r11, #0");
    divide(&mut k, 9, 10, 9, [8, 11, 12, 13, 14], nr);
    if back.is_some() {
        k.c(format!("movb r8, #{SELF_LSB}"));
        if extra_bits() > 0 {
            k.c(format!("sll r8, r8, #{}", extra_bits()));
        }
        k.c("(f) cmp.gt r9, r8");
    }
    k.comment("axial coordinate of the hit");
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        let x = 11 + i;
        k.cq(format!("ldacc r{o}, <<14"))
            .cq(format!("mac r{x}, r9, r{d}, >>14"))
            .c(format!("rsb r{x}, fb0, r{x}"));
    }
    k.c("mul out, fb0, r11")
        .c("mac out, fb0, r12")
        .cq("mac r14, fb0, r13, >>14"); // z
    k.c("(f) cmp.ge r14, #-2")
        .c("mov r15, fb0")
        .c("(f) cmp.le r14, r15");
    k.comment("normal: n2 = -(sg p2 / r + sqrt(s) d2n) across the axis, n = n2.x e1 + n2.y e2");
    k.c("(f) mov r7, r9")
        .c("mov r15, fb0")
        .c(format!("ld r8, [r0 + #{}]", ram::TMP4));
    for (x, pn, dn) in [(11, ram::TMP0, ram::TMP2), (12, ram::TMP1, ram::TMP3)] {
        k.c(format!("ld r{x}, [r0 + #{pn}]"))
            .c(format!("ld r13, [r0 + #{dn}]"))
            .c("mul out, r8, r13")
            .cq(format!("mac r{x}, r15, r{x}, >>14"))
            .c(format!("neg r{x}, r{x}"));
    }
    for x in [13, 14, 15] {
        k.c("mul out, fb0, r11")
            .cq(format!("mac r{x}, fb0, r12, >>14"));
    }
    for (i, x) in [13, 14, 15].into_iter().enumerate() {
        k.c(format!("(f) st r{x}, [#{}]", ram::HIT_N + i as u32));
    }
    commit_obj_mat(&mut k, back);
    k
}

/// Open cone body (unequal radii; caps, native format only, are
/// [`Inside::Disc`] planar records as the cylinder's). Record (40 words):
/// `M.xyz, invS, ce1.xyz, ce2.xyz, a.xyz, ce1.xyz, ce2.xyz, a.xyz, s, g,
/// sg, R, hh, -sg c, -sg s, (e1, e2, a) x, (e1, e2, a) y, (e1, e2, a) z,
/// obj, mat`: M the middle of the axis, R (scene LSBs) at least the radius
/// of the cone's bounding sphere about M, `S = 4 R` the kernel's unit,
/// `invS = 2^(14+ks) / S`; (e1, e2, a) an orthonormal frame, a from base to
/// apex, `ce1 = c e1`, `ce2 = c e2` with `c = cos`, `s = sin` of the
/// half-angle (`tan = (ra - rb) / h`); `g = c (rb + ra) / 2 / S`, `hh` half
/// the height (plus 1 LSB) over S, all Q.14; `sg` +-16384 (NFF's inside-
/// visible cone).
///
/// Method: the sphere's perpendicular method against the bounding sphere
/// (`b = (M - o).d`, `w = ((M - o) - b d) / S`, miss where `|w| > 1/4`)
/// moves the ray's origin to `o' = o + b d`, the point of its line closest
/// to M; every quantity from there on is a Q.14 multiple of S bounded by 1,
/// however far the ray came from. In the cone's frame, with `q = o' - M`,
/// `G = c rho(q_z)` (`= g + s q_z`, the radius at q's height, scaled by c):
/// `f(tau) = c^2 |q_perp + tau d_perp|^2 - (G + s tau d_z)^2 = A tau^2 +
/// 2 B tau + C` (each coefficient one accumulator chain, all |.| <= 1),
/// times `sg`. The visible side is where `f` falls along the ray, the root
/// with `A tau + B = -sqrt(D)`, `D = B^2 - A C`, taken without cancellation:
/// `tau = -(B + sqrt D) / A` where `B > 0`, else `C / (sqrt D - B)`, by
/// [`divide`] after checking `|tau| <= 1/2` (a hit lies within `S / 4` of
/// `o'`); so a ray parallel to the surface (`A = 0`) or down a steep cone
/// (`A < 0`) needs no special case. `t = b + S tau`; the hit's height
/// `|q_z + tau d_z| <= hh`; the normal is the gradient
/// `sg (c^2 p_perp, -s c rho)` at the hit, normalised, in the scene's axes.
pub fn cone(ks: u32, ep: u32, nr: impl Into<Approx>) -> K {
    cone_sides(ks, ep, nr, None)
}

/// The body of a transmitting cone, one side per run (its record holds the
/// body twice, with `sg` and `-sg`), as [`cylinder_side`].
pub fn cone_side(ks: u32, ep: u32, nr: impl Into<Approx>, back: bool) -> K {
    cone_sides(ks, ep, nr, Some(back))
}

fn cone_sides(ks: u32, ep: u32, nr: impl Into<Approx>, back: Option<bool>) -> K {
    let nr: Approx = nr.into();
    let ct = ram::CONE_TMP;
    let mut k = K::default();
    k.comment("cone: bounding sphere about M: b = (M - o).d, p = (M - o) - b d");
    k.c("sub r8, fb0, r1")
        .c("sub r9, fb0, r2")
        .c("sub r10, fb0, r3");
    k.c("mul out, r8, r4")
        .c("mac out, r9, r5")
        .cq("mac r11, r10, r6, >>14"); // b
    for (x, d) in [(8, 4), (9, 5), (10, 6)] {
        k.cq(format!("ldacc r{x}, <<14"))
            .c(format!("msu r{x}, r11, r{d}, >>{}", q(14) - ep));
    }
    k.c("mov r12, fb0"); // invS
    for x in [8, 9, 10] {
        k.c(format!("mul r{x}, r{x}, r12, >>{}", ks + ep)); // w = p / S
    }
    k.c("movb r15, #1")
        .c(format!("ldacc r15, <<{}", 26 + 2 * extra_bits()))
        .c("msu out, r8, r8")
        .c("msu out, r9, r9")
        .cq("msu r15, r10, r10, >>14") // 1/4 - |w|^2
        .c("cmp.ge r15, #0")
        .c(format!("st r11, [#{}]", ram::TMP0));
    k.comment(
        "frame: w.ce1 = -c qx, w.ce2 = -c qy, w.a = -qz; d.ce1 = c dx, d.ce2 = c dy, d.a = dz",
    );
    for x in [12, 13, 14] {
        k.c("mul out, fb0, r8")
            .c("mac out, fb0, r9")
            .cq(format!("mac r{x}, fb0, r10, >>14"));
    }
    for x in [8, 9, 10] {
        k.c("mul out, fb0, r4")
            .c("mac out, fb0, r5")
            .cq(format!("mac r{x}, fb0, r6, >>14"));
    }
    k.c(format!("st r14, [#{}]", ram::TMP1))
        .c(format!("st r10, [#{}]", ram::TMP2))
        .c("mov r11, fb0") // s
        .cq("mul r10, r10, r11, >>14") // s dz
        .cq("mul r14, r14, r11, >>14") // -s qz
        .c("sub r14, fb0, r14"); // G = g + s qz
    k.comment("zoom: (c q_perp, G) times 2^e into [1/8, 1/4), e = clz(max) - 4 in -3..=3");
    k.c("abs r15, r12")
        .c("abs r11, r13")
        .c("max r15, r15, r11")
        .c("abs r11, r14")
        .c("max r15, r15, r11")
        .c("clz r15, r15")
        .c("sub r15, r15, #4")
        .c("min r15, r15, #3")
        .c("movb r11, #0")
        .c("min r11, r15, r11")
        .c("neg r11, r11") // max(-e, 0)
        .c("max r15, r15, #0") // max(e, 0)
        .c(format!("st r15, [#{}]", ct + 6))
        .c(format!("st r11, [#{}]", ct + 7));
    for x in [12, 13, 14] {
        k.c(format!("sll r{x}, r{x}, r15"))
            .c(format!("sra r{x}, r{x}, r11"));
    }
    for (i, x) in [8, 9, 10, 12, 13, 14].into_iter().enumerate() {
        k.c(format!("st r{x}, [#{}]", ct + i as u32));
    }
    k.comment("A, -2B, 4C (zoomed: 2^e B, 2^2e C), times sg; 4D = 4B^2 - 4A C");
    k.c("mul out, r8, r8")
        .c("mac out, r9, r9")
        .cq("msu r15, r10, r10, >>14") // A
        .c("mul out, r8, r12")
        .c("mac out, r9, r13")
        .cq("mac r11, r10, r14, >>13") // -2B
        .c("mul out, r12, r12")
        .c("mac out, r13, r13")
        .cq("msu r12, r14, r14, >>12") // 4C
        .c("mov r13, fb0") // sg
        .cq("mul r15, r15, r13, >>14")
        .cq("mul r11, r11, r13, >>14")
        .cq("mul r12, r12, r13, >>14")
        .c("mul out, r11, r11")
        .cq("msu r14, r15, r12, >>14") // D
        .c("(f) cmp.ge r14, #0")
        .c(format!("st r15, [#{}]", ram::TMP3));
    sqrt_q14(&mut k, 14, 8, [9, 10, 13, 15], nr);
    k.comment("tau' = 2^e tau = X / 2Y: B > 0: -(2B + sqrt 4D) / 2A, else 4C / 2(sqrt 4D - 2B)");
    k.c("movb r9, #0")
        .c("(f) movb r9, #1")
        .c("cmp.lt r11, #0")
        .c(format!("ld r10, [r0 + #{}]", ram::TMP3))
        .c("sub r13, r11, r8")
        .c("add r14, r11, r8")
        .c("sel r13, r13, r12") // N
        .c("sel r14, r10, r14") // Den
        .c("xor r12, r13, r14")
        .cq("sra r12, r12, #15") // -1 where tau < 0
        .c("abs r10, r13")
        .c("abs r15, r14")
        .c("cmp.ne r9, #0")
        .c("(f) cmp.gt r15, #0")
        .c("asl r11, r15, #2")
        .c("(f) cmp.lt r10, r11"); // |tau'| < 2
    divide_q13(&mut k, 10, 15, 10, [8, 9, 11, 13, 14], nr);
    k.c("xor r10, r10, r12").c("sub r10, r10, r12"); // tau'
    k.comment("tau = tau' / 2^e (rounded); t = b + S tau, S = 2 R");
    k.c(format!("ld r11, [r0 + #{}]", ct + 6))
        .c("movb r12, #1")
        .c("sll r12, r12, r11")
        .c("sra r12, r12, #1")
        .c("adds r13, r10, r12")
        .c("sra r13, r13, r11")
        .c(format!("ld r11, [r0 + #{}]", ct + 7))
        .c("asl r13, r13, r11") // tau
        .c("abs r12, r13")
        .cq("sra r12, r12, #13")
        .c("(f) cmp.eq r12, #0") // |tau| < 1/2: within the bounding sphere
        .c(format!("ld r11, [r0 + #{}]", ram::TMP0))
        .cq("ldacc r11, <<13")
        .cq("mac r11, fb0, r13, >>13");
    if back.is_some() {
        k.c(format!("movb r12, #{SELF_LSB}"));
        if extra_bits() > 0 {
            k.c(format!("sll r12, r12, #{}", extra_bits()));
        }
        k.c("(f) cmp.gt r11, r12");
    } else {
        k.c("(f) cmp.gt r11, #0");
    }
    k.c("(f) cmp.lt r11, r7")
        .c(format!("st r11, [#{}]", ram::TMP4));
    k.comment("height of the hit: |qz + tau dz| <= hh");
    k.c(format!("ld r12, [r0 + #{}]", ram::TMP1))
        .c(format!("ld r14, [r0 + #{}]", ram::TMP2))
        .cq("ldacc r12, <<14")
        .cq("msu r12, r13, r14, >>14")
        .c("abs r12, r12")
        .c("(f) cmp.ge fb0, r12");
    k.comment("normal: sg (c (c q_perp + tau c d_perp), -s (G + tau s dz)), zoomed, halved");
    for (x, qa, da) in [(8, 3, 0), (9, 4, 1)] {
        k.c(format!("ld r{x}, [r0 + #{}]", ct + qa))
            .c(format!("ld r13, [r0 + #{}]", ct + da))
            .cq(format!("ldacc r{x}, <<14"))
            .cq(format!("msu r{x}, r10, r13, >>15")); // -(c q + tau c d) / 2
    }
    k.c(format!("ld r11, [r0 + #{}]", ct + 5))
        .c(format!("ld r13, [r0 + #{}]", ct + 2))
        .cq("ldacc r11, <<14")
        .cq("mac r11, r10, r13, >>15") // c rho / 2 at the hit
        .c("mov r13, fb0") // -sg c
        .cq("mul r8, r8, r13, >>14")
        .cq("mul r9, r9, r13, >>14")
        .cq("mul r10, fb0, r11, >>14"); // -sg s c rho
    normalize(&mut k, [8, 9, 10], [11, 12, 13, 14, 15], false, nr);
    for x in [11, 12, 13] {
        k.c("mul out, fb0, r8")
            .c("mac out, fb0, r9")
            .cq(format!("mac r{x}, fb0, r10, >>14"));
    }
    k.c(format!("ld r14, [r0 + #{}]", ram::TMP4))
        .c("(f) mov r7, r14");
    for (i, x) in [11, 12, 13].into_iter().enumerate() {
        k.c(format!("(f) st r{x}, [#{}]", ram::HIT_N + i as u32));
    }
    commit_obj_mat(&mut k, back);
    k
}

/// Program start: RAM tables and constants from the FB (258 words).
pub fn init() -> K {
    let mut k = K::default();
    k.c("movb r0, #0");
    for a in 0..256 {
        k.c(format!("st fb0, [#{a}]"));
    }
    k.c(format!("st fb0, [#{}]", ram::C_ONE))
        .c(format!("st fb0, [#{}]", ram::C_INF));
    k
}

/// Row-mode group: row i gets `movb r8, #i`.
pub fn rows() -> K {
    let mut k = K::default();
    for i in 0..8 {
        k.c(format!("movb r8, #{i}"));
    }
    k
}

/// Lane bookkeeping after the row/column groups: which RCs take part for
/// the number of ways (`tw` x `th` tile), the others sleep for good.
pub fn lanes(tw: u32, th: u32) -> K {
    let mut k = K::default();
    k.c(format!("ld r8, [r0 + #{}]", ram::LANE_ROW))
        .c(format!("ld r9, [r0 + #{}]", ram::LANE_COL))
        .c("movb r10, #0")
        .c(format!("cmp.lt r8, #{th}"))
        .c(format!("(f) cmp.lt r9, #{tw}"))
        .c("(f) movb r10, #1")
        .c(format!("st r10, [#{}]", ram::LANE_ACT))
        .c("(!f) sleep");
    k
}

/// Wake every RC, then put the RCs that take no part back to sleep.
pub fn wake_restore() -> K {
    let mut k = K::default();
    k.c("wake")
        .c(format!("ld r8, [r0 + #{}]", ram::LANE_ACT))
        .c("cmp.eq r8, #0")
        .c("(f) sleep");
    k
}

/// Sign of the ray direction along `axis` into F.
pub fn sign(axis: u8) -> K {
    let mut k = K::default();
    k.c(format!("cmp.lt r{}, #0", 4 + axis));
    k
}

/// BSP node status: does the segment `[o, o + tbest d]` reach below the
/// split plane (F, read by TinyRISC) and above it (r13 threshold, second
/// kernel [`classify_above`]). Stream: the split position.
pub fn classify(axis: u8) -> K {
    let (o, d) = (1 + axis, 4 + axis);
    let mut k = K::default();
    k.cq(format!("ldacc r{o}, <<14"))
        .cq(format!("mac r8, r7, r{d}, >>14"))
        .c(format!("min r9, r{o}, r8"))
        .c(format!("max r10, r{o}, r8"))
        .c("mov r11, fb0")
        .c("add r12, r11, #1")
        .c("sub r13, r11, #1")
        .c("cmp.le r9, r12");
    k
}

pub fn classify_above() -> K {
    let mut k = K::default();
    k.c("cmp.ge r10, r13");
    k
}

/// At a leaf, closest-hit pass: RCs whose hit lies inside the leaf's cell
/// (bounds streamed, widened by 2 LSB) sleep.
pub fn leaf_closest() -> K {
    let mut k = K::default();
    k.c(format!("ld r8, [r0 + #{}]", ram::PASS_T0))
        .c("cmp.lt r7, r8");
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        k.cq(format!("ldacc r{o}, <<14"))
            .cq(format!("mac r{}, r7, r{d}, >>14", 9 + i));
    }
    for x in [9, 10, 11] {
        k.c(format!("(f) cmp.le fb0, r{x}"));
    }
    for x in [9, 10, 11] {
        k.c(format!("(f) cmp.ge fb0, r{x}"));
    }
    k.c("(f) sleep");
    k
}

/// Streamed layout: [`leaf_closest`] for rays not inside an unordered
/// subtree visited against their direction (`ram::UNORD` = 0) only.
pub fn leaf_closest_ordered() -> K {
    let mut k = K::default();
    k.c(format!("ld r12, [r0 + #{}]", ram::UNORD))
        .c(format!("ld r8, [r0 + #{}]", ram::PASS_T0))
        .c("cmp.lt r7, r8")
        .c("(f) cmp.eq r12, #0");
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        k.cq(format!("ldacc r{o}, <<14"))
            .cq(format!("mac r{}, r7, r{d}, >>14", 9 + i));
    }
    for x in [9, 10, 11] {
        k.c(format!("(f) cmp.le fb0, r{x}"));
    }
    for x in [9, 10, 11] {
        k.c(format!("(f) cmp.ge fb0, r{x}"));
    }
    k.c("(f) sleep");
    k
}

/// Streamed layout: entering (`delta` 1) or leaving (-1) an unordered
/// subtree visited below-first: rays going down along `axis` count it.
pub fn unord_count(axis: u8, delta: i32) -> K {
    let mut k = K::default();
    k.c(format!("cmp.lt r{}, #0", 4 + axis))
        .c(format!("ld r8, [r0 + #{}]", ram::UNORD))
        .c(if delta > 0 {
            "(f) add r8, r8, #1"
        } else {
            "(f) sub r8, r8, #1"
        })
        .c(format!("st r8, [#{}]", ram::UNORD));
    k
}

/// Streamed layout: no unordered subtree at a pass's start.
pub fn unord_zero() -> K {
    let mut k = K::default();
    k.c("sub r8, r8, r8").c(format!("st r8, [#{}]", ram::UNORD));
    k
}

/// At a leaf, any-hit (shadow) pass: RCs that found any hit sleep.
pub fn leaf_any() -> K {
    let mut k = K::default();
    k.c(format!("ld r8, [r0 + #{}]", ram::PASS_T0))
        .c("cmp.lt r7, r8")
        .c("(f) sleep");
    k
}

/// Eye rays. Stream: `px0, py0, from.xyz, (A, B, C) per axis`: the
/// direction through pixel (i, j) is `A + i B + j C` with A in Q2.13 and
/// B, C scaled by 2^kd; normalised in the RC.
pub fn eye(kd: u32, nr: impl Into<Approx>) -> K {
    let nr: Approx = nr.into();
    let sh = kd - q(13);
    let mut k = K::default();
    k.c(format!("ld r8, [r0 + #{}]", ram::LANE_COL))
        .c("add r8, fb0, r8")
        .c(format!("ld r9, [r0 + #{}]", ram::LANE_ROW))
        .c("add r9, fb0, r9")
        .c("mov r1, fb0")
        .c("mov r2, fb0")
        .c("mov r3, fb0");
    for x in [10, 11, 12] {
        k.c(format!("ldacc fb0, <<{sh}"))
            .c("mac out, fb0, r8")
            .c(format!("mac r{x}, fb0, r9, >>{sh}"));
    }
    normalize(&mut k, [10, 11, 12], [13, 14, 15, 8, 9], false, nr);
    k.c("mov r4, r10").c("mov r5, r11").c("mov r6, r12");
    new_level_common(&mut k);
    k.c("movb r8, #-1").c(format!("st r8, [#{}]", ram::OUT_OBJ));
    k
}

fn new_level_common(k: &mut K) {
    k.c(format!("ld r7, [r0 + #{}]", ram::C_INF))
        .c(format!("st r7, [#{}]", ram::PASS_T0))
        .c("movb r8, #0");
    for i in 0..3 {
        k.c(format!("st r8, [#{}]", ram::COL + i));
    }
    for (i, d) in [4, 5, 6].into_iter().enumerate() {
        k.c(format!("st r{d}, [#{}]", ram::SH_D + i as u32));
    }
}

/// After a closest-hit pass: F = hit; keep the hit (offset point, normal,
/// material, reflection weight) for shading; misses get the background.
/// Stream: `bg.rgb, (mat id, ks) per material`.
pub fn post(level0: bool, materials: usize, eps: i32) -> K {
    let mut k = K::default();
    k.c(format!("ld r8, [r0 + #{}]", ram::C_INF))
        .c("cmp.lt r7, r8")
        .c("movb r9, #0")
        .c("(f) movb r9, #1")
        .c(format!("st r9, [#{}]", ram::ACT));
    if level0 {
        k.c(format!("ld r10, [r0 + #{}]", ram::HIT_OBJ))
            .c("movb r11, #-1")
            .c("(f) mov r11, r10")
            .c(format!("st r11, [#{}]", ram::OUT_OBJ));
    }
    for i in 0..3 {
        k.c(format!("(!f) st fb0, [#{}]", ram::COL + i));
    }
    k.c(format!("movb r12, #{eps}"));
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        let i = i as u32;
        k.c(format!("ld r8, [r0 + #{}]", ram::HIT_N + i))
            .c(format!("st r8, [#{}]", ram::SH_N + i))
            .cq(format!("ldacc r{o}, <<14"))
            .c(format!("mac out, r7, r{d}"))
            .cq("mac r11, r8, r12, >>14")
            .c(format!("st r11, [#{}]", ram::SH_P + i));
    }
    k.c(format!("ld r13, [r0 + #{}]", ram::HIT_MAT))
        .c(format!("st r13, [#{}]", ram::SH_MAT))
        .c("movb r14, #0")
        .c(format!("st r14, [#{}]", ram::SH_KS));
    for _ in 0..materials {
        k.c("cmp.ne r9, #0")
            .c("(f) cmp.eq fb0, r13")
            .c(format!("(f) st fb0, [#{}]", ram::SH_KS));
    }
    k
}

/// Shadow ray towards a light (stream: the light's position): from the
/// offset hit point, unit direction, `tbest` = distance - 2 LSB; RCs with
/// no hit or with the light behind the surface (N.L <= 0, the SPD rule)
/// sleep. Also keeps N.L and R.V for shading.
///
/// `shifted`: the stream starts with a scale shift `k` and holds the
/// light divided by `2^k` ([`super::layout::light_shift`]); the direction
/// is that of `light / 2^k - P / 2^k`, and where `k > 0` (a light outside
/// every object's reach) the segment is not cut at the light.
pub fn light_setup(nr: impl Into<Approx>, shifted: bool) -> K {
    let nr: Approx = nr.into();
    let mut k = K::default();
    for (i, o) in [1, 2, 3].into_iter().enumerate() {
        k.c(format!("ld r{o}, [r0 + #{}]", ram::SH_P + i as u32));
    }
    if shifted {
        k.c("mov r15, fb0");
        for (x, o) in [(8, 1), (9, 2), (10, 3)] {
            k.c(format!("sra r{x}, r{o}, r15"))
                .c(format!("sub r{x}, fb0, r{x}"));
        }
        k.c(format!("st r15, [#{}]", ram::TMP0));
    } else {
        k.c("sub r8, fb0, r1")
            .c("sub r9, fb0, r2")
            .c("sub r10, fb0, r3");
    }
    normalize(&mut k, [8, 9, 10], [11, 12, 13, 14, 15], true, nr);
    k.c("mov r4, r8").c("mov r5, r9").c("mov r6, r10");
    if shifted {
        k.c(format!("ld r15, [r0 + #{}]", ram::TMP0))
            .c("cmp.gt r15, #0")
            .c(format!("(f) ld r11, [r0 + #{}]", ram::C_INF));
    }
    k.c("sub r7, r11, #2")
        .c(format!("st r7, [#{}]", ram::PASS_T0));
    // nl = N.L
    k.c(format!("ld r12, [r0 + #{}]", ram::SH_N))
        .c("mul out, r12, r4")
        .c(format!("ld r13, [r0 + #{}]", ram::SH_N + 1))
        .c("mac out, r13, r5")
        .c(format!("ld r14, [r0 + #{}]", ram::SH_N + 2))
        .cq("mac r15, r14, r6, >>14")
        .c(format!("st r15, [#{}]", ram::SH_NL));
    // nd = N.D, ld = L.D, rv = ld - 2 nl nd
    k.c(format!("ld r8, [r0 + #{}]", ram::SH_D))
        .c(format!("ld r9, [r0 + #{}]", ram::SH_D + 1))
        .c(format!("ld r10, [r0 + #{}]", ram::SH_D + 2))
        .c("mul out, r12, r8")
        .c("mac out, r13, r9")
        .cq("mac r11, r14, r10, >>14") // nd
        .c("mul out, r4, r8")
        .c("mac out, r5, r9")
        .cq("mac r12, r6, r10, >>14") // ld
        .cq("ldacc r12, <<14")
        .c("msu out, r15, r11")
        .cq("msu r12, r15, r11, >>14")
        .c("max r12, r12, #0")
        .c(format!("st r12, [#{}]", ram::SH_RV));
    k.c(format!("ld r8, [r0 + #{}]", ram::ACT))
        .c("cmp.ne r8, #0")
        .c("(f) cmp.gt r15, #0")
        .c("movb r9, #0")
        .c("(f) movb r9, #1")
        .c(format!("st r9, [#{}]", ram::LIT))
        .c("(!f) sleep");
    k
}

/// After a shadow pass: where the light is visible, add its Phong terms
/// for the RC's material. Stream per material: `id`, with a fractional
/// exponent `f` and `1 - f` (Q.14), then per channel `kd c lc, ks lc`
/// (Q3.12); `shines[m]` the Phong exponent of material m as integer part
/// and fraction: `x^(n+f)` is computed as `x^n (1 - f + f x)`.
pub fn shade(shines: &[(u32, f64)]) -> K {
    let mut k = K::default();
    k.c(format!("ld r8, [r0 + #{}]", ram::LIT))
        .c("cmp.ne r8, #0")
        .c(format!("ld r9, [r0 + #{}]", ram::PASS_T0))
        .c("(f) cmp.ge r7, r9")
        .c("movb r10, #0")
        .c("(f) movb r10, #1")
        .c(format!("ld r11, [r0 + #{}]", ram::SH_NL))
        .c(format!("ld r12, [r0 + #{}]", ram::SH_RV))
        .c(format!("ld r13, [r0 + #{}]", ram::SH_MAT));
    for &(n, f) in shines {
        k.c("cmp.ne r10, #0").c("(f) cmp.eq fb0, r13");
        pow_q14(&mut k, 12, 14, 15, n);
        if f > 0.0 {
            k.c("mov r15, fb0")
                .cq("mul r15, r15, r12, >>14")
                .c("add r15, fb0, r15")
                .cq("mul r14, r14, r15, >>14");
        }
        for c in 0..3 {
            k.c("mul out, fb0, r11")
                .cq("mac r15, fb0, r14, >>14")
                .c(format!("ld r9, [r0 + #{}]", ram::COL + c))
                .c("adds r9, r9, r15")
                .c(format!("(f) st r9, [#{}]", ram::COL + c));
        }
    }
    k
}

/// Start recursion level `level + 1`: push the colour and the reflection
/// weight of `level` onto the RC stack, and spawn the reflection ray
/// `d - 2 (d.N) N` where the hit surface reflects (Ks > 0); the others sleep.
pub fn reflect_setup(level: u32) -> K {
    reflect_setup_with(level, false)
}

/// [`reflect_setup`] for scenes with smooth triangles: where the mirror
/// direction about the shading normal would go below the surface
/// (`r.Ng <= 0`), the mirror direction about the geometric normal
/// `ram::SH_NG`, as the reference does.
pub fn reflect_setup_smooth(level: u32) -> K {
    reflect_setup_with(level, true)
}

fn reflect_setup_with(level: u32, smooth: bool) -> K {
    let base = ram::STACK + ram::STACK_FRAME * level;
    let mut k = K::default();
    k.c(format!("ld r8, [r0 + #{}]", ram::SH_KS))
        .c(format!("st r8, [#{}]", base + 3))
        .c("movb r10, #0");
    for c in 0..3 {
        k.c(format!("ld r9, [r0 + #{}]", ram::COL + c))
            .c(format!("st r9, [#{}]", base + c))
            .c(format!("st r10, [#{}]", ram::COL + c));
    }
    for (i, o) in [1, 2, 3].into_iter().enumerate() {
        k.c(format!("ld r{o}, [r0 + #{}]", ram::SH_P + i as u32));
    }
    for (i, x) in [8, 9, 10].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::SH_D + i as u32));
    }
    for (i, x) in [11, 12, 13].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::SH_N + i as u32));
    }
    k.c("mul out, r8, r11")
        .c("mac out, r9, r12")
        .cq("mac r14, r10, r13, >>14"); // d.N
    for (d, x, n) in [(4, 8, 11), (5, 9, 12), (6, 10, 13)] {
        k.cq(format!("ldacc r{x}, <<14"))
            .c(format!("msu out, r14, r{n}"))
            .cq(format!("msu r{d}, r14, r{n}, >>14"));
    }
    if smooth {
        for (i, n) in [11, 12, 13].into_iter().enumerate() {
            k.c(format!("ld r{n}, [r0 + #{}]", ram::SH_NG + i as u32));
        }
        k.c("mul out, r4, r11")
            .c("mac out, r5, r12")
            .cq("mac r15, r6, r13, >>14")
            .c("mul out, r8, r11")
            .c("mac out, r9, r12")
            .cq("mac r14, r10, r13, >>14")
            .c("cmp.le r15, #0");
        for (d, x, n) in [(4, 8, 11), (5, 9, 12), (6, 10, 13)] {
            k.cq(format!("ldacc r{x}, <<14"))
                .c(format!("msu out, r14, r{n}"))
                .cq(format!("msu r15, r14, r{n}, >>14"))
                .c(format!("(f) mov r{d}, r15"));
        }
    }
    k.c(format!("ld r7, [r0 + #{}]", ram::C_INF))
        .c(format!("st r7, [#{}]", ram::PASS_T0));
    for (i, d) in [4, 5, 6].into_iter().enumerate() {
        k.c(format!("st r{d}, [#{}]", ram::SH_D + i as u32));
    }
    k.c(format!("ld r9, [r0 + #{}]", ram::ACT))
        .c(format!("ld r8, [r0 + #{}]", ram::SH_KS))
        .c("cmp.ne r9, #0")
        .c("(f) cmp.gt r8, #0")
        .c("(!f) sleep");
    k
}

/// Refraction set-up of recursion level `level` (before its reflection):
/// where the hit surface transmits (stream per transmitting material: `id,
/// T, 1/ior, ior`, Q3.12), the refracted direction by Snell's law,
/// `eta = 1/ior` entering (a front hit) and `ior` leaving (a back hit,
/// `ram::SH_BACK`), `c1 = -d.N`, `k = 1 - eta^2 (1 - c1^2)`,
/// `T = eta d + (eta c1 - sqrt(k)) N` (normalised); none where `k <= 0`
/// (total internal reflection). Pushed into `ram::REFR` with the hit point
/// and the weight (0 where no ray is spawned) for [`refract_setup`].
pub fn refract_prepare(level: u32, materials: usize, nr: impl Into<Approx>) -> K {
    let nr: Approx = nr.into();
    let rf = ram::REFR + ram::REFR_FRAME * level;
    let mut k = K::default();
    k.c(format!("ld r8, [r0 + #{}]", ram::ACT))
        .c(format!("ld r9, [r0 + #{}]", ram::SH_MAT))
        .c(format!("ld r10, [r0 + #{}]", ram::SH_BACK))
        .c("movb r12, #0")
        .c("movb r13, #0");
    for _ in 0..materials {
        k.c("cmp.ne r8, #0")
            .c("(f) cmp.eq fb0, r9")
            .c("(f) mov r12, fb0")
            .c("(f) mov r13, fb0")
            .c("(f) cmp.ne r10, #0")
            .c("(f) mov r13, fb0");
    }
    k.comment("c1 = -d.N, k = 1 - eta^2 (1 - c1^2)");
    for (i, x) in [1, 2, 3].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::SH_D + i as u32));
    }
    for (i, x) in [4, 5, 6].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::SH_N + i as u32));
    }
    k.c("mul out, r1, r4")
        .c("mac out, r2, r5")
        .cq("mac r7, r3, r6, >>14")
        .c("neg r7, r7")
        .cq("mul r11, r7, r7, >>14")
        .c(format!("ld r14, [r0 + #{}]", ram::C_ONE))
        .c("sub r11, r14, r11")
        .cq("mul r11, r13, r11, >>14")
        .cq("ldacc r14, <<10")
        .cq("msu r15, r13, r11, >>10")
        .c("cmp.le r15, #0")
        .c("(f) movb r12, #0")
        .c("max r15, r15, #1");
    sqrt_q14(&mut k, 15, 11, [8, 9, 10, 14], nr);
    k.comment("T = eta d + (eta c1 - sqrt(k)) N");
    k.cq("mul r10, r13, r7, >>14")
        .c("sra r11, r11, #2")
        .c("sub r10, r10, r11");
    for (x, d, n) in [(8, 1, 4), (9, 2, 5), (14, 3, 6)] {
        k.c(format!("mul out, r13, r{d}"))
            .cq(format!("mac r{x}, r10, r{n}, >>12"));
    }
    normalize(&mut k, [8, 9, 14], [1, 2, 3, 4, 5], false, nr);
    for i in 0..3 {
        k.c(format!("ld r1, [r0 + #{}]", ram::SH_P + i))
            .c(format!("st r1, [#{}]", rf + i));
    }
    k.c(format!("st r8, [#{}]", rf + 3))
        .c(format!("st r9, [#{}]", rf + 4))
        .c(format!("st r14, [#{}]", rf + 5))
        .c(format!("st r12, [#{}]", rf + 6))
        .c(format!("ld r1, [r0 + #{}]", ram::ORIG_OBJ))
        .c(format!("st r1, [#{}]", ram::ORIG_STACK + level));
    k
}

/// After the reflection of level `level` returned: push the colour so far
/// and spawn the refracted ray that [`refract_prepare`] set up; the rays
/// with none sleep (F = 1 on the awake ones, for `rcany`).
pub fn refract_setup(level: u32) -> K {
    let base = ram::STACK + ram::STACK_FRAME * level;
    let rf = ram::REFR + ram::REFR_FRAME * level;
    let mut k = K::default();
    k.c("movb r10, #0");
    for c in 0..3 {
        k.c(format!("ld r9, [r0 + #{}]", ram::COL + c))
            .c(format!("st r9, [#{}]", base + c))
            .c(format!("st r10, [#{}]", ram::COL + c));
    }
    for (i, x) in [1, 2, 3, 4, 5, 6].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", rf + i as u32));
    }
    k.c(format!("ld r7, [r0 + #{}]", ram::C_INF))
        .c(format!("st r7, [#{}]", ram::PASS_T0));
    for (i, d) in [4, 5, 6].into_iter().enumerate() {
        k.c(format!("st r{d}, [#{}]", ram::SH_D + i as u32));
    }
    k.c(format!("ld r8, [r0 + #{}]", ram::ORIG_STACK + level))
        .c(format!("st r8, [#{}]", ram::ORIG_OBJ))
        .c(format!("ld r8, [r0 + #{}]", rf + 6))
        .c("cmp.gt r8, #0")
        .c("(!f) sleep");
    k
}

/// Return from the refracted ray of level `level`: colour = pushed +
/// T * refracted.
pub fn refract_pop(level: u32) -> K {
    let base = ram::STACK + ram::STACK_FRAME * level;
    let rf = ram::REFR + ram::REFR_FRAME * level;
    let mut k = K::default();
    k.c(format!("ld r10, [r0 + #{}]", rf + 6));
    for c in 0..3 {
        k.c(format!("ld r8, [r0 + #{}]", base + c))
            .c(format!("ld r9, [r0 + #{}]", ram::COL + c))
            .cq("mul r9, r9, r10, >>12")
            .c("adds r9, r8, r9")
            .c(format!("st r9, [#{}]", ram::COL + c));
    }
    k
}

/// Return from level `level + 1`: pop, colour = pushed + weight * reflected.
pub fn reflect_pop(level: u32) -> K {
    let base = ram::STACK + ram::STACK_FRAME * level;
    let mut k = K::default();
    k.c(format!("ld r10, [r0 + #{}]", base + 3));
    for c in 0..3 {
        k.c(format!("ld r8, [r0 + #{}]", base + c))
            .c(format!("ld r9, [r0 + #{}]", ram::COL + c))
            .cq("mul r9, r9, r10, >>12")
            .c("adds r9, r8, r9")
            .c(format!("st r9, [#{}]", ram::COL + c));
    }
    k
}

/// Put one output word (colour channel 0..2, or 3 = object id) into `out`.
pub fn out_word(i: u32) -> K {
    let mut k = K::default();
    let a = if i < 3 { ram::COL + i } else { ram::OUT_OBJ };
    k.c(format!("ld out, [r0 + #{a}]"));
    k
}

// ---- Packet traversal (`Traversal::Packet`, `control::packet_trace`) ----
//
// Every ray keeps its parametric interval `[tmin, tmax]` inside the cell
// being visited in r8, r9 while the packet descends (no object kernel runs
// between two inner nodes); its upper end is always taken together with
// `tbest` (r7). The distance to a split plane at `x` along axis `a` is
// `t(x) = (x - o_a) / d_a`, from the reciprocal of the direction computed
// once per pass ([`pk_init`]): `|D|` (Q1.14, clamped to [1, 2^14 - 1]) is
// normalised by `z = clz(|D|) - 1` into [2^14, 2^15), `R = ±2^29 / (|D|
// << z)` (table and two Newton-Raphson steps, the sign of `d_a`), and
// `t(x) = ((x - o_a) << (z - 1)) * R >> 14`. The shift saturates exactly
// when `t` does (`|R| >= 2^14`), so a saturated `t` lies beyond every
// segment. Every plane is widened by [`P_TOL`] LSB on both sides: a ray
// meets the cell below for `t` up to `t(s) + dt` and the cell above from
// `t(s) - dt` on, `dt = P_TOL / |d_a|`, more than the error of `t` (2.5
// LSB at the end of the range), so an interval never misses a cell its
// ray meets. The far child's intervals are pushed into RC RAM, one slot
// per BSP depth (`P_SLOT`), only when TinyRISC pushes the child; a pop
// reads and clears the slot in every RC.

/// Widening of every split plane and of the root box in the packet
/// traversal, in LSB of the scene format.
pub const P_TOL: i32 = 4;

/// Newton-Raphson steps of the traversal's direction reciprocals: the
/// intervals' widening assumes a relative error under 2^-14, which one
/// step reaches from the 128-entry table (0.4% before the step, 1.5e-5
/// after) and two from any smaller one.
fn p_newton(nr: Approx) -> u32 {
    if nr.table_entries >= 128 {
        1
    } else {
        2
    }
}

/// `t(x)` for the operand `x` (a register or `fb0`) into `out`:
/// `out = ((x - o) << zr) * rr >> 14`.
fn pk_t(k: &mut K, out: u8, x: &str, o: u8, zr: u8, rr: u8) {
    k.c(format!("sub r{out}, {x}, r{o}"))
        .c(format!("asl r{out}, r{out}, r{zr}"))
        .cq(format!("mul r{out}, r{out}, r{rr}, >>14"));
}

/// Start of a packet pass (stream: the root box widened by [`P_TOL`], per
/// axis min then max). Every awake ray takes part (`P_ALIVE` = 1); per
/// axis the direction's reciprocal (`P_Z`, `P_R`) and `dt` (`P_DT`) are
/// computed, and the interval (r8, r9) is `[0, tbest]` clipped to the root
/// box; a ray that misses the box is not alive and sleeps. `nr`: the
/// reciprocal table's size (the Newton steps: [`p_newton`]).
pub fn pk_init(nr: impl Into<Approx>) -> K {
    let nr: Approx = nr.into();
    let mut k = K::default();
    k.c("movb r8, #1").c(format!("st r8, [#{}]", ram::P_ALIVE));
    k.c(format!("ld r9, [r0 + #{}]", ram::C_ONE))
        .c("sub r9, r9, #1")
        .c(format!("ld r15, [r0 + #{}]", ram::C_ONE));
    for a in 0..3u32 {
        let d = 4 + a;
        k.comment(&format!("1 / d{a}"));
        k.c(format!("abs r8, r{d}"))
            .c("max r8, r8, #1")
            .c("min r8, r8, r9")
            .c("clz r10, r8")
            .c("sub r10, r10, #1")
            .c("sll r11, r8, r10")
            .c(format!("srl r12, r11, #{}", q(7) + nr.coarse()))
            .c(format!("and r12, r12, #{}", nr.table_entries - 1))
            .c(format!("ld r12, [r12 + #{}]", ram::RCP));
        for _ in 0..p_newton(nr) {
            k.cq("mul r14, r11, r12, >>15")
                .c("sub r14, r14, r15")
                .cq("ldacc r12, <<14")
                .cq("msu r12, r12, r14, >>14");
        }
        k.c("sub r10, r10, #1")
            .c(format!("st r10, [#{}]", ram::P_Z + a))
            .c(format!("movb r13, #{P_TOL}"))
            .c("asl r13, r13, r10")
            .cq("mul r13, r13, r12, >>14")
            .c(format!("st r13, [#{}]", ram::P_DT + a))
            .c(format!("cmp.lt r{d}, #0"))
            .c("(f) neg r12, r12")
            .c(format!("st r12, [#{}]", ram::P_R + a));
    }
    k.comment("root interval");
    k.c("movb r8, #0").c("mov r9, r7");
    for a in 0..3u32 {
        k.c(format!("ld r12, [r0 + #{}]", ram::P_Z + a))
            .c(format!("ld r13, [r0 + #{}]", ram::P_R + a));
        pk_t(&mut k, 10, "fb0", 1 + a as u8, 12, 13);
        pk_t(&mut k, 11, "fb0", 1 + a as u8, 12, 13);
        k.c("min r14, r10, r11")
            .c("max r10, r10, r11")
            .c("max r8, r8, r14")
            .c("min r9, r9, r10");
    }
    k.c("cmp.lt r8, r9")
        .c("movb r10, #0")
        .c(format!("(!f) st r10, [#{}]", ram::P_ALIVE))
        .c("(!f) sleep");
    k
}

/// Inner node on `axis` (stream: the split). Each awake ray cuts its
/// interval (r8, r9; `r9 <= tbest`: the pass start and every pop clip it,
/// and no hit is found between two inner nodes) at the plane into the part
/// below and the part above
/// (each reaching [`P_TOL`] LSB past the plane); `first_above` names the
/// child the packet visits first. The first child's interval becomes the
/// current one (r8, r9), the second's is left in r11, r14 for
/// [`pk_second`], [`pk_push`] and [`pk_take`]; rays that reach neither
/// child sleep; F = reaches the first child.
pub fn pk_node(axis: u8, first_above: bool) -> K {
    let (o, d) = (1 + axis, 4 + axis);
    let a = axis as u32;
    let mut k = K::default();
    k.c(format!("ld r12, [r0 + #{}]", ram::P_Z + a))
        .c(format!("ld r13, [r0 + #{}]", ram::P_R + a));
    pk_t(&mut k, 10, "fb0", o, 12, 13);
    k.c(format!("ld r12, [r0 + #{}]", ram::P_DT + a))
        .c("subs r11, r10, r12")
        .c("adds r10, r10, r12")
        .comment("near = [tmin, min(hi, t + dt)], far = [max(tmin, t - dt), hi]")
        .c("min r12, r9, r10")
        .c("max r13, r8, r11")
        .c(if first_above {
            format!("cmp.lt r{d}, #0")
        } else {
            format!("cmp.ge r{d}, #0")
        })
        .c("sel r14, r9, r12")
        .c("sel r9, r12, r9")
        .c("sel r11, r13, r8")
        .c("sel r8, r8, r13")
        .c("cmp.lt r11, r14")
        .c("(!f) cmp.lt r8, r9")
        .c("(!f) sleep")
        .c("cmp.lt r8, r9");
    k
}

/// After [`pk_node`], when every awake ray reaches the first child: F =
/// reaches the second too.
pub fn pk_second() -> K {
    let mut k = K::default();
    k.c("cmp.lt r11, r14");
    k
}

/// After [`pk_node`], when the packet visits both children: the rays that
/// do not reach the first sleep until the second is popped.
pub fn pk_sleep_first() -> K {
    let mut k = K::default();
    k.c("(!f) sleep");
    k
}

/// After [`pk_node`], the second child is pushed (stream: the node's slot
/// address): every awake ray stores its interval for it, words `tmax, tmin`.
pub fn pk_push() -> K {
    let mut k = K::default();
    k.c("mov r15, fb0")
        .c("st r14, [r15]")
        .c("add r15, r15, #1")
        .c("st r11, [r15]");
    k
}

/// After [`pk_node`], the packet visits the second child only (every awake
/// ray reaches it): its interval becomes the current one.
pub fn pk_take() -> K {
    let mut k = K::default();
    k.c("mov r8, r11").c("mov r9, r14");
    k
}

/// A popped node (stream: the slot its parent pushed it with): every RC
/// wakes, takes its interval from the slot and clears the slot; the rays
/// that are not alive in this pass, or whose interval is empty or lies
/// beyond their hit, sleep again (F = awake).
pub fn pk_pop() -> K {
    let mut k = K::default();
    k.c("wake")
        .c("mov r15, fb0")
        .c("ld r9, [r15 + #0]")
        .c("ld r8, [r15 + #1]")
        .c("movb r10, #-1")
        .c("st r10, [r15]")
        .c("min r9, r9, r7")
        .c(format!("ld r11, [r0 + #{}]", ram::P_ALIVE))
        .c("cmp.ne r11, #0")
        .c("(f) cmp.lt r8, r9")
        .c("(!f) sleep");
    k
}

/// Packet traversal, any-hit (shadow) pass, after a leaf: a ray that found
/// a hit is done for the pass.
pub fn pk_leaf_any() -> K {
    let mut k = K::default();
    k.c(format!("ld r8, [r0 + #{}]", ram::PASS_T0))
        .c("cmp.lt r7, r8")
        .c("movb r9, #0")
        .c(format!("(f) st r9, [#{}]", ram::P_ALIVE))
        .c("(f) sleep");
    k
}

/// [`wake_restore`] for the packet traversal: no ray is alive in a pass
/// until the pass starts ([`pk_init`]).
pub fn pk_wake_restore() -> K {
    let mut k = K::default();
    k.c("wake")
        .c(format!("st r0, [#{}]", ram::P_ALIVE))
        .c(format!("ld r8, [r0 + #{}]", ram::LANE_ACT))
        .c("cmp.eq r8, #0")
        .c("(f) sleep");
    k
}

/// Appended to [`init`] for the packet traversal: no ray alive, every
/// interval slot empty.
pub fn pk_init_ram(k: &mut K) {
    k.c(format!("st r0, [#{}]", ram::P_ALIVE)).c("movb r8, #-1");
    for d in 0..ram::P_SLOTS {
        k.c(format!("st r8, [#{}]", ram::P_SLOT + 2 * d));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tracer::layout::{
        CONE_BODY_WORDS, CYL_BODY_WORDS, CYL_BODY_WORDS_COARSE, PLANAR_WORDS, SPHERE_FINE_WORDS,
        SPHERE_WORDS,
    };

    #[test]
    fn every_kernel_reads_exactly_its_record() {
        assert_eq!(sphere(8, 2, 2).fb_reads, SPHERE_WORDS);
        assert_eq!(sphere_with(8, 2, 2, true, true).fb_reads, SPHERE_FINE_WORDS);
        assert_eq!(
            sphere_with(8, 2, 2, true, false).fb_reads,
            SPHERE_FINE_WORDS
        );
        for i in [Inside::Triangle, Inside::Rectangle, Inside::Disc] {
            assert_eq!(planar(i, 9, 2).fb_reads, PLANAR_WORDS);
        }
        assert_eq!(cylinder(8, 2, 2, true).fb_reads, CYL_BODY_WORDS);
        assert_eq!(cylinder(8, 2, 2, false).fb_reads, CYL_BODY_WORDS_COARSE);
        assert_eq!(cone(8, 2, 2).fb_reads, CONE_BODY_WORDS);
        assert_eq!(polygon_head(2).fb_reads, 15);
        assert_eq!(aabox(2).fb_reads, crate::tracer::layout::BOX_WORDS);
        assert_eq!(polygon_edge().fb_reads, 5);
        assert_eq!(polygon_tail().fb_reads, 5);
        assert_eq!(init().fb_reads, 258);
        assert_eq!(eye(20, 2).fb_reads, 14);
        assert_eq!(light_setup(2, false).fb_reads, 3);
        assert_eq!(light_setup(2, true).fb_reads, 4);
        assert_eq!(post(true, 5, 3).fb_reads, 3 + 2 * 5);
        assert_eq!(
            shade(&[(1, 0.0), (10, 0.5), (200, 0.0)]).fb_reads,
            7 * 3 + 2
        );
        assert_eq!(leaf_closest().fb_reads, 6);
        assert_eq!(classify(2).fb_reads, 1);
    }

    #[test]
    fn tables_match_their_definitions() {
        use crate::tracer::layout::{rcp_table, rsq_table};
        let rsq = rsq_table(128);
        for (k, &y) in rsq.iter().enumerate().skip(8) {
            let x = (k as f64 + 0.5) * 256.0 / 2048.0;
            assert!((y as f64 / 16384.0 - 1.0 / x.sqrt()).abs() < 1e-4);
        }
        let rcp = rcp_table(128);
        for (k, &r) in rcp.iter().enumerate() {
            assert!(r > 16384 && r < 32768, "{k}");
        }
    }
}
