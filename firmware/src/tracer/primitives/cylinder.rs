//! Open cylinder with optional end caps (`scene/shape/cone.rs`
//! with equal radii; the caps `disc`).
//!
//! **Record**: a caps flag (`CYL_CAPS`), the body (`CYL_BODY`), then the
//! two caps as disc records ([`super::planar`], `CYL_CAP0`, `CYL_CAP1`)
//! whether or not the flag is set. The body (36 words): `B.xyz, e1.xyz,
//! b1, e2.xyz, b2, e1.xyz, e2.xyz, invr, r, sg, B.xyz, a.xyz, H+2, sg, (e1,
//! e2) x, (e1, e2) y, (e1, e2) z, obj, mat` (e1, e2, a an orthonormal
//! frame, a along the axis, B the base centre rounded to the LSB and `b1`,
//! `b2` what the rounding left of it along e1 and e2 in 2^-14 LSB, H the
//! height, scene units; `r` with `EP_CYL` extra fraction bits, `invr =
//! 2^(14+KS_CYL) / r` of the unrounded radius; `r` before `invr` where
//! the opaque kernel starts with its bound, [`Fit::cyl_bound`]). With
//! coarse normals the body has no `b1`, `b2` (34 words), `r` is rounded to
//! the LSB and `invr` is of that. A glass cylinder's record holds the body twice (`sg`, then
//! `-sg`: `GCYL_INNER`) before its caps (`GCYL_CAP0`, `GCYL_CAP1`). Under
//! the packet traversal, where no cylinder of the scene has caps, the
//! record is the body (or bodies) alone: no flag, no discs.
//!
//! **Method**: in the plane across the axis the ray is a 2D ray: its
//! direction `d2 = (d.e1, d.e2)` is normalised (`|d2|` kept), the 2D
//! problem is the sphere's perpendicular method, and `t = tau / |d2|`;
//! the hit's axial coordinate must lie in `[-2, H + 2]` LSB. The
//! perpendicular vector keeps `EP_CYL` extra fraction bits, formed (fine
//! normals) from the unrounded `(B - o).e1`, `(B - o).e2` (the rounding
//! remainders of the projections and of B added back in the accumulator)
//! and made perpendicular to the 2D direction; the normal `n2 = -(sg p2 /
//! r + sqrt(s) d2n)` across the axis follows from it without the hit
//! point, `n = n2.x e1 + n2.y e2`.
//!
//! **Two-sided** (a transmitting cylinder): one run per copy of the body
//! ([`Body::Outer`], [`Body::Inner`]: the far root, normal turned inwards,
//! a back hit); both accept a root only more than `SELF_LSB` ahead along
//! the ray (a ray starting on the surface, however rounded, does not hit
//! it there again); the caps are two-sided discs.
//!
//! **Registers**: r1..r7 the ray (r7 the new `tbest` where F); r8..r15
//! temporaries; RAM `TMP0..TMP6`.
//!
//! **Error** against the f64 cylinder: its `error_bound` (below), which
//! `tb/tests/kernels.rs` holds both chips to; fine normals beat coarse
//! ones on a thin cylinder.

use super::super::emit::{define, Code, Reg, K, R7};
use super::super::math::{divide, normalize, perpendicular_to, sqrt_q14};
use super::super::memory_map::ram;
use super::planar::{self, Inside, Planar};
use super::record::{Field, Fitter, Layout, W};
use super::{
    commit_obj_mat, perpendicular, self_margin, Body, CutTest, ErrorBound, Fit, Gen, Geometry,
    Object, RecordError, Sides, TestCost,
};
use crate::scene::{PrimType, Scene, Shape, Surface, Vec3};

/// The margin of the bound before the first cut, in LSB: the bound's
/// rounding (under 2 LSB: `oc2` rounded, the products) and the exact
/// test's (about 1 LSB in `p2`), with room to spare.
const BOUND_MARGIN_LSB: i32 = 8;

/// Words of the body, fine and coarse normals.
pub const BODY_WORDS: usize = 36;
pub const BODY_WORDS_COARSE: usize = 34;

/// Words of a body.
pub const fn body_words(fine_normals: bool) -> usize {
    if fine_normals {
        BODY_WORDS
    } else {
        BODY_WORDS_COARSE
    }
}

