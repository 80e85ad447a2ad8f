//! Open cone with unequal radii and optional end caps
//! (`scene/shape/cone.rs`; the caps `disc`).
//!
//! **Record**: a caps flag (`CONE_CAPS`), the body (`CONE_BODY`, 40
//! words), the two caps as disc records (`CONE_CAP0`, `CONE_CAP1`; a cap
//! of a pointed end never hits). A glass cone's record holds the body
//! twice (`sg`, then `-sg`: `GCONE_INNER`) before its caps. Under the
//! packet traversal, where no cone of the scene has caps, the record is
//! the body (or bodies) alone: no flag, no discs. The body:
//! `M.xyz, invS, ce1.xyz, ce2.xyz, a.xyz, ce1.xyz, ce2.xyz, a.xyz, s, g,
//! sg, R, hh, -sg c, -sg s, (e1, e2, a) x, (e1, e2, a) y, (e1, e2, a) z,
//! obj, mat`: M the middle of the axis, R (scene LSBs) at least the radius
//! of the cone's bounding sphere about M, `S = 2 R` the kernel's unit,
//! `invS = 2^(14+KS_CONE) / S`; (e1, e2, a) an orthonormal frame, a from
//! base to apex, `ce1 = c e1`, `ce2 = c e2` with `c = cos`, `s = sin` of
//! the half-angle (`tan = (ra - rb) / h`); `g = c (rb + ra) / 2 / S`, `hh`
//! half the height (plus 1 LSB) over S, all Q.14; `sg` +-1 (NFF's
//! inside-visible cone).
//!
//! **Method**: the sphere's perpendicular method against the bounding
//! sphere (`b = (M - o).d`, `w = ((M - o) - b d) / S`, miss where `|w| >
//! 1/4`) moves the ray's origin to `o' = o + b d`, the point of its line
//! closest to M; every quantity from there on is a Q.14 multiple of S
//! bounded by 1, however far the ray came from. In the cone's frame, with
//! `q = o' - M`, `G = c rho(q_z)` (`= g + s q_z`, the radius at q's
//! height, scaled by c): `f(tau) = c^2 |q_perp + tau d_perp|^2 - (G + s
//! tau d_z)^2 = A tau^2 + 2 B tau + C` (each coefficient one accumulator
//! chain, all |.| <= 1), times `sg`. The visible side is where `f` falls
//! along the ray, the root with `A tau + B = -sqrt(D)`, `D = B^2 - A C`,
//! taken without cancellation: `tau = -(B + sqrt D) / A` where `B > 0`,
//! else `C / (sqrt D - B)`, by division after checking `|tau| <= 1/2` (a
//! hit lies within `S / 4` of `o'`); so a ray parallel to the surface (`A
//! = 0`) or down a steep cone (`A < 0`) needs no special case. `t = b + S
//! tau`; the hit's height `|q_z + tau d_z| <= hh`; the normal is the
//! gradient `sg (c^2 p_perp, -s c rho)` at the hit, normalised, in the
//! scene's axes.
//!
//! **Two-sided** (a transmitting cone): as the cylinder's, one run per
//! copy of the body, roots more than `SELF_LSB` ahead.
//!
//! **Registers**: r1..r7 the ray (r7 the new `tbest` where F); r8..r15
//! temporaries; RAM `TMP0..TMP4`, `CONE_TMP` (8 words).
//!
//! **Error** against the f64 cone: its `error_bound` (below), which
//! `tb/tests/kernels.rs` holds both chips to on a cone, a steep one and a
//! nearly cylindrical one seen from inside.

use super::super::emit::{define, Code, Reg, K, R7};
use super::super::math::{divide_q13, normalize, sqrt_q14, Approx};
use super::super::memory_map::ram;
use super::planar::{self, Inside, Planar};
use super::record::{Field, Fitter, Layout, W};
use super::{
    commit_obj_mat, perpendicular, self_margin, Body, CutTest, ErrorBound, Fit, Gen, Geometry,
    Object, RecordError, Sides, TestCost,
};
use crate::scene::{PrimType, Scene, Shape, Surface, Vec3};

