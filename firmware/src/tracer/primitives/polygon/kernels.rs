//! The polygon's kernels: the head (the plane, the point projected),
//! the edge and the banded record's sub-edge and probes (the crossing
//! test), the tail (the commit). Their records: [`super`].

use super::super::super::emit::K;
use super::super::super::memory_map::ram;
use super::super::super::positions;
use super::super::planar::{self, plane_hit, plane_hit_fine, plane_hit_past_rem};
use super::super::{commit_streamed_normal, commit_streamed_normal_two, Gen, Sides};
use super::{head_name, tail_name, ABOVE, BELOW};

pub(super) fn head(g: &Gen, sides: Sides, fine: bool) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{}: the polygon's plane (the head of its record){}; then -px, -py.\n\
         In: r1..r3 o, r4..r6 d, r7 tbest. Out: {}TMP0 = valid (F too), r10, r11 = -px, -py{}, r8 = 0 (parity).",
        head_name(sides),
        if sides == Sides::Both {
            ", seen from either side"
        } else {
            ""
        },
        if fine { "TMP1 = t, " } else { "r9 = t, " },
        if fine {
            " (2^-POLY_K LSB, px floored) and r9, r15 their parts below (2^-14 LSB)"
        } else {
            ""
        },
    ));
    if fine && sides == Sides::Front {
        head_fine(&mut k, g);
        return k;
    }
    match (fine, sides) {
        (true, _) => plane_hit_past_rem(&mut k, g, sides, None),
        (false, _) => plane_hit(&mut k, g, sides, None),
    }
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        let x = 10 + i;
        k.c(format!("ldacc r{o}, <<Q14"))
            .c(format!("mac r{x}, r9, r{d}, >>Q14"))
            .c(format!("subs r{x}, fb0, r{x}"));
    }
    k.note("v0 - P");
    k.c("movb r15, #0")
        .c("(f) movb r15, #1")
        .c(format!("st r15, [#{}]", ram::TMP0))
        .note("valid");
    k.comment("v0 - P on the plane of U, V: -px in r10, -py in r11");
    k.c("mul out, fb0, r10")
        .c("mac out, fb0, r11")
        .c("mac r13, fb0, r12, >>Q14");
    k.c("mul out, fb0, r10")
        .c("mac out, fb0, r11")
        .c("mac r11, fb0, r12, >>Q14")
        .c("mov r10, r13")
        .c("movb r8, #0")
        .note("parity");
    if fine {
        for _ in 0..6 {
            k.c("mov r12, fb0");
        }
        k.note("U, V again: not used")
            .c("asl r10, r10, #POLY_K")
            .c("asl r11, r11, #POLY_K")
            .note("in 2^-POLY_K LSB, the edges' unit")
            .c(format!("st r9, [#{}]", ram::TMP1))
            .note("t")
            .c("movb r9, #0")
            .c("movb r15, #0")
            .note("the point without a remainder");
    }
    k
}

/// Where [`head_fine`] keeps the hit point for the tail (its LSB part,
/// then its remainder, per axis): `CONE_TMP`'s words (scratch of one
/// object's test).
const POINT_AT: u32 = 0;
const POINT_REM_AT: u32 = 3;

/// The head of a fine record (one side): the plane test with the
/// numerator exact ([`plane_hit_fine`]), `t` to 2^-14 LSB
/// ([`planar::fine_t`], into `TMP1`, `TMP2`), the hit point `o + t d` to
/// 2^-14 LSB (into `CONE_TMP`), and `v0 - P` on the plane of `U`, `V`:
/// in `2^-POLY_K` LSB (the edges' unit, [`fine_k`]) `-px`, `-py` (r10,
/// r11), the part below `bx`, `by` (r9, r15) in `(-2^POLY_KSH, 0]`
/// (2^-14 LSB), so that `px` is floored and the edges' straddle tests stay
/// in integers. F = valid at the end.
fn head_fine(k: &mut K, g: &Gen) {
    plane_hit_fine(k, g, None);
    k.c("movb r15, #0")
        .c("(f) movb r15, #1")
        .c(format!("st r15, [#{}]", ram::TMP0))
        .note("valid");
    planar::fine_t(k);
    k.c(format!("st r15, [#{}]", ram::TMP1))
        .c(format!("st r12, [#{}]", ram::TMP2))
        .note("t and its remainder, for the tail");
    k.comment("the hit point o + t d to 2^-14 LSB; v0 - P's LSB part");
    for (i, hi) in [(0u32, 10u8), (1, 11), (2, 13)] {
        positions::ray_point_axis(k, i, 15, 12, [8, 9, hi, 14]);
        k.c(format!("st r{hi}, [#{}]", ram::CONE_TMP + POINT_AT + i))
            .c(format!("st r14, [#{}]", ram::CONE_TMP + POINT_REM_AT + i))
            .c(format!("subs r{hi}, fb0, r{hi}"));
    }
    k.comment("on the plane of U, V: -px, -py (LSB), then -(the remainder's)");
    for x in [8, 9] {
        k.c("mul out, fb0, r10")
            .c("mac out, fb0, r11")
            .c(format!("mac r{x}, fb0, r13, >>Q14"));
    }
    for (i, x) in [10, 11, 13].into_iter().enumerate() {
        k.c(format!(
            "ld r{x}, [r0 + #{}]",
            ram::CONE_TMP + POINT_REM_AT + i as u32
        ));
    }
    for x in [14, 15] {
        k.c("mul out, fb0, r10")
            .c("mac out, fb0, r11")
            .c(format!("mac r{x}, fb0, r13, >>Q14"))
            .c(format!("neg r{x}, r{x}"));
    }
    k.comment("in 2^-POLY_K LSB: -px = a + b 2^-POLY_KSH, b in (-2^POLY_KSH, 0]");
    for (a, b) in [(8, 14), (9, 15)] {
        k.c(format!("neg r12, r{b}"))
            .c("sra r12, r12, #POLY_KSH")
            .note("floor(-b 2^-POLY_KSH)")
            .c(format!("asl r{a}, r{a}, #POLY_K"))
            .c(format!("subs r{a}, r{a}, r12"))
            .c("sll r12, r12, #POLY_KSH")
            .c(format!("add r{b}, r{b}, r12"));
    }
    k.note("the parts below in (-2^POLY_KSH, 0]")
        .c("mov r10, r8")
        .c("mov r11, r9")
        .c("mov r9, r14")
        .c("movb r8, #0")
        .note("parity")
        .c(format!("ld r12, [r0 + #{}]", ram::TMP0))
        .c("cmp.ne r12, #0")
        .note("F: valid");
}

