//! The planar primitives: rectangle, triangle and disc (an object of a
//! native scene, and the caps of cylinders and cones), held to
//! `scene/shape/rectangle.rs`, `triangle.rs`, `disc.rs` and the caps of
//! `cone.rs`. The polygon and the smooth triangle start with the same
//! plane test ([`plane_hit`]).
//!
//! **Record** (20 words): `n.xyz (Q1.14), v0.xyz, v0.xyz, eu.xyz, ew.xyz,
//! n.xyz, obj, mat`, where `u = (P - v0).eu`, `w = (P - v0).ew` (the
//! edge duals scaled by `2^KT_RECT`, `2^KT_TRI` or `2^KT_DISC`) are the
//! barycentric or edge coordinates of the hit point in Q.14.
//!
//! **Method**: `den = -n.d > 0` (the front face), `num = -n.(v0 - o) > 0`;
//! the test `num 2^14 < tbest den` is done in the accumulator before the
//! division, so the quotient `t = num / den` always fits; then `u`, `w` of
//! `P = o + t d` and the inside test, with a tolerance of `INSIDE_TOL`:
//! triangle `u, w >= 0, u + w <= 1`; rectangle `0 <= u, w <= 1`; disc
//! `u^2 + w^2 <= 1`.
//!
//! **Two-sided** ([`Sides::Both`], a transmitting object): where the plane
//! is seen from its back `den` and `num` change sign, the normal turns to
//! the ray and the hit is a back hit (`HIT_BACK_OBJ`); a ray leaving the
//! object (`ORIG_OBJ`) does not hit it again (a distance margin would also
//! drop the hits of rays starting near an edge on the next face).
//!
//! **Local positions** (an opaque rectangle or disc; flat triangles have
//! a frame of their own, [`super::triangle_local`]): the record
//! [`FINE_FIELDS`] (21 words, the plane's offset below the LSB after the
//! vertex), [`plane_hit_fine`] (the numerator exact from the origin's
//! remainder and that offset, F before `tbest + 1`) and, past the inside
//! cut, [`fine_commit`]: `t` and the hit point `o + t d` to 2^-14 LSB,
//! compared and tagged as the local kernels' hits
//! ([`crate::tracer::positions`]).
//!
//! **Registers**: r1..r7 the ray (r7 the new `tbest` where F); r8..r15
//! temporaries; RAM `TMP3` (two-sided: the back flag); local positions
//! `TMP1`, `TMP2`, `TMP4..TMP8`.
//!
//! **Error** against the f64 shapes: their `error_bound` (below), which
//! `tb/tests/kernels.rs` holds both chips to; the largest `t` errors at
//! grazing incidence, where the rounding of the direction is amplified.

use super::super::emit::{define, Code, K};
use super::super::math::{self, divide};
use super::super::memory_map::ram;
use super::super::positions;
use super::record::{total, Field, Layout, W};
use super::{
    commit_streamed_normal, commit_streamed_normal_two, CutTest, ErrorBound, Fit, Gen, Geometry,
    Object, RecordError, Sides, TestCost,
};
use crate::scene::{Shape, Vec3};

/// The record's fields, in stream order.
pub const NORMAL: Field = Field::part("n.xyz", "the plane's unit normal (Q1.14)");
pub const VERTEX: Field = Field::part("v0.xyz", "a vertex, for the plane's offset");
/// Local positions, one side ([`plane_hit_fine`]): the plane's offset
/// below the LSB.
pub const PLANE_REM: Field = Field::part(
    "v0n",
    "local: -n.(v0 - v0 rounded), the plane's offset below the LSB, 2^-14 LSB",
);
pub const VERTEX_AGAIN: Field =
    Field::part("v0.xyz'", "the vertex again, for the hit's coordinates");
pub const EDGE_U: Field = Field::part("eu.xyz", "the first edge dual, scaled by 2^KT");
pub const EDGE_W: Field = Field::part("ew.xyz", "the second edge dual, scaled by 2^KT");
pub const NORMAL_AGAIN: Field = Field::part("n.xyz'", "the normal again, for the hit");
pub const OBJ: Field = Field::part("obj", "the object's id");
pub const MAT: Field = Field::part("mat", "its material");
pub const FIELDS: [(Field, usize); 8] = [
    (NORMAL, 3),
    (VERTEX, 3),
    (VERTEX_AGAIN, 3),
    (EDGE_U, 3),
    (EDGE_W, 3),
    (NORMAL_AGAIN, 3),
    (OBJ, 1),
    (MAT, 1),
];