/// Words of the body.
pub const BODY_WORDS: usize = 40;

/// The record's fields: the caps flag, the body (twice for a glass cone:
/// the second seen from inside), the caps' discs.
pub const CONE_CAPS: Field = Field::named("CONE_CAPS", "cone record: caps flag");
pub const CONE_BODY: Field = Field::named("CONE_BODY", "cone record: the body's stream");
pub const GCONE_INNER: Field = Field::named("GCONE_INNER", "glass cone record: the inner body");
pub const CONE_CAP0: Field = Field::named("CONE_CAP0", "cone record: base cap (a disc)");
pub const CONE_CAP1: Field = Field::named("CONE_CAP1", "cone record: apex cap");
pub const GCONE_CAP0: Field = Field::named("GCONE_CAP0", "glass cone record: base cap");
pub const GCONE_CAP1: Field = Field::named("GCONE_CAP1", "glass cone record: apex cap");

/// The record of `s`: caps flag, body (twice for a glass cone), caps;
/// without `caps` (records that carry none) the body alone.
pub fn layout(fit: &Fit, s: Sides, caps: bool) -> Layout {
    if fit.cone_local && s == Sides::Front {
        // No caps whatever `caps` says, as the local cylinder's.
        return super::cone_local::layout();
    }
    let glass = s == Sides::Both;
    let mut l = Vec::new();
    if caps {
        l.push((CONE_CAPS, 1));
    }
    l.push((CONE_BODY, BODY_WORDS));
    if glass {
        l.push((GCONE_INNER, BODY_WORDS));
    }
    if caps {
        let (c0, c1) = if glass {
            (GCONE_CAP0, GCONE_CAP1)
        } else {
            (CONE_CAP0, CONE_CAP1)
        };
        l.extend([(c0, planar::WORDS), (c1, planar::WORDS)]);
    }
    Layout(l)
}

fn body_name(b: Body) -> &'static str {
    match b {
        Body::Opaque => "k_cone",
        Body::Outer => "k_glass_cone_out",
        Body::Inner => "k_glass_cone_in",
    }
}

/// The kernels of a cone's test, in load order: the body run(s), the caps'
/// disc.
pub fn kernels(g: &Gen, fit: &Fit, s: Sides) -> Vec<(&'static str, K)> {
    let cap = planar::kernel_name(Inside::Disc, s);
    if fit.cone_local && s == Sides::Front {
        return vec![(body_name(Body::Opaque), super::cone_local::kernel(g))];
    }
    match s {
        Sides::Front => vec![
            (body_name(Body::Opaque), kernel(g, Body::Opaque)),
            (cap, planar::kernel(g, Inside::Disc, s)),
        ],
        Sides::Both => vec![
            (body_name(Body::Outer), kernel(g, Body::Outer)),
            (body_name(Body::Inner), kernel(g, Body::Inner)),
            (cap, planar::kernel(g, Inside::Disc, s)),
        ],
    }
}

/// A cone's record geometry, in scene LSBs where not a ratio.
#[derive(Clone, Copy, Debug)]
pub struct ConeFit {
    /// The middle of the axis, rounded to the scene format (LSBs).
    pub m_q: Vec3,
    pub e1: Vec3,
    pub e2: Vec3,
    pub a: Vec3,
    /// Cosine and sine of the half-angle, `tan = (ra - rb) / h`.
    pub c: f64,
    pub s: f64,
    /// Bounding radius about `m_q` (whole LSBs) and the kernel's unit 2 R.
    pub r: f64,
    pub big_s: f64,
    /// `c (rb + ra) / 2 / S` and `(h / 2 + 1 LSB) / S`.
    pub g: f64,
    pub hh: f64,
}

