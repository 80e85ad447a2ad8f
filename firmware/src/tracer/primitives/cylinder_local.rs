//! The open cylinder in a frame of its own (local positions,
//! [`super::Fit::cyl_local`]: seen from one side, records without caps;
//! `scene/shape/cone.rs` with equal radii).
//!
//! **Record** (43 words): `M.xyz, Rn, sh, ml.xyz, e1.xyz, e2.xyz, invr, r,
//! sg, nsc, a.xyz, hh, sg, (e1, e2) x, (e1, e2) y, (e1, e2) z, obj, mat,
//! sg r, e, (-a, M, ml) per axis`. `M` is the axis' midpoint rounded to the scene's
//! LSB and `ml` its remainder (2^-14 LSB); the frame's LSB is `2^-e` of
//! the scene's, `e` fitted to the cylinder's extent `R = sqrt((H/2)^2 +
//! r^2)` about `M` ([`crate::scene_image::local_exponent`]); `sh` is `e +
//! 2, 14 - e`, `nsc` is `2^(14-e)`; `Rn` the bound of the first cut
//! ([`positions::near`]); `e1, e2, a` an orthonormal frame, `a` along the axis;
//! `r` the radius and `invr = 2^(14+KS_CYLL) / r` in the frame; `hh` half
//! the height in the frame, plus 2.
//!
//! **Method**: `b = round((M - o).d)` in the scene's LSB, the cut `near`
//! where the line passes outside `Rn` ([`positions::near`]), and `p =
//! (M - o) - b d` in the frame, exactly ([`positions::offset_in_frame`]).
//! Across the axis the method of the scene
//! format's kernel: `d2 = (d.e1, d.e2)` normalised (`|d2|` kept), `p2 =
//! (p.e1, p.e2)`, `b2 = p2.d2n`, `q2 = p2 - b2 d2n` made perpendicular to
//! `d2n`, `s2 = 1 - |q2 / r|^2`, `tau = b2 - sg r sqrt(s2)` and `s = tau /
//! |d2|` (F only where `|s| < 2^15`); `t = b + s 2^-e` with its
//! remainder, compared as the local sphere's ([`positions::nearer`]);
//! `g = p - s d` (the midpoint seen from the hit) and the height test
//! `|g.a| <= hh`; the normal `n2 = -(sg q2 / r + sqrt(s2) d2n)` across the
//! axis, `n = n2.x e1 + n2.y e2`; the hit point `M + (z a + sg r n) 2^-e`
//! to 2^-14 LSB (`HIT_PH`, `HIT_PL`; `z = -g.a` the axial coordinate: on
//! the cylinder to the normal's precision, the division's error along
//! its surface).
//!
//! **Registers**: r1..r7 the ray (r7 the new `tbest` where F); r8..r15
//! temporaries; RAM `TMP0..TMP8`.

use super::super::emit::K;
use super::super::math::{divide, normalize, perpendicular_to, remainder, sqrt_q14};
use super::super::memory_map::ram;
use super::super::positions;
use super::cylinder::CUTS;
use super::record::{Field, Fitter, Layout, W};
use super::{perpendicular, sphere};
use crate::scene::Vec3;

pub const MID: Field = Field::part("M.xyz", "the axis' midpoint, rounded");
pub const SHIFTS: Field = Field::part("sh", "e + 2 and 14 - e, the frame's shifts");
pub const MID_REM: Field = Field::part("ml.xyz", "the midpoint's remainder, 2^-14 LSB");
pub const ACROSS: Field = Field::part("e1.xyz, e2.xyz", "the unit vectors across the axis");
pub const INV_R: Field = Field::part("invr", "2^(14+KS_CYLL) / r, r in the frame");
pub const RADIUS: Field = Field::part("r", "the radius in the frame");
pub const SIGN: Field = Field::part("sg", "+1 seen from outside, -1 inside-visible");
pub const SCALE: Field = Field::part("nsc", "2^(14-e), a length of the frame in 2^-14 LSB");
pub const AXIS: Field = Field::part("a.xyz", "the unit axis");
pub const HALF: Field = Field::part("hh", "half the height in the frame, plus 2");
pub const SIGN_AGAIN: Field = Field::part("sg'", "the sign again, for the normal");
pub const ACROSS_AXES: Field = Field::part("(e1, e2) xyz", "e1 and e2 per axis, for the normal");
pub const OBJ: Field = Field::part("obj", "the object's id");
pub const MAT: Field = Field::part("mat", "its material");
pub const RADIUS_SG: Field = Field::part("rs", "sg r, in the frame (the hit point)");
pub const EXPONENT: Field = Field::part("e", "the frame's exponent (the hit point)");
pub const MID_AGAIN: Field = Field::part(
    "pc",
    "per axis -a, the midpoint and its remainder again (the hit point)",
);