pub(super) fn edge(fine: bool) -> K {
    let mut k = K::new();
    if fine {
        k.doc(
            "k_polygon_edge: one edge of the crossing test (stream: yi, yj, xi, s ey, s ex).\n\
             In: r10, r11 = -px, -py (2^-POLY_K LSB, px floored), r9, r15 their parts below (2^-14 LSB),\n\
             r8 parity. Out: r8 flipped where the edge crosses the point's row to its right: (yi > py)\n\
             != (yj > py) and s ((xi - px) ey - ex (yi - py)) > 0, exact: 2^POLY_KSH A + bx ey - ex by\n\
             with A the integer parts' (saturated in the word: |ex| + |ey| < 2^15 keeps its sign).",
        );
        k.c("adds r13, fb0, r11")
            .note("yi - py")
            .c("adds r14, fb0, r11")
            .note("yj - py")
            .c("min r12, r13, r14")
            .c("max r14, r13, r14")
            .c("cmp.le r12, #0")
            .c("(f) cmp.gt r14, #0")
            .note("F: straddles the row")
            .c("adds r12, fb0, r10")
            .note("xi - px");
        fine_crossing(&mut k);
        return k;
    }
    k.doc(
        "k_polygon_edge: one edge of the crossing test (stream: xi, yi, yj, s ey, s ex).\n\
         In: r10, r11 = -px, -py, r8 parity. Out: r8 flipped where the edge crosses the\n\
         point's row to its right: (yi > py) != (yj > py) and s ((xi - px) ey - ex (yi - py)) > 0.",
    );
    k.c("adds r12, fb0, r10")
        .note("xi - px")
        .c("adds r13, fb0, r11")
        .note("yi - py")
        .c("adds r14, fb0, r11")
        .note("yj - py")
        .c("movb r15, #0")
        .c("cmp.gt r13, #0")
        .c("(f) movb r15, #1")
        .c("cmp.gt r14, #0")
        .c("(f) xor r15, r15, #1")
        .note("straddles the row")
        .c("mov r14, fb0")
        .c("mul out, r12, r14")
        .c("msu r13, fb0, r13")
        .c("cmp.ne r15, #0")
        .c("(f) cmp.gt r13, #0")
        .c("(f) xor r8, r8, #1")
        .note("crosses to the right: flip");
    k
}

