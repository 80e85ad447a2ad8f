//! The RC kernels around the ray passes: start-up (tables, lanes), eye
//! rays, the hit's shading state after a pass, shadow rays and Phong
//! shading, reflection and refraction (Snell) set-up, the local stack of
//! the ray tree, and the output words. The TinyRISC side that runs them
//! in order is [`super::tiles`].
//!
//! Every kernel keeps the ray in r1..r7 (origin, direction, `tbest`) and
//! what outlives it in RC RAM ([`super::memory_map::ram`]): the hit of
//! the last pass (`HIT_*`), the shading state of the current level
//! (`SH_*`, `ACT`, `COL`), a stack frame per recursion level (`STACK_Ln`)
//! and per refracting level (`REFR_Ln`).

use super::emit::{Code, K, R0, R1, R2, R3};
use super::kernel_names as names;
use super::math::{normalize, pow_q14, sqrt_q14, Approx};
use super::memory_map::ram;
use super::primitives::{kaddr, smooth_triangle};

/// The largest Phong exponent the shading kernel raises to (a larger one
/// is clamped; `tracer::chip_warnings` names it where Ks > 0).
pub const MAX_SHINE: f64 = 4096.0;

/// A Phong exponent as integer part `n` and fraction `f` (0 when below
/// 1/1024): the kernel computes `x^n (1 - f + f x)`, the linear blend of
/// `x^n` and `x^(n+1)`, for `x^(n+f)`.
pub fn split_shine(shine: f64) -> (u32, f64) {
    let s = shine.clamp(0.0, MAX_SHINE);
    let n = s.floor();
    let f = s - n;
    if f < 1.0 / 1024.0 {
        (n as u32, 0.0)
    } else if f > 1.0 - 1.0 / 1024.0 {
        (n as u32 + 1, 0.0)
    } else {
        (n as u32, f)
    }
}

/// The exponent `k_phong` raises `R.V` to for material `m`
/// ([`split_shine`]); none (`x^0`, no fraction) where the material has no
/// specular term and `skip_dull` (the packet traversal's firmware): its
/// `ks lc` words are 0, so the power would be multiplied by 0 and the
/// colour is the same bit for bit. The paper's traversal keeps the power
/// its published cycles were counted with.
pub fn phong_exponent(m: &crate::scene::Material, skip_dull: bool) -> (u32, f64) {
    if skip_dull && m.ks == 0.0 {
        (0, 0.0)
    } else {
        split_shine(m.shine)
    }
}

/// `frame+field+i`, a word of a stack frame.
fn word(frame: &str, field: &str, i: u32) -> String {
    match i {
        0 => format!("{frame}+{field}"),
        i => format!("{frame}+{field}+{i}"),
    }
}

/// Program start: RAM tables and constants from the FB (258 words).
pub fn init() -> K {
    let mut k = K::new();
    k.doc(
        "k_init: every RC's RAM from the FB image's start (stream): the RSQ and RCP tables,\n\
         1.0 and the no-hit distance. Out: r0 = 0 in every RC.",
    );
    k.c("movb r0, #0");
    k.rept(256, "i", |k| {
        k.c(format!("st fb0, [#{}+i]", ram::RSQ));
    });
    k.c(format!("st fb0, [#{}]", ram::C_ONE))
        .c(format!("st fb0, [#{}]", ram::C_INF));
    k
}

/// Row-mode group: row i gets `movb r8, #i`.
pub fn rows() -> K {
    let mut k = K::new();
    k.doc(
        "k_row_index: a group of 8 contexts, one per row (row mode) or column (column mode):\n\
         row i gets r8 = i. Broadcast twice, its results stored to LANE_ROW and LANE_COL.",
    );
    k.rept(8, "i", |k| {
        k.c("movb r8, #i");
    });
    k
}

/// Store r8 into a lane word (after [`rows`]).
pub fn store_lane(name: &str, at: super::emit::Name) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{name}: r8 (the row or column [`k_row_index`] gave) into {at}."
    ));
    k.c(format!("st r8, [#{at}]"));
    k
}