/// The record (its body from its start: `CYL_BODY`, which the
/// broadcast names, is 0).
pub fn layout() -> Layout {
    Layout::new([
        (super::cylinder::CYL_BODY, 0),
        (MID, 3),
        (sphere::NEAR, 1),
        (SHIFTS, 2),
        (MID_REM, 3),
        (ACROSS, 6),
        (INV_R, 1),
        (RADIUS, 1),
        (SIGN, 1),
        (SCALE, 1),
        (AXIS, 3),
        (HALF, 1),
        (SIGN_AGAIN, 1),
        (ACROSS_AXES, 6),
        (OBJ, 1),
        (MAT, 1),
        (RADIUS_SG, 1),
        (EXPONENT, 1),
        (MID_AGAIN, 9),
    ])
}

/// A cylinder's frame from `base` to `apex` of radius `r` (scene units),
/// `s` LSB per scene unit: its midpoint, its exponent and its radius in
/// the frame.
fn frame(base: Vec3, apex: Vec3, r: f64, s: f64) -> (Vec3, u32, f64) {
    let m = (base + apex) * 0.5;
    let h2 = (apex - base).length() * 0.5;
    let ext = (h2 * h2 + r * r).sqrt() * s;
    let e = sphere::local_exponent(ext);
    (m, e, r.abs() * s * (e as f64).exp2())
}

/// `KS_CYLL` for the scene's cylinders (base, apex, radius), `s` LSB per
/// scene unit: fitted to the smallest radius in its frame.
pub fn fit_ks(cyls: impl Iterator<Item = (Vec3, Vec3, f64)>, s: f64, f: &Fitter) -> u32 {
    f.ks(cyls
        .map(|(b, a, r)| frame(b, a, r, s).2)
        .fold(f64::INFINITY, f64::min))
}

/// Write the local record of the cylinder from `base` to `apex` of radius
/// `radius` (`inside`: seen from inside); `ks`: `KS_CYLL`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn write(
    w: &mut W,
    ks: u32,
    base: Vec3,
    apex: Vec3,
    radius: f64,
    inside: bool,
    id: usize,
    mat: usize,
) {
    let (m, e, rf) = frame(base, apex, radius, w.s);
    let per = w.s * (e as f64).exp2();
    let axis = apex - base;
    let a = axis.normalized();
    let e1 = perpendicular(a);
    let e2 = a.cross(e1);
    let ext = ((axis.length() * 0.5).powi(2) + radius * radius).sqrt() * w.s;
    let sg = if inside { -w.one() } else { w.one() };
    let parts = sphere::write_frame(w, [MID, SHIFTS, MID_REM], (m, ext), e);
    w.field(ACROSS);
    w.unit(e1);
    w.unit(e2);
    w.field(INV_R);
    w.push((14.0 + ks as f64).exp2() / rf);
    w.field(RADIUS);
    w.push(rf);
    w.field(SIGN);
    w.push(sg);
    w.field(SCALE);
    w.push((14.0 - e as f64).exp2());
    w.field(AXIS);
    w.unit(a);
    w.field(HALF);
    w.push(axis.length() * 0.5 * per + 2.0);
    w.field(SIGN_AGAIN);
    w.push(sg);
    w.field(ACROSS_AXES);
    for c in 0..3 {
        w.unit_axis(e1.axis(c));
        w.unit_axis(e2.axis(c));
    }
    w.field(OBJ);
    w.raw(id as i64);
    w.field(MAT);
    w.raw(mat as i64);
    w.field(RADIUS_SG);
    w.push(if inside { -rf } else { rf });
    w.field(EXPONENT);
    w.raw(e as i64);
    w.field(MID_AGAIN);
    for (c, (hi, rem)) in parts.into_iter().enumerate() {
        w.unit_axis(-a.axis(c));
        w.push(hi);
        w.push(rem);
    }
}