pub(super) fn band_edge(fine: bool) -> K {
    let mut k = K::new();
    if fine {
        k.doc(
            "k_polygon_band_edge: one sub-edge of a banded record's crossing test (stream: ya - 1,\n\
             yb - 1, xi, yi, s ey, s ex). In: r10, r11 = -px, -py (2^-POLY_K LSB, floored), r9, r15 their\n\
             parts below (2^-14 LSB), r8 parity. Out: r8 flipped where the point's row lies in\n\
             [ya, yb) and the edge's line crosses it to the right, exact as k_polygon_edge's.",
        );
        k.c("adds r13, fb0, r11")
            .note("ya - 1 - py")
            .c("adds r14, fb0, r11")
            .note("yb - 1 - py")
            .c("xor r12, r13, r14")
            .c("cmp.lt r12, #0")
            .note("F: straddles the row within the band")
            .c("adds r12, fb0, r10")
            .note("xi - px")
            .c("adds r13, fb0, r11")
            .note("yi - py");
        fine_crossing(&mut k);
        return k;
    }
    k.doc(
        "k_polygon_band_edge: one sub-edge of a banded record's crossing test (stream: xi, ya - 1,\n\
         yb - 1, yi, s ey, s ex). In: r10, r11 = -px, -py, r8 parity. Out: r8 flipped where the\n\
         point's row lies in [ya, yb) and the edge's line crosses it to the right: s ((xi - px) ey -\n\
         ex (yi - py)) > 0. (ya - 1) - py >= 0 where ya - py > 0 (saturating adds keep the sign), so\n\
         the row is straddled where the sign bits of (ya - 1) - py and (yb - 1) - py differ.",
    );
    k.c("adds r12, fb0, r10")
        .note("xi - px")
        .c("adds r13, fb0, r11")
        .note("ya - 1 - py")
        .c("adds r14, fb0, r11")
        .note("yb - 1 - py")
        .c("xor r15, r13, r14")
        .note("negative: straddles the row within the band")
        .c("adds r13, fb0, r11")
        .note("yi - py")
        .c("mov r14, fb0")
        .c("mul out, r12, r14")
        .c("msu r13, fb0, r13")
        .c("cmp.lt r15, #0")
        .c("(f) cmp.gt r13, #0")
        .c("(f) xor r8, r8, #1")
        .note("crosses to the right: flip");
    k
}

/// A band probe (stream: a band bound Y): F where the plane hit is valid
/// and the point's row is below Y (`above`: at or above it).
pub(super) fn probe(above: bool) -> K {
    let mut k = K::new();
    let (name, what) = if above {
        (ABOVE, "py >= Y")
    } else {
        (BELOW, "py < Y")
    };
    k.doc(&format!(
        "{name}: a band probe (stream: a band bound Y). In: TMP0 = valid, r11 = -py.\n\
         Out: F where valid and {what} (F is free between the head and the tail)."
    ));
    k.c(format!("ld r12, [r0 + #{}]", ram::TMP0))
        .c("cmp.ne r12, #0")
        .c("adds r13, fb0, r11")
        .note("Y - py")
        .c(if above {
            "(f) cmp.le r13, #0"
        } else {
            "(f) cmp.gt r13, #0"
        });
    k
}

pub(super) fn tail(sides: Sides, fine: bool) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{}: commit where valid and the parity is odd (stream: n.xyz, obj, mat).\n\
         Out where F: r7 = t, HIT_N, HIT_OBJ, HIT_MAT{}.",
        tail_name(sides),
        match (sides, fine) {
            (Sides::Both, _) => ", HIT_BACK_OBJ",
            (Sides::Front, true) => ", HIT_TL = t, HIT_PH and HIT_PL the hit point",
            _ => "",
        }
    ));
    if fine && sides == Sides::Both {
        k.c(format!("ld r9, [r0 + #{}]", ram::TMP1)).note("t");
    }
    k.c(format!("ld r13, [r0 + #{}]", ram::TMP0))
        .c("cmp.ne r13, #0")
        .c("(f) cmp.ne r8, #0");
    match sides {
        Sides::Front if fine => {
            k.c(format!("ld r15, [r0 + #{}]", ram::TMP1))
                .c(format!("ld r12, [r0 + #{}]", ram::TMP2));
            positions::nearer(&mut k, 15, 12, 11, 13);
            commit_streamed_normal(&mut k, 15);
            k.comment("the hit point the head left");
            for i in 0..3 {
                k.c(format!("ld r13, [r0 + #{}]", ram::CONE_TMP + POINT_AT + i))
                    .c(format!("(f) st r13, [#{}]", ram::HIT_PH + i))
                    .c(format!(
                        "ld r14, [r0 + #{}]",
                        ram::CONE_TMP + POINT_REM_AT + i
                    ))
                    .c(format!("(f) st r14, [#{}]", ram::HIT_PL + i));
            }
        }
        Sides::Front => commit_streamed_normal(&mut k, 9),
        Sides::Both => commit_streamed_normal_two(&mut k, 9),
    }
    k
}

/// The fine edge kernels' crossing (after the straddle test in F, `xi -
/// px` in r12 and `yi - py` in r13; stream: `s ey, s ex`): `2^POLY_KSH A +
/// bx ey - ex by` exact in the accumulator, the parity flipped where it
/// is positive.
fn fine_crossing(k: &mut K) {
    k.c("mov r14, fb0")
        .c("mul out, r12, r14")
        .c("mov r12, fb0")
        .c("msu r13, r12, r13")
        .note("A")
        .c("ldacc r13, <<POLY_KSH")
        .c("mac out, r9, r14")
        .c("msu r13, r12, r15")
        .c("(f) cmp.gt r13, #0")
        .c("(f) xor r8, r8, #1")
        .note("crosses to the right: flip");
}
