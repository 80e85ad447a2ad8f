//! Sphere (`scene/shape/sphere.rs`).
//!
//! **Record** (8 words): `c.xyz, invr, r, sg, obj, mat`, with `invr =
//! 2^(14+KS_SPHERE) / r` (scene LSBs) and `sg` = +1 (Q1.14) for a sphere
//! seen from outside, -1 for NFF's inside-visible sphere. Fine records
//! (11 words, where the smallest sphere is under [`FINE_BELOW_LSB`] LSB in
//! radius): `c.xyz, cl.xyz, invr, r, sg, obj, mat`, with the centre's
//! rounding remainder `cl` in units of 2^-14 LSB and `r` with `EP_SPHERE`
//! extra fraction bits: spheres a few LSB across, whose rounded centre
//! and radius would move their silhouettes and shadows by a sizeable part
//! of their size.
//!
//! **Method** (perpendicular, no hit point needed for the normal):
//! `b = (c - o).d`, `p = (c - o) - b d` kept with `EP_SPHERE` extra
//! fraction bits (it saturates only beyond twice the largest radius, which
//! is a miss); only `p / r` is squared: `s = 1 - |p / r|^2`,
//! `t = b - sg r sqrt(s)`, `n = -(sg p / r + sqrt(s) d)`. With a fine
//! record, `p` is formed in the accumulator from the unrounded centre:
//! `p = (c - o) + cl - b d` to 2^-EP_SPHERE LSB. With fine normals `p` is
//! then made perpendicular to `d` ([`perpendicular_to`], which also takes
//! out what `b`'s rounding left along `d`); with a fine record and coarse
//! normals `b`'s remainder below an LSB is read back with `accl` and taken
//! out along `d` instead.
//!
//! **Two-sided** (a transmitting sphere, [`Sides::Both`]): where the near
//! root is not ahead of the ray by more than `SELF_LSB` the far root, the
//! normal turned to the ray; a far-side hit records the object in
//! `HIT_BACK_OBJ`. With local positions the same in the sphere's frame
//! ([`kernel_local`]).
//!
//! **Registers**: r1..r7 the ray (kept but r7, which becomes the new
//! `tbest` where F); r8..r15 temporaries; RAM `TMP0..TMP3`.
//!
//! **Error** against the f64 sphere: its `error_bound` (below), which
//! `tb/tests/kernels.rs` holds both chips to; a sphere 6 LSB in radius
//! with a fine record within 2 LSB and 0.1.

use super::super::emit::{define, Code, K};
use super::super::math::{perpendicular_to, remainder, sqrt_q14};
use super::super::memory_map::ram;
use super::super::positions;
use super::record::{Field, Fitter, Layout, W};
use super::{
    self_margin, CutTest, ErrorBound, Fit, Gen, Geometry, Object, RecordError, Sides, TestCost,
};
use crate::scene::{Scene, Vec3};

/// The record's fields (the fine record has the centre's remainder).
pub const CENTRE: Field = Field::part("c.xyz", "the centre");
pub const CENTRE_REM: Field = Field::part("cl.xyz", "the centre's rounding remainder, 2^-14 LSB");
pub const INV_R: Field = Field::part("invr", "2^(14+KS_SPHERE) / r");
pub const RADIUS: Field = Field::part("r", "the radius (fine: EP_SPHERE extra bits)");
pub const SIGN: Field = Field::part("sg", "+1 seen from outside, -1 inside-visible");
pub const OBJ: Field = Field::part("obj", "the object's id");
pub const MAT: Field = Field::part("mat", "its material");
/// Local positions ([`crate::tracer::Positions::Local`]): the record's
/// frame, its LSB `2^-e` of the scene's ([`local_exponent`]).
pub const SHIFTS: Field = Field::part("sh", "local: e + 2 and 14 - e, the frame's shifts");
/// A local record's bound on the ray's line about its centre
/// ([`positions::near`]).
pub const NEAR: Field = Field::part(
    "R",
    "local: the shape's extent about the centre plus the roundings, LSB",
);
pub const SCALE: Field = Field::part("n", "local: 2^(14-e), a local length in 2^-14 LSB");
pub const RADIUS_SG: Field = Field::part("rs", "local: sg r");
pub const CENTRE_AGAIN: Field = Field::part(
    "pc",
    "local: the centre and its remainder again, per axis (the hit point)",
);

