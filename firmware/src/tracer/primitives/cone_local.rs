//! The open cone in a frame of its own (local positions,
//! [`super::Fit::cone_local`]: seen from one side, records without caps;
//! the scene format's kernel, [`super::cone`], in the frame).
//!
//! **Record** (47 words): `M.xyz, Rn, sh, ml.xyz, invS, (ce1, ce2, a) twice,
//! s, g, sg, R, nsc, hh, -sg c, -sg s, (e1, e2, a) x, (e1, e2, a) y,
//! (e1, e2, a) z, obj, mat`. `M` is the axis'
//! midpoint rounded to the scene's LSB and `ml` its remainder (2^-14
//! LSB); the frame's LSB is `2^-e` of the scene's, `e` fitted to the
//! cone's extent `sqrt((h/2)^2 + max(rb, ra)^2)` about `M`
//! ([`crate::scene_image::local_exponent`]); `sh` is `e + 2, 14 - e`,
//! `nsc` is `2^(14-e)`; `R` the bounding radius in the frame (the
//! extent plus 3 LSB of the scene's format),
//! `S = 2 R`, `invS = 2^(14+KS_CONEL) / S`; the rest the scene format's
//! record ([`super::cone::ConeFit`]) in the frame.
//!
//! **Method**: `b = round((M - o).d)` in the scene's LSB, the cut
//! `sphere` where the line passes outside `Rn` ([`positions::near`]),
//! `p = (M - o) - b d` in the frame, exactly
//! ([`positions::offset_in_frame`]); `w = p / S` and the scene format's
//! kernel from there (the bounding sphere, the quadratic, its root `tau`,
//! the height, the normal);
//! `s = S tau` in the frame, `t = b + s 2^-e` with its remainder,
//! compared as the local sphere's ([`positions::nearer`]); the hit point
//! `o + t d` to 2^-14 LSB (the origin, the direction and `t` with their
//! remainders: `M - p + s d` but for roundings at 2^-14 LSB).
//!
//! **Registers**: r1..r7 the ray (r7 the new `tbest` where F); r8..r15
//! temporaries; RAM `TMP0..TMP4`, `CONE_TMP`.

use super::super::emit::K;
use super::super::math::remainder;
use super::super::memory_map::ram;
use super::super::positions;
use super::cone::{self, ConeFit, CUTS};
use super::record::{Field, Fitter, Layout, W};
use super::{commit_obj_mat, sphere, Body, Gen};
use crate::scene::Vec3;

pub const MID: Field = Field::part("M.xyz", "the axis' midpoint, rounded");
pub const SHIFTS: Field = Field::part("sh", "e + 2 and 14 - e, the frame's shifts");
pub const MID_REM: Field = Field::part("ml.xyz", "the midpoint's remainder, 2^-14 LSB");
pub const INV_S: Field = Field::part("invS", "2^(14+KS_CONEL) / S, S in the frame");
pub const FRAME: Field = Field::part(
    "(ce1, ce2, a) x2",
    "c e1, c e2 and the axis, for w and for d",
);
pub const SLOPE: Field = Field::part(
    "s, g, sg",
    "the half-angle's sine, c rho at M / S, the side",
);
pub const RADIUS: Field = Field::part("R", "the bounding radius in the frame, S / 2");
pub const SCALE: Field = Field::part("nsc", "2^(14-e), a length of the frame in 2^-14 LSB");
pub const HALF: Field = Field::part("hh", "half the height (plus 1) over S");
pub const GRADIENT: Field = Field::part("-sg c, -sg s", "the gradient's scales");
pub const AXES: Field = Field::part("(e1, e2, a) xyz", "the frame per axis, for the normal");
pub const OBJ: Field = Field::part("obj", "the object's id");
pub const MAT: Field = Field::part("mat", "its material");