/// Lane bookkeeping after the row/column groups: which RCs take part for
/// the number of ways (`TILE_W` x `TILE_H` tile), the others sleep for good.
pub fn lanes() -> K {
    let mut k = K::new();
    k.doc(
        "k_lanes: the RCs inside the TILE_W x TILE_H tile trace its rays (LANE_ACT = 1);\n\
         the others sleep for good.",
    );
    k.c(format!("ld r8, [r0 + #{}]", ram::LANE_ROW))
        .c(format!("ld r9, [r0 + #{}]", ram::LANE_COL))
        .c("movb r10, #0")
        .c("cmp.lt r8, #TILE_H")
        .c("(f) cmp.lt r9, #TILE_W")
        .c("(f) movb r10, #1")
        .c(format!("st r10, [#{}]", ram::LANE_ACT))
        .c("(!f) sleep");
    k
}

/// Wake every RC, then put the RCs that take no part back to sleep;
/// `packet`: no ray is alive in a pass until the pass starts.
pub fn wake_restore(packet: bool) -> K {
    let mut k = K::new();
    k.doc("k_wake_tile: every RC of the tile awake again after a pass (the others asleep).");
    k.c("wake");
    if packet {
        k.c(format!("st r0, [#{}]", ram::P_ALIVE));
    }
    k.c(format!("ld r8, [r0 + #{}]", ram::LANE_ACT))
        .c("cmp.eq r8, #0")
        .c("(f) sleep");
    k
}

/// Eye rays. Stream: `px0, py0, from.xyz, (A, B, C) per axis`: the
/// direction through pixel (i, j) is `A + i B + j C` with A in Q2.13 and
/// B, C scaled by 2^KD; normalised in the RC. `refract`: eye rays leave
/// no object (`ORIG_OBJ` = -1) and have no back hit yet
/// (`HIT_BACK_OBJ` = -1, [`back_hit_none`]).
pub fn eye(nr: Approx, refract: bool) -> K {
    let mut k = K::new();
    k.doc(
        "k_eye: the tile's eye rays (stream: px0, py0, eye.xyz, (A, B, C) per axis).\n\
         Out: r1..r3 = eye, r4..r6 = normalize(A + i B + j C) for pixel (px0 + col, py0 + row),\n\
         r7 = C_INF; a new level (PASS_T0, COL = 0, SH_D), OUT_OBJ = -1.",
    );
    eye_pixel(&mut k);
    for x in [10, 11, 12] {
        k.c("ldacc fb0, <<KD-Q13")
            .c("mac out, fb0, r8")
            .c(format!("mac r{x}, fb0, r9, >>KD-Q13"));
    }
    normalize(&mut k, &[10, 11, 12], [13, 14, 15, 8, 9], false, nr);
    k.c("mov r4, r10").c("mov r5, r11").c("mov r6, r12");
    new_level_common(&mut k);
    k.c("movb r8, #-1").c(format!("st r8, [#{}]", ram::OUT_OBJ));
    if refract {
        k.c(format!("st r8, [#{}]", ram::ORIG_OBJ))
            .c(format!("st r8, [#{}]", ram::HIT_BACK_OBJ))
            .note("no back hit yet in this pass");
    }
    k
}

/// The eye kernels' start (stream: px0, py0, eye.xyz): r8 = i, r9 = j,
/// the RC's pixel; r1..r3 = the eye.
pub(super) fn eye_pixel(k: &mut K) {
    k.c(format!("ld r8, [r0 + #{}]", ram::LANE_COL))
        .c("add r8, fb0, r8")
        .note("i")
        .c(format!("ld r9, [r0 + #{}]", ram::LANE_ROW))
        .c("add r9, fb0, r9")
        .note("j")
        .c("mov r1, fb0")
        .c("mov r2, fb0")
        .c("mov r3, fb0");
}