/// The kernel (one side, no caps; the cuts of the scene format's opaque
/// cylinder, [`CUTS`]).
pub fn kernel(g: &super::Gen) -> K {
    let nr = g.approx;
    let mut k = K::new();
    k.doc(
        "k_cylinder: the open cylinder test of one local record (the stream), for every awake ray.\n\
         In: r1..r7 the rays, RAY_OL, RAY_DL. Out where F (a nearer hit): r7 = t, HIT_N, HIT_OBJ, HIT_MAT,\n\
         HIT_TL = t, HIT_PH and HIT_PL the hit point. b = round((M - o).d), p = ((M - o) - b d) 2^e;\n\
         across the axis d2n = d2 / |d2|, q2 = p2 - (p2.d2n) d2n, s2 = 1 - |q2/r|^2, tau = p2.d2n - sg r sqrt(s2),\n\
         s = tau / |d2|, t = b + s 2^-e, g = p - s d, |g.a| <= hh, P = M + (-(g.a) a + sg r n) 2^-e",
    );
    sphere::enter_frame(&mut k, ["M", "midpoint", "ml"], CUTS[0].0);
    for (i, x) in [8, 9, 10].into_iter().enumerate() {
        k.c(format!("st r{x}, [#{}]", ram::TMP0 + i as u32));
    }
    k.c(format!("st r11, [#{}]", ram::TMP7));
    k.note("p in TMP0..2, b in TMP7");
    across(&mut k, nr);
    sqrt_q14(&mut k, 15, 8, [9, 11, 12, 14], nr);
    k.c(format!("st r8, [#{}]", ram::TMP8))
        .c("mul r9, fb0, r8, >>Q14")
        .note("h = r sqrt(s2)")
        .c("mov r11, fb0")
        .note("sg")
        .c("mul r9, r9, r11, >>Q14")
        .c("sub r9, r13, r9")
        .note("tau = b2 - sg h")
        .c("sra r15, r9, #15")
        .note("its sign, 0 or -1")
        .c("abs r9, r9")
        .c("adds r14, r10, r10")
        .c("(f) cmp.lt r9, r14")
        .note("F: |s| < 2^15");
    divide(&mut k, 9, 10, 9, [8, 11, 12, 13, 14], nr);
    k.c("xor r9, r9, r15")
        .c("sub r9, r9, r15")
        .note("s = tau / |d2|, signed");
    k.c(format!("ld r11, [r0 + #{}]", ram::TMP7))
        .c("mov r14, fb0")
        .note("2^(14-e)")
        .c("ldacc r11, <<Q14")
        .c("mac r12, r14, r9, >>Q14")
        .note("t = b + s 2^-e");
    remainder(&mut k, 13, 12, 15, "Q14");
    k.note("its remainder, 2^-14 LSB")
        .c("(f) cmp.ge r12, #0")
        .c("(f) cmp.le r12, r7")
        .note("F: ahead, not beyond tbest");
    k.cut(CUTS[2].0);
    k.comment("g = p - s d, the midpoint seen from the hit; the height");
    for (i, (x, d)) in [(8, 4), (10, 5), (11, 6)].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::TMP0 + i as u32))
            .c(format!("ldacc r{x}, <<Q14"))
            .c(format!("msu r{x}, r9, r{d}, >>Q14"));
    }
    k.c("mul out, fb0, r8")
        .c("mac out, fb0, r10")
        .c("mac r15, fb0, r11, >>Q14")
        .note("g.a")
        .c("mov r9, fb0")
        .note("hh")
        .c("(f) cmp.le r15, r9")
        .c("neg r9, r9")
        .c("(f) cmp.ge r15, r9")
        .note("F: within the height");
    k.cut(CUTS[3].0);
    k.c(format!("st r15, [#{}]", ram::TMP0))
        .note("g.a, minus the hit's axial coordinate");
    positions::nearer(&mut k, 12, 13, 9, 15);
    k.c("(f) mov r7, r12");
    normal(&mut k);
    k.comment("the hit point M + (z a + sg r n) 2^-e, to 2^-14 LSB (z = -g.a)");
    k.c(format!("ld r8, [r0 + #{}]", ram::TMP0))
        .c("mov r15, fb0")
        .note("sg r")
        .c("mov r10, fb0")
        .note("e");
    for i in 0..3 {
        k.c(format!("ld r9, [r0 + #{}]", ram::HIT_N + i))
            .c("mul out, fb0, r8")
            .c("mac r11, r15, r9, >>Q14")
            .note("v = z a + sg r n, in the frame");
        remainder(&mut k, 12, 11, 9, "Q14");
        k.c("sra r12, r12, r10").note("its remainder, in 2^-14 LSB");
        positions::hit_point_axis(&mut k, i, "mac", 11, Some(12), 14, [9, 13, 12]);
    }
    k
}

