//! The flat triangle in a frame of its own (local positions,
//! [`super::Fit::local`]; `scene/shape/triangle.rs`).
//!
//! **Record** (34 words): `c.xyz, Rn, sh, cl.xyz, n.xyz, nsc, uc, au.xyz,
//! wc, aw.xyz, n.xyz, obj, mat, (c, cl) per axis`. `c` is the centroid
//! rounded to the scene's LSB and `cl` its remainder (2^-14 LSB); the
//! frame's LSB is `2^-e` of the scene's, `e` fitted to the triangle's
//! extent `R` about `c` ([`crate::scene_image::local_exponent`]); `sh` is
//! `e + 2, 14 - e` and `nsc` is `2^(14-e)`. `au`, `aw` are the edge duals
//! per LSB of the frame, negated, scaled by `2^(14+KT_LOCAL)`; `uc`, `wc`
//! the centroid's barycentric coordinates (Q1.14).
//!
//! **Method**: `b = round((c - o).d)` in the scene's LSB, the cut `near`
//! where the line passes outside `Rn` ([`positions::near`]), and `p =
//! (c - o) - b d` in the frame, exactly as the local sphere forms it
//! ([`positions::offset_in_frame`]): `|p| <= R` where the ray can hit.
//! Then the plane through `c`: `den = -n.d > 0` (the front face), `num =
//! -n.p`, `s = num / den` (F only where `|s| < 2^15`: a hit lies within
//! `2 R` of the ray's point `b`), `g = p - s d` (the centroid seen from the
//! hit, `|g| <= R` inside the triangle), `u = uc + g.au`, `w = wc + g.aw`
//! and the barycentric test with [`planar::INSIDE_TOL`]; `t = b + s 2^-e`
//! rounded to the scene's LSB with its remainder, compared as the local
//! sphere's ([`positions::nearer`]); the streamed normal; the hit point
//! `c - g 2^-e` to 2^-14 LSB (`HIT_PH`, `HIT_PL`).
//!
//! **Registers**: r1..r7 the ray (r7 the new `tbest` where F); r8..r15
//! temporaries; RAM `TMP0..TMP3`.

use super::super::emit::K;
use super::super::math::{divide, remainder};
use super::super::memory_map::ram;
use super::super::positions;
use super::planar::{self, Inside, Planar};
use super::record::{Field, Fitter, Layout, W};
use super::sphere;
use crate::scene::Vec3;

pub const CENTRE: Field = Field::part("c.xyz", "the centroid, rounded");
pub const SHIFTS: Field = Field::part("sh", "e + 2 and 14 - e, the frame's shifts");
pub const CENTRE_REM: Field = Field::part("cl.xyz", "the centroid's remainder, 2^-14 LSB");
pub const NORMAL: Field = Field::part("n.xyz", "the plane's unit normal (Q1.14)");
pub const SCALE: Field = Field::part("nsc", "2^(14-e), a length of the frame in 2^-14 LSB");
pub const DUAL_U: Field = Field::part(
    "au.xyz",
    "-eu per LSB of the frame, scaled by 2^(14+KT_LOCAL)",
);
pub const U_CENTRE: Field = Field::part("uc", "u at the centroid (Q1.14)");
pub const DUAL_W: Field = Field::part(
    "aw.xyz",
    "-ew per LSB of the frame, scaled by 2^(14+KT_LOCAL)",
);
pub const W_CENTRE: Field = Field::part("wc", "w at the centroid (Q1.14)");
pub const OBJ_FIRST: Field = Field::part(
    "obj'",
    "seen from either side: the object's id, before the normal (ORIG_OBJ)",
);
pub const NORMAL_AGAIN: Field = Field::part("n.xyz'", "the normal again, for the hit");
pub const OBJ: Field = Field::part("obj", "the object's id");
pub const MAT: Field = Field::part("mat", "its material");
pub const CENTRE_AGAIN: Field = Field::part(
    "pc",
    "the centroid and its remainder again, per axis (the hit point)",
);

/// The record; `two` (seen from either side): with the object's id
/// again before the normal ([`OBJ_FIRST`]).
pub fn layout(two: bool) -> Layout {
    if two {
        let mut f = one_side();
        f.insert(10, (OBJ_FIRST, 1));
        return Layout::new(f);
    }
    Layout::new(one_side())
}