pub(super) fn new_level_common(k: &mut K) {
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
/// Stream: `bg.rgb, (mat id, ks) per material`. With the extensions the
/// scene's types need: smooth triangles (the shading normal,
/// [`smooth_triangle::shading_normal`]) and refraction (whether the hit is
/// on an object's back, `SH_BACK`, for the index of refraction, and the
/// object the rays it spawns leave).
pub fn post(level0: bool, materials: usize, smooth: bool, refract: bool, local: bool) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{}: after a closest-hit pass: the hit's shading state (stream: background.rgb,\n\
         then (material id, ks) per material). In: r1..r7 the rays and their tbest, HIT_*.\n\
         Out: ACT, SH_P (the hit point, EPS_LSB off the surface), SH_N, SH_MAT, SH_KS;\n\
         COL = the background where no hit{}.",
        if level0 { names::POST_EYE } else { names::POST },
        if level0 {
            "; OUT_OBJ, the eye ray's object"
        } else {
            ""
        }
    ));
    k.c(format!("ld r8, [r0 + #{}]", ram::C_INF))
        .c("cmp.lt r7, r8")
        .note("F: a hit")
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
    k.note("the background where no hit");
    k.c("movb r12, #EPS_LSB");
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        let i = i as u32;
        k.c(format!("ld r8, [r0 + #{}]", ram::HIT_N + i))
            .c(format!("st r8, [#{}]", ram::SH_N + i))
            .c(format!("ldacc r{o}, <<Q14"))
            .c(format!("mac out, r7, r{d}"))
            .c("mac r11, r8, r12, >>Q14")
            .c(format!("st r11, [#{}]", ram::SH_P + i));
    }
    k.note("P = o + t d + EPS_LSB n");
    if local {
        super::positions::post(&mut k, 9);
    }
    k.c(format!("ld r13, [r0 + #{}]", ram::HIT_MAT))
        .c(format!("st r13, [#{}]", ram::SH_MAT))
        .c("movb r14, #0")
        .c(format!("st r14, [#{}]", ram::SH_KS));
    k.comment("Ks of the hit's material: one test per material");
    k.rept(materials as u32, "m", |k| {
        k.c("cmp.ne r9, #0")
            .c("(f) cmp.eq fb0, r13")
            .c(format!("(f) st fb0, [#{}]", ram::SH_KS));
    });
    if smooth {
        smooth_triangle::shading_normal(&mut k);
    }
    if refract {
        // A missed ray's HIT_* hold what an earlier hit in the RC left
        // (the frame's earlier tiles): the back-hit test only where this
        // pass hit, so that no RC's work depends on them.
        k.comment("a back hit? the rays this hit spawns leave its object");
        k.c(format!("ld r8, [r0 + #{}]", ram::ACT))
            .c("cmp.ne r8, #0")
            .note("F: a hit")
            .c(format!("ld r8, [r0 + #{}]", ram::HIT_BACK_OBJ))
            .c(format!("ld r9, [r0 + #{}]", ram::HIT_OBJ))
            .c("movb r10, #0")
            .c("(f) cmp.eq r8, r9")
            .note("F: on its object's back")
            .c("(f) movb r10, #1")
            .c(format!("st r10, [#{}]", ram::SH_BACK))
            .c(format!("ld r8, [r0 + #{}]", ram::ACT))
            .c("cmp.eq r8, #0")
            .c("(f) movb r9, #-1")
            .c(format!("st r9, [#{}]", ram::ORIG_OBJ));
    }
    k
}

