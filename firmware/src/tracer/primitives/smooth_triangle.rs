//! A triangle with vertex normals (NFF `pp`), shaded smoothly as the
//! reference shades it (`scene/shape/triangle.rs`, with
//! the interpolated shading normal).
//!
//! **Record** (29 words): `n.xyz, v0.xyz, v0.xyz, eu.xyz, ew.xyz, (n0, n1,
//! n2).x, .y, .z, n.xyz, obj, mat`: the triangle's planar record with the
//! unit vertex normals (Q1.14) per axis before its face normal.
//!
//! **Method**: the planar test ([`planar::plane_hit`],
//! [`planar::inside_test`]), then at the hit the vertex normals weighted
//! by the barycentric coordinates `(1 - u - w, u, w)` in the accumulator
//! and normalised into `HIT_NS`, with the object id in `HIT_NS_OBJ`; the
//! face normal goes to `HIT_N` as every kernel's does. After the pass,
//! [`shading_normal`] (in the post-pass kernel) takes the interpolated
//! normal where the hit is a smooth triangle and the normal lies on the
//! face's side, the reference's rule; the reflection falls back on the
//! geometric normal `SH_NG` where the mirror direction would go below the
//! surface.
//!
//! **Two-sided**: as the planar kernels', both normals turned to the ray
//! on a back hit.
//!
//! **Registers**: r1..r7 the ray (r7 the new `tbest` where F); r8..r15
//! temporaries; RAM `TMP2..TMP4`.
//!
//! **Error** against the f64 interpolation: its `error_bound` (below),
//! which `tb/tests/kernels.rs` holds both chips to.

use super::super::emit::{Code, K};
use super::super::math::normalize;
use super::super::memory_map::ram;
use super::planar::{self, Inside, Planar};
use super::record::{total, Field, Layout, W};
use super::{CutTest, ErrorBound, Fit, Gen, Geometry, Object, RecordError, Sides, TestCost};
use crate::scene::{Shape, Vec3};

/// Record words: the planar record with the vertex normals.
/// The record's fields: the planar record's up to its edge duals, the
/// unit vertex normals by axis, then the planar record's last three.
pub const VERTEX_NORMALS: Field =
    Field::part("(n0, n1, n2).xyz", "the unit vertex normals, by axis");
pub const FIELDS: [(Field, usize); 9] = [
    planar::FIELDS[0],
    planar::FIELDS[1],
    planar::FIELDS[2],
    planar::FIELDS[3],
    planar::FIELDS[4],
    (VERTEX_NORMALS, 9),
    planar::FIELDS[5],
    planar::FIELDS[6],
    planar::FIELDS[7],
];

/// Record words.
pub const WORDS: usize = total(&FIELDS);

pub fn kernel_name(s: Sides) -> &'static str {
    match s {
        Sides::Front => "k_smooth_triangle",
        Sides::Both => "k_glass_smooth_triangle",
    }
}

/// Write the record of a smooth triangle of planar geometry `p` and vertex
/// normals `ns`.
pub(crate) fn write(w: &mut W, kt: &[u32; 3], p: &Planar, ns: [Vec3; 3], id: usize, mat: usize) {
    // The planar record up to its face normal, the unit vertex normals by
    // axis (the kernel's read order), then the face normal, obj, mat.
    planar::write(w, kt, p, id, mat);
    w.truncate(w.fb.len() - 5);
    w.field(VERTEX_NORMALS);
    let ns = ns.map(|n| n.normalized());
    for c in 0..3 {
        for n in &ns {
            w.unit_axis(n.axis(c));
        }
    }
    w.field(planar::NORMAL_AGAIN);
    w.unit(p.n);
    w.field(planar::OBJ);
    w.raw(id as i64);
    w.field(planar::MAT);
    w.raw(mat as i64);
}