/// Record words.
pub const WORDS: usize = total(&FIELDS);

/// The record of [`plane_hit_fine`]'s kernels: [`FIELDS`] with the
/// plane's offset below the LSB ([`PLANE_REM`]) after the vertex.
pub const FINE_FIELDS: [(Field, usize); 9] = [
    FIELDS[0],
    FIELDS[1],
    (PLANE_REM, 1),
    FIELDS[2],
    FIELDS[3],
    FIELDS[4],
    FIELDS[5],
    FIELDS[6],
    FIELDS[7],
];

/// Tolerance of the barycentric / rectangle / disc inside tests, Q.14.
pub const INSIDE_TOL: i32 = 2;

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

impl Inside {
    /// Index of the kind's scale shift in `Fit::kt`.
    pub fn kt_index(self) -> usize {
        match self {
            Inside::Rectangle => 0,
            Inside::Triangle => 1,
            Inside::Disc => 2,
        }
    }
    /// The header's name of the kind's scale shift.
    fn kt_name(self) -> &'static str {
        match self {
            Inside::Rectangle => "KT_RECT",
            Inside::Triangle => "KT_TRI",
            Inside::Disc => "KT_DISC",
        }
    }
}

pub fn kernel_name(i: Inside, s: Sides) -> &'static str {
    match (i, s) {
        (Inside::Rectangle, Sides::Front) => "k_rectangle",
        (Inside::Triangle, Sides::Front) => "k_triangle",
        (Inside::Disc, Sides::Front) => "k_disc",
        (Inside::Rectangle, Sides::Both) => "k_glass_rectangle",
        (Inside::Triangle, Sides::Both) => "k_glass_triangle",
        (Inside::Disc, Sides::Both) => "k_glass_disc",
    }
}

/// A planar record's geometry: normal, origin vertex, edge duals.
#[derive(Clone, Copy, Debug)]
pub struct Planar {
    pub n: Vec3,
    pub v0: Vec3,
    pub eu: Vec3,
    pub ew: Vec3,
    pub kind: Inside,
}

impl Planar {
    /// A triangle `a, b, c` with normal `n`.
    pub fn triangle(a: Vec3, b: Vec3, c: Vec3, n: Vec3) -> Planar {
        let (e1, e2) = (b - a, c - a);
        let x = e2.cross(n);
        let y = n.cross(e1);
        let (dx, dy) = (e1.dot(x), e2.dot(y));
        if dx.abs() < 1e-300 || dy.abs() < 1e-300 {
            // Degenerate: a record that never hits (zero normal).
            return Planar::never(a, Inside::Triangle);
        }
        Planar {
            n,
            v0: a,
            eu: x * (1.0 / dx),
            ew: y * (1.0 / dy),
            kind: Inside::Triangle,
        }
    }

    /// A rectangle from `corner` along `e1`, `e2`.
    pub fn rectangle(corner: Vec3, e1: Vec3, e2: Vec3, n: Vec3) -> Planar {
        Planar {
            n,
            v0: corner,
            eu: e1 * (1.0 / e1.dot(e1)),
            ew: e2 * (1.0 / e2.dot(e2)),
            kind: Inside::Rectangle,
        }
    }

    /// A disc of radius `r` about `center`, spanned by the unit `e1`, `e2`.
    pub fn disc(center: Vec3, e1: Vec3, e2: Vec3, r: f64, n: Vec3) -> Planar {
        Planar {
            n,
            v0: center,
            eu: e1 * (1.0 / r),
            ew: e2 * (1.0 / r),
            kind: Inside::Disc,
        }
    }

    /// A record that never hits (zero normal): a degenerate triangle, the
    /// tip of a pointed cone.
    pub fn never(at: Vec3, kind: Inside) -> Planar {
        Planar {
            n: Vec3::ZERO,
            v0: at,
            eu: Vec3::ZERO,
            ew: Vec3::ZERO,
            kind,
        }
    }

    /// The largest component of the edge duals as the record holds them
    /// before the kind's scale shift (for the fit of `KT_*`).
    pub fn dual_max(&self, w_frac: i32) -> f64 {
        self.eu
            .to_array()
            .into_iter()
            .chain(self.ew.to_array())
            .map(|x| x.abs() * (w_frac as f64).exp2())
            .fold(0.0, f64::max)
    }
}