/// Appended to [`post`] for the packet traversal: F = the RC's ray hit,
/// so that TinyRISC's `rcany` skips the level's shadow passes where no ray
/// did.
pub fn flag_hit(k: &mut K) {
    k.c(format!("ld r8, [r0 + #{}]", ram::ACT))
        .c("cmp.ne r8, #0")
        .note("F: a hit (for rcany)");
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
/// `local` (local positions, lights not shifted): the direction to
/// 2^-27 from the hit point with its remainder
/// ([`super::positions::shadow_direction`]).
pub fn light_setup(nr: Approx, shifted: bool, local: bool) -> K {
    let precise = local && !shifted;
    let mut k = K::new();
    k.doc(&format!(
        "k_shadow_rays: the shadow rays towards one light (stream: {}the light's position).\n\
         In: SH_P, SH_N, SH_D, ACT. Out: r1..r7 the shadow rays (tbest: the light's distance less 2 LSB),\n\
         SH_NL, SH_RV, LIT; the RCs with no hit or the light behind the surface sleep.",
        if shifted { "a scale shift k, " } else { "" }
    ));
    for (i, o) in [1, 2, 3].into_iter().enumerate() {
        k.c(format!("ld r{o}, [r0 + #{}]", ram::SH_P + i as u32));
    }
    if shifted {
        k.c("mov r15, fb0").note("k");
        for (x, o) in [(8, 1), (9, 2), (10, 3)] {
            k.c(format!("sra r{x}, r{o}, r15"))
                .c(format!("sub r{x}, fb0, r{x}"));
        }
        k.note("L / 2^k - P / 2^k")
            .c(format!("st r15, [#{}]", ram::TMP0));
    } else {
        k.c("sub r8, fb0, r1")
            .c("sub r9, fb0, r2")
            .c("sub r10, fb0, r3")
            .note("L - P");
        if precise {
            for (i, x) in [8, 9, 10].into_iter().enumerate() {
                k.c(format!("st r{x}, [#{}]", ram::TMP0 + i as u32));
            }
        }
    }
    normalize(&mut k, &[8, 9, 10], [11, 12, 13, 14, 15], true, nr);
    k.c("mov r4, r8").c("mov r5, r9").c("mov r6, r10");
    if shifted {
        k.c(format!("ld r15, [r0 + #{}]", ram::TMP0))
            .c("cmp.gt r15, #0")
            .c(format!("(f) ld r11, [r0 + #{}]", ram::C_INF))
            .note("a far light: no end");
    }
    k.c("sub r7, r11, #2")
        .note("tbest = |L - P| - 2")
        .c(format!("st r7, [#{}]", ram::PASS_T0));
    if precise {
        super::positions::shadow_direction(&mut k, nr);
    }
    k.comment("nl = N.L");
    k.c(format!("ld r12, [r0 + #{}]", ram::SH_N))
        .c("mul out, r12, r4")
        .c(format!("ld r13, [r0 + #{}]", ram::SH_N + 1))
        .c("mac out, r13, r5")
        .c(format!("ld r14, [r0 + #{}]", ram::SH_N + 2))
        .c("mac r15, r14, r6, >>Q14")
        .c(format!("st r15, [#{}]", ram::SH_NL));
    k.comment("nd = N.D, ld = L.D, rv = ld - 2 nl nd");
    k.c(format!("ld r8, [r0 + #{}]", ram::SH_D))
        .c(format!("ld r9, [r0 + #{}]", ram::SH_D + 1))
        .c(format!("ld r10, [r0 + #{}]", ram::SH_D + 2))
        .c("mul out, r12, r8")
        .c("mac out, r13, r9")
        .c("mac r11, r14, r10, >>Q14")
        .note("nd")
        .c("mul out, r4, r8")
        .c("mac out, r5, r9")
        .c("mac r12, r6, r10, >>Q14")
        .note("ld")
        .c("ldacc r12, <<Q14")
        .c("msu out, r15, r11")
        .c("msu r12, r15, r11, >>Q14")
        .c("max r12, r12, #0")
        .c(format!("st r12, [#{}]", ram::SH_RV));
    k.c(format!("ld r8, [r0 + #{}]", ram::ACT))
        .c("cmp.ne r8, #0")
        .c("(f) cmp.gt r15, #0")
        .note("F: a hit lit from its front")
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
/// `runs` (the broadcast unit's `cut` contexts): each material's block
/// from material 1 on is an entry (`k_phong_from_mM`) and has a cut after
/// its material test, so that TinyRISC runs the kernel a material at a
/// time ([`phong_runs`]) and a material no lit RC has costs its test.
pub fn shade(shines: &[(u32, f64)], runs: bool) -> K {
    let mut k = K::new();
    k.doc(
        "k_phong: after a shadow pass, the light's Phong terms where it is visible\n\
         (stream per material: id, [f, 1 - f,] then per channel kd c lc, ks lc).\n\
         In: LIT, PASS_T0, r7 (no hit: tbest >= PASS_T0), SH_NL, SH_RV, SH_MAT. Out: COL += kd c lc N.L + ks lc (R.V)^n.",
    );
    k.c(format!("ld r8, [r0 + #{}]", ram::LIT))
        .c("cmp.ne r8, #0")
        .c(format!("ld r9, [r0 + #{}]", ram::PASS_T0))
        .c("(f) cmp.ge r7, r9")
        .note("F: lit and not shadowed")
        .c("movb r10, #0")
        .c("(f) movb r10, #1")
        .c(format!("ld r11, [r0 + #{}]", ram::SH_NL))
        .c(format!("ld r12, [r0 + #{}]", ram::SH_RV))
        .c(format!("ld r13, [r0 + #{}]", ram::SH_MAT));
    for (m, &(n, f)) in shines.iter().enumerate() {
        if runs && m > 0 {
            k.entry(&format!("m{m}"));
        }
        k.comment(&format!("material {m}: exponent {}", n as f64 + f));
        k.c("cmp.ne r10, #0").c("(f) cmp.eq fb0, r13");
        if runs {
            k.cut(&format!("m{m}"));
        }
        pow_q14(&mut k, 12, 14, 15, n);
        if f > 0.0 {
            k.c("mov r15, fb0")
                .c("mul r15, r15, r12, >>Q14")
                .c("add r15, fb0, r15")
                .c("mul r14, r14, r15, >>Q14");
        }
        for c in 0..3 {
            k.c("mul out, fb0, r11")
                .c("mac r15, fb0, r14, >>Q14")
                .c(format!("ld r9, [r0 + #{}]", ram::COL + c))
                .c("adds r9, r9, r15")
                .c(format!("(f) st r9, [#{}]", ram::COL + c));
        }
    }
    k
}

/// Start recursion level `level + 1`: push the colour and the reflection
/// weight of `level` onto the RC stack, and spawn the reflection ray
/// `d - 2 (d.N) N` where the hit surface reflects (Ks > 0); the others
/// sleep. `smooth` (scenes with smooth triangles): where the mirror
/// direction about the shading normal would go below the surface
/// (`r.Ng <= 0`), the mirror direction about the geometric normal
/// `SH_NG`, as the reference does.
pub fn reflect_setup(level: u32, smooth: bool, refract: bool) -> K {
    let f = format!("STACK_L{level}");
    let mut k = K::new();
    k.doc(&format!(
        "{}: level {level}'s colour and Ks onto the stack ({f}); the reflected rays\n\
         d - 2 (d.N) N from SH_P where Ks > 0, the others sleep. Out: r1..r7 the rays, a new level.",
        names::reflect(level),
    ));
    k.c(format!("ld r8, [r0 + #{}]", ram::SH_KS))
        .c(format!("st r8, [#{}]", word(&f, "FR_KS", 0)))
        .c("movb r10, #0");
    for c in 0..3 {
        k.c(format!("ld r9, [r0 + #{}]", ram::COL + c))
            .c(format!("st r9, [#{}]", word(&f, "FR_COL", c)))
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
        .c("mac r14, r10, r13, >>Q14")
        .note("d.N");
    for (d, x, n) in [(4, 8, 11), (5, 9, 12), (6, 10, 13)] {
        k.c(format!("ldacc r{x}, <<Q14"))
            .c(format!("msu out, r14, r{n}"))
            .c(format!("msu r{d}, r14, r{n}, >>Q14"));
    }
    k.note("r = d - 2 (d.N) N");
    if smooth {
        k.comment("below the geometric surface: the mirror direction about Ng");
        for (i, n) in [11, 12, 13].into_iter().enumerate() {
            k.c(format!("ld r{n}, [r0 + #{}]", ram::SH_NG + i as u32));
        }
        k.c("mul out, r4, r11")
            .c("mac out, r5, r12")
            .c("mac r15, r6, r13, >>Q14")
            .c("mul out, r8, r11")
            .c("mac out, r9, r12")
            .c("mac r14, r10, r13, >>Q14")
            .c("cmp.le r15, #0");
        for (d, x, n) in [(4, 8, 11), (5, 9, 12), (6, 10, 13)] {
            k.c(format!("ldacc r{x}, <<Q14"))
                .c(format!("msu out, r14, r{n}"))
                .c(format!("msu r15, r14, r{n}, >>Q14"))
                .c(format!("(f) mov r{d}, r15"));
        }
    }
    k.c(format!("ld r7, [r0 + #{}]", ram::C_INF))
        .c(format!("st r7, [#{}]", ram::PASS_T0));
    for (i, d) in [4, 5, 6].into_iter().enumerate() {
        k.c(format!("st r{d}, [#{}]", ram::SH_D + i as u32));
    }
    if refract {
        back_hit_none(&mut k);
    }
    k.c(format!("ld r9, [r0 + #{}]", ram::ACT))
        .c(format!("ld r8, [r0 + #{}]", ram::SH_KS))
        .c("cmp.ne r9, #0")
        .c("(f) cmp.gt r8, #0")
        .note("F: a hit that reflects")
        .c("(!f) sleep");
    k
}

/// `HIT_BACK_OBJ = -1` at a closest-hit pass's set-up (a scene with
/// transmitting objects): the pass's own back hits only, in every RC, so
/// that the hit's shading ([`post`]) does not depend on what the RC's
/// earlier passes (or tiles) left. Clobbers r8.
fn back_hit_none(k: &mut K) {
    k.c("movb r8, #-1")
        .c(format!("st r8, [#{}]", ram::HIT_BACK_OBJ))
        .note("no back hit yet in this pass");
}

/// Refraction set-up of recursion level `level` (before its reflection):
/// where the hit surface transmits (stream per transmitting material: `id,
/// T, 1/ior, ior`, Q3.12), the refracted direction by Snell's law,
/// `eta = 1/ior` entering (a front hit) and `ior` leaving (a back hit,
/// `SH_BACK`), `c1 = -d.N`, `k = 1 - eta^2 (1 - c1^2)`,
/// `T = eta d + (eta c1 - sqrt(k)) N` (normalised); none where `k <= 0`
/// (total internal reflection). Pushed into `REFR_Ln` with the hit point
/// and the weight (0 where no ray is spawned) for [`refract_setup`].
pub fn refract_prepare(level: u32, materials: usize, nr: Approx) -> K {
    let rf = format!("REFR_L{level}");
    let mut k = K::new();
    k.doc(&format!(
        "{}: level {level}'s refracted rays by Snell's law, kept in {rf} for after its\n\
         reflection (stream per transmitting material: id, T, 1/ior, ior). In: SH_*, ACT.\n\
         T = eta d + (eta c1 - sqrt(k)) N, c1 = -d.N, k = 1 - eta^2 (1 - c1^2); weight 0 where k <= 0.",
        names::refract_prepare(level),
    ));
    k.c(format!("ld r8, [r0 + #{}]", ram::ACT))
        .c(format!("ld r9, [r0 + #{}]", ram::SH_MAT))
        .c(format!("ld r10, [r0 + #{}]", ram::SH_BACK))
        .c("movb r12, #0")
        .c("movb r13, #0");
    k.comment("T and eta of the hit's material: one test per transmitting material");
    k.rept(materials as u32, "m", |k| {
        k.c("cmp.ne r8, #0")
            .c("(f) cmp.eq fb0, r9")
            .c("(f) mov r12, fb0")
            .c("(f) mov r13, fb0")
            .c("(f) cmp.ne r10, #0")
            .c("(f) mov r13, fb0");
    });
    k.comment("c1 = -d.N, k = 1 - eta^2 (1 - c1^2)");
    for (i, x) in [1, 2, 3].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::SH_D + i as u32));
    }
    for (i, x) in [4, 5, 6].into_iter().enumerate() {
        k.c(format!("ld r{x}, [r0 + #{}]", ram::SH_N + i as u32));
    }
    k.c("mul out, r1, r4")
        .c("mac out, r2, r5")
        .c("mac r7, r3, r6, >>Q14")
        .c("neg r7, r7")
        .c("mul r11, r7, r7, >>Q14")
        .c(format!("ld r14, [r0 + #{}]", ram::C_ONE))
        .c("sub r11, r14, r11")
        .c("mul r11, r13, r11, >>Q14")
        .c("ldacc r14, <<Q10")
        .c("msu r15, r13, r11, >>Q10")
        .c("cmp.le r15, #0")
        .c("(f) movb r12, #0")
        .note("total internal reflection: no ray")
        .c("max r15, r15, #1");
    sqrt_q14(&mut k, 15, 11, [8, 9, 10, 14], nr);
    k.comment("T = eta d + (eta c1 - sqrt(k)) N");
    k.c("mul r10, r13, r7, >>Q14")
        .c("sra r11, r11, #2")
        .c("sub r10, r10, r11");
    for (x, d, n) in [(8, 1, 4), (9, 2, 5), (14, 3, 6)] {
        k.c(format!("mul out, r13, r{d}"))
            .c(format!("mac r{x}, r10, r{n}, >>Q12"));
    }
    normalize(&mut k, &[8, 9, 14], [1, 2, 3, 4, 5], false, nr);
    for i in 0..3 {
        k.c(format!("ld r1, [r0 + #{}]", ram::SH_P + i))
            .c(format!("st r1, [#{}]", word(&rf, "RF_O", i)));
    }
    k.c(format!("st r8, [#{}]", word(&rf, "RF_D", 0)))
        .c(format!("st r9, [#{}]", word(&rf, "RF_D", 1)))
        .c(format!("st r14, [#{}]", word(&rf, "RF_D", 2)))
        .c(format!("st r12, [#{}]", word(&rf, "RF_T", 0)))
        .c(format!("ld r1, [r0 + #{}]", ram::ORIG_OBJ))
        .c(format!("st r1, [#{}]", ram::ORIG_STACK + level));
    k
}