/// The record's fields: the caps flag, the body (twice for a glass
/// cylinder: the second seen from inside), the caps' discs.
pub const CYL_CAPS: Field = Field::named("CYL_CAPS", "cylinder record: caps flag");
pub const CYL_BODY: Field = Field::named("CYL_BODY", "cylinder record: the body's stream");
pub const GCYL_INNER: Field = Field::named("GCYL_INNER", "glass cylinder record: the inner body");
pub const CYL_CAP0: Field = Field::named("CYL_CAP0", "cylinder record: base cap (a disc)");
pub const CYL_CAP1: Field = Field::named("CYL_CAP1", "cylinder record: apex cap");
pub const GCYL_CAP0: Field = Field::named("GCYL_CAP0", "glass cylinder record: base cap");
pub const GCYL_CAP1: Field = Field::named("GCYL_CAP1", "glass cylinder record: apex cap");

/// The record of `s`: caps flag, body (twice for a glass cylinder), caps;
/// without `caps` (records that carry none) the body alone.
pub fn layout(fit: &Fit, s: Sides, caps: bool) -> Layout {
    if fit.cyl_local && s == Sides::Front {
        // No caps whatever `caps` says: no cylinder of the scene has them
        // (the paper traversal's layout, built to size a local scene's
        // stream, asks with caps).
        return super::cylinder_local::layout();
    }
    let body = body_words(fit.fine_normals);
    let glass = s == Sides::Both;
    let mut l = Vec::new();
    if caps {
        l.push((CYL_CAPS, 1));
    }
    l.push((CYL_BODY, body));
    if glass {
        l.push((GCYL_INNER, body));
    }
    if caps {
        let (c0, c1) = if glass {
            (GCYL_CAP0, GCYL_CAP1)
        } else {
            (CYL_CAP0, CYL_CAP1)
        };
        l.extend([(c0, planar::WORDS), (c1, planar::WORDS)]);
    }
    Layout(l)
}

fn body_name(b: Body) -> &'static str {
    match b {
        Body::Opaque => "k_cylinder",
        Body::Outer => "k_glass_cylinder_out",
        Body::Inner => "k_glass_cylinder_in",
    }
}

/// The kernels of a cylinder's test, in load order: the body run(s), the
/// caps' disc.
pub fn kernels(g: &Gen, fit: &Fit, s: Sides) -> Vec<(&'static str, K)> {
    let cap = planar::kernel_name(Inside::Disc, s);
    if fit.cyl_local && s == Sides::Front {
        return vec![(body_name(Body::Opaque), super::cylinder_local::kernel(g))];
    }
    match s {
        Sides::Front => vec![
            (body_name(Body::Opaque), kernel(g, fit, Body::Opaque)),
            (cap, planar::kernel(g, Inside::Disc, s)),
        ],
        Sides::Both => vec![
            (body_name(Body::Outer), kernel(g, fit, Body::Outer)),
            (body_name(Body::Inner), kernel(g, fit, Body::Inner)),
            (cap, planar::kernel(g, Inside::Disc, s)),
        ],
    }
}

/// The scale shifts of the cylinders: `(KS_CYL, EP_CYL)` from the
/// cylinders' radii in LSB and the largest base radius of every cone-like
/// object (cylinders and cones).
pub(crate) fn fit(
    radii: impl Iterator<Item = f64>,
    all_base_radii: impl Iterator<Item = f64>,
    f: &Fitter,
) -> (u32, u32) {
    let r_min = radii.fold(f64::INFINITY, f64::min);
    let r_max = all_base_radii.fold(1.0f64, f64::max);
    (f.ks(r_min), f.shift(2.0 * r_max, 4))
}

/// The caps of a cylinder from `base` to `apex` of radius `r`, as discs.
pub fn caps(base: Vec3, apex: Vec3, r: f64) -> [Planar; 2] {
    let a = (apex - base).normalized();
    let e1 = perpendicular(a);
    let e2 = a.cross(e1);
    [
        Planar::disc(base, e1, e2, r, -a),
        Planar::disc(apex, e1, e2, r, a),
    ]
}

