//! Polygon, convex or concave, by the even-odd rule as the reference
//! (`tb/src/reference/shapes.rs`: `polygon`), by the crossing test in
//! exact integer arithmetic: three kernels, the edge one run once per edge.
//!
//! **Record** (`1 + 15 + 5 fan + 5` words, `fan` the scene's largest
//! number of edges): the edge count (`POLY_EDGES`), then
//! - head (`POLY_HEAD`, 15 words: `n.xyz, v0.xyz, v0.xyz, U.xyz, V.xyz`):
//!   the plane test and division of the planar kernels, then `v0 - P`
//!   (saturating) projected on the plane of the two axes `U`, `V` (unit
//!   axis vectors, the normal's dominant axis dropped: a dot product with
//!   an axis vector is exact): `-px`, `-py`; the validity kept in `TMP0`,
//!   the parity (r8) cleared;
//! - edges (`POLY_FAN`, `POLY_EDGE_WORDS` = 5 words per edge `(xi, yi) ->
//!   (xj, yj)`, vertices relative to `v0` in the scene format: `xi, yi, yj,
//!   s ey, s ex` with `e = vj - vi` and `s = sign(ey)`; horizontal edges
//!   are left out, they never cross): the parity flips where the edge
//!   straddles the point's row (`(yi > py) != (yj > py)`, half-open, so a
//!   vertex is counted once) and crosses it to the right of the point,
//!   `s ((xi - px) ey - ex (yi - py)) > 0` (the differences by saturating
//!   adds of `-px`, `-py`). The products are exact in the accumulator and
//!   the sign of their difference survives saturation, so no point on a
//!   shared edge or near a vertex is counted twice or not at all: no
//!   cracks, however thin the polygon's parts (a fan of triangles from
//!   `v0` would need the duals of slivers, whose rounding flips points near
//!   every diagonal);
//! - tail (5 words: `n.xyz, obj, mat`): commit where valid and the parity
//!   is odd; then zeros up to the record's size.
//!
//! **Two-sided** (a transmitting polygon): the head's plane test on both
//! sides and the planar kernels' two-sided commit in the tail.
//!
//! **Registers**: r1..r7 the ray (r7 the new `tbest` where F); r8 the
//! parity and r9 `t` across the runs; r10, r11 `-px`, `-py` across the
//! runs; r12..r15 temporaries; RAM `TMP0` (valid), `TMP3` (two-sided:
//! back).
//!
//! **Error** against the f64 polygon (`tb/tests/kernels.rs`, a convex, a
//! concave and a gear-like polygon): `t` within 3 LSB, no crack.

use super::super::emit::{define, Code, Reg, K, R1, R2, R3, R7};
use super::super::memory_map::ram;
use super::planar::plane_hit;
use super::{commit_streamed_normal, commit_streamed_normal_two, kaddr, klen, Gen, Sides};
use crate::scene::Vec3;
use crate::tracer::layout::W;

/// Words of the head, one edge and the tail.
pub const HEAD_WORDS: usize = 15;
pub const EDGE_WORDS: usize = 5;
pub const TAIL_WORDS: usize = 5;

/// Words of a record with room for `fan` edges.
pub fn words(fan: usize) -> usize {
    1 + HEAD_WORDS + fan * EDGE_WORDS + TAIL_WORDS
}

/// The record's fields the broadcast addresses (header lines).
pub fn header() -> Vec<String> {
    vec![
        define("POLY_EDGES", 0, "polygon record: number of edges (words)"),
        define("POLY_HEAD", 1, "polygon record: the head kernel's stream"),
        define(
            "POLY_FAN",
            1 + HEAD_WORDS,
            "polygon record: the first edge's stream",
        ),
        define("POLY_EDGE_WORDS", EDGE_WORDS, "words of an edge's stream"),
    ]
}

pub fn head_name(s: Sides) -> &'static str {
    match s {
        Sides::Front => "k_polygon_head",
        Sides::Both => "k_glass_polygon_head",
    }
}

fn tail_name(s: Sides) -> &'static str {
    match s {
        Sides::Front => "k_polygon_tail",
        Sides::Both => "k_glass_polygon_tail",
    }
}

const EDGE: &str = "k_polygon_edge";

/// The kernels of a polygon's test, in load order.
pub fn kernels(g: &Gen, s: Sides) -> Vec<(&'static str, K)> {
    vec![
        (head_name(s), head(g, s)),
        (EDGE, edge()),
        (tail_name(s), tail(s)),
    ]
}

/// A polygon's normal, as NFF and the reference take it: from its first
/// three vertices.
pub fn normal(v: &[Vec3]) -> Vec3 {
    (v[1] - v[0]).cross(v[2] - v[0]).normalized()
}