/// After the reflection of level `level` returned: push the colour so far
/// and spawn the refracted ray that [`refract_prepare`] set up; the rays
/// with none sleep (F = 1 on the awake ones, for `rcany`).
pub fn refract_setup(level: u32) -> K {
    let (f, rf) = (format!("STACK_L{level}"), format!("REFR_L{level}"));
    let mut k = K::new();
    k.doc(&format!(
        "{}: level {level}'s colour so far onto the stack; the refracted rays {rf} traced;\n\
         the RCs with none sleep. Out: r1..r7 the rays, F = 1 on the awake ones.",
        names::refract(level),
    ));
    k.c("movb r10, #0");
    for c in 0..3 {
        k.c(format!("ld r9, [r0 + #{}]", ram::COL + c))
            .c(format!("st r9, [#{}]", word(&f, "FR_COL", c)))
            .c(format!("st r10, [#{}]", ram::COL + c));
    }
    for (i, x) in [1, 2, 3, 4, 5, 6].into_iter().enumerate() {
        let i = i as u32;
        let w = if i < 3 {
            word(&rf, "RF_O", i)
        } else {
            word(&rf, "RF_D", i - 3)
        };
        k.c(format!("ld r{x}, [r0 + #{w}]"));
    }
    k.c(format!("ld r7, [r0 + #{}]", ram::C_INF))
        .c(format!("st r7, [#{}]", ram::PASS_T0));
    for (i, d) in [4, 5, 6].into_iter().enumerate() {
        k.c(format!("st r{d}, [#{}]", ram::SH_D + i as u32));
    }
    back_hit_none(&mut k);
    k.c(format!("ld r8, [r0 + #{}]", ram::ORIG_STACK + level))
        .c(format!("st r8, [#{}]", ram::ORIG_OBJ))
        .c(format!("ld r8, [r0 + #{}]", word(&rf, "RF_T", 0)))
        .c("cmp.gt r8, #0")
        .c("(!f) sleep");
    k
}