/// The one-sided record's fields.
fn one_side() -> Vec<(Field, usize)> {
    Vec::from([
        (CENTRE, 3),
        (sphere::NEAR, 1),
        (SHIFTS, 2),
        (CENTRE_REM, 3),
        (NORMAL, 3),
        (SCALE, 1),
        (U_CENTRE, 1),
        (DUAL_U, 3),
        (W_CENTRE, 1),
        (DUAL_W, 3),
        (NORMAL_AGAIN, 3),
        (OBJ, 1),
        (MAT, 1),
        (CENTRE_AGAIN, 6),
    ])
}

/// A planar shape's centre and extent about it (scene units): a
/// triangle's centroid (its vertices `v`), a rectangle's or a disc's
/// centre (from its record geometry `p`).
pub fn centre(p: &Planar, v: Option<&[Vec3; 3]>) -> (Vec3, f64) {
    match (p.kind, v) {
        (planar::Inside::Triangle, Some(v)) => {
            let c = (v[0] + v[1] + v[2]) * (1.0 / 3.0);
            (c, v.iter().map(|x| (*x - c).length()).fold(0.0, f64::max))
        }
        (planar::Inside::Disc, _) => (p.v0, 1.0 / p.eu.length().max(1e-300)),
        _ => {
            // A rectangle: its edges from the duals (`eu = e1 / |e1|^2`).
            let edge = |d: Vec3| d * (1.0 / d.dot(d).max(1e-300));
            let half = (edge(p.eu) + edge(p.ew)) * 0.5;
            (p.v0 + half, half.length())
        }
    }
}

/// A planar shape's frame: its centre and extent about it (LSB), its
/// exponent `e` and its edge duals' largest component per LSB of the
/// frame (for `KT_LOCAL`), `s` LSB per scene unit.
fn frame(c: (Vec3, f64), p: &Planar, s: f64) -> ((Vec3, f64), u32, f64) {
    let (c, r) = (c.0, c.1 * s);
    let e = sphere::local_exponent(r);
    let per = s * (e as f64).exp2();
    let dual =
        p.eu.to_array()
            .into_iter()
            .chain(p.ew.to_array())
            .map(|x| x.abs() / per)
            .fold(0.0, f64::max);
    ((c, r), e, dual)
}

/// Whether a planar shape of extent `r` (scene units, [`centre`]) fits a
/// frame at `s` LSB per unit.
pub fn fits(r: f64, s: f64) -> bool {
    crate::scene_image::local_exponent(r * s).is_some()
}

/// Whether a scene's rectangles and discs of extents `r` (scene units,
/// [`centre`]; `s` LSB per unit) are tested in frames: every one fits a
/// frame and most have one of [`FRAME_E_PAYS`] or finer. A frame's `t`
/// and hit point are as fine as its LSB (a shape over a few thousand LSB
/// gets a frame no finer than the scene's, where the fine planar kernel
/// has `t` to 2^-11 LSB); its edges are its Q1.14 coordinates'.
pub fn frames_pay(r: &[f64], s: f64) -> bool {
    let e = |r: f64| crate::scene_image::local_exponent(r * s);
    let fine = r
        .iter()
        .filter(|&&r| e(r).is_some_and(|e| e >= FRAME_E_PAYS))
        .count();
    !r.is_empty() && r.iter().all(|&r| fits(r, s)) && 2 * fine > r.len()
}

/// The frame exponent from which a rectangle's or disc's frame pays
/// ([`frames_pay`]): 2^-3 LSB.
pub const FRAME_E_PAYS: u32 = 3;

/// `KT_LOCAL` for the scene's planar shapes in frames (their
/// [`centre`]s and record geometry), `s` LSB per scene unit: the largest
/// shift that keeps every scaled dual in the word.
pub fn fit_kt(shapes: impl Iterator<Item = ((Vec3, f64), Planar)>, s: f64, f: &Fitter) -> u32 {
    let m = shapes
        .map(|(c, p)| frame(c, &p, s).2 * 16384.0)
        .fold(0.0, f64::max);
    f.shift(m, 20)
}

