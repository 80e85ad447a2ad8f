//! Local positions ([`super::Positions::Local`]): the shading's part.
//! Every ray's origin carries a remainder (`RAY_OL`, 2^-14 LSB) beside
//! the rounded origin in r1..r3: zero at the eye (on the format's grid
//! where the scene has curved objects, [`super::build`]), the remainder of
//! the hit point it leaves (`SH_PL`) for shadow and reflected rays. A
//! kernel that tests an object in a frame of its own (the sphere's,
//! [`super::primitives::sphere`]) leaves its hit point to 2^-14 LSB
//! (`HIT_PH`, `HIT_PL`) tagged with its `t` (`HIT_TL`); where the pass's
//! nearest hit is such a one (`tbest = HIT_TL`), [`post`] takes that point
//! for the hit being shaded instead of `o + t d`, which the scene's format
//! rounds to an LSB.

use super::emit::{Name, K};
use super::math::{remainder, Approx};
use super::memory_map::ram;

/// Whether the eye rays' kernel is [`eye`] (and the camera stream its):
/// local positions, or the 16-bit chip with fine normals (its eye rays'
/// Q1.14 directions then rounded once from the exact `v Y` instead of
/// normalised from the rounded `v`; the paper's traversal with coarse
/// normals keeps the paper's kernel and its cycles).
pub fn precise_eye(opt: &super::Options, fine_normals: bool) -> bool {
    opt.positions == super::Positions::Local
        || (opt.datapath == rtl::rc::Datapath::W16 && fine_normals)
}

/// `k_eye` for local positions: the tile's eye rays with their
/// directions to about 2^-27 (stream: px0, py0, eye.xyz, its remainder,
/// then per axis `B_L, C_L, A, A_L, B, C`, [`crate::tracer::layout`]'s
/// camera). `v = A + i B + j C` is summed exactly in the accumulator
/// (2^-KD) and split into `v_H` (Q2.13) and its remainder `v_R`
/// (2^-28); `Y = 1/|v|` (Q1.14) from the RSQ table and Newton steps on
/// `v_H`; the direction `v Y` (length within a few 2^-14 of 1, its
/// direction that of `v`) as `D_H` (Q1.14, r4..r6) and `D_L` (2^-27,
/// `RAY_DL`). The origin's remainder is the eye's (`RAY_OL`).
pub fn eye(nr: Approx, refract: bool, local: bool) -> K {
    let mut k = K::new();
    k.doc(
        "k_eye: the tile's eye rays, directions to 2^-27 (stream: px0, py0, eye.xyz, eye_l.xyz,\n\
         (B_L, C_L, A, A_L, B, C) per axis).\n\
         Out: r1..r3 = eye, RAY_OL its remainder, r4..r6 + RAY_DL = (A + i B + j C) / |.|\n\
         for pixel (px0 + col, py0 + row), r7 = C_INF; a new level (PASS_T0, COL = 0, SH_D), OUT_OBJ = -1.",
    );
    super::shading::eye_pixel(&mut k);
    for i in 0..3 {
        if local {
            k.c(format!("st fb0, [#{}]", ram::RAY_OL + i));
        } else {
            k.c("mov r13, fb0");
        }
    }
    k.note("the eye's remainder");
    for (a, v) in [10, 11, 12].into_iter().enumerate() {
        let a = a as u32;
        k.c("mul r13, fb0, r8, >>16")
            .note("i B_L")
            .c("mul r14, fb0, r9, >>16")
            .note("j C_L")
            .c("ldacc fb0, <<KD-Q13")
            .c("mac out, fb0, #1")
            .note("+ A_L")
            .c("mac out, r13, #1")
            .c("mac out, r14, #1")
            .c("mac out, fb0, r8")
            .c(format!("mac r{v}, fb0, r9, >>KD-Q13"))
            .note("v_H, Q2.13");
        remainder(&mut k, 13, v, 14, "KD-Q13");
        k.c("sll r13, r13, #28-KD")
            .c(format!("st r13, [#{}]", ram::TMP0 + a))
            .note("v_R, 2^-28");
    }
    unit_with_remainder(&mut k, nr, [10, 11, 12], ram::TMP0, [7, 13], local);
    super::shading::new_level_common(&mut k);
    k.c("movb r8, #-1").c(format!("st r8, [#{}]", ram::OUT_OBJ));
    if local {
        k.c(format!("st r8, [#{}]", ram::HIT_TL));
    }
    if refract {
        k.c(format!("st r8, [#{}]", ram::ORIG_OBJ))
            .c(format!("st r8, [#{}]", ram::HIT_BACK_OBJ))
            .note("no back hit yet in this pass");
    }
    k
}