/// Return from the refracted ray of level `level`: colour = pushed +
/// T * refracted.
pub fn refract_pop(level: u32) -> K {
    let (f, rf) = (format!("STACK_L{level}"), format!("REFR_L{level}"));
    let mut k = K::new();
    k.doc(&format!(
        "{}: back from level {level}'s refracted rays: COL = {f}'s colour + T COL.",
        names::refracted(level),
    ));
    k.c(format!("ld r10, [r0 + #{}]", word(&rf, "RF_T", 0)));
    for c in 0..3 {
        k.c(format!("ld r8, [r0 + #{}]", word(&f, "FR_COL", c)))
            .c(format!("ld r9, [r0 + #{}]", ram::COL + c))
            .c("mul r9, r9, r10, >>Q12")
            .c("adds r9, r8, r9")
            .c(format!("st r9, [#{}]", ram::COL + c));
    }
    k
}

/// Return from level `level + 1`: pop, colour = pushed + weight * reflected.
pub fn reflect_pop(level: u32) -> K {
    let f = format!("STACK_L{level}");
    let mut k = K::new();
    k.doc(&format!(
        "{}: back from level {level}'s reflected rays: COL = {f}'s colour + Ks COL.",
        names::reflected(level),
    ));
    k.c(format!("ld r10, [r0 + #{}]", word(&f, "FR_KS", 0)));
    for c in 0..3 {
        k.c(format!("ld r8, [r0 + #{}]", word(&f, "FR_COL", c)))
            .c(format!("ld r9, [r0 + #{}]", ram::COL + c))
            .c("mul r9, r9, r10, >>Q12")
            .c("adds r9, r8, r9")
            .c(format!("st r9, [#{}]", ram::COL + c));
    }
    k
}