/// Write the record of a cylinder; `caps`: whether its caps are on and
/// the discs (from [`caps`]), `None` where the record carries no caps.
#[allow(clippy::too_many_arguments)]
pub(crate) fn write(
    w: &mut W,
    fit: &Fit,
    sides: Sides,
    base: Vec3,
    apex: Vec3,
    radius: f64,
    inside: bool,
    caps: Option<(bool, &[Planar; 2])>,
    id: usize,
    mat: usize,
) {
    let s = w.s;
    let axis = apex - base;
    let h = axis.length();
    let av = axis * (1.0 / h);
    let e1 = perpendicular(av);
    let e2 = av.cross(e1);
    let rs = radius.abs() * s;
    // Fine normals: the radius with `ep` extra bits and its reciprocal
    // unrounded; otherwise both of the rounded radius.
    let rq = rs.round().max(1.0);
    let invr = ((14 + w.x + fit.ks_cyl) as f64).exp2() / if fit.fine_normals { rs } else { rq };
    // The base's rounding remainder along e1 and e2.
    let bq = Vec3::from(base.to_array().map(|x| w.sat(x * s) as f64));
    let brem = base * s - bq;
    let sg = if inside { -1.0 } else { 1.0 };
    if let Some((on, _)) = caps {
        w.field(CYL_CAPS);
        w.raw(on as i64);
    }
    // A transmitting cylinder: the body twice, the second seen from the
    // other side.
    let copies: &[f64] = if sides == Sides::Both {
        &[1.0, -1.0]
    } else {
        &[1.0]
    };
    for (&side, field) in copies.iter().zip([CYL_BODY, GCYL_INNER]) {
        w.field(field);
        let sg = sg * side;
        w.point(base);
        w.unit(e1);
        if fit.fine_normals {
            w.push(brem.dot(e1) * w.one());
        }
        w.unit(e2);
        if fit.fine_normals {
            w.push(brem.dot(e2) * w.one());
        }
        w.unit(e1);
        w.unit(e2);
        let r = if fit.fine_normals {
            rs * (fit.ep_cyl as f64).exp2()
        } else {
            rq
        };
        // The bound needs r before its cut, the rest invr after it.
        if fit.cyl_bound && sides == Sides::Front {
            w.push(r);
            w.push(invr);
        } else {
            w.push(invr);
            w.push(r);
        }
        w.push(sg * w.one());
        w.point(base);
        w.unit(av);
        w.raw((h * s).round() as i64 + 2);
        w.push(sg * w.one());
        for c in 0..3 {
            w.push(e1.axis(c) * w.one());
            w.push(e2.axis(c) * w.one());
        }
        w.raw(id as i64);
        w.raw(mat as i64);
    }
    let cap_fields = if sides == Sides::Both {
        [GCYL_CAP0, GCYL_CAP1]
    } else {
        [CYL_CAP0, CYL_CAP1]
    };
    for (p, field) in caps.into_iter().flat_map(|(_, c)| c).zip(cap_fields) {
        w.field(field);
        let mut p = *p;
        p.n = p.n * sg;
        planar::write(w, &fit.kt, &p, id, mat);
    }
}