/// The exponent `e` of a sphere's local frame (its LSB `2^-e` of the
/// scene's) for its radius `r` in LSB
/// ([`crate::scene_image::local_exponent`]: the vector from the centre
/// to the ray's point at the rounded `b` fits with a guard bit; the scene
/// compiler refuses a sphere too large for a frame).
pub fn local_exponent(r: f64) -> u32 {
    crate::scene_image::local_exponent(r).unwrap_or(0)
}

/// The record of `fit`'s spheres (seen from either side: a transmitting
/// sphere's is the opaque one's).
pub fn layout(fit: &Fit) -> Layout {
    if fit.local {
        return Layout::new([
            (CENTRE, 3),
            (NEAR, 1),
            (SHIFTS, 2),
            (CENTRE_REM, 3),
            (INV_R, 1),
            (RADIUS, 1),
            (SIGN, 1),
            (SCALE, 1),
            (OBJ, 1),
            (MAT, 1),
            (RADIUS_SG, 1),
            (CENTRE_AGAIN, 6),
        ]);
    }
    let fine = fit.sphere_fine.then_some((CENTRE_REM, 3));
    Layout::new([(CENTRE, 3)].into_iter().chain(fine).chain([
        (INV_R, 1),
        (RADIUS, 1),
        (SIGN, 1),
        (OBJ, 1),
        (MAT, 1),
    ]))
}

/// Spheres get the fine record when the smallest is under this many LSB in
/// radius (the rounding of the centre, up to 0.87 LSB, is then over 1.4% of
/// the radius).
pub const FINE_BELOW_LSB: f64 = 64.0;

/// Words of a record.
pub fn words(fit: &Fit) -> usize {
    layout(fit).words()
}

/// The opaque kernel's cut ([`K::cut`]) and what F holds there.
pub const CUTS: [(&str, &str); 1] = [(
    "line",
    "the ray's line meets the sphere and, where none is seen from inside, its centre lies ahead",
)];

/// The local kernel's cuts: [`positions::near`], then [`CUTS`].
pub const LOCAL_CUTS: [(&str, &str); 2] = [NEAR_CUT, CUTS[0]];

/// The first cut of the local kernels ([`positions::near`]) and what F
/// holds there.
pub const NEAR_CUT: (&str, &str) = (
    "near",
    "the ray's line passes within the shape's extent (and the roundings) of its frame's centre",
);

pub fn kernel_name(s: Sides) -> &'static str {
    match s {
        Sides::Front => "k_sphere",
        Sides::Both => "k_glass_sphere",
    }
}

/// The scale shifts of the spheres of the scene, whose radii in LSB are
/// `radii`: `(KS_SPHERE, EP_SPHERE, fine record)`.
pub(crate) fn fit(radii: impl Iterator<Item = f64> + Clone, f: &Fitter) -> (u32, u32, bool) {
    let r_min = radii.clone().fold(f64::INFINITY, f64::min);
    let r_max = radii.fold(1.0f64, f64::max);
    // Extra fraction bits of the perpendicular vector: up to 4, as long as
    // twice the largest radius still fits.
    (f.ks(r_min), f.shift(2.0 * r_max, 4), r_min < FINE_BELOW_LSB)
}