/// Appended to the kernels that set up reflected rays: their origins'
/// remainders (the shaded hit point's, `SH_PL`), their directions'
/// (none: Q1.14) and no local hit yet (`HIT_TL = -1`). Clobbers r8.
pub fn origins(k: &mut K) {
    k.comment("local positions: the origins' remainders, no local hit yet");
    shadow_origins(k, true);
    k.c("movb r8, #-1").c(format!("st r8, [#{}]", ram::HIT_TL));
}

/// Appended to the kernels that set up refracted rays: they start at the
/// hit point as the refraction stack keeps it, rounded to the scene's
/// LSB (no remainder), with Q1.14 directions, and no local hit yet.
/// Clobbers r8.
pub fn refracted_origins(k: &mut K) {
    k.comment("local positions: the rounded origin's remainder (none), no local hit yet");
    k.c("movb r8, #0");
    for i in 0..3 {
        k.c(format!("st r8, [#{}]", ram::RAY_OL + i))
            .c(format!("st r8, [#{}]", ram::RAY_DL + i));
    }
    k.c("movb r8, #-1").c(format!("st r8, [#{}]", ram::HIT_TL));
}

/// The origins' remainders (the shaded hit point's), and with `dl` the
/// directions' (none: Q1.14; shadow rays towards a light not shifted
/// have theirs from [`shadow_direction`]). Shadow rays need no more:
/// their pass's hits are not shaded. Clobbers r8.
pub fn shadow_origins(k: &mut K, dl: bool) {
    for i in 0..3 {
        k.c(format!("ld r8, [r0 + #{}]", ram::SH_PL + i))
            .c(format!("st r8, [#{}]", ram::RAY_OL + i));
    }
    if dl {
        k.c("movb r8, #0");
        for i in 0..3 {
            k.c(format!("st r8, [#{}]", ram::RAY_DL + i));
        }
    }
}

/// In `k_shadow_rays` (local positions, a light not shifted), after
/// `tbest` (r7): the direction from the hit point with its remainder
/// (`SH_P` + `SH_PL` 2^-14) to the light, to 2^-27, as the eye rays'
/// ([`eye`]): `A = (L - P) 2^14 - PL` exact in the accumulator (`L - P`
/// in `TMP0..2`), taken `2^e` times finer (`e = clz(max |L - P|) - 2`,
/// -1..=13, its largest component in [2^13, 2^14): Q2.13) as `v_H` and
/// the bits below (`v_R`, 2^-15 of its LSB, as the eye's 2^-28), `Y =
/// 1/|v_H|` from the RSQ table and three Newton steps, and `D = v Y`:
/// `D_H` in r4..r6 (Q1.14), `D_L` in `RAY_DL` (2^-27). Clobbers r8..r15,
/// `TMP3..5`.
pub fn shadow_direction(k: &mut K, nr: Approx) {
    k.comment("local positions: D = (L - P - PL) / |.| to 2^-27 (P with its remainder)");
    for (i, x) in [8, 9, 10].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::TMP0 + i as u32));
    }
    k.c("abs r12, r8")
        .c("abs r13, r9")
        .c("max r12, r12, r13")
        .c("abs r13, r10")
        .c("max r12, r12, r13")
        .c("clz r12, r12")
        .c("sub r12, r12, #2")
        .c("min r12, r12, #13")
        .note("e")
        .c("add r13, r12, #2")
        .note("e + 2")
        .c("movb r14, #14")
        .c("sub r14, r14, r12")
        .note("14 - e");
    for (i, x) in [8, 9, 10].into_iter().enumerate() {
        let i = i as u32;
        k.c(format!("ld r15, [r0 + #{}]", ram::SH_PL + i))
            .c(format!("ldacc r{x}, <<Q14"))
            .c("msu out, r15, #1")
            .note("A = (L - P) 2^14 - PL")
            .c("acch r11")
            .c("accl r12")
            .c("asl r11, r11, r13")
            .c("srl r15, r12, r14")
            .c(format!("or r{x}, r11, r15"))
            .note("v_H = A 2^e >> 14, floored")
            .c("sll r12, r12, r13")
            .c("srl r12, r12, #1")
            .c(format!("st r12, [#{}]", ram::TMP3 + i))
            .note("v_R, the bits below, 2^-15 of v_H's LSB");
    }
    unit_with_remainder(k, nr, [8, 9, 10], ram::TMP3, [13, 11], true);
}