/// One run of the cylinder body kernel.
pub fn kernel(g: &Gen, fit: &Fit, body: Body) -> K {
    let fine = g.fine_normals;
    let nr = g.approx;
    let mut k = K::new();
    k.doc(&format!(
        "{}: the open cylinder test of one body record (the stream){}.\n\
         In: r1..r3 o, r4..r6 d, r7 tbest. Out where F: r7 = t, HIT_N, HIT_OBJ, HIT_MAT{}.\n\
         Across the axis: d2 = (d.e1, d.e2) normalised, p2 = oc2 - b d2n, s = 1 - |p2/r|^2,\n\
         tau = b - sg r sqrt(s), t = tau / |d2|; the axial coordinate within [-2, H+2].",
        body_name(body),
        match body {
            Body::Opaque => "",
            Body::Outer => ", a glass cylinder's outer surface",
            Body::Inner => ", a glass cylinder's inner surface (its second body)",
        },
        if body == Body::Opaque {
            ""
        } else {
            ", HIT_BACK_OBJ"
        },
    ));
    origin_across(&mut k, fine);
    // The record's order says whether the opaque kernel has the bound.
    let bound = body == Body::Opaque && fit.cyl_bound;
    let er = if fine { "+EP_CYL" } else { "" };
    if !bound {
        store_oc2(&mut k);
    }
    k.c("mul out, fb0, r4")
        .c("mac out, fb0, r5")
        .c("mac r8, fb0, r6, >>Q14");
    k.c("mul out, fb0, r4")
        .c("mac out, fb0, r5")
        .c("mac r9, fb0, r6, >>Q14")
        .note("d2 = (d.e1, d.e2)");
    if bound {
        line_bound(&mut k, g, fit, er);
    }
    across_axis(&mut k, g, nr);
    if body == Body::Opaque {
        k.cut(CUTS[1].0);
    }
    sqrt_q14(&mut k, 15, 8, [9, 11, 12, 14], nr);
    k.c(format!("st r8, [#{}]", ram::TMP4));
    if bound {
        k.c(format!("ld r9, [r0 + #{}]", ram::TMP8));
    } else {
        k.c("mov r9, fb0");
    }
    k.c(format!("mul r9, r9, r8, >>Q14{er}"))
        .note("h = r sqrt(s)")
        .c("mov r11, fb0")
        .c("mul r9, r9, r11, >>Q14")
        .c("sub r9, r13, r9")
        .note("tau = b - sg h")
        .c("(f) cmp.gt r9, #0")
        .c("ldacc r9, <<Q14")
        .c("msu out, r7, r10")
        .c("acch r11")
        .c("(f) cmp.lt r11, #0")
        .note("F: tau < tbest |d2|");
    if body == Body::Opaque {
        k.cut(CUTS[2].0);
    }
    divide(&mut k, 9, 10, 9, [8, 11, 12, 13, 14], nr);
    if body != Body::Opaque {
        self_margin(&mut k, 8, g.datapath);
        k.c("(f) cmp.gt r9, r8");
    }
    axial_and_normal(&mut k, (body == Body::Opaque).then_some(CUTS[3].0));
    commit_obj_mat(&mut k, body);
    k
}

/// `oc = B - o` projected on e1, e2: `oc2` rounded to LSB in r11, r12,
/// and (fine normals) what the rounding left, in 2^-14 LSB, to RAM: added
/// back when the perpendicular vector is formed, whose half-LSB error over
/// a radius of a few dozen LSB would tilt the normal.
fn origin_across(k: &mut K, fine: bool) {
    k.comment("oc = B - o, projected on e1, e2");
    k.c("sub r8, fb0, r1")
        .c("sub r9, fb0, r2")
        .c("sub r10, fb0, r3");
    // The remainder: the accumulator's low half minus the rounded value's,
    // exact below 2^13.
    for (x, rem, t, tmp) in [(11, 14, 15, ram::TMP5), (12, 15, 13, ram::TMP6)] {
        k.c("mul out, fb0, r8")
            .c("mac out, fb0, r9")
            .c(format!("mac r{x}, fb0, r10, >>Q14"));
        if fine {
            k.c(format!("accl r{rem}"))
                .c(format!("sll r{t}, r{x}, #Q14"))
                .c(format!("sub r{rem}, r{rem}, r{t}"))
                .c(format!("add r{rem}, fb0, r{rem}"))
                .c(format!("st r{rem}, [#{tmp}]"))
                .note("the projection's remainder, plus B's");
        }
    }
}

/// `oc2` to RAM for after the normalisation; with the bound, only once the
/// test goes on past it (a test cut there spends no store).
fn store_oc2(k: &mut K) {
    k.c(format!("st r11, [#{}]", ram::TMP0))
        .c(format!("st r12, [#{}]", ram::TMP1))
        .note("oc2");
}

/// The opaque kernel's bound before the normalisation and its cut:
/// `|oc2 x d2| = |p2| |d2| <= r |d2| <= r |d2|_1` where the line meets the
/// cylinder, with a margin for its rounding and the exact test's (a few
/// LSB each); r stays in r14 up to the cut, invr comes from the stream
/// after it.
fn line_bound(k: &mut K, g: &Gen, fit: &Fit, er: &str) {
    k.comment("bound: the line can meet the cylinder only where |oc2 x d2| <= r |d2|_1")
        .c("mov r14, fb0")
        .note("r")
        .c("abs r10, r8")
        .c("abs r15, r9")
        .c("add r15, r10, r15")
        .note("|d2|_1")
        .c(format!("mul r15, r14, r15, >>Q14{er}"))
        .c(format!("add r15, r15, #{BOUND_MARGIN_LSB}"))
        .c("mul out, r11, r9")
        .c("msu r10, r12, r8, >>Q14")
        .note("oc2 x d2")
        .c("abs r10, r10")
        .c("cmp.le r10, r15")
        .note("F: the line may meet it");
    if !g.published && !fit.cyl_inside {
        // Seen from outside (sg = +1), tau = b - h with h >= 0 and
        // b = oc2.d2 / |d2|: no root ahead where oc2.d2 <= 0. The
        // margin covers b's rounding after the normalisation.
        k.c("mul out, r11, r8")
            .c("mac r10, r12, r9, >>Q14")
            .c(format!("(f) cmp.gt r10, #-{BOUND_MARGIN_LSB}"))
            .note("and the axis lies ahead across it");
    }
    k.cut(CUTS[0].0);
    store_oc2(k);
    k.c(format!("st r14, [#{}]", ram::TMP8)).note("r");
}