/// Write the record of a sphere (object `id`, material `mat`).
/// `unrounded`: `invr` of the unrounded radius (the streamed layout's
/// format; fine records always).
#[allow(clippy::too_many_arguments)]
pub(crate) fn write(
    w: &mut W,
    fit: &Fit,
    unrounded: bool,
    center: Vec3,
    radius: f64,
    inside: bool,
    id: usize,
    mat: usize,
) {
    let s = w.s;
    if fit.local {
        write_local(w, fit, center, radius, inside, id, mat);
        return;
    }
    let rq = (radius.abs() * s).round().max(1.0);
    let invr = ((14 + w.x + fit.ks_sphere) as f64).exp2()
        / if unrounded || fit.sphere_fine {
            radius.abs() * s
        } else {
            rq
        };
    let sg = if inside { -1.0 } else { 1.0 };
    w.field(CENTRE);
    w.point(center);
    if fit.sphere_fine {
        w.field(CENTRE_REM);
        for (_, rem) in split(w, center) {
            w.push(rem);
        }
    }
    // invr before r: the packet traversal's kernel needs only invr before
    // its cut, and reads r straight from the stream after it.
    w.field(INV_R);
    w.push(invr);
    w.field(RADIUS);
    if fit.sphere_fine {
        w.push(radius.abs() * s * (fit.ep_sphere as f64).exp2());
    } else {
        w.push(rq);
    }
    w.field(SIGN);
    w.push(sg * w.one());
    w.field(OBJ);
    w.raw(id as i64);
    w.field(MAT);
    w.raw(mat as i64);
}

/// Write the local record of a sphere ([`layout`] with
/// `fit.local`): its centre rounded and the remainders in 2^-14
/// LSB, its radius and `invr` in its frame of `2^-e` LSB.
fn write_local(
    w: &mut W,
    fit: &Fit,
    center: Vec3,
    radius: f64,
    inside: bool,
    id: usize,
    mat: usize,
) {
    let s = w.s;
    let r = radius.abs() * s;
    let e = local_exponent(r);
    let rl = r * (e as f64).exp2();
    let sg = if inside { -1.0 } else { 1.0 };
    let one = w.one();
    let parts = write_frame(w, [CENTRE, SHIFTS, CENTRE_REM], (center, r), e);
    w.field(INV_R);
    w.push(((14 + w.x + fit.ks_sphere) as f64).exp2() / rl);
    w.field(RADIUS);
    w.push(rl);
    w.field(SIGN);
    w.push(sg * one);
    w.field(SCALE);
    w.push((14.0 - e as f64).exp2());
    w.field(OBJ);
    w.raw(id as i64);
    w.field(MAT);
    w.raw(mat as i64);
    w.field(RADIUS_SG);
    w.push(sg * rl);
    write_centre_again(w, CENTRE_AGAIN, parts);
}

/// The head of a local record: the frame's centre `c` rounded to the
/// scene's LSB, the bound of [`positions::near`] for a shape of extent
/// `r` LSB about it ([`NEAR`]), the frame's shifts `e + 2` and `14 - e`,
/// the centre's remainders (2^-14 LSB), as the fields `[centre, shifts,
/// remainder]`; the centre's parts, for [`write_centre_again`].
pub(super) fn write_frame(
    w: &mut W,
    fields: [Field; 3],
    (c, r): (Vec3, f64),
    e: u32,
) -> [(f64, f64); 3] {
    let parts = split(w, c);
    w.field(fields[0]);
    w.point(c);
    w.field(NEAR);
    w.push(positions::near_bound(r));
    w.field(fields[1]);
    w.raw(e as i64 + 2);
    w.raw(14 - e as i64);
    w.field(fields[2]);
    for (_, rem) in parts {
        w.push(rem);
    }
    parts
}

/// The tail of a local record: the centre and its remainder per axis
/// (field `field`), for the hit point ([`positions::hit_point_axis`]).
pub(super) fn write_centre_again(w: &mut W, field: Field, parts: [(f64, f64); 3]) {
    w.field(field);
    for (hi, rem) in parts {
        w.push(hi);
        w.push(rem);
    }
}

/// A point's coordinates as the records hold them: rounded to the LSB,
/// and what the rounding left, in 2^-14 LSB (2^-30 on the 32-bit chip).
fn split(w: &W, p: Vec3) -> [(f64, f64); 3] {
    p.to_array().map(|x| {
        let hi = w.sat(x * w.s) as f64;
        (hi, (x * w.s - hi) * w.one())
    })
}