/// Write the local record of the planar shape of centre and extent `c`
/// ([`centre`]), record geometry `p`; `two`: seen from either side
/// ([`layout`]).
pub(crate) fn write(
    w: &mut W,
    (kt, two): (u32, bool),
    c: (Vec3, f64),
    p: &Planar,
    (id, mat): (usize, usize),
) {
    let ((c, r), e, _) = frame(c, p, w.s);
    let per = w.s * (e as f64).exp2();
    let one = w.one();
    let sc = (14.0 + kt as f64).exp2() / per;
    let parts = sphere::write_frame(w, [CENTRE, SHIFTS, CENTRE_REM], (c, r), e);
    w.field(NORMAL);
    w.unit(p.n);
    w.field(SCALE);
    w.push((14.0 - e as f64).exp2());
    w.field(U_CENTRE);
    w.push((c - p.v0).dot(p.eu) * one);
    w.field(DUAL_U);
    w.scaled(p.eu, -sc);
    w.field(W_CENTRE);
    w.push((c - p.v0).dot(p.ew) * one);
    w.field(DUAL_W);
    w.scaled(p.ew, -sc);
    if two {
        w.field(OBJ_FIRST);
        w.raw(id as i64);
    }
    w.field(NORMAL_AGAIN);
    w.unit(p.n);
    w.field(OBJ);
    w.raw(id as i64);
    w.field(MAT);
    w.raw(mat as i64);
    sphere::write_centre_again(w, CENTRE_AGAIN, parts);
}

/// The kernel's cuts: [`positions::near`], then [`planar::CUTS`].
pub const CUTS: [(&str, &str); 3] = [sphere::NEAR_CUT, planar::CUTS[0], planar::CUTS[1]];

/// The kernel of a triangle, rectangle or disc (`inside`) in its frame,
/// named `name` (cuts [`CUTS`]); `two`: seen from either side (a
/// transmitting one: the back turns `den`, `num` and the normal, the hit
/// is a back hit, `HIT_BACK_OBJ`, and a ray leaving the object, its
/// `ORIG_OBJ`, does not hit it again; the record [`layout`] of two sides).
pub fn kernel(g: &super::Gen, inside: Inside, name: &str, two: bool) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{name}: the {} test of one local record (the stream), for every awake ray{}.\n\
         In: r1..r7 the rays, RAY_OL, RAY_DL. Out where F (a nearer hit): r7 = t, HIT_N, HIT_OBJ, HIT_MAT,\n\
         HIT_TL = t, HIT_PH and HIT_PL the hit point{}. b = round((c - o).d), p = ((c - o) - b d) 2^e,\n\
         s = n.p / n.d, g = p - s d, u = uc + g.au, w = wc + g.aw, t = b + s 2^-e, P = c - g 2^-e",
        match inside {
            Inside::Triangle => "triangle",
            Inside::Rectangle => "rectangle",
            Inside::Disc => "disc",
        },
        if two { ", seen from either side" } else { "" },
        if two { ", HIT_BACK_OBJ" } else { "" },
    ));
    sphere::enter_frame(&mut k, ["c", "centre", "cl"], CUTS[0].0);
    plane_in_frame(&mut k, g, two);
    inside_in_frame(&mut k, inside);
    k.cut(planar::CUTS[1].0);
    if two {
        k.c("mov r13, fb0")
            .note("obj")
            .c(format!("ld r11, [r0 + #{}]", ram::ORIG_OBJ))
            .c("(f) cmp.ne r13, r11")
            .note("not the object the ray leaves");
    }
    positions::nearer(&mut k, 15, 12, 11, 13);
    if two {
        commit_two(&mut k);
    } else {
        super::commit_streamed_normal(&mut k, 15);
    }
    k.comment("the hit point c - g 2^-e, to 2^-14 LSB");
    k.c(format!("ld r14, [r0 + #{}]", ram::TMP3));
    for (i, v) in [8, 9, 10].into_iter().enumerate() {
        positions::hit_point_axis(&mut k, i as u32, "msu", v, None, 14, [11, 12, 13]);
    }
    k
}