/// Write the record of planar `p` (object `id`, material `mat`); `kt`:
/// the scale shifts of [`super::Fit::kt`].
pub(crate) fn write(w: &mut W, kt: &[u32; 3], p: &Planar, id: usize, mat: usize) {
    write_as(w, kt, p, (id, mat), false)
}

/// The word [`PLANE_REM`] of a plane of normal `n` through `v0`, after
/// `v0` rounded: `-n.(v0 - v0 rounded)` in 2^-14 LSB with the normal as
/// the record holds it (Q1.14), so that the chip's plane passes through
/// `v0` itself.
pub(super) fn plane_rem(w: &mut W, n: Vec3, v0: Vec3) {
    let one = w.one();
    let off: f64 = (0..3)
        .map(|i| {
            let x = v0.axis(i) * w.s;
            (n.axis(i) * one).round() / one * (x - w.sat(x) as f64)
        })
        .sum();
    w.field(PLANE_REM);
    w.push(-off * 16384.0);
}

/// [`write`], with `fine` the record of [`plane_hit_fine`]'s kernels
/// ([`FINE_FIELDS`]): `-n.(v0 - v0 rounded)` with the normal as the
/// record holds it, so that the chip's plane passes through `v0` itself.
fn write_as(w: &mut W, kt: &[u32; 3], p: &Planar, (id, mat): (usize, usize), fine: bool) {
    let k = kt[p.kind.kt_index()];
    let sc = ((14 + w.x) as f64 - w.frac as f64 + k as f64).exp2();
    w.field(NORMAL);
    w.unit(p.n);
    w.field(VERTEX);
    w.point(p.v0);
    if fine {
        plane_rem(w, p.n, p.v0);
    }
    w.field(VERTEX_AGAIN);
    w.point(p.v0);
    w.field(EDGE_U);
    w.scaled(p.eu, sc);
    w.field(EDGE_W);
    w.scaled(p.ew, sc);
    w.field(NORMAL_AGAIN);
    w.unit(p.n);
    w.field(OBJ);
    w.raw(id as i64);
    w.field(MAT);
    w.raw(mat as i64);
}

/// The cuts of the triangle and rectangle kernels, opaque or glass, and of
/// the smooth triangle's ([`K::cut`]), and what F holds at each: the
/// plane is hit before `tbest`; the hit lies inside (the normal and the
/// commit are left where no awake ray hits the primitive itself).
pub const CUTS: [(&str, &str); 2] = [
    (
        "plane",
        "the plane hit in front (two-sided: on either side), before tbest",
    ),
    ("inside", "and the hit inside"),
];

/// The ray-plane part shared by the planar, polygon and smooth triangle
/// kernels: reads the plane normal and a vertex from the stream, and
/// leaves `t = num / den` in r9 with F set where the plane is hit in
/// front (two-sided: on either side, `TMP3` = 1 on the back), closer than
/// `tbest`. With `cut`, the kernel has a cut ([`K::cut`]) of that name
/// once F is known, before the division.
pub fn plane_hit(k: &mut K, g: &Gen, sides: Sides, cut: Option<&str>) {
    plane_hit_as(k, g, sides, cut, false, false)
}

/// [`plane_hit`] for local positions (one side): F where the plane is hit
/// in front before `tbest + 1` (a local `tbest` carries a remainder,
/// [`positions::nearer`] tells them apart), and the part of `t` below
/// the quotient `q` (r9) in `TMP1` ([`positions::quotient_rest`]), for
/// [`fine_commit`].
pub fn plane_hit_fine(k: &mut K, g: &Gen, cut: Option<&str>) {
    plane_hit_as(k, g, Sides::Front, cut, true, false)
}

/// [`plane_hit`] of a record that carries [`PLANE_REM`] after the vertex
/// (a polygon's of a scene with local positions) without using it (the
/// two-sided test): the word is read past.
pub fn plane_hit_past_rem(k: &mut K, g: &Gen, sides: Sides, cut: Option<&str>) {
    plane_hit_as(k, g, sides, cut, false, true)
}