/// The sphere kernel for records of `fit` and the sides `sides`.
pub fn kernel(g: &Gen, fit: &Fit, sides: Sides) -> K {
    match (fit.local, sides) {
        (true, _) => kernel_local(g, fit, sides == Sides::Both),
        (false, _) => kernel_global(g, fit, sides, ["KS_SPHERE", "EP_SPHERE"]),
    }
}

/// The sphere kernel of records in the scene's format, its shifts named
/// `ks` and `ep`.
fn kernel_global(g: &Gen, fit: &Fit, sides: Sides, [ks, ep]: [&str; 2]) -> K {
    let (fine, perp, two) = (fit.sphere_fine, g.fine_normals, sides == Sides::Both);
    let nr = g.approx;
    let mut k = K::new();
    k.doc(&format!(
        "{}: the sphere test of one record (the stream), for every awake ray.\n\
         In: r1..r3 o, r4..r6 d, r7 tbest. Out where F (a nearer hit): r7 = t, HIT_N, HIT_OBJ, HIT_MAT{}.\n\
         b = (c - o).d, p = (c - o) - b d, s = 1 - |p/r|^2, t = b - sg r sqrt(s), n = -(sg p/r + sqrt(s) d)",
        kernel_name(sides),
        if two { ", HIT_BACK_OBJ (the far side)" } else { "" }
    ));
    k.comment("oc = c - o");
    oc_and_b(&mut k, "b = oc.d");
    if fine && !perp {
        // b's remainder: the accumulator minus round(b) 2^14, below 2^13
        // in magnitude, so its low half is exact (the wrap is intended).
        k.c("accl r12")
            .c("sll r14, r11, #Q14")
            .c("sub r12, r12, r14")
            .note("b's remainder below an LSB");
    }
    k.comment(&format!("p = oc - b d, with {ep} more fraction bits"));
    for (x, d) in [(8, 4), (9, 5), (10, 6)] {
        if fine && !perp {
            k.c(format!("mul r13, r12, r{d}, >>Q14"))
                .c(format!("ldacc r{x}, <<Q14"))
                .c("mac out, fb0, #1")
                .c("msu out, r13, #1");
        } else {
            k.c(format!("ldacc r{x}, <<Q14"));
            if fine {
                k.c("mac out, fb0, #1").note("+ the centre's remainder");
            }
        }
        k.c(format!("msu r{x}, r11, r{d}, >>Q14-{ep}"));
    }
    if perp {
        perpendicular_to(&mut k, &[8, 9, 10], &[4, 5, 6], 12);
    }
    let er = if fine {
        format!("+{ep}")
    } else {
        String::new()
    };
    // The paper's traversal keeps r in a register (its published
    // contexts); the packet traversal's multiplies by r from the stream
    // after the cut.
    k.c("mov r13, fb0").note("invr");
    if g.published {
        k.c("mov r12, fb0").note("r");
    }
    let r = if g.published { "r12" } else { "fb0" };
    meets(&mut k, &format!("{ks}+{ep}"));
    if !two && g.test_cuts && !g.published && !fit.sphere_inside {
        // Seen from outside (sg = +1), t = b - h with h >= 0: a sphere
        // whose centre is not ahead has no root ahead, exactly.
        k.c("(f) cmp.gt r11, #0").note("and its centre lies ahead");
    }
    if !two {
        k.cut(CUTS[0].0);
    }
    // p/r to RAM for the normal: past the cut, so that a test cut there
    // spends no store.
    for (i, x) in [8, 9, 10].into_iter().enumerate() {
        k.c(format!("st r{x}, [#{}]", ram::TMP0 + i as u32));
    }
    k.note("p/r in TMP0..2");
    sqrt_q14(&mut k, 15, 8, [9, 10, 13, 14], nr);
    root(&mut k, g, two, r, &er);
    normal_and_commit(&mut k, two);
    k
}