/// Across the axis: `d2` normalised (`|d2|` in r10), `b = oc2.d2n`,
/// `p2 = oc2 - b d2n` (fine normals: made perpendicular to `d2n`), `p2/r`
/// to RAM, `s = 1 - |p2/r|^2` in r15 and F where `s > 0` and `|d2| > 0`.
fn across_axis(k: &mut K, g: &Gen, nr: super::super::math::Approx) {
    let fine = g.fine_normals;
    if g.published {
        k.c("movb r10, #0");
        normalize(k, &[8, 9, 10], [11, 12, 13, 14, 15], true, nr);
        k.c("mov r10, r11").note("|d2|, Q.14");
    } else {
        normalize(k, &[8, 9], [10, 11, 12, 13, 14], true, nr);
        k.note("|d2| in r10, Q.14");
    }
    k.c(format!("st r8, [#{}]", ram::TMP2))
        .c(format!("st r9, [#{}]", ram::TMP3))
        .note("d2n");
    k.c(format!("ld r11, [r0 + #{}]", ram::TMP0))
        .c(format!("ld r12, [r0 + #{}]", ram::TMP1));
    k.c("mul out, r11, r8")
        .c("mac r13, r12, r9, >>Q14")
        .note("b = oc2.d2n");
    if fine {
        k.c(format!("ld r14, [r0 + #{}]", ram::TMP5))
            .c(format!("ld r15, [r0 + #{}]", ram::TMP6));
    }
    for (x, rem, d) in [(11, 14, 8), (12, 15, 9)] {
        k.c(format!("ldacc r{x}, <<Q14"));
        if fine {
            k.c(format!("mac out, r{rem}, #1"));
        }
        k.c(format!("msu r{x}, r13, r{d}, >>Q14-EP_CYL"));
    }
    k.note("p2 = oc2 - b d2n");
    if fine {
        // p2 perpendicular to the 2D direction d2n
        perpendicular_to(k, &[11, 12], &[8, 9], 14);
    }
    k.c("mov r14, fb0")
        .note("invr")
        .c("mul r11, r11, r14, >>KS_CYL+EP_CYL")
        .c("mul r12, r12, r14, >>KS_CYL+EP_CYL")
        .c(format!("st r11, [#{}]", ram::TMP0))
        .c(format!("st r12, [#{}]", ram::TMP1))
        .note("p2/r");
    k.c(format!("ld r14, [r0 + #{}]", ram::C_ONE))
        .c("ldacc r14, <<Q14")
        .c("msu out, r11, r11")
        .c("msu r15, r12, r12, >>Q14")
        .note("s = 1 - |p2/r|^2")
        .c("cmp.gt r15, #0")
        .c("(f) cmp.gt r10, #0");
}

/// The opaque body kernel's cuts ([`K::cut`]; the first with [`Fit::cyl_bound`])
/// and what F holds at each: a bound says the ray's line may meet the
/// infinite cylinder; it does (`s > 0`); its root lies ahead of the ray and
/// before `tbest`; the hit lies within the height (the normal and the
/// commit are left where no awake ray hits the segment itself).
pub const CUTS: [(&str, &str); 4] = [
    (
        "near",
        "the ray's line may meet the cylinder (|oc2 x d2| <= r |d2|_1) and, where none is seen from inside, its axis lies ahead across it",
    ),
    ("line", "the ray's line meets the cylinder"),
    ("ahead", "the root ahead, before tbest"),
    ("height", "the hit within the height"),
];