/// The crossing test's data of a polygon: the two axes it is projected on
/// (the normal's dominant axis dropped) and, per non-horizontal edge
/// `vi -> vj` (vertices quantized to the scene format `s`, relative to
/// `v0`), `[xi, yi, yj, s ey, s ex]` with `s = sign(ey)`.
pub fn edges(v: &[Vec3], s: f64) -> ((usize, usize), Vec<[i64; 5]>) {
    let n = normal(v);
    // The normal's dominant axis is dropped (ties as the reference breaks
    // them).
    let drop = if n.x.abs() >= n.y.abs() && n.x.abs() >= n.z.abs() {
        0
    } else if n.y.abs() >= n.z.abs() {
        1
    } else {
        2
    };
    let (ua, va) = ((drop + 1) % 3, (drop + 2) % 3);
    let q = |x: f64| (x * s).round() as i64;
    let p2 = |p: Vec3| {
        (
            q(p.axis(ua)) - q(v[0].axis(ua)),
            q(p.axis(va)) - q(v[0].axis(va)),
        )
    };
    let mut edges = Vec::new();
    for k in 0..v.len() {
        let ((xi, yi), (xj, yj)) = (p2(v[k]), p2(v[(k + 1) % v.len()]));
        let (ex, ey) = (xj - xi, yj - yi);
        if ey != 0 {
            let sg = ey.signum();
            edges.push([xi, yi, yj, sg * ey, sg * ex]);
        }
    }
    ((ua, va), edges)
}

/// Write the record of polygon `v` into a record of `size` words.
pub(crate) fn write(w: &mut W, v: &[Vec3], size: usize, id: usize, mat: usize) {
    let start = w.fb.len();
    let n = normal(v);
    let ((ua, va), edges) = edges(v, w.s);
    w.raw(edges.len() as i64);
    w.unit(n);
    w.point(v[0]);
    w.point(v[0]);
    let axis = |a: usize| {
        Vec3::new(
            (a == 0) as u8 as f64,
            (a == 1) as u8 as f64,
            (a == 2) as u8 as f64,
        )
    };
    w.unit(axis(ua));
    w.unit(axis(va));
    for e in &edges {
        for x in e {
            w.raw(*x);
        }
    }
    w.unit(n);
    w.raw(id as i64);
    w.raw(mat as i64);
    w.fb.resize(start + size, 0);
}

fn head(g: &Gen, sides: Sides) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{}: the polygon's plane (the head of its record){}; then -px, -py.\n\
         In: r1..r3 o, r4..r6 d, r7 tbest. Out: r9 = t, TMP0 = valid, r10, r11 = -px, -py, r8 = 0 (parity).",
        head_name(sides),
        if sides == Sides::Both {
            ", seen from either side"
        } else {
            ""
        }
    ));
    plane_hit(&mut k, g, sides, None);
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
    k
}

fn edge() -> K {
    let mut k = K::new();
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

fn tail(sides: Sides) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{}: commit where valid and the parity is odd (stream: n.xyz, obj, mat).\n\
         Out where F: r7 = t, HIT_N, HIT_OBJ, HIT_MAT{}.",
        tail_name(sides),
        if sides == Sides::Both {
            ", HIT_BACK_OBJ"
        } else {
            ""
        }
    ));
    k.c(format!("ld r13, [r0 + #{}]", ram::TMP0))
        .c("cmp.ne r13, #0")
        .c("(f) cmp.ne r8, #0");
    match sides {
        Sides::Front => commit_streamed_normal(&mut k, 9),
        Sides::Both => commit_streamed_normal_two(&mut k, 9),
    }
    k
}

/// Broadcast a polygon's test (record at r7): the head, one edge run per
/// edge, the tail. Labels begin with `at`.
pub fn broadcast(t: &mut Code, at: &str, sides: Sides) {
    t.m("BCAST_REC", format!("{}, r7, POLY_HEAD", head_name(sides)))
        .c("the plane");
    broadcast_edges(t, at, sides, R7);
}

/// After the head (record at `rec`): one edge run per edge, the tail.
pub fn broadcast_edges(t: &mut Code, at: &str, sides: Sides, rec: Reg) {
    t.lfb(R3, super::super::emit::at("POLY_EDGES", rec))
        .c("edges")
        .addi(R2, rec, "POLY_FAN")
        .li(R1, kaddr(EDGE));
    t.label(format!("{at}_fan"))
        .beqz(R3, format!("{at}_tail"))
        .sbcb(R1, R2, klen(EDGE))
        .c("one edge of the crossing test")
        .addi(R2, R2, "POLY_EDGE_WORDS")
        .addi(R3, R3, -1)
        .j(format!("{at}_fan"));
    t.label(format!("{at}_tail"))
        .m("BCAST_AT", format!("{}, r2", tail_name(sides)))
        .c("commit where the parity is odd");
}