impl ConeFit {
    /// The cone from `base` (radius `rb`) to `apex` (radius `ra`) in the
    /// scene format of scale `scale` (LSBs per unit).
    pub fn of(base: Vec3, rb: f64, apex: Vec3, ra: f64, scale: f64) -> ConeFit {
        ConeFit::with_margin(base, rb, apex, ra, scale, 2.0)
    }

    /// [`ConeFit::of`] with the bounding radius `margin` LSB more than
    /// the cone's extent about its exact middle (`of`: 2).
    pub fn with_margin(
        base: Vec3,
        rb: f64,
        apex: Vec3,
        ra: f64,
        scale: f64,
        margin: f64,
    ) -> ConeFit {
        let axis = apex - base;
        let h = axis.length();
        let a = axis * (1.0 / h);
        let e1 = perpendicular(a);
        let e2 = a.cross(e1);
        let alpha = ((ra - rb) / h).atan();
        let (c, s) = (alpha.cos(), alpha.sin());
        let m = (base + apex) * 0.5;
        let m_q = Vec3::new(
            (m.x * scale).round(),
            (m.y * scale).round(),
            (m.z * scale).round(),
        );
        // The cone lies within sqrt((h/2)^2 + max(rb, ra)^2) of its exact
        // middle; the margin covers the rounding of M and of the ray's
        // point nearest it.
        let bound = ((h / 2.0).powi(2) + rb.max(ra).powi(2)).sqrt() * scale;
        let r = (bound + margin).ceil();
        let big_s = 2.0 * r;
        ConeFit {
            m_q,
            e1,
            e2,
            a,
            c,
            s,
            r,
            big_s,
            g: c * (rb + ra) / 2.0 * scale / big_s,
            hh: (h / 2.0 * scale + 1.0) / big_s,
        }
    }

    /// The caps as discs (a pointed end's never hits).
    pub fn caps(&self, base: Vec3, rb: f64, apex: Vec3, ra: f64, scale: f64) -> [Planar; 2] {
        let disc_or_none = |c: Vec3, r: f64, n: Vec3| {
            if r * scale >= 0.5 {
                Planar::disc(c, self.e1, self.e2, r, n)
            } else {
                Planar::never(c, Inside::Disc)
            }
        };
        [
            disc_or_none(base, rb, -self.a),
            disc_or_none(apex, ra, self.a),
        ]
    }
}

/// The scale shifts of the cones, of their fits: `(KS_CONE, EP_CONE)`:
/// `invS` fits for the smallest S; the perpendicular vector saturates only
/// beyond twice the largest R.
pub(crate) fn fit(fits: impl Iterator<Item = ConeFit> + Clone, f: &Fitter) -> (u32, u32) {
    let s_min = fits.clone().map(|c| c.big_s).fold(f64::INFINITY, f64::min);
    let r_max = fits.map(|c| c.r).fold(1.0f64, f64::max);
    (f.ks(s_min), f.shift(2.0 * r_max, 4))
}