/// Broadcast a cylinder's test (record at r7): the body (both runs for a
/// glass cylinder), then, where the records carry caps (`caps_on`), the caps
/// where its flag is set. Labels begin with `lbl`.
pub fn broadcast(t: &mut Code, lbl: &str, _fit: &Fit, sides: Sides, caps_on: bool) {
    let cap = planar::kernel_name(Inside::Disc, sides);
    let nocap = format!("{lbl}_nocap");
    let caps: [&str; 2] = match sides {
        Sides::Front => {
            let k = body_name(Body::Opaque);
            t.m("BCAST_REC", format!("{k}, r7, CYL_BODY")).c("the body");
            ["CYL_CAP0", "CYL_CAP1"]
        }
        Sides::Both => {
            let (f, b) = (body_name(Body::Outer), body_name(Body::Inner));
            t.m("BCAST_REC", format!("{f}, r7, CYL_BODY"))
                .c("the body's outside")
                .m("BCAST_REC", format!("{b}, r7, GCYL_INNER"))
                .c("its inside");
            ["GCYL_CAP0", "GCYL_CAP1"]
        }
    };
    if caps_on {
        super::caps(t, &nocap, R7, "CYL_CAPS", cap, caps);
    }
}

/// An opaque cylinder's caps (record at `rec`), where its flag is set
/// (after its body's run in parts, [`super::run_with_cut_contexts`]).
pub fn broadcast_caps(t: &mut Code, lbl: &str, rec: Reg) {
    let cap = planar::kernel_name(Inside::Disc, Sides::Front);
    super::caps(
        t,
        &format!("{lbl}_nocap"),
        rec,
        "CYL_CAPS",
        cap,
        ["CYL_CAP0", "CYL_CAP1"],
    );
}

/// After the division (`t` in r9, F the hit so far): the hit's axial
/// coordinate within `[-2, H + 2]`, then the normal `n2 = -(sg p2 / r +
/// sqrt(s) d2n)` across the axis, `n = n2.x e1 + n2.y e2` (from `TMP0..TMP4`)
/// into `HIT_N` and `t` into `tbest` where F; `cut`: the cut after the
/// height test (the opaque body's).
fn axial_and_normal(k: &mut K, cut: Option<&str>) {
    k.comment("axial coordinate of the hit");
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        let x = 11 + i;
        k.c(format!("ldacc r{o}, <<Q14"))
            .c(format!("mac r{x}, r9, r{d}, >>Q14"))
            .c(format!("rsb r{x}, fb0, r{x}"));
    }
    k.c("mul out, fb0, r11")
        .c("mac out, fb0, r12")
        .c("mac r14, fb0, r13, >>Q14")
        .note("z");
    k.c("(f) cmp.ge r14, #-2")
        .c("mov r15, fb0")
        .c("(f) cmp.le r14, r15")
        .note("F: within the height");
    if let Some(c) = cut {
        k.cut(c);
    }
    k.comment("normal: n2 = -(sg p2 / r + sqrt(s) d2n) across the axis, n = n2.x e1 + n2.y e2");
    k.c("(f) mov r7, r9")
        .c("mov r15, fb0")
        .c(format!("ld r8, [r0 + #{}]", ram::TMP4));
    for (x, pn, dn) in [(11, ram::TMP0, ram::TMP2), (12, ram::TMP1, ram::TMP3)] {
        k.c(format!("ld r{x}, [r0 + #{pn}]"))
            .c(format!("ld r13, [r0 + #{dn}]"))
            .c("mul out, r8, r13")
            .c(format!("mac r{x}, r15, r{x}, >>Q14"))
            .c(format!("neg r{x}, r{x}"));
    }
    for x in [13, 14, 15] {
        k.c("mul out, fb0, r11")
            .c(format!("mac r{x}, fb0, r12, >>Q14"));
    }
    for (i, x) in [13, 14, 15].into_iter().enumerate() {
        k.c(format!("(f) st r{x}, [#{}]", ram::HIT_N + i as u32));
    }
}

/// The cylinder ([`super::ChipPrimitive`]): an NFF or native cone of
/// equal radii.
pub struct Cylinder;

impl super::ChipPrimitive for Cylinder {
    fn names(&self) -> [&'static str; 2] {
        ["cylinder", "glass_cylinder"]
    }

    fn layout(&self, sides: Sides, fit: &Fit, _fan: usize, caps: bool) -> Layout {
        layout(fit, sides, caps)
    }

    fn kernels(&self, sides: Sides, g: &Gen, fit: &Fit) -> Vec<(&'static str, K)> {
        kernels(g, fit, sides)
    }