fn plane_hit_as(k: &mut K, g: &Gen, sides: Sides, cut: Option<&str>, fine: bool, past_rem: bool) {
    k.comment("den = -n.d, num = -n.(v0 - o)");
    k.c("mov r8, fb0").c("mov r9, fb0").c("mov r10, fb0");
    k.c("mul out, r8, r4")
        .c("mac out, r9, r5")
        .c("mac r11, r10, r6, >>Q14");
    k.c("sub r12, fb0, r1")
        .c("sub r13, fb0, r2")
        .c("sub r14, fb0, r3");
    if past_rem {
        k.c("mov r15, fb0")
            .note("the plane's offset below the LSB, not used");
    }
    if fine {
        // num = n.(ol - (v0 - o)) exact in the accumulator (the origin's
        // remainder, the plane's offset below the LSB from the record),
        // rounded, and its remainder kept for the quotient's rest.
        for (i, n) in [8, 9, 10].into_iter().enumerate() {
            k.c(format!("ld r15, [r0 + #{}]", ram::RAY_OL + i as u32));
            k.c(match i {
                0 => "mul out, r8, r15".to_string(),
                1 => "mac out, r9, r15".to_string(),
                _ => format!("mac r15, r{n}, r15, >>Q14"),
            });
        }
        k.note("n.ol, 2^-14 LSB")
            .c("ldacc r15")
            .c("mac out, fb0, #1")
            .note("- n.(v0's part below the LSB)")
            .c("msu out, r8, r12")
            .c("msu out, r9, r13")
            .c("msu r15, r10, r14, >>Q14")
            .note("num");
        math::remainder(k, 12, 15, 13, "Q14");
        k.note("its remainder, 2^-14 LSB")
            .c(format!("st r12, [#{}]", ram::TMP2))
            .c("neg r11, r11");
    } else {
        k.c("mul out, r8, r12")
            .c("mac out, r9, r13")
            .c("mac r15, r10, r14, >>Q14");
        k.c("neg r11, r11").c("neg r15, r15");
    }
    if sides == Sides::Both {
        k.c("movb r12, #0")
            .c("cmp.lt r11, #0")
            .note("the back: den and num change sign")
            .c("(f) movb r12, #1")
            .c("(f) neg r11, r11")
            .c("(f) neg r15, r15")
            .c(format!("st r12, [#{}]", ram::TMP3))
            .note("1: a back hit");
    }
    k.c("cmp.gt r11, #0").c("(f) cmp.gt r15, #0");
    if fine {
        k.c("ldacc r15, <<Q14")
            .c("adds r13, r7, #1")
            .note("tbest + 1")
            .c("mac out, r12, #1")
            .c("msu out, r13, r11")
            .c("acch r12");
    } else {
        k.c("ldacc r15, <<Q14").c("msu out, r7, r11").c("acch r8");
    }
    k.c(format!("(f) cmp.lt r{}, #0", if fine { 12 } else { 8 }))
        .note("F: num 2^14 < tbest den, t fits");
    if let Some(c) = cut {
        k.cut(c);
    }
    if fine {
        for (x, at) in [(8, ram::TMP6), (9, ram::TMP7), (10, ram::TMP8)] {
            k.c(format!("st r{x}, [#{at}]"));
        }
        k.note("n, for fine_commit");
    }
    divide(k, 15, 11, 9, [8, 10, 12, 13, 14], g.approx);
    if fine {
        for (x, at) in [(15, ram::TMP1), (12, ram::TMP4), (8, ram::TMP5)] {
            k.c(format!("st r{x}, [#{at}]"));
        }
        k.note("num, the reciprocal and its shift, for fine_commit");
    }
}

/// After [`plane_hit_fine`] and the inside test (the quotient `q` in r9;
/// the polygon's: the crossing test):
/// `t` (r15) with its remainder (r12) from `q` and the rest the division
/// left ([`positions::quotient_rest`]: the numerator with its remainder,
/// the denominator `-n.(d + dl)` exact from the normal kept in
/// `TMP6..TMP8` and the direction's remainder), F kept where it is nearer
/// than `tbest` to 2^-14 LSB ([`positions::nearer`]), the commit, and the
/// hit point `o + t d` to 2^-14 LSB ([`positions::ray_point`]).
pub fn fine_commit(k: &mut K) {
    fine_t(k);
    positions::nearer(k, 15, 12, 11, 13);
    commit_streamed_normal(k, 15);
    positions::ray_point(k, 15, 12, [8, 10, 11, 13]);
}