/// Write the record of a cone of fit `cf` and caps `caps` (whether they
/// are on, the discs; `None`: the record carries no caps); an error where
/// the cone is too large for the kernel beside the scene's smallest cone.
#[allow(clippy::too_many_arguments)]
pub(crate) fn write(
    w: &mut W,
    fit: &Fit,
    sides: Sides,
    cf: &ConeFit,
    inside: bool,
    caps: Option<(bool, &[Planar; 2])>,
    id: usize,
    mat: usize,
) -> Result<(), String> {
    let inv_s = ((14 + w.x + fit.ks_cone) as f64).exp2() / cf.big_s;
    if inv_s < 256.0 || cf.r > 16383.0 * (w.x as f64).exp2() {
        return Err(format!(
            "cone too large for the chip's cone kernel next to the scene's smallest cone (bounding radius {:.0} LSB)",
            cf.r
        ));
    }
    let sg = if inside { -1.0 } else { 1.0 };
    let one = w.one();
    if let Some((on, _)) = caps {
        w.field(CONE_CAPS);
        w.raw(on as i64);
    }
    // A transmitting cone: the body twice, the second seen from the other
    // side.
    let copies: &[f64] = if sides == Sides::Both {
        &[1.0, -1.0]
    } else {
        &[1.0]
    };
    for (&side, field) in copies.iter().zip([CONE_BODY, GCONE_INNER]) {
        w.field(field);
        let sg = sg * side;
        w.push(cf.m_q.x);
        w.push(cf.m_q.y);
        w.push(cf.m_q.z);
        w.push(inv_s);
        for _ in 0..2 {
            w.scaled(cf.e1, one * cf.c);
            w.scaled(cf.e2, one * cf.c);
            w.unit(cf.a);
        }
        w.push(one * cf.s);
        w.push(one * cf.g);
        w.push(one * sg);
        w.raw(cf.r as i64);
        w.push(one * cf.hh);
        w.push(one * -sg * cf.c);
        w.push(one * -sg * cf.s);
        for c in 0..3 {
            w.push(one * cf.e1.axis(c));
            w.push(one * cf.e2.axis(c));
            w.push(one * cf.a.axis(c));
        }
        w.raw(id as i64);
        w.raw(mat as i64);
    }
    let cap_fields = if sides == Sides::Both {
        [GCONE_CAP0, GCONE_CAP1]
    } else {
        [CONE_CAP0, CONE_CAP1]
    };
    for (p, field) in caps.into_iter().flat_map(|(_, c)| c).zip(cap_fields) {
        w.field(field);
        let mut p = *p;
        p.n = p.n * sg;
        planar::write(w, &fit.kt, &p, id, mat);
    }
    Ok(())
}

/// One run of the cone body kernel.
pub fn kernel(g: &Gen, body: Body) -> K {
    let nr = g.approx;
    let mut k = K::new();
    k.doc(&format!(
        "{}: the open cone test of one body record (the stream){}.\n\
         In: r1..r3 o, r4..r6 d, r7 tbest. Out where F: r7 = t, HIT_N, HIT_OBJ, HIT_MAT{}.\n\
         o' = o + b d (nearest M), q = o' - M in the cone's frame, f(tau) = A tau^2 + 2B tau + C,\n\
         tau = -(B + sqrt D) / A or C / (sqrt D - B), t = b + S tau, |q_z + tau d_z| <= hh.",
        body_name(body),
        match body {
            Body::Opaque => "",
            Body::Outer => ", a glass cone's outer surface",
            Body::Inner => ", a glass cone's inner surface (its second body)",
        },
        if body == Body::Opaque {
            ""
        } else {
            ", HIT_BACK_OBJ"
        },
    ));
    let opaque = body == Body::Opaque;
    bounding_sphere(&mut k);
    if opaque {
        k.cut(CUTS[0].0);
    }
    // b for the root, stored past the cut (a test cut there spends no store).
    k.c(format!("st r11, [#{}]", ram::TMP0)).note("b");
    frame(&mut k);
    quadratic(&mut k, nr, opaque.then_some(CUTS[1].0));
    root(&mut k, g, body);
    if opaque {
        k.cut(CUTS[2].0);
    }
    height(&mut k);
    normal(&mut k, nr);
    commit_obj_mat(&mut k, body);
    k
}

/// The opaque body kernel's cuts ([`K::cut`]) and what F holds at each.
pub const CUTS: [(&str, &str); 3] = [
    ("sphere", "the ray's line meets the bounding sphere"),
    ("real", "and the cone's quadratic has real roots"),
    (
        "ahead",
        "the root ahead, before tbest, within the bounding sphere",
    ),
];