/// The sphere kernel of local records ([`layout`] with `fit.local`,
/// one side): `b = round((c - o).d)` in the scene's LSB as in [`kernel`],
/// then `p = (c - o) - b d` formed exactly in the accumulator from the
/// rounded centre and origin and both remainders (`cl`, `RAY_OL`, 2^-14
/// LSB) and the direction's (`RAY_DL`, 2^-27) and taken into the sphere's frame, `2^e` times finer: the
/// accumulator's words shifted by the record's `e + 2` (saturating) and
/// `14 - e`. In the frame: `p` made perpendicular to `d` (its part along
/// `d`, `pd`, kept), `s = 1 - |p/r|^2`, `t = b + (pd - sg r sqrt(s)) 2^-e`
/// rounded to the scene's LSB (for the nearest-hit comparisons), the
/// normal as in [`kernel`], and the hit point `c + sg r n` back in the
/// scene's format with its remainder: `HIT_PH`, `HIT_PL`, tagged by
/// `HIT_TL = t` (its remainder `HIT_TLL`: nearest hits are told apart to
/// 2^-14 LSB where both are local, overlapping spheres). Two-sided
/// (`two`, a transmitting sphere): where the near root is not more than
/// `SELF_LSB` ahead, the far root `b + (pd + sg h) 2^-e`, the sign turned
/// to the ray and the hit a far-side one (`HIT_BACK_OBJ`), its point
/// `c - sg r n 2^-e` with the turned normal.
fn kernel_local(g: &Gen, fit: &Fit, two: bool) -> K {
    let nr = g.approx;
    let mut k = K::new();
    k.doc(&format!(
        "{}: the sphere test of one local record (the stream), for every awake ray{}.\n\
         In: r1..r7 the rays, RAY_OL. Out where F (a nearer hit): r7 = t, HIT_N, HIT_OBJ, HIT_MAT,\n\
         HIT_TL = t, HIT_PH and HIT_PL the hit point{}. b = round((c - o).d), p = ((c - o) - b d) 2^e,\n\
         s = 1 - |p/r|^2, t = b + (pd - sg r sqrt(s)) 2^-e, n = -(sg p/r + sqrt(s) d), P = c + sg r n 2^-e",
        kernel_name(if two { Sides::Both } else { Sides::Front }),
        if two { ", seen from either side" } else { "" },
        if two { ", HIT_BACK_OBJ (the far side)" } else { "" },
    ));
    enter_frame(&mut k, ["c", "centre", "cl"], NEAR_CUT.0);
    perpendicular_to(&mut k, &[8, 9, 10], &[4, 5, 6], 12);
    k.note("r12 = pd, what p had along d");
    k.c("mov r13, fb0").note("invr, in the frame");
    meets(&mut k, "KS_SPHERE");
    if g.test_cuts && !fit.sphere_inside && !two {
        k.c("(f) cmp.gt r11, #0").note("and its centre lies ahead");
    }
    k.cut(LOCAL_CUTS[1].0);
    for (i, x) in [8, 9, 10].into_iter().enumerate() {
        k.c(format!("st r{x}, [#{}]", ram::TMP0 + i as u32));
    }
    k.note("p/r in TMP0..2");
    sqrt_q14(&mut k, 15, 8, [9, 10, 13, 14], nr);
    if two {
        local_roots_two(&mut k, g);
        return k;
    }
    k.c("mul r9, fb0, r8, >>Q14")
        .note("h = r sqrt(s), in the frame")
        .c("mov r10, fb0")
        .note("sg")
        .c("mul r9, r9, r10, >>Q14")
        .c("sub r9, r12, r9")
        .note("pd - sg h")
        .c("mov r14, fb0")
        .note("2^(14-e)")
        .c("ldacc r11, <<Q14")
        .c("mac r9, r14, r9, >>Q14")
        .note("t = b + (pd - sg h) 2^-e");
    remainder(&mut k, 12, 9, 13, "Q14");
    k.note("its remainder, 2^-14 LSB");
    positions::nearer(&mut k, 9, 12, 15, 13);
    normal_and_commit(&mut k, false);
    k.comment("the hit point c + sg r n 2^-e, to 2^-14 LSB");
    k.c("mov r15, fb0").note("sg r");
    hit_point_from_normal(&mut k);
    k
}