/// The unit direction of `v = v_H + v_R 2^-15` (`v_H` in registers `v`,
/// Q2.13 with its largest component in [2^13, 2^14); `v_R` in RAM from
/// `v_r`, 2^-28): `Y = 1/|v_H|` (r14, Q1.14) from the RSQ table and at
/// least three Newton steps (the direction's length within a few 2^-14
/// of one from the smallest table on; its direction is `v`'s whatever
/// `Y`), then `D = v Y` as `D_H` in r4..r6 (Q1.14) and, with `dl`, its
/// remainder in `RAY_DL` (2^-27). `one` is set to 1, `tmp` clobbered, as
/// are r13..r15.
fn unit_with_remainder(
    k: &mut K,
    nr: Approx,
    v: [u8; 3],
    v_r: Name,
    [one, tmp]: [u8; 2],
    dl: bool,
) {
    k.comment("Y = 1/|v_H| (Q1.14)");
    k.c(format!("mul out, r{}, r{}", v[0], v[0]))
        .c(format!("mac out, r{}, r{}", v[1], v[1]))
        .c(format!("mac r13, r{}, r{}, >>Q15", v[2], v[2]))
        .note("X = |v_H|^2, Q.11")
        .c("srl r14, r13, #RSQ_SHIFT")
        .c(format!("ld r14, [r14 + #{}]", ram::RSQ))
        .c(format!("ld r4, [r0 + #{}]", ram::C_ONE));
    for _ in 0..nr.newton_steps.max(3) {
        k.c("mul r15, r14, r14, >>Q14")
            .c("mul r15, r15, r13, >>Q11")
            .c("sub r15, r15, r4")
            .c("ldacc r14, <<Q15")
            .c("msu r14, r14, r15, >>Q15");
    }
    k.comment("D = v Y: D_H (Q1.14) and D_L (2^-27)");
    k.c(format!("movb r{one}, #1"));
    for (a, (x, d)) in v.into_iter().zip([4u8, 5, 6]).enumerate() {
        k.c(format!("ld r15, [r0 + #{}]", v_r + a as u32))
            .c("mul r15, r15, r14, >>Q15")
            .c(format!("mul out, r{x}, r14"))
            .c(format!("mac r{d}, r15, r{one}, >>Q13"));
        remainder(k, 15, d, tmp, "Q13");
        if dl {
            k.c(format!("st r15, [#{}]", ram::RAY_DL + a as u32));
        }
    }
}

/// In [`super::shading::post`], after `SH_P = o + t d`: `SH_PL = 0`, and
/// where the pass's nearest hit is a local one (F: a hit, `r7 =
/// HIT_TL`) its point and remainder. `hit`: the register that is nonzero
/// where the pass hit. Clobbers r8, r10, r11.
pub fn post(k: &mut K, hit: u8) {
    k.comment("a local hit (tbest = HIT_TL): its point to 2^-14 LSB");
    k.c("movb r10, #0");
    for i in 0..3 {
        k.c(format!("st r10, [#{}]", ram::SH_PL + i));
    }
    k.c(format!("ld r8, [r0 + #{}]", ram::HIT_TL))
        .c(format!("cmp.ne r{hit}, #0"))
        .c("(f) cmp.eq r8, r7")
        .note("F: the nearest hit is local");
    for i in 0..3 {
        k.c(format!("ld r10, [r0 + #{}]", ram::HIT_PH + i))
            .c(format!("(f) st r10, [#{}]", ram::SH_P + i))
            .c(format!("ld r11, [r0 + #{}]", ram::HIT_PL + i))
            .c(format!("(f) st r11, [#{}]", ram::SH_PL + i));
    }
}