/// After [`plane_hit_fine`] (the quotient `q` in r9): `t` (r15) with its
/// remainder (r12, 2^-14 LSB) from `q` and the rest the division left
/// ([`positions::quotient_rest`]: the numerator with its remainder, the
/// denominator `-n.(d + dl)` exact from the normal kept in `TMP6..TMP8`
/// and the direction's remainder). Clobbers r8..r15; F kept.
pub fn fine_t(k: &mut K) {
    k.comment("den = -n.(d + dl) to 2^-28 (Q1.14 and its remainder)");
    for (i, (x, d)) in [(8, 12), (10, 13), (11, 14)].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::TMP6 + i as u32))
            .c(format!("ld r{d}, [r0 + #{}]", ram::RAY_DL + i as u32));
    }
    k.c("mul out, r8, r12")
        .c("mac out, r10, r13")
        .c("mac r15, r11, r14, >>Q13")
        .note("n.dl, 2^-28");
    k.c("neg r15, r15")
        .c("ldacc r15")
        .c("msu out, r8, r4")
        .c("msu out, r10, r5")
        .c("msu r11, r11, r6, >>Q14")
        .note("den");
    math::remainder(k, 14, 11, 13, "Q14");
    k.note("its remainder, 2^-28")
        .c("mul r13, r9, r14, >>Q14")
        .note("q den_l 2^-14")
        .c(format!("ld r14, [r0 + #{}]", ram::TMP2))
        .note("num's remainder");
    for (x, at) in [(15, ram::TMP1), (12, ram::TMP4), (8, ram::TMP5)] {
        k.c(format!("ld r{x}, [r0 + #{at}]"));
    }
    positions::quotient_rest(k, [15, 14, 11, 13, 9, 12, 8], 13, [10, 14]);
    positions::fine_t(k, 9, 13, [15, 12, 14]);
}

/// After [`plane_hit`]: the hit point relative to `v0` (the stream's
/// `v0.xyz`), its coordinates `u` (r13), `w` (r14) along the record's dual
/// edge vectors, and F kept only where they are inside the primitive
/// (`u + w` in r15 for a triangle), with a tolerance of [`INSIDE_TOL`].
pub fn inside_test(k: &mut K, inside: Inside) {
    let kt = inside.kt_name();
    k.comment("P - v0");
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        let x = 10 + i;
        k.c(format!("ldacc r{o}, <<Q14"))
            .c(format!("mac r{x}, r9, r{d}, >>Q14"))
            .c(format!("rsb r{x}, fb0, r{x}"));
    }
    k.c("mul out, fb0, r10")
        .c("mac out, fb0, r11")
        .c(format!("mac r13, fb0, r12, >>{kt}"))
        .note("u");
    k.c("mul out, fb0, r10")
        .c("mac out, fb0, r11")
        .c(format!("mac r14, fb0, r12, >>{kt}"))
        .note("w");
    k.c(format!("ld r8, [r0 + #{}]", ram::C_ONE))
        .c("add r8, r8, #INSIDE_TOL");
    match inside {
        Inside::Triangle => {
            k.c("(f) cmp.ge r13, #-INSIDE_TOL")
                .c("(f) cmp.ge r14, #-INSIDE_TOL")
                .c("adds r15, r13, r14")
                .c("(f) cmp.le r15, r8")
                .note("F: inside the triangle");
        }
        Inside::Rectangle => {
            k.c("(f) cmp.ge r13, #-INSIDE_TOL")
                .c("(f) cmp.ge r14, #-INSIDE_TOL")
                .c("(f) cmp.le r13, r8")
                .c("(f) cmp.le r14, r8")
                .note("F: inside the rectangle");
        }
        Inside::Disc => {
            k.c("mul out, r13, r13")
                .c("mac r15, r14, r14, >>Q14")
                .c("(f) cmp.le r15, r8")
                .note("F: inside the disc");
        }
    }
}

/// The kernel of a disc object (a disc of a native scene): the caps'
/// disc kernel with the rectangle's and triangle's cuts.
pub fn disc_object_name(s: Sides) -> &'static str {
    match s {
        Sides::Front => "k_disc_object",
        Sides::Both => "k_glass_disc_object",
    }
}