/// Broadcast a cone's test (record at r7): the body (both runs for a glass
/// cone), then, where the records carry caps (`caps_on`), the caps where
/// its flag is set. Labels begin with `lbl`.
pub fn broadcast(t: &mut Code, lbl: &str, sides: Sides, caps_on: bool) {
    let cap = planar::kernel_name(Inside::Disc, sides);
    let nocap = format!("{lbl}_nocap");
    let caps: [&str; 2] = match sides {
        Sides::Front => {
            let k = body_name(Body::Opaque);
            t.m("BCAST_REC", format!("{k}, r7, CONE_BODY"))
                .c("the body");
            ["CONE_CAP0", "CONE_CAP1"]
        }
        Sides::Both => {
            let (f, b) = (body_name(Body::Outer), body_name(Body::Inner));
            t.m("BCAST_REC", format!("{f}, r7, CONE_BODY"))
                .c("the body's outside")
                .m("BCAST_REC", format!("{b}, r7, GCONE_INNER"))
                .c("its inside");
            ["GCONE_CAP0", "GCONE_CAP1"]
        }
    };
    if caps_on {
        super::caps(t, &nocap, R7, "CONE_CAPS", cap, caps);
    }
}

/// An opaque cone's caps (record at `rec`), where its flag is set (after
/// its body's run in parts, [`super::run_with_cut_contexts`]).
pub fn broadcast_caps(t: &mut Code, lbl: &str, rec: Reg) {
    let cap = planar::kernel_name(Inside::Disc, Sides::Front);
    super::caps(
        t,
        &format!("{lbl}_nocap"),
        rec,
        "CONE_CAPS",
        cap,
        ["CONE_CAP0", "CONE_CAP1"],
    );
}

/// The bounding sphere: `b = (M - o).d` (r11), `w = ((M - o) - b d) / S`
/// (r8..r10); F where the line meets the sphere (`|w| <= 1/4`).
fn bounding_sphere(k: &mut K) {
    k.comment("bounding sphere about M: b = (M - o).d, p = (M - o) - b d");
    super::sphere::oc_and_b(k, "b");
    for (x, d) in [(8, 4), (9, 5), (10, 6)] {
        k.c(format!("ldacc r{x}, <<Q14"))
            .c(format!("msu r{x}, r11, r{d}, >>Q14-EP_CONE"));
    }
    meets_bound(k, "KS_CONE+EP_CONE");
}

/// `w = p / S` (r8..r10: `p` times the stream's `invS`, shifted by
/// `shift`); F where the line meets the bounding sphere (`|w| <= 1/2`).
/// Clobbers r12, r15.
pub(super) fn meets_bound(k: &mut K, shift: &str) {
    k.c("mov r12, fb0").note("invS");
    for x in [8, 9, 10] {
        k.c(format!("mul r{x}, r{x}, r12, >>{shift}"));
    }
    k.note("w = p / S");
    k.c("movb r15, #1")
        .c("ldacc r15, <<2*Q13")
        .c("msu out, r8, r8")
        .c("msu out, r9, r9")
        .c("msu r15, r10, r10, >>Q14")
        .note("1/4 - |w|^2")
        .c("cmp.ge r15, #0")
        .note("F: the line meets the bounding sphere");
}

/// The cone's frame: `c q_perp`, `G` (zoomed into [1/8, 1/4) by `2^e`) and `c d_perp`,
/// `s dz` into `CONE_TMP`, `TMP1`, `TMP2`.
pub(super) fn frame(k: &mut K) {
    let ct = ram::CONE_TMP;
    k.comment(
        "frame: w.ce1 = -c qx, w.ce2 = -c qy, w.a = -qz; d.ce1 = c dx, d.ce2 = c dy, d.a = dz",
    );
    for x in [12, 13, 14] {
        k.c("mul out, fb0, r8")
            .c("mac out, fb0, r9")
            .c(format!("mac r{x}, fb0, r10, >>Q14"));
    }
    for x in [8, 9, 10] {
        k.c("mul out, fb0, r4")
            .c("mac out, fb0, r5")
            .c(format!("mac r{x}, fb0, r6, >>Q14"));
    }
    k.c(format!("st r14, [#{}]", ram::TMP1))
        .c(format!("st r10, [#{}]", ram::TMP2))
        .c("mov r11, fb0")
        .note("s")
        .c("mul r10, r10, r11, >>Q14")
        .note("s dz")
        .c("mul r14, r14, r11, >>Q14")
        .note("-s qz")
        .c("sub r14, fb0, r14")
        .note("G = g + s qz");
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
        .c("neg r11, r11")
        .note("max(-e, 0)")
        .c("max r15, r15, #0")
        .note("max(e, 0)")
        .c(format!("st r15, [#{}]", ct + 6))
        .c(format!("st r11, [#{}]", ct + 7));
    for x in [12, 13, 14] {
        k.c(format!("sll r{x}, r{x}, r15"))
            .c(format!("sra r{x}, r{x}, r11"));
    }
    for (i, x) in [8, 9, 10, 12, 13, 14].into_iter().enumerate() {
        k.c(format!("st r{x}, [#{}]", ct + i as u32));
    }
}

