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
use super::planar::{self, Planar};
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
pub const NORMAL_AGAIN: Field = Field::part("n.xyz'", "the normal again, for the hit");
pub const OBJ: Field = Field::part("obj", "the object's id");
pub const MAT: Field = Field::part("mat", "its material");
pub const CENTRE_AGAIN: Field = Field::part(
    "pc",
    "the centroid and its remainder again, per axis (the hit point)",
);

/// The record.
pub fn layout() -> Layout {
    Layout::new([
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

/// A triangle's frame: its centroid and extent about it (LSB), its
/// exponent `e` and its edge duals' largest component per LSB of the
/// frame (for `KT_LOCAL`), `s` LSB per scene unit.
fn frame(v: &[Vec3; 3], p: &Planar, s: f64) -> ((Vec3, f64), u32, f64) {
    let c = (v[0] + v[1] + v[2]) * (1.0 / 3.0);
    let r = v.iter().map(|x| (*x - c).length()).fold(0.0, f64::max) * s;
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

/// `KT_LOCAL` for the scene's flat triangles `tris` (vertices, record
/// geometry), `s` LSB per scene unit: the largest shift that keeps every
/// scaled dual in the word.
pub fn fit_kt(tris: impl Iterator<Item = ([Vec3; 3], Planar)>, s: f64, f: &Fitter) -> u32 {
    let m = tris
        .map(|(v, p)| frame(&v, &p, s).2 * 16384.0)
        .fold(0.0, f64::max);
    f.shift(m, 20)
}

/// Write the local record of the flat triangle `v` (record geometry `p`).
pub(crate) fn write(w: &mut W, kt: u32, v: &[Vec3; 3], p: &Planar, id: usize, mat: usize) {
    let ((c, r), e, _) = frame(v, p, w.s);
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

/// The kernel (one side; cuts [`CUTS`]).
pub fn kernel(g: &super::Gen) -> K {
    let mut k = K::new();
    k.doc(
        "k_triangle: the triangle test of one local record (the stream), for every awake ray.\n\
         In: r1..r7 the rays, RAY_OL, RAY_DL. Out where F (a nearer hit): r7 = t, HIT_N, HIT_OBJ, HIT_MAT,\n\
         HIT_TL = t, HIT_PH and HIT_PL the hit point. b = round((c - o).d), p = ((c - o) - b d) 2^e,\n\
         s = n.p / n.d, g = p - s d, u = uc + g.au, w = wc + g.aw, t = b + s 2^-e, P = c - g 2^-e",
    );
    sphere::enter_frame(&mut k, ["c", "centroid", "cl"], CUTS[0].0);
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
    divide(&mut k, 12, 15, 12, [8, 9, 10, 13, 14], g.approx);
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
    remainder(&mut k, 12, 15, 13, "Q14");
    k.note("its remainder, 2^-14 LSB")
        .c(format!("st r14, [#{}]", ram::TMP3));
    k.comment("u = uc + g.au, w = wc + g.aw (Q1.14)");
    for x in [13, 14] {
        k.c("ldacc fb0, <<KT_LOCAL")
            .c("mac out, fb0, r8")
            .c("mac out, fb0, r9")
            .c(format!("mac r{x}, fb0, r10, >>KT_LOCAL"));
    }
    k.c(format!("ld r11, [r0 + #{}]", ram::C_ONE))
        .c("add r11, r11, #INSIDE_TOL")
        .c("(f) cmp.ge r13, #-INSIDE_TOL")
        .c("(f) cmp.ge r14, #-INSIDE_TOL")
        .c("adds r13, r13, r14")
        .c("(f) cmp.le r13, r11")
        .note("F: inside the triangle");
    k.cut(planar::CUTS[1].0);
    positions::nearer(&mut k, 15, 12, 11, 13);
    super::commit_streamed_normal(&mut k, 15);
    k.comment("the hit point c - g 2^-e, to 2^-14 LSB");
    k.c(format!("ld r14, [r0 + #{}]", ram::TMP3));
    for (i, v) in [8, 9, 10].into_iter().enumerate() {
        positions::hit_point_axis(&mut k, i as u32, "msu", v, None, 14, [11, 12, 13]);
    }
    k
}