    fn broadcast(&self, sides: Sides, t: &mut Code, at: &str, fit: &Fit, caps: bool) {
        broadcast(t, at, fit, sides, caps)
    }

    fn cut_test(&self, sides: Sides, _fit: &Fit) -> Option<CutTest> {
        (sides == Sides::Front).then(|| CutTest {
            kernel: body_name(Body::Opaque),
            field: CYL_BODY.name,
            cuts: &CUTS,
            then: None,
        })
    }

    fn disc_caps(&self) -> bool {
        true
    }

    fn broadcast_after_cut_test(&self, sides: Sides, t: &mut Code, at: &str, rec: Reg, caps: bool) {
        if caps && sides == Sides::Front {
            broadcast_caps(t, at, rec);
        }
    }

    fn fit_header(&self, fit: &Fit) -> Vec<String> {
        let mut v = vec![
            define("KS_CYL", fit.ks_cyl, "cylinders: invr = 2^(Q14+KS_CYL) / r"),
            define("EP_CYL", fit.ep_cyl, "cylinders: extra fraction bits of p"),
        ];
        if fit.cyl_local {
            v.push(define(
                "KS_CYLL",
                fit.ks_cyll,
                "cylinders in frames of their own: invr = 2^(Q14+KS_CYLL) / r, r in the frame",
            ));
        }
        v
    }

    fn geometry(&self, shape: &Shape, _s: f64) -> Geometry {
        match shape.as_cone() {
            Some(c) => Geometry::Planars(caps(c.base, c.apex, c.base_radius.abs()).to_vec()),
            None => Geometry::None,
        }
    }

    fn fit(&self, scene: &Scene, _geo: &[Geometry], s: f64, f: &Fitter, fit: &mut Fit) {
        // Every cone-like object (cylinders and cones), and the cylinders.
        let cones = || scene.objects.iter().filter_map(|o| o.shape.as_cone());
        let cylinders = || cones().filter(|c| c.prim_type() == PrimType::Cylinder);
        let radii = cylinders().map(|c| c.base_radius.abs() * s);
        let base_radii = cones().map(|c| c.base_radius.abs() * s);
        (fit.ks_cyl, fit.ep_cyl) = self::fit(radii, base_radii, f);
        fit.cyl_inside = cylinders().any(|c| c.inside);
        // Local positions: opaque cylinders in frames of their own where
        // no cylinder has caps (their records then carry none,
        // `layout::records_carry_caps`).
        fit.cyl_local = fit.local && !cylinders().any(|c| c.caps);
        if fit.cyl_local {
            let local = cylinders().map(|c| (c.base, c.apex, c.base_radius));
            fit.ks_cyll = super::cylinder_local::fit_ks(local, s, f);
        }
    }

    fn test_cost(&self, g: &Gen, fit: &Fit) -> TestCost {
        if fit.cyl_local {
            return TestCost::of(&super::cylinder_local::kernel(g));
        }
        TestCost {
            each: planar::kernel(g, Inside::Disc, Sides::Front).len(),
            ..TestCost::of(&kernel(g, fit, Body::Opaque))
        }
    }

    /// The largest `t` errors: rays grazing the body, where the root's
    /// quadratic is flat (on the 32-bit chip too: its direction is Q1.30).
    fn error_bound(&self) -> ErrorBound {
        ErrorBound {
            t_lsb: [18.0, 64.0],
            mean_t_lsb: [1.5, 2.0],
            normal: [0.03, 1e-6],
        }
    }

    fn write(&self, w: &mut W, o: &Object) -> Result<(), RecordError> {
        let (Some(c), Geometry::Planars(discs)) = (o.shape.as_cone(), o.geometry) else {
            return Err(RecordError::mismatch("cylinder"));
        };
        if o.fit.cyl_local && o.sides == Sides::Front {
            super::cylinder_local::write(
                w,
                o.fit.ks_cyll,
                c.base,
                c.apex,
                c.base_radius,
                c.inside,
                o.id,
                o.mat,
            );
            return Ok(());
        }
        write(
            w,
            o.fit,
            o.sides,
            c.base,
            c.apex,
            c.base_radius,
            c.inside,
            o.caps.then_some((c.caps, &[discs[0], discs[1]])),
            o.id,
            o.mat,
        );
        Ok(())
    }
}