/// Across the axis, from `p` (r8..r10): `p2` and `d2` (the stream's `e1`,
/// `e2`), `d2` normalised (`d2n` in TMP5, TMP6, `|d2|` in r10), `b2 =
/// p2.d2n` (r13, with what the perpendicular left along `d2n`), `q2/r`
/// (TMP3, TMP4) and `s2 = 1 - |q2/r|^2` (r15); F kept where `s2 > 0` and
/// `|d2| > 0`, the cut `line`.
fn across(k: &mut K, nr: super::super::math::Approx) {
    k.comment("across the axis: p2 = (p.e1, p.e2), d2 = (d.e1, d.e2)");
    k.c("mov r13, fb0").c("mov r14, fb0").c("mov r15, fb0");
    k.c("mul out, r13, r8")
        .c("mac out, r14, r9")
        .c("mac r11, r15, r10, >>Q14")
        .c("mul out, r13, r4")
        .c("mac out, r14, r5")
        .c("mac r12, r15, r6, >>Q14")
        .c(format!("st r11, [#{}]", ram::TMP3));
    k.c("mov r13, fb0").c("mov r14, fb0").c("mov r15, fb0");
    k.c("mul out, r13, r8")
        .c("mac out, r14, r9")
        .c("mac r10, r15, r10, >>Q14")
        .c("mul out, r13, r4")
        .c("mac out, r14, r5")
        .c("mac r9, r15, r6, >>Q14")
        .c(format!("st r10, [#{}]", ram::TMP4))
        .c("mov r8, r12");
    normalize(k, &[8, 9], [10, 11, 12, 13, 14], true, nr);
    k.note("|d2| in r10, Q.14")
        .c(format!("st r8, [#{}]", ram::TMP5))
        .c(format!("st r9, [#{}]", ram::TMP6))
        .note("d2n")
        .c(format!("ld r11, [r0 + #{}]", ram::TMP3))
        .c(format!("ld r12, [r0 + #{}]", ram::TMP4))
        .c("mul out, r11, r8")
        .c("mac r13, r12, r9, >>Q14")
        .note("b2 = p2.d2n");
    for (x, d) in [(11, 8), (12, 9)] {
        k.c(format!("ldacc r{x}, <<Q14"))
            .c(format!("msu r{x}, r13, r{d}, >>Q14"));
    }
    perpendicular_to(k, &[11, 12], &[8, 9], 14);
    k.c("add r13, r13, r14")
        .note("q2 = p2 - b2 d2n, b2 with what q2 had along d2n")
        .c("mov r14, fb0")
        .note("invr")
        .c("mul r11, r11, r14, >>KS_CYLL")
        .c("mul r12, r12, r14, >>KS_CYLL")
        .c(format!("st r11, [#{}]", ram::TMP3))
        .c(format!("st r12, [#{}]", ram::TMP4))
        .note("q2/r")
        .c(format!("ld r14, [r0 + #{}]", ram::C_ONE))
        .c("ldacc r14, <<Q14")
        .c("msu out, r11, r11")
        .c("msu r15, r12, r12, >>Q14")
        .note("s2 = 1 - |q2/r|^2")
        .c("(f) cmp.gt r15, #0")
        .c("(f) cmp.gt r10, #0");
    k.cut(CUTS[1].0);
}

/// The normal `n2 = -(sg q2/r + sqrt(s2) d2n)` across the axis (TMP3..6,
/// TMP8, the stream's `sg`), `n = n2.x e1 + n2.y e2` (the stream's `(e1,
/// e2)` per axis) into `HIT_N`, and `HIT_OBJ`, `HIT_MAT`, where F.
/// Clobbers r8..r13, r15.
fn normal(k: &mut K) {
    k.comment("normal: n2 = -(sg q2/r + sqrt(s2) d2n), n = n2.x e1 + n2.y e2");
    k.c("mov r15, fb0")
        .note("sg")
        .c(format!("ld r8, [r0 + #{}]", ram::TMP8));
    for (x, pn, dn) in [(11, ram::TMP3, ram::TMP5), (12, ram::TMP4, ram::TMP6)] {
        k.c(format!("ld r{x}, [r0 + #{pn}]"))
            .c(format!("ld r13, [r0 + #{dn}]"))
            .c("mul out, r8, r13")
            .c(format!("mac r{x}, r15, r{x}, >>Q14"))
            .c(format!("neg r{x}, r{x}"));
    }
    for x in [9, 10, 13] {
        k.c("mul out, fb0, r11")
            .c(format!("mac r{x}, fb0, r12, >>Q14"));
    }
    for (i, x) in [9, 10, 13].into_iter().enumerate() {
        k.c(format!("(f) st r{x}, [#{}]", ram::HIT_N + i as u32));
    }
    k.c(format!("(f) st fb0, [#{}]", ram::HIT_OBJ))
        .c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
}