/// The margin of a local record's bound on the ray's line ([`near`]),
/// LSB of the scene's format: the roundings of the centre and the origin
/// (up to 1 LSB per axis), of `b d` and `oc - b d` (0.5 per axis), what
/// the direction's remainder moves `b d` (up to 1 per axis), and the
/// distance along the ray that `b`'s rounding and the Q1.14 direction's
/// length leave in `oc - b d` (3, as [`crate::scene_image::local_exponent`]
/// allows for).
pub const NEAR_MARGIN: f64 = 8.0;

/// The bound a local record holds for [`near`]: a shape's extent `r`
/// (LSB) about its frame's centre and [`NEAR_MARGIN`], in whole LSB.
pub fn near_bound(r: f64) -> f64 {
    (r + NEAR_MARGIN).ceil()
}

/// In a local kernel, after `oc = c - o` (r8..r10) and `b = round(oc.d)`
/// (r11), before the frame: F where the ray's line passes within the
/// stream's bound `R` ([`near_bound`]) of the frame's centre, by `oc - b
/// d` in the scene's LSB (`|oc - b d|^2 <= R^2`, exact in the
/// accumulator; saturated far from the centre): a test of a few
/// contexts that rejects rays the frame's test would (the kernels' first
/// cut). Clobbers r12..r15.
pub fn near(k: &mut K) {
    k.comment("near: the line within R of the centre, in the scene's LSB");
    for (x, d, y) in [(8, 4, 12), (9, 5, 13), (10, 6, 14)] {
        k.c(format!("ldacc r{x}, <<Q14"))
            .c(format!("msu r{y}, r11, r{d}, >>Q14"));
    }
    k.note("oc - b d")
        .c("mov r15, fb0")
        .note("R")
        .c("mul out, r15, r15")
        .c("msu out, r12, r12")
        .c("msu out, r13, r13")
        .c("msu out, r14, r14")
        .c("acch r15")
        .c("cmp.ge r15, #0")
        .note("F: |oc - b d| <= R");
}

/// In a local kernel, after `oc = c - o` (r8..r10, the rounded centre
/// and origin) and `b = round(oc.d)` (r11), with the frame's shifts in
/// r14 (`e + 2`) and r15 (`14 - e`): `p = oc + cl - ol - b (d + dl)` in
/// 2^-14 LSB (the stream's `cl` per axis, `RAY_OL`, `RAY_DL`) taken into
/// the frame, `2^e` times finer than the scene's LSB: r8..r10 (saturated
/// far from the frame's centre). Clobbers r12, r13.
pub fn offset_in_frame(k: &mut K) {
    for (i, (x, d)) in [(8, 4), (9, 5), (10, 6)].into_iter().enumerate() {
        let i = i as u32;
        k.c(format!("ld r12, [r0 + #{}]", ram::RAY_OL + i))
            .c(format!("ld r13, [r0 + #{}]", ram::RAY_DL + i))
            .c("mul r13, r11, r13, >>Q13")
            .note("b dl")
            .c(format!("ldacc r{x}, <<Q14"))
            .c("mac out, fb0, #1")
            .note("+ cl")
            .c("msu out, r12, #1")
            .note("- ol")
            .c("msu out, r13, #1")
            .c(format!("msu out, r11, r{d}"))
            .note("- b d")
            .c("acch r12")
            .c("accl r13")
            .c("asl r12, r12, r14")
            .c("srl r13, r13, r15")
            .c(format!("or r{x}, r12, r13"))
            .note("p 2^e (saturated far from the frame)");
    }
}

/// The nearest hit a local kernel keeps, 2^-14 LSB ([`nearer`]): 1/32
/// LSB. A ray leaving a surface meets it again only where its origin's
/// error puts it behind (the entry root of a ray leaving a curved
/// surface lies behind its origin, a plane's back is not tested), and a
/// shadow ray from a floor a few LSB beside the point where a sphere
/// touches it meets the sphere under half an LSB away.
pub const NEAREST: i32 = 512;