/// The end of the local kernels: the hit point `c + v n 2^-e` to 2^-14
/// LSB from the normal (r11..r13) and `v` in the frame (r15: `sg r`,
/// turned on a far-side hit), the frame's `2^(14-e)` in r14, the
/// stream's centre and its remainder per axis: where F, `HIT_PH` and
/// `HIT_PL`. Clobbers r8..r10.
fn hit_point_from_normal(k: &mut K) {
    for (i, n) in [11, 12, 13].into_iter().enumerate() {
        k.c(format!("mul r8, r{n}, r15, >>Q14"));
        positions::hit_point_axis(k, i as u32, "mac", 8, None, 14, [9, 8, 10]);
    }
}

/// The two-sided end of [`kernel_local`], after `sqrt(s)` (r8), with
/// `b` (r11), `pd` (r12), `p/r` in `TMP0..2` and F where the line meets
/// the sphere: the near root, or the far one where the near root is not
/// more than `SELF_LSB` ahead (`TMP3` = 1, the sign turned), `t` with its
/// remainder, [`positions::nearer`], the normal turned to the ray and the
/// commit with `HIT_BACK_OBJ`, and the hit point `c + sg' r n 2^-e` with
/// the turned sign `sg'`.
fn local_roots_two(k: &mut K, g: &Gen) {
    k.c("movb r13, #0")
        .c("(f) movb r13, #1")
        .c(format!("st r13, [#{}]", ram::TMP4))
        .note("meets");
    k.c("mul r9, fb0, r8, >>Q14")
        .note("h = r sqrt(s), in the frame")
        .c("mov r10, fb0")
        .note("sg")
        .c("mul r9, r9, r10, >>Q14")
        .c("mov r14, fb0")
        .note("2^(14-e)")
        .c("sub r13, r12, r9")
        .c("ldacc r11, <<Q14")
        .c("mac r15, r14, r13, >>Q14")
        .note("t1 = b + (pd - sg h) 2^-e");
    self_margin(k, 13, g.datapath);
    k.c("cmp.le r15, r13")
        .note("the near root not ahead: the far side")
        .c("(f) add r12, r12, r9")
        .c("(!f) sub r12, r12, r9")
        .c("(f) neg r10, r10")
        .c("movb r15, #0")
        .c("(f) movb r15, #1")
        .c(format!("st r15, [#{}]", ram::TMP3))
        .c("ldacc r11, <<Q14")
        .c("mac r9, r14, r12, >>Q14")
        .note("t = b + (pd -+ sg h) 2^-e");
    remainder(k, 12, 9, 15, "Q14");
    k.note("its remainder, 2^-14 LSB")
        .c(format!("ld r15, [r0 + #{}]", ram::TMP4))
        .c("cmp.ne r15, #0")
        .c("(f) cmp.gt r9, r13")
        .note("F: the line meets the sphere, the root more than SELF_LSB ahead");
    positions::nearer(k, 9, 12, 15, 13);
    normal_and_commit(k, true);
    k.comment("the hit point c + sg' r n 2^-e, to 2^-14 LSB (sg' turned on the far side)");
    k.c(format!("ld r13, [r0 + #{}]", ram::HIT_N + 2))
        .note("n.z again (the commit took r13; where F it is the hit's)")
        .c("mov r15, fb0")
        .note("sg r")
        .c("xor r15, r15, r9")
        .c("sub r15, r15, r9")
        .note("negated on the far side (r9 = -back)");
    hit_point_from_normal(k);
}