/// The shading normal: with `u` (r13), `w` (r14), `u + w` (r15) from
/// [`planar::inside_test`], the streamed unit vertex normals weighted by
/// `(1 - u - w, u, w)` into r10..r12, normalised (clobbers r8, r9,
/// r13..r15).
fn interpolate_normal(k: &mut K, g: &Gen) {
    k.c(format!("ld r8, [r0 + #{}]", ram::C_ONE))
        .c("sub r8, r8, r15")
        .note("1 - u - w");
    for x in [10, 11, 12] {
        k.c("mul out, fb0, r8")
            .c("mac out, fb0, r13")
            .c(format!("mac r{x}, fb0, r14, >>Q14"));
    }
    normalize(k, &[10, 11, 12], [9, 8, 13, 14, 15], false, g.approx);
}

/// The smooth triangle kernel.
pub fn kernel(g: &Gen, sides: Sides) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{}: the smooth triangle test of one record (the stream){}.\n\
         In: r1..r3 o, r4..r6 d, r7 tbest. Out where F: r7 = t, HIT_N (the face's), HIT_NS\n\
         (Ns = (1 - u - w) n0 + u n1 + w n2, normalised), HIT_NS_OBJ, HIT_OBJ, HIT_MAT{}.",
        kernel_name(sides),
        if sides == Sides::Both {
            ", seen from either side"
        } else {
            ""
        },
        if sides == Sides::Both {
            ", HIT_BACK_OBJ"
        } else {
            ""
        },
    ));
    let cut = Some(planar::CUTS[0].0);
    planar::plane_hit(&mut k, g, sides, cut);
    planar::inside_test(&mut k, Inside::Triangle);
    k.cut(planar::CUTS[1].0);
    k.comment("Ns = (1 - u - w) n0 + u n1 + w n2, normalised");
    if sides == Sides::Front {
        k.c("(f) mov r7, r9");
        interpolate_normal(&mut k, g);
        for (i, x) in [10, 11, 12].into_iter().enumerate() {
            k.c(format!("(f) st r{x}, [#{}]", ram::HIT_NS + i as u32));
        }
        for i in 0..3 {
            k.c(format!("(f) st fb0, [#{}]", ram::HIT_N + i));
        }
        k.c("mov r8, fb0")
            .c(format!("(f) st r8, [#{}]", ram::HIT_OBJ))
            .c(format!("(f) st r8, [#{}]", ram::HIT_NS_OBJ))
            .c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
        return k;
    }
    k.c(format!("st r9, [#{}]", ram::TMP4)).note("t");
    interpolate_normal(&mut k, g);
    k.comment("turned to the ray on a back hit; the face normal, obj");
    k.c(format!("ld r15, [r0 + #{}]", ram::TMP3))
        .c("movb r14, #1")
        .c("sub r14, r14, r15")
        .c("sub r14, r14, r15")
        .note("1 - 2 back");
    for x in [10, 11, 12] {
        k.c(format!("mul r{x}, r{x}, r14"));
    }
    k.c("mul r8, fb0, r14")
        .c("mul r9, fb0, r14")
        .c("mul r13, fb0, r14")
        .c(format!("st r13, [#{}]", ram::TMP2))
        .c("mov r13, fb0")
        .c(format!("ld r14, [r0 + #{}]", ram::ORIG_OBJ))
        .c("(f) cmp.ne r13, r14")
        .note("not the triangle the ray leaves")
        .c(format!("ld r14, [r0 + #{}]", ram::TMP4))
        .c("(f) mov r7, r14");
    for (i, x) in [10, 11, 12].into_iter().enumerate() {
        k.c(format!("(f) st r{x}, [#{}]", ram::HIT_NS + i as u32));
    }
    k.c(format!("(f) st r8, [#{}]", ram::HIT_N))
        .c(format!("(f) st r9, [#{}]", ram::HIT_N + 1))
        .c(format!("ld r8, [r0 + #{}]", ram::TMP2))
        .c(format!("(f) st r8, [#{}]", ram::HIT_N + 2))
        .c(format!("(f) st r13, [#{}]", ram::HIT_OBJ))
        .c(format!("(f) st r13, [#{}]", ram::HIT_NS_OBJ))
        .c("neg r15, r15")
        .c("add r14, r13, #1")
        .c("and r14, r14, r15")
        .c("sub r14, r14, #1")
        .c(format!("(f) st r14, [#{}]", ram::HIT_BACK_OBJ))
        .note("obj on a back hit, else -1")
        .c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
    k
}