/// In a local kernel: F kept where `t` (register `t`, the scene's LSB)
/// with its remainder (`rem`, 2^-14 LSB) lies more than [`NEAREST`]
/// ahead and is nearer than `tbest` (r7), told apart to 2^-14 LSB where
/// `tbest` is a local hit's (`HIT_TL`; one that is not has no
/// remainder); there `HIT_TL` and `HIT_TLL` take them. Clobbers `f` (F
/// on entry) and `tmp`.
pub fn nearer(k: &mut K, t: u8, rem: u8, f: u8, tmp: u8) {
    k.c(format!("movb r{f}, #0"))
        .c(format!("(f) movb r{f}, #1"));
    k.comment("t more than NEAREST ahead: min(max(t, -1), 1) 2^14 + rem");
    k.c(format!("min r{tmp}, r{t}, #1"))
        .c(format!("max r{tmp}, r{tmp}, #-1"))
        .c(format!("sll r{tmp}, r{tmp}, #14"))
        .c(format!("add r{tmp}, r{tmp}, r{rem}"))
        .c(format!("cmp.le r{tmp}, #{NEAREST}"))
        .c(format!("(f) movb r{f}, #0"));
    k.comment("t < tbest to 2^-14 LSB (a tbest not local has no remainder)");
    k.c(format!("ld r{tmp}, [r0 + #{}]", ram::HIT_TL))
        .c(format!("cmp.eq r{tmp}, r7"))
        .c(format!("ld r{tmp}, [r0 + #{}]", ram::HIT_TLL))
        .c(format!("(!f) movb r{tmp}, #0"))
        .c(format!("cmp.eq r{t}, r7"))
        .c(format!("(f) cmp.lt r{rem}, r{tmp}"))
        .c(format!("(!f) cmp.lt r{t}, r7"))
        .c(format!("(f) cmp.ne r{f}, #0"))
        .note("F: a hit ahead, nearer than tbest")
        .c(format!("(f) st r{t}, [#{}]", ram::HIT_TL))
        .c(format!("(f) st r{rem}, [#{}]", ram::HIT_TLL));
}

/// In a local kernel, after [`nearer`]: axis `i` of the hit point `c +
/// v 2^-e` (`op` "mac") or `c - v 2^-e` ("msu") to 2^-14 LSB, `v` in the
/// frame (register `v`), `2^(14-e)` in `scale`, the stream's centre and
/// its remainder (`c_i`, `cl_i`), and (`fine`) what `v`'s rounding left
/// in 2^-14 LSB (a register, added as `op` "mac" adds `v`): where F,
/// `HIT_PH` and `HIT_PL`. Clobbers `hi`, `lo`, `tmp`.
#[allow(clippy::too_many_arguments)]
pub fn hit_point_axis(
    k: &mut K,
    i: u32,
    op: &str,
    v: u8,
    fine: Option<u8>,
    scale: u8,
    [hi, lo, tmp]: [u8; 3],
) {
    k.c("ldacc fb0, <<Q14").c("mac out, fb0, #1");
    if let Some(f) = fine {
        k.c(format!("mac out, r{f}, #1"));
    }
    k.c(format!("{op} r{hi}, r{v}, r{scale}, >>Q14")).note("P");
    remainder(k, lo, hi, tmp, "Q14");
    k.note("its remainder")
        .c(format!("(f) st r{hi}, [#{}]", ram::HIT_PH + i))
        .c(format!("(f) st r{lo}, [#{}]", ram::HIT_PL + i));
}