/// `oc = c - o` (r8..r10, the centre from the stream) and `b = oc.d`
/// (r11; `note` says which).
pub(super) fn oc_and_b(k: &mut K, note: &str) {
    k.c("sub r8, fb0, r1")
        .c("sub r9, fb0, r2")
        .c("sub r10, fb0, r3");
    k.c("mul out, r8, r4")
        .c("mac out, r9, r5")
        .c("mac r11, r10, r6, >>Q14")
        .note(note);
}

/// The start of every local kernel, its record's head from
/// [`write_frame`]: `oc` (r8..r10) and `b = round(oc.d)` (r11) from the
/// rounded centre (`c`, the `what` in the comments) and origin, the cut
/// `cut` where the line passes outside the record's bound
/// ([`positions::near`]), the frame's shifts (r14 `e + 2`, r15 `14 - e`)
/// and `p` in the frame (r8..r10, [`positions::offset_in_frame`], the
/// centre's remainder named `rem`). Clobbers r12..r15.
pub(super) fn enter_frame(k: &mut K, [c, what, rem]: [&str; 3], cut: &str) {
    k.comment(&format!("oc = {c} - o (the rounded {what} and origin)"));
    oc_and_b(k, "b = round(oc.d)");
    positions::near(k);
    k.cut(cut);
    k.c("mov r14, fb0")
        .note("e + 2")
        .c("mov r15, fb0")
        .note("14 - e");
    k.comment(&format!(
        "p = oc + {rem} - ol - b (d + dl) in 2^-14 LSB, then in the frame: >> (14 - e)"
    ));
    positions::offset_in_frame(k);
}

/// `p/r` (r8..r10: `p` times `invr` in r13, shifted by `shift`) and
/// `s = 1 - |p/r|^2` (r15); F where the line meets the sphere.
fn meets(k: &mut K, shift: &str) {
    for x in [8, 9, 10] {
        k.c(format!("mul r{x}, r{x}, r13, >>{shift}"));
    }
    k.note("p/r");
    k.c(format!("ld r14, [r0 + #{}]", ram::C_ONE))
        .c("ldacc r14, <<Q14")
        .c("msu out, r8, r8")
        .c("msu out, r9, r9")
        .c("msu r15, r10, r10, >>Q14")
        .note("s = 1 - |p/r|^2")
        .c("cmp.gt r15, #0")
        .note("F: the line meets the sphere");
}

/// The root: `h = r sqrt(s)` (`r` the register or stream that holds r,
/// `er` its extra bits), `t = b - sg h` in r9, F where a hit lies ahead,
/// nearer than tbest; two-sided (`two`), the far root where the near one
/// is not ahead (TMP3 = 1 then), r10 the sign turned to the ray.
fn root(k: &mut K, g: &Gen, two: bool, r: &str, er: &str) {
    if two {
        k.c(format!("mul r9, {r}, r8, >>Q14{er}"))
            .note("h = r sqrt(s)")
            .c("mov r10, fb0")
            .note("sg")
            .c("mul r14, r9, r10, >>Q14")
            .c("sub r9, r11, r14")
            .note("t1 = b - sg h")
            .c("movb r15, #0")
            .c("(f) movb r15, #1")
            .c("movb r12, #0");
        self_margin(k, 13, g.datapath);
        k.c("cmp.le r9, r13")
            .c("(f) add r9, r11, r14")
            .note("not ahead: t2 = b + sg h, the far side")
            .c("(f) neg r10, r10")
            .c("(f) movb r12, #1")
            .c(format!("st r12, [#{}]", ram::TMP3))
            .c("cmp.ne r15, #0")
            .c("(f) cmp.gt r9, r13")
            .c("(f) cmp.lt r9, r7")
            .note("F: a hit ahead, nearer than tbest");
    } else {
        k.c(format!("mul r9, {r}, r8, >>Q14{er}"))
            .note("h = r sqrt(s)")
            .c("mov r10, fb0")
            .note("sg")
            .c("mul r9, r9, r10, >>Q14")
            .c("sub r9, r11, r9")
            .note("t = b - sg h")
            .c("(f) cmp.gt r9, #0")
            .c("(f) cmp.lt r9, r7")
            .note("F: a hit ahead, nearer than tbest");
    }
}