/// The record (its body from its start: `CONE_BODY`, which the broadcast
/// names, is 0).
pub fn layout() -> Layout {
    Layout::new([
        (cone::CONE_BODY, 0),
        (MID, 3),
        (sphere::NEAR, 1),
        (SHIFTS, 2),
        (MID_REM, 3),
        (INV_S, 1),
        (FRAME, 18),
        (SLOPE, 3),
        (RADIUS, 1),
        (SCALE, 1),
        (HALF, 1),
        (GRADIENT, 2),
        (AXES, 9),
        (OBJ, 1),
        (MAT, 1),
    ])
}

/// The extent of the cone from `base` (radius `rb`) to `apex` (radius
/// `ra`) about its axis' midpoint, scene units: what
/// [`crate::scene_image::local_frame`] fits the frame to.
pub fn extent(base: Vec3, rb: f64, apex: Vec3, ra: f64) -> f64 {
    let h2 = (apex - base).length() * 0.5;
    (h2 * h2 + rb.abs().max(ra.abs()).powi(2)).sqrt()
}

/// A cone's frame, `s` LSB per scene unit: its midpoint, its exponent
/// and its fit in the frame.
fn frame(base: Vec3, rb: f64, apex: Vec3, ra: f64, s: f64) -> (Vec3, u32, ConeFit) {
    let e = sphere::local_exponent(extent(base, rb, apex, ra) * s);
    // The margin: 3 LSB of the scene's format, as the frame's exponent
    // allows for (the rounding of the ray's point nearest M and of its
    // direction's length).
    let f = (e as f64).exp2();
    let cf = ConeFit::with_margin(base, rb, apex, ra, s * f, 3.0 * f);
    ((base + apex) * 0.5, e, cf)
}

/// `KS_CONEL` for the scene's cones (base, base radius, apex, apex
/// radius), `s` LSB per scene unit: fitted to the smallest `S` in its
/// frame.
pub fn fit_ks(cones: impl Iterator<Item = (Vec3, f64, Vec3, f64)>, s: f64, f: &Fitter) -> u32 {
    f.ks(cones
        .map(|(b, rb, a, ra)| frame(b, rb, a, ra, s).2.big_s)
        .fold(f64::INFINITY, f64::min))
}

/// Write the local record of the cone from `base` (radius `rb`) to
/// `apex` (radius `ra`), `inside`: seen from inside; `ks`: `KS_CONEL`. An
/// error where `invS` would hold too few bits (a cone far larger in its
/// frame than the scene's smallest).
#[allow(clippy::too_many_arguments)]
pub(crate) fn write(
    w: &mut W,
    ks: u32,
    (base, rb): (Vec3, f64),
    (apex, ra): (Vec3, f64),
    inside: bool,
    id: usize,
    mat: usize,
) -> Result<(), String> {
    let (m, e, cf) = frame(base, rb, apex, ra, w.s);
    let inv_s = ((14 + ks) as f64).exp2() / cf.big_s;
    if inv_s < 256.0 {
        return Err(format!(
            "cone too large in its frame for the chip's cone kernel next to the scene's smallest (S = {:.0} LSB of its frame)",
            cf.big_s
        ));
    }
    let one = w.one();
    let sg = if inside { -1.0 } else { 1.0 };
    let ext = extent(base, rb, apex, ra) * w.s;
    sphere::write_frame(w, [MID, SHIFTS, MID_REM], (m, ext), e);
    w.field(INV_S);
    w.push(inv_s);
    w.field(FRAME);
    for _ in 0..2 {
        w.scaled(cf.e1, one * cf.c);
        w.scaled(cf.e2, one * cf.c);
        w.unit(cf.a);
    }
    w.field(SLOPE);
    w.push(one * cf.s);
    w.push(one * cf.g);
    w.push(one * sg);
    w.field(RADIUS);
    w.raw(cf.r as i64);
    w.field(SCALE);
    w.push((14.0 - e as f64).exp2());
    w.field(HALF);
    w.push(one * cf.hh);
    w.field(GRADIENT);
    w.push(one * -sg * cf.c);
    w.push(one * -sg * cf.s);
    w.field(AXES);
    for c in 0..3 {
        w.push(one * cf.e1.axis(c));
        w.push(one * cf.e2.axis(c));
        w.push(one * cf.a.axis(c));
    }
    w.field(OBJ);
    w.raw(id as i64);
    w.field(MAT);
    w.raw(mat as i64);
    Ok(())
}