/// The kernel of a cylinder's or cone's cap, or of a rectangle or a
/// triangle.
pub fn kernel(g: &Gen, inside: Inside, sides: Sides) -> K {
    let cuts = inside != Inside::Disc;
    planar_kernel(g, inside, sides, kernel_name(inside, sides), cuts, false)
}

/// The kernel of a planar test named `name`, with the cuts of [`CUTS`]
/// or without; `fine` (local positions, one side): `t` and the hit point
/// to 2^-14 LSB ([`plane_hit_fine`], [`fine_commit`]).
fn planar_kernel(g: &Gen, inside: Inside, sides: Sides, name: &str, cuts: bool, fine: bool) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{}: the {} test of one record (the stream){}.\n\
         In: r1..r3 o, r4..r6 d, r7 tbest. Out where F: r7 = t, HIT_N, HIT_OBJ, HIT_MAT{}.\n\
         t = n.(v0 - o) / n.d, P = o + t d, u = (P - v0).eu, w = (P - v0).ew",
        name,
        match inside {
            Inside::Rectangle => "rectangle",
            Inside::Triangle => "triangle",
            Inside::Disc => "disc",
        },
        if sides == Sides::Both {
            ", seen from either side"
        } else {
            ""
        },
        if sides == Sides::Both {
            ", HIT_BACK_OBJ"
        } else if fine {
            ", HIT_TL = t, HIT_TLL its remainder, HIT_PH and HIT_PL the hit point"
        } else {
            ""
        },
    ));
    let cut = cuts.then_some(CUTS[0].0);
    if fine {
        plane_hit_fine(&mut k, g, cut);
    } else {
        plane_hit(&mut k, g, sides, cut);
    }
    inside_test(&mut k, inside);
    if cut.is_some() {
        k.cut(CUTS[1].0);
    }
    match sides {
        _ if fine => fine_commit(&mut k),
        Sides::Front => commit_streamed_normal(&mut k, 9),
        Sides::Both => commit_streamed_normal_two(&mut k, 9),
    }
    k
}

/// The rectangle, the triangle and the disc ([`super::ChipPrimitive`]),
/// by their inside test.
pub struct PlanarPrimitive(Inside);

/// The rectangle.
pub const RECTANGLE: PlanarPrimitive = PlanarPrimitive(Inside::Rectangle);
/// The triangle (flat shaded).
pub const TRIANGLE: PlanarPrimitive = PlanarPrimitive(Inside::Triangle);
/// The disc (native scenes).
pub const DISC: PlanarPrimitive = PlanarPrimitive(Inside::Disc);

impl PlanarPrimitive {
    /// Whether its records are in frames of their own
    /// ([`super::triangle_local`]): a flat triangle of a scene with local
    /// positions, a rectangle or disc of one whose rectangles and discs
    /// all fit a frame ([`Fit::planar_frames`]); either side.
    fn local(&self, fit: &Fit) -> bool {
        match self.0 {
            Inside::Triangle => fit.local,
            _ => fit.planar_frames,
        }
    }

    /// Its kernel in frames of their own.
    fn local_kernel(&self, g: &Gen, sides: Sides) -> K {
        super::triangle_local::kernel(g, self.0, self.label(sides), sides == Sides::Both)
    }

    /// Its object test's kernel label.
    fn label(&self, sides: Sides) -> &'static str {
        match self.0 {
            Inside::Disc => disc_object_name(sides),
            i => kernel_name(i, sides),
        }
    }

    /// Whether its scene-format records are tested with `t` and the hit
    /// point to 2^-14 LSB ([`plane_hit_fine`]): local positions, one side,
    /// not in frames.
    fn fine(&self, sides: Sides, fit: &Fit) -> bool {
        sides == Sides::Front && fit.local && !self.local(fit)
    }

    /// Its object test's kernel (with cuts).
    fn object_kernel(&self, g: &Gen, sides: Sides, fit: &Fit) -> K {
        let fine = self.fine(sides, fit);
        planar_kernel(g, self.0, sides, self.label(sides), true, fine)
    }
}

impl super::ChipPrimitive for PlanarPrimitive {
    fn names(&self) -> [&'static str; 2] {
        match self.0 {
            Inside::Triangle => ["triangle", "glass_triangle"],
            Inside::Rectangle => ["rectangle", "glass_rectangle"],
            Inside::Disc => ["disc", "glass_disc"],
        }
    }