/// The post-pass part of smooth shading: the geometric normal kept in
/// `SH_NG` (for the reflection's fallback) and the shading normal `SH_N`
/// the interpolated one where the hit is a smooth triangle (`HIT_NS_OBJ`
/// = the hit's id) and it lies on the face's side (the reference's rule:
/// otherwise the face normal).
pub fn shading_normal(k: &mut K) {
    k.comment("smooth triangles: the interpolated normal where it faces as the face does");
    for i in 0..3 {
        k.c(format!("ld r{}, [r0 + #{}]", 8 + i, ram::HIT_N + i))
            .c(format!("st r{}, [#{}]", 8 + i, ram::SH_NG + i))
            .c(format!("ld r{}, [r0 + #{}]", 11 + i, ram::HIT_NS + i));
    }
    k.c("mul out, r8, r11")
        .c("mac out, r9, r12")
        .c("mac r14, r10, r13, >>Q14")
        .c(format!("ld r15, [r0 + #{}]", ram::HIT_NS_OBJ))
        .c(format!("ld r8, [r0 + #{}]", ram::HIT_OBJ))
        .c("cmp.eq r15, r8")
        .c("(f) cmp.gt r14, #0");
    for i in 0..3 {
        k.c(format!("(f) st r{}, [#{}]", 11 + i, ram::SH_N + i));
    }
}

/// The smooth triangle ([`super::ChipPrimitive`]): a triangle with
/// vertex normals (NFF `pp`).
pub struct SmoothTriangle;

impl super::ChipPrimitive for SmoothTriangle {
    fn names(&self) -> [&'static str; 2] {
        ["smooth_triangle", "glass_smooth_triangle"]
    }

    fn layout(&self, _sides: Sides, _fit: &Fit, _fan: usize, _caps: bool) -> Layout {
        Layout::new(FIELDS)
    }

    fn kernels(&self, sides: Sides, g: &Gen, _fit: &Fit) -> Vec<(&'static str, K)> {
        vec![(kernel_name(sides), kernel(g, sides))]
    }

    fn broadcast(&self, sides: Sides, t: &mut Code, _at: &str, _fit: &Fit, _caps: bool) {
        super::one(t, kernel_name(sides));
    }

    fn cut_test(&self, sides: Sides, _fit: &Fit) -> Option<CutTest> {
        Some(CutTest {
            kernel: kernel_name(sides),
            field: "0",
            cuts: &planar::CUTS,
            then: None,
        })
    }

    fn fit_header(&self, fit: &Fit) -> Vec<String> {
        super::ChipPrimitive::fit_header(&planar::TRIANGLE, fit)
    }

    fn has_inside_test(&self) -> bool {
        true
    }

    fn geometry(&self, shape: &Shape, _s: f64) -> Geometry {
        match shape.as_triangle() {
            Some(t) => Geometry::Planars(vec![planar::flat_triangle(t.v)]),
            None => Geometry::None,
        }
    }

    fn smooth(&self) -> bool {
        true
    }

    /// Priced as the flat triangle's test (the cost model's kernels).
    fn test_cost(&self, g: &Gen, fit: &Fit) -> TestCost {
        super::ChipPrimitive::test_cost(&planar::TRIANGLE, g, fit)
    }

    /// The normal: the interpolated shading normal.
    fn error_bound(&self) -> ErrorBound {
        ErrorBound::lsb(6.0, 2e-3)
    }

    fn write(&self, w: &mut W, o: &Object) -> Result<(), RecordError> {
        let (Some(ns), [p]) = (
            o.shape.as_triangle().and_then(|t| t.normals.as_ref()),
            o.geometry.planars(),
        ) else {
            return Err(RecordError::mismatch("smooth triangle"));
        };
        write(w, &o.fit.kt, p, *ns, o.id, o.mat);
        Ok(())
    }
}