/// Put one output word (colour channel 0..2, or 3 = object id) into `out`.
pub fn out_word(i: u32) -> K {
    let mut k = K::new();
    let a = if i < 3 {
        ram::COL + i
    } else {
        ram::OUT_OBJ + 0
    };
    k.doc(&format!(
        "{}: the pixel's {} into the output register (for wfb).",
        names::out(i),
        ["red", "green", "blue", "object id"][i as usize]
    ));
    k.c(format!("ld out, [r0 + #{a}]"));
    k
}

/// Whether `k_phong` runs a material at a time ([`shade`]'s `runs`): the
/// broadcast unit's `cut` contexts (`cut_runs`), and more than one
/// material.
pub fn phong_in_runs(cut_runs: bool, materials: usize) -> bool {
    cut_runs && materials > 1
}

/// TinyRISC code shading the light of Phong stream `stream` (an FB
/// address): `k_phong` broadcast whole, or where it runs a material at a
/// time (`runs`, [`phong_in_runs`]) a call of the `phong` routine
/// (clobbers r1..r3 and r15).
pub fn broadcast_phong(t: &mut Code, runs: bool, stream: &str) {
    if runs {
        t.li(R3, stream)
            .jal("phong")
            .c("its Phong terms, a material at a time");
    } else {
        t.m("BCAST_FB", format!("{}, {stream}", names::PHONG));
    }
}