/// The kernel (one side, no caps; the cuts of the scene format's opaque
/// cone, [`CUTS`]).
pub fn kernel(g: &Gen) -> K {
    let nr = g.approx;
    let mut k = K::new();
    k.doc(
        "k_cone: the open cone test of one local record (the stream), for every awake ray.\n\
         In: r1..r7 the rays, RAY_OL, RAY_DL. Out where F (a nearer hit): r7 = t, HIT_N, HIT_OBJ, HIT_MAT,\n\
         HIT_TL = t, HIT_PH and HIT_PL the hit point. b = round((M - o).d), p = ((M - o) - b d) 2^e,\n\
         w = p / S; the scene format's cone test on w: tau; s = S tau, t = b + s 2^-e,\n\
         P = o + t d (with the remainders of o, t and d)",
    );
    sphere::enter_frame(&mut k, ["M", "midpoint", "ml"], CUTS[0].0);
    cone::meets_bound(&mut k, "KS_CONEL");
    k.c(format!("st r11, [#{}]", ram::TMP0)).note("b");
    cone::frame(&mut k);
    cone::quadratic(&mut k, nr, Some(CUTS[1].0));
    cone::root_tau(&mut k, g);
    k.comment("s = S tau in the frame, t = b + s 2^-e and its remainder");
    k.c(format!("ld r11, [r0 + #{}]", ram::TMP0))
        .c("mul r9, fb0, r13, >>Q13")
        .note("s = 2 R tau")
        .c("mov r14, fb0")
        .note("2^(14-e)")
        .c("ldacc r11, <<Q14")
        .c("mac r11, r14, r9, >>Q14")
        .note("t");
    remainder(&mut k, 15, 11, 8, "Q14");
    k.note("its remainder, 2^-14 LSB")
        .c(format!("st r11, [#{}]", ram::TMP4))
        .c("(f) cmp.ge r11, #0")
        .c("(f) cmp.le r11, r7")
        .note("F: ahead, not beyond tbest");
    k.cut(CUTS[2].0);
    cone::height(&mut k);
    positions::nearer(&mut k, 11, 15, 12, 14);
    cone::normal(&mut k, nr);
    commit_obj_mat(&mut k, Body::Opaque);
    hit_point(&mut k);
    k
}

/// Where F (after [`positions::nearer`]): the hit point `o + t d` to
/// 2^-14 LSB from the origin and direction with their remainders
/// (`RAY_OL`, `RAY_DL`) and `t` with its (`HIT_TL`, `HIT_TLL`), into
/// `HIT_PH`, `HIT_PL`. Clobbers r8..r15.
fn hit_point(k: &mut K) {
    k.comment("the hit point o + t d, to 2^-14 LSB (t and d with their remainders)");
    k.c(format!("ld r11, [r0 + #{}]", ram::HIT_TL))
        .c(format!("ld r15, [r0 + #{}]", ram::HIT_TLL));
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        let i = i as u32;
        k.c(format!("ld r12, [r0 + #{}]", ram::RAY_OL + i))
            .c(format!("ld r13, [r0 + #{}]", ram::RAY_DL + i))
            .c("mul r13, r11, r13, >>Q13")
            .note("t dl")
            .c(format!("mul r14, r15, r{d}, >>Q14"))
            .note("tl d")
            .c(format!("ldacc r{o}, <<Q14"))
            .c("mac out, r12, #1")
            .c("mac out, r13, #1")
            .c("mac out, r14, #1")
            .c(format!("mac r9, r11, r{d}, >>Q14"))
            .note("P");
        remainder(k, 10, 9, 8, "Q14");
        k.note("its remainder")
            .c(format!("(f) st r9, [#{}]", ram::HIT_PH + i))
            .c(format!("(f) st r10, [#{}]", ram::HIT_PL + i));
    }
}