/// The quadratic `A tau^2 + 2 B tau + C` (zoomed), times `sg`, its discriminant and
/// `sqrt(4D)` (r8); with `cut`, the kernel's cut of that name before the
/// square root.
pub(super) fn quadratic(k: &mut K, nr: Approx, cut: Option<&str>) {
    k.comment("A, -2B, 4C (zoomed: 2^e B, 2^2e C), times sg; 4D = 4B^2 - 4A C");
    k.c("mul out, r8, r8")
        .c("mac out, r9, r9")
        .c("msu r15, r10, r10, >>Q14")
        .note("A")
        .c("mul out, r8, r12")
        .c("mac out, r9, r13")
        .c("mac r11, r10, r14, >>Q13")
        .note("-2B")
        .c("mul out, r12, r12")
        .c("mac out, r13, r13")
        .c("msu r12, r14, r14, >>Q12")
        .note("4C")
        .c("mov r13, fb0")
        .note("sg")
        .c("mul r15, r15, r13, >>Q14")
        .c("mul r11, r11, r13, >>Q14")
        .c("mul r12, r12, r13, >>Q14")
        .c("mul out, r11, r11")
        .c("msu r14, r15, r12, >>Q14")
        .note("D")
        .c("(f) cmp.ge r14, #0");
    if let Some(c) = cut {
        k.cut(c);
    }
    k.c(format!("st r15, [#{}]", ram::TMP3)).note("A");
    sqrt_q14(k, 14, 8, [9, 10, 13, 15], nr);
}

/// The visible root `tau`, then `t = b + S tau` (r11, `TMP4`) where it is ahead and
/// nearer than `tbest`.
fn root(k: &mut K, g: &Gen, body: Body) {
    root_tau(k, g);
    k.c(format!("ld r11, [r0 + #{}]", ram::TMP0))
        .c("ldacc r11, <<Q13")
        .c("mac r11, fb0, r13, >>Q13")
        .note("t = b + S tau");
    if body != Body::Opaque {
        self_margin(k, 12, g.datapath);
        k.c("(f) cmp.gt r11, r12");
    } else {
        k.c("(f) cmp.gt r11, #0");
    }
    k.c("(f) cmp.lt r11, r7")
        .c(format!("st r11, [#{}]", ram::TMP4));
}