    fn layout(&self, sides: Sides, fit: &Fit, _fan: usize, _caps: bool) -> Layout {
        if self.local(fit) {
            return super::triangle_local::layout(sides == Sides::Both);
        }
        if self.fine(sides, fit) {
            return Layout::new(FINE_FIELDS);
        }
        Layout::new(FIELDS)
    }

    fn kernels(&self, sides: Sides, g: &Gen, fit: &Fit) -> Vec<(&'static str, K)> {
        if self.local(fit) {
            return vec![(self.label(sides), self.local_kernel(g, sides))];
        }
        vec![(self.label(sides), self.object_kernel(g, sides, fit))]
    }

    fn broadcast(&self, sides: Sides, t: &mut Code, _at: &str, _fit: &Fit, _caps: bool) {
        super::one(t, self.label(sides));
    }

    fn cut_test(&self, sides: Sides, fit: &Fit) -> Option<CutTest> {
        Some(CutTest {
            kernel: self.label(sides),
            field: "0",
            cuts: if self.local(fit) {
                &super::triangle_local::CUTS
            } else {
                &CUTS
            },
            then: None,
        })
    }

    fn fit_header(&self, fit: &Fit) -> Vec<String> {
        let what = match self.0 {
            Inside::Triangle => "triangles",
            Inside::Rectangle => "rectangles",
            Inside::Disc => "discs",
        };
        let name = self.0.kt_name();
        let mut v = vec![define(
            name,
            fit.kt[self.0.kt_index()],
            &format!("{what}: edge duals scaled by 2^{name}"),
        )];
        if self.local(fit) {
            v.push(define(
                "KT_LOCAL",
                fit.kt_local,
                "planar shapes in frames of their own: edge duals per LSB of the frame scaled by 2^(14+KT_LOCAL)",
            ));
        }
        v
    }

    fn has_inside_test(&self) -> bool {
        true
    }

    fn glass_self_margin(&self) -> bool {
        false
    }

    fn geometry(&self, shape: &Shape, _s: f64) -> Geometry {
        if let Some(r) = shape.as_rectangle() {
            let n = r.edge1.cross(r.edge2).normalized();
            Geometry::Planars(vec![Planar::rectangle(r.corner, r.edge1, r.edge2, n)])
        } else if let Some(t) = shape.as_triangle() {
            Geometry::Planars(vec![flat_triangle(t.v)])
        } else if let Some(d) = shape.as_disc() {
            let n = d.normal.normalized();
            let e1 = super::perpendicular(n);
            Geometry::Planars(vec![Planar::disc(d.center, e1, n.cross(e1), d.radius, n)])
        } else {
            Geometry::None
        }
    }

    /// Rectangles are priced as triangles (the cost model's kernels).
    fn test_cost(&self, g: &Gen, fit: &Fit) -> TestCost {
        match self.0 {
            _ if self.local(fit) => TestCost::of(&self.local_kernel(g, Sides::Front)),
            Inside::Disc => TestCost::of(&self.object_kernel(g, Sides::Front, fit)),
            _ if fit.local => TestCost::of(&self.object_kernel(g, Sides::Front, fit)),
            _ => TestCost::of(&kernel(g, Inside::Triangle, Sides::Front)),
        }
    }

    /// The largest `t` errors at grazing incidence, where the rounding of the
    /// direction is amplified.
    fn error_bound(&self) -> ErrorBound {
        ErrorBound::lsb(16.0, 1e-3)
    }

    fn write(&self, w: &mut W, o: &Object) -> Result<(), RecordError> {
        if self.local(o.fit) {
            let [p] = o.geometry.planars() else {
                return Err(RecordError::mismatch("planar"));
            };
            let c = super::triangle_local::centre(p, o.shape.as_triangle().map(|t| &t.v));
            let two = o.sides == Sides::Both;
            super::triangle_local::write(w, (o.fit.kt_local, two), c, p, (o.id, o.mat));
            return Ok(());
        }
        let fine = self.fine(o.sides, o.fit);
        for p in o.geometry.planars() {
            write_as(w, &o.fit.kt, p, (o.id, o.mat), fine);
        }
        Ok(())
    }
}

/// A triangle's planar record geometry, its normal from its vertices.
pub fn flat_triangle(v: [Vec3; 3]) -> Planar {
    let n = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
    Planar::triangle(v[0], v[1], v[2], n)
}