/// TinyRISC's `phong` routine (with [`shade`]'s `runs`): the light's Phong
/// terms a material at a time, the stream of the light at r3: the
/// kernel's start and material 0's block, then each further material's
/// block from its entry, the stream from its words. A block whose
/// material no lit RC has ends at its cut. Clobbers r1, r2; returns by
/// r15.
pub fn phong_runs(t: &mut Code, materials: usize) {
    let k = names::PHONG;
    let from = |m: usize| crate::tracer::emit::entry_label(k, &format!("m{m}"));
    let end = |m: usize| {
        if m + 1 < materials {
            from(m + 1)
        } else {
            format!("{k}_end")
        }
    };
    t.doc(
        "phong: the light's Phong terms (stream at r3) a material at a time: a block whose\n\
         material no lit RC has ends at its cut. Clobbers r1, r2.",
    );
    t.label("phong")
        .addi(R1, R0, kaddr(k))
        .sbcb(R1, R3, format!("({} - {k}) / 4", end(0)))
        .c("the terms' set-up and material 0");
    for m in 1..materials {
        t.addi(R1, R0, kaddr(&from(m)))
            .addi(R2, R3, format!("{}_fb", from(m)))
            .sbcb(R1, R2, format!("({} - {}) / 4", end(m), from(m)))
            .c(format!("material {m}"));
    }
    t.line("jr r15");
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shading kernels read exactly their streams as the layout writes
    /// them.
    #[test]
    fn shading_kernels_read_exactly_their_streams() {
        let nr = Approx::default();
        assert_eq!(init().fb_reads, 258);
        assert_eq!(eye(nr, false).fb_reads, 14);
        for local in [false, true] {
            assert_eq!(light_setup(nr, false, local).fb_reads, 3);
            assert_eq!(light_setup(nr, true, local).fb_reads, 4);
        }
        assert_eq!(post(true, 5, false, false, false).fb_reads, 3 + 2 * 5);
        assert_eq!(post(false, 5, true, true, true).fb_reads, 3 + 2 * 5);
        // Per material: the id, then per channel two words; a fractional
        // exponent two more.
        for runs in [false, true] {
            assert_eq!(
                shade(&[(1, 0.0), (10, 0.5), (200, 0.0)], runs).fb_reads,
                7 * 3 + 2
            );
        }
        assert_eq!(refract_prepare(0, 3, nr).fb_reads, 4 * 3);
    }
}