/// The visible root: `tau` (r13, Q.14 of S) and `2^e tau` (r10), F kept
/// where `|tau| < 1/2` (a hit within the bounding sphere). Clobbers r8,
/// r9, r11, r12, r14, r15.
pub(super) fn root_tau(k: &mut K, g: &Gen) {
    let ct = ram::CONE_TMP;
    let nr = g.approx;
    k.comment("tau' = 2^e tau = X / 2Y: B > 0: -(2B + sqrt 4D) / 2A, else 4C / 2(sqrt 4D - 2B)");
    k.c("movb r9, #0")
        .c("(f) movb r9, #1")
        .c("cmp.lt r11, #0")
        .c(format!("ld r10, [r0 + #{}]", ram::TMP3))
        .c("sub r13, r11, r8")
        .c("add r14, r11, r8")
        .c("sel r13, r13, r12")
        .note("N")
        .c("sel r14, r10, r14")
        .note("Den")
        .c("xor r12, r13, r14")
        .c("sra r12, r12, #Q15")
        .note("-1 where tau < 0")
        .c("abs r10, r13")
        .c("abs r15, r14")
        .c("cmp.ne r9, #0")
        .c("(f) cmp.gt r15, #0")
        .c("asl r11, r15, #2")
        .c("(f) cmp.lt r10, r11")
        .note("|tau'| < 2");
    divide_q13(k, 10, 15, 10, [8, 9, 11, 13, 14], nr);
    k.c("xor r10, r10, r12").c("sub r10, r10, r12").note("tau'");
    k.comment("tau = tau' / 2^e (rounded); t = b + S tau, S = 2 R");
    k.c(format!("ld r11, [r0 + #{}]", ct + 6))
        .c("movb r12, #1")
        .c("sll r12, r12, r11")
        .c("sra r12, r12, #1")
        .c("adds r13, r10, r12")
        .c("sra r13, r13, r11")
        .c(format!("ld r11, [r0 + #{}]", ct + 7))
        .c("asl r13, r13, r11")
        .note("tau")
        .c("abs r12, r13")
        .c("sra r12, r12, #Q13")
        .c("(f) cmp.eq r12, #0")
        .note("|tau| < 1/2: within the bounding sphere");
}

/// The hit's height within the cone: F kept where `|q_z + tau d_z| <= hh`.
pub(super) fn height(k: &mut K) {
    k.comment("height of the hit: |qz + tau dz| <= hh");
    k.c(format!("ld r12, [r0 + #{}]", ram::TMP1))
        .c(format!("ld r14, [r0 + #{}]", ram::TMP2))
        .c("ldacc r12, <<Q14")
        .c("msu r12, r13, r14, >>Q14")
        .c("abs r12, r12")
        .c("(f) cmp.ge fb0, r12");
}

/// The gradient at the hit, normalised, in the scene's axes: `HIT_N`, `tbest`.
pub(super) fn normal(k: &mut K, nr: Approx) {
    let ct = ram::CONE_TMP;
    k.comment("normal: sg (c (c q_perp + tau c d_perp), -s (G + tau s dz)), zoomed, halved");
    for (x, qa, da) in [(8, 3, 0), (9, 4, 1)] {
        k.c(format!("ld r{x}, [r0 + #{}]", ct + qa))
            .c(format!("ld r13, [r0 + #{}]", ct + da))
            .c(format!("ldacc r{x}, <<Q14"))
            .c(format!("msu r{x}, r10, r13, >>Q15"))
            .note("-(c q + tau c d) / 2");
    }
    k.c(format!("ld r11, [r0 + #{}]", ct + 5))
        .c(format!("ld r13, [r0 + #{}]", ct + 2))
        .c("ldacc r11, <<Q14")
        .c("mac r11, r10, r13, >>Q15")
        .note("c rho / 2 at the hit")
        .c("mov r13, fb0")
        .note("-sg c")
        .c("mul r8, r8, r13, >>Q14")
        .c("mul r9, r9, r13, >>Q14")
        .c("mul r10, fb0, r11, >>Q14")
        .note("-sg s c rho");
    normalize(k, &[8, 9, 10], [11, 12, 13, 14, 15], false, nr);
    for x in [11, 12, 13] {
        k.c("mul out, fb0, r8")
            .c("mac out, fb0, r9")
            .c(format!("mac r{x}, fb0, r10, >>Q14"));
    }
    k.c(format!("ld r14, [r0 + #{}]", ram::TMP4))
        .c("(f) mov r7, r14");
    for (i, x) in [11, 12, 13].into_iter().enumerate() {
        k.c(format!("(f) st r{x}, [#{}]", ram::HIT_N + i as u32));
    }
}

/// The cone ([`super::ChipPrimitive`]): an NFF or native cone of unequal
/// radii.
pub struct Cone;

impl super::ChipPrimitive for Cone {
    fn names(&self) -> [&'static str; 2] {
        ["cone", "glass_cone"]
    }