/// In the frame (`p` in r8..r10, `b` in r11): the plane through the
/// centre (`two`: on either side, `TMP4` = 1 on the back), F where it is
/// hit in front within `2^15` of `b`, `s`, `g` (r8..r10), `t` (r15)
/// with its remainder (r12), `2^(14-e)` in `TMP3`.
fn plane_in_frame(k: &mut K, g: &super::Gen, two: bool) {
    k.comment("den = -n.d, num = -n.p, s = num / den");
    k.c("mov r12, fb0").c("mov r13, fb0").c("mov r14, fb0");
    k.c("mul out, r12, r4")
        .c("mac out, r13, r5")
        .c("mac r15, r14, r6, >>Q14")
        .c("mul out, r12, r8")
        .c("mac out, r13, r9")
        .c("mac r12, r14, r10, >>Q14")
        .c("neg r15, r15")
        .note("den")
        .c("neg r12, r12")
        .note("num");
    if two {
        k.c("movb r13, #0")
            .c("cmp.lt r15, #0")
            .note("the back: den and num change sign")
            .c("(f) movb r13, #1")
            .c("(f) neg r15, r15")
            .c("(f) neg r12, r12")
            .c(format!("st r13, [#{}]", ram::TMP4))
            .note("1: a back hit");
    }
    for (i, x) in [8, 9, 10].into_iter().enumerate() {
        k.c(format!("st r{x}, [#{}]", ram::TMP0 + i as u32));
    }
    k.note("p in TMP0..2")
        .c("sra r13, r12, #15")
        .c(format!("st r13, [#{}]", ram::TMP3))
        .note("num's sign, 0 or -1")
        .c("abs r12, r12")
        .c("adds r14, r15, r15")
        .c("cmp.gt r15, #0")
        .c("(f) cmp.lt r12, r14")
        .note("F: the front face, |s| < 2^15");
    k.cut(planar::CUTS[0].0);
    divide(k, 12, 15, 12, [8, 9, 10, 13, 14], g.approx);
    k.c(format!("ld r13, [r0 + #{}]", ram::TMP3))
        .c("xor r12, r12, r13")
        .c("sub r12, r12, r13")
        .note("s, signed");
    k.comment("g = p - s d, the centroid seen from the hit");
    for (i, (x, d)) in [(8, 4), (9, 5), (10, 6)].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::TMP0 + i as u32))
            .c(format!("ldacc r{x}, <<Q14"))
            .c(format!("msu r{x}, r12, r{d}, >>Q14"));
    }
    k.c("mov r14, fb0")
        .note("2^(14-e)")
        .c("ldacc r11, <<Q14")
        .c("mac r15, r14, r12, >>Q14")
        .note("t = b + s 2^-e");
    remainder(k, 12, 15, 13, "Q14");
    k.note("its remainder, 2^-14 LSB")
        .c(format!("st r14, [#{}]", ram::TMP3));
}

/// `u = uc + g.au`, `w = wc + g.aw` (Q1.14, r13, r14) and F kept where
/// they are inside (with [`planar::INSIDE_TOL`]).
fn inside_in_frame(k: &mut K, inside: Inside) {
    k.comment("u = uc + g.au, w = wc + g.aw (Q1.14)");
    for x in [13, 14] {
        k.c("ldacc fb0, <<KT_LOCAL")
            .c("mac out, fb0, r8")
            .c("mac out, fb0, r9")
            .c(format!("mac r{x}, fb0, r10, >>KT_LOCAL"));
    }
    k.c(format!("ld r11, [r0 + #{}]", ram::C_ONE))
        .c("add r11, r11, #INSIDE_TOL");
    match inside {
        Inside::Triangle => {
            k.c("(f) cmp.ge r13, #-INSIDE_TOL")
                .c("(f) cmp.ge r14, #-INSIDE_TOL")
                .c("adds r13, r13, r14")
                .c("(f) cmp.le r13, r11")
                .note("F: inside the triangle");
        }
        Inside::Rectangle => {
            k.c("(f) cmp.ge r13, #-INSIDE_TOL")
                .c("(f) cmp.ge r14, #-INSIDE_TOL")
                .c("(f) cmp.le r13, r11")
                .c("(f) cmp.le r14, r11")
                .note("F: inside the rectangle");
        }
        Inside::Disc => {
            k.c("mul out, r13, r13")
                .c("mac r13, r14, r14, >>Q14")
                .c("(f) cmp.le r13, r11")
                .note("F: inside the disc");
        }
    }
}

/// The commit of a two-sided kernel where F (`t` in r15): the streamed
/// normal turned where the back was hit (`TMP4`), the object, and
/// `HIT_BACK_OBJ` (the object on the back, else -1). Keeps r8..r10.
fn commit_two(k: &mut K) {
    k.c(format!("ld r11, [r0 + #{}]", ram::TMP4))
        .c("movb r13, #1")
        .c("sub r13, r13, r11")
        .c("sub r13, r13, r11")
        .note("1 - 2 back")
        .c("(f) mov r7, r15");
    for i in 0..3 {
        k.c("mul r14, fb0, r13")
            .c(format!("(f) st r14, [#{}]", ram::HIT_N + i));
    }
    k.c("mov r14, fb0")
        .c(format!("(f) st r14, [#{}]", ram::HIT_OBJ))
        .c("neg r11, r11")
        .c("add r13, r14, #1")
        .c("and r13, r13, r11")
        .c("sub r13, r13, #1")
        .c(format!("(f) st r13, [#{}]", ram::HIT_BACK_OBJ))
        .c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
}