/// The normal `-(sg p/r + sqrt(s) d)` and, where F, the hit: t, HIT_N,
/// HIT_OBJ (two-sided: HIT_BACK_OBJ), HIT_MAT.
fn normal_and_commit(k: &mut K, two: bool) {
    k.comment("normal = -(sg p/r + sqrt(s) d)");
    for (i, (x, d)) in [(11, 4), (12, 5), (13, 6)].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::TMP0 + i as u32))
            .c(format!("mul out, r8, r{d}"))
            .c(format!("mac r{x}, r10, r{x}, >>Q14"))
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
            .c(format!("(f) st r13, [#{}]", ram::HIT_BACK_OBJ))
            .note("obj on a far-side hit, else -1");
    } else {
        k.c(format!("(f) st fb0, [#{}]", ram::HIT_OBJ));
    }
    k.c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
}

/// The sphere ([`super::ChipPrimitive`]).
pub struct Sphere;

impl super::ChipPrimitive for Sphere {
    fn names(&self) -> [&'static str; 2] {
        ["sphere", "glass_sphere"]
    }

    fn layout(&self, _sides: Sides, fit: &Fit, _fan: usize, _caps: bool) -> Layout {
        layout(fit)
    }

    fn kernels(&self, sides: Sides, g: &Gen, fit: &Fit) -> Vec<(&'static str, K)> {
        vec![(kernel_name(sides), kernel(g, fit, sides))]
    }

    fn broadcast(&self, sides: Sides, t: &mut Code, _at: &str, _fit: &Fit, _caps: bool) {
        super::one(t, kernel_name(sides));
    }

    fn cut_test(&self, sides: Sides, fit: &Fit) -> Option<CutTest> {
        (sides == Sides::Front).then(|| CutTest {
            kernel: kernel_name(sides),
            field: "0",
            cuts: if fit.local { &LOCAL_CUTS } else { &CUTS },
            then: None,
        })
    }

    fn fit_header(&self, fit: &Fit) -> Vec<String> {
        vec![
            define(
                "KS_SPHERE",
                fit.ks_sphere,
                "spheres: invr = 2^(Q14+KS_SPHERE) / r",
            ),
            define(
                "EP_SPHERE",
                fit.ep_sphere,
                "spheres: extra fraction bits of the perpendicular vector",
            ),
        ]
    }

    fn fit(&self, scene: &Scene, _geo: &[Geometry], s: f64, f: &Fitter, fit: &mut Fit) {
        let spheres = || scene.objects.iter().filter_map(|o| o.shape.as_sphere());
        let radii = spheres().map(|sp| sp.radius.abs() * s);
        if fit.local {
            // Radii in their frames, transmitting spheres' too; no fine
            // record (the remainders are the local record's).
            let local = radii.map(|r| r * (local_exponent(r) as f64).exp2());
            (fit.ks_sphere, fit.ep_sphere, _) = self::fit(local, f);
            fit.sphere_fine = false;
        } else {
            (fit.ks_sphere, fit.ep_sphere, fit.sphere_fine) = self::fit(radii, f);
        }
        fit.sphere_inside = spheres().any(|sp| sp.inside);
    }

    fn test_cost(&self, g: &Gen, fit: &Fit) -> TestCost {
        TestCost::of(&kernel(g, fit, Sides::Front))
    }

    /// A sphere a few LSB in radius is held apart (`tb/tests/kernels.rs`).
    fn error_bound(&self) -> ErrorBound {
        ErrorBound::lsb(6.0, 0.03)
    }

    fn write(&self, w: &mut W, o: &Object) -> Result<(), RecordError> {
        let Some(sp) = o.shape.as_sphere() else {
            return Err(RecordError::mismatch("sphere"));
        };
        write(
            w,
            o.fit,
            o.unrounded,
            sp.center,
            sp.radius,
            sp.inside,
            o.id,
            o.mat,
        );
        Ok(())
    }
}