    fn layout(&self, sides: Sides, fit: &Fit, _fan: usize, caps: bool) -> Layout {
        layout(fit, sides, caps)
    }

    fn kernels(&self, sides: Sides, g: &Gen, fit: &Fit) -> Vec<(&'static str, K)> {
        kernels(g, fit, sides)
    }

    fn broadcast(&self, sides: Sides, t: &mut Code, at: &str, _fit: &Fit, caps: bool) {
        broadcast(t, at, sides, caps)
    }

    fn cut_test(&self, sides: Sides, _fit: &Fit) -> Option<CutTest> {
        (sides == Sides::Front).then(|| CutTest {
            kernel: body_name(Body::Opaque),
            field: CONE_BODY.name,
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
            define("KS_CONE", fit.ks_cone, "cones: invS = 2^(Q14+KS_CONE) / S"),
            define("EP_CONE", fit.ep_cone, "cones: extra fraction bits of p"),
        ];
        if fit.cone_local {
            v.push(define(
                "KS_CONEL",
                fit.ks_conel,
                "cones in frames of their own: invS = 2^(Q14+KS_CONEL) / S, S in the frame",
            ));
        }
        v
    }

    fn geometry(&self, shape: &Shape, s: f64) -> Geometry {
        let Some(c) = shape.as_cone() else {
            return Geometry::None;
        };
        let (base, base_radius, apex, apex_radius) = (c.base, c.base_radius, c.apex, c.apex_radius);
        let f = ConeFit::of(base, base_radius, apex, apex_radius, s);
        let caps = f.caps(base, base_radius, apex, apex_radius, s);
        Geometry::Cone(Box::new((f, caps)))
    }

    fn fit(&self, scene: &Scene, geo: &[Geometry], s: f64, f: &Fitter, fit: &mut Fit) {
        let fits = geo.iter().filter_map(|g| match g {
            Geometry::Cone(fc) => Some(fc.0),
            _ => None,
        });
        (fit.ks_cone, fit.ep_cone) = self::fit(fits, f);
        // Local positions: opaque cones in frames of their own where no
        // cone has caps (their records then carry none).
        let cones = || {
            scene
                .objects
                .iter()
                .filter_map(|o| o.shape.as_cone())
                .filter(|c| c.prim_type() == PrimType::Cone)
        };
        fit.cone_local = fit.local && !cones().any(|c| c.caps);
        if fit.cone_local {
            let local = cones().map(|c| (c.base, c.base_radius, c.apex, c.apex_radius));
            fit.ks_conel = super::cone_local::fit_ks(local, s, f);
        }
    }

    fn test_cost(&self, g: &Gen, fit: &Fit) -> TestCost {
        if fit.cone_local {
            return TestCost::of(&super::cone_local::kernel(g));
        }
        TestCost {
            each: planar::kernel(g, Inside::Disc, Sides::Front).len(),
            ..TestCost::of(&kernel(g, Body::Opaque))
        }
    }

    /// The largest `t` errors: rays grazing along a generator.
    fn error_bound(&self) -> ErrorBound {
        ErrorBound::lsb(24.0, 0.03)
    }

    fn write(&self, w: &mut W, o: &Object) -> Result<(), RecordError> {
        let (Some(c), Geometry::Cone(fc)) = (o.shape.as_cone(), o.geometry) else {
            return Err(RecordError::mismatch("cone"));
        };
        if o.fit.cone_local && o.sides == Sides::Front {
            return super::cone_local::write(
                w,
                o.fit.ks_conel,
                (c.base, c.base_radius),
                (c.apex, c.apex_radius),
                c.inside,
                o.id,
                o.mat,
            )
            .map_err(RecordError::Object);
        }
        write(
            w,
            o.fit,
            o.sides,
            &fc.0,
            c.inside,
            o.caps.then_some((c.caps, &fc.1)),
            o.id,
            o.mat,
        )
        .map_err(RecordError::Object)
    }
}