/// After a plane's division ([`super::math::divide`]: `q = num 2^14 /
/// den` in `q`, the normalised divisor's reciprocal `rc` and its shift
/// `sh` left by it): the part of `t` the quotient leaves, in 2^-11 LSB
/// (within 16 LSB of `q`), into `out`. `num` with its remainder `num_l`
/// (2^-14 LSB) and `den` (Q1.14) with its remainder (2^-28), whose
/// product with `q` is in `q_den_l` (`q den_l 2^-14`), are the exact
/// numerator and denominator, which may differ from those `q` was divided
/// from by a few LSB: the residual `num 2^14 + num_l - q den - q den_l
/// 2^-14` is exact in the accumulator and divided by the same reciprocal,
/// so `q` + it is `t` to a few 2^-14 LSB whatever the division's error.
/// Clobbers `a`, `b` (`num_l` may be `b`).
pub fn quotient_rest(
    k: &mut K,
    [num, num_l, den, q_den_l, q, rc, sh]: [u8; 7],
    out: u8,
    [a, b]: [u8; 2],
) {
    k.comment("t's rest below q: (num 2^14 + num_l - q den) / den, 2^-11 LSB");
    k.c(format!("ldacc r{num}, <<Q14"))
        .c(format!("mac out, r{num_l}, #1"))
        .c(format!("msu out, r{q}, r{den}"))
        .c(format!("msu out, r{q_den_l}, #1"))
        .c(format!("acc r{a}, >>4"))
        .note("the residual / 16")
        .c(format!("mul out, r{a}, r{rc}"))
        .c(format!("acch r{out}"))
        .c(format!("accl r{b}"))
        .c(format!("add r{a}, r{sh}, #2"))
        .c(format!("sll r{out}, r{out}, r{a}"))
        .c(format!("rsb r{a}, r{sh}, #Q14"))
        .c(format!("srl r{b}, r{b}, r{a}"))
        .c(format!("or r{out}, r{out}, r{b}"))
        .note("(residual rc 2^sh) >> 14");
}

/// `t = q + rest 2^-11` (the LSB quotient `q`, its [`quotient_rest`]
/// `rest`) rounded to the scene's LSB into `t` and its remainder (2^-14
/// LSB) into `rem`. Clobbers `tmp`.
pub fn fine_t(k: &mut K, q: u8, rest: u8, [t, rem, tmp]: [u8; 3]) {
    k.c(format!("ldacc r{q}, <<Q14"))
        .c(format!("mac out, r{rest}, #8"))
        .c(format!("acc r{t}, >>Q14"))
        .note("t");
    remainder(k, rem, t, tmp, "Q14");
    k.note("its remainder, 2^-14 LSB");
}

/// In a kernel that has `t` (register `t`, the scene's LSB) with its
/// remainder (`rem`, 2^-14 LSB), after [`nearer`]: the hit point `o + t
/// d` to 2^-14 LSB, from the origin with its remainder (`RAY_OL`) and the
/// direction with its (`RAY_DL`): where F, `HIT_PH` and `HIT_PL`.
/// Clobbers the four `tmp`.
pub fn ray_point(k: &mut K, t: u8, rem: u8, [a, b, hi, lo]: [u8; 4]) {
    k.comment("the hit point o + t d, to 2^-14 LSB");
    for i in 0..3 {
        ray_point_axis(k, i, t, rem, [a, b, hi, lo]);
        k.c(format!("(f) st r{hi}, [#{}]", ram::HIT_PH + i))
            .c(format!("(f) st r{lo}, [#{}]", ram::HIT_PL + i));
    }
}

/// Axis `i` of [`ray_point`]'s point into `hi` (the scene's LSB) and `lo`
/// (its remainder, 2^-14 LSB). Clobbers `a`, `b`.
pub fn ray_point_axis(k: &mut K, i: u32, t: u8, rem: u8, [a, b, hi, lo]: [u8; 4]) {
    let (o, d) = (1 + i, 4 + i);
    k.c(format!("ld r{a}, [r0 + #{}]", ram::RAY_OL + i))
        .c(format!("ld r{b}, [r0 + #{}]", ram::RAY_DL + i))
        .c(format!("mul r{b}, r{t}, r{b}, >>Q13"))
        .note("t dl")
        .c(format!("mul r{lo}, r{rem}, r{d}, >>Q14"))
        .note("t's remainder d")
        .c(format!("ldacc r{o}, <<Q14"))
        .c(format!("mac out, r{a}, #1"))
        .note("+ ol")
        .c(format!("mac out, r{b}, #1"))
        .c(format!("mac out, r{lo}, #1"))
        .c(format!("mac r{hi}, r{t}, r{d}, >>Q14"))
        .note("P");
    remainder(k, lo, hi, a, "Q14");
    k.note("its remainder");
}
