//! Axis-aligned box (`scene/shape/aabox.rs`), by the slab
//! method, one section per axis.
//!
//! **Record** (24 words): per axis `a` (b, c the two others): `min_a,
//! max_a, min_b - 1, max_b + 1, min_c - 1, max_c + 1, obj, mat`. A glass
//! box's record holds it twice (48 words): entry faces, then exit faces.
//!
//! **Method**, per axis `a`: each RC picks the face of axis `a` that faces
//! its ray with `sel` (`max_a` where `d_a < 0`), `t = |c - o_a| / |d_a|`
//! by division after the accumulator test `|c - o_a| 2^14 < tbest |d_a|`,
//! and accepts it where the hit point lies within the other two slabs;
//! the normal is `-sign(d_a)` along `a`.
//!
//! **Two-sided** (a transmitting box): the entry faces as above, skipping
//! the box a ray leaves (`ORIG_OBJ`: a ray starting on a convex box cannot
//! enter it again), then the exit faces (the face each axis's direction
//! leads to, more than `SELF_LSB` ahead along the ray; a back hit, the
//! normal turned to the ray, `HIT_BACK_OBJ`).
//!
//! **Registers**: r1..r7 the ray (r7 the new `tbest` where F); r8..r15
//! temporaries; RAM `TMP0`.
//!
//! **Error** against the f64 box: its `error_bound` (below), which
//! `tb/tests/kernels.rs` holds both chips to; the normal exact (an axis).

use super::super::emit::{Code, K};
use super::super::math::divide;
use super::super::memory_map::ram;
use super::record::{Field, Layout, W};
use super::{self_margin, ErrorBound, Fit, Gen, Object, RecordError, Sides, TestCost};
use crate::scene::Vec3;

/// Words of one copy of the record.
pub const WORDS: usize = 24;

/// The record's fields: a section per axis, entry faces (and for a glass
/// box exit faces), each `face_a, face_a', slab_b, slab_c, obj, mat`.
pub const SECTIONS: [Field; 6] = [
    Field::part("x", "the x faces and the y, z slabs"),
    Field::part("y", "the y faces and the z, x slabs"),
    Field::part("z", "the z faces and the x, y slabs"),
    Field::part("exit x", "a glass box's x exit faces"),
    Field::part("exit y", "a glass box's y exit faces"),
    Field::part("exit z", "a glass box's z exit faces"),
];

/// The record of a box of `s`: 8 words per section.
pub fn layout(s: Sides) -> Layout {
    let n = if s == Sides::Both { 6 } else { 3 };
    Layout::new(SECTIONS[..n].iter().map(|&f| (f, WORDS / 3)))
}

/// Words of a record.
pub fn words(s: Sides) -> usize {
    layout(s).words()
}

pub fn kernel_name(s: Sides) -> &'static str {
    match s {
        Sides::Front => "k_box",
        Sides::Both => "k_glass_box",
    }
}

/// Write the record of the box `[min, max]`.
pub(crate) fn write(w: &mut W, sides: Sides, min: Vec3, max: Vec3, id: usize, mat: usize) {
    let s = w.s;
    let q = |x: f64| (x * s).round() as i64;
    let copies = words(sides) / WORDS;
    for (k, a) in (0..3).cycle().take(3 * copies).enumerate() {
        w.field(SECTIONS[k]);
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        w.raw(q(min.axis(a)));
        w.raw(q(max.axis(a)));
        w.raw(q(min.axis(b)) - 1);
        w.raw(q(max.axis(b)) + 1);
        w.raw(q(min.axis(c)) - 1);
        w.raw(q(max.axis(c)) + 1);
        w.raw(id as i64);
        w.raw(mat as i64);
    }
}

/// The box kernel.
pub fn kernel(g: &Gen, sides: Sides) -> K {
    let mut k = K::new();
    let two = sides == Sides::Both;
    k.doc(&format!(
        "{}: the box test of one record (the stream), one section per axis{}.\n\
         In: r1..r3 o, r4..r6 d, r7 tbest. Out where F: r7 = t, HIT_N, HIT_OBJ, HIT_MAT{}.\n\
         Per axis a: the face facing the ray, t = |face - o_a| / |d_a|, inside the other two slabs.",
        kernel_name(sides),
        if two { ", entry faces then exit faces" } else { "" },
        if two { ", HIT_BACK_OBJ" } else { "" },
    ));
    for a in 0..3u32 {
        face(&mut k, g, a, two, false);
    }
    if two {
        for a in 0..3u32 {
            face(&mut k, g, a, true, true);
        }
    }
    k
}

/// The section of axis `a`: its entry faces (`exit` false) or exit faces.
fn face(k: &mut K, g: &Gen, a: u32, two: bool, exit: bool) {
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    let (oa, da) = (1 + a, 4 + a);
    let axis = ["x", "y", "z"][a as usize];
    k.comment(&match (two, exit) {
        (false, _) => format!("faces across {axis}"),
        (true, false) => format!("entry faces across {axis}"),
        (true, true) => format!("exit faces across {axis}"),
    });
    // F: the max face is the one (entry: d_a < 0; exit: d_a > 0).
    k.c(format!("cmp.{} r{da}, #0", if exit { "gt" } else { "lt" }))
        .note("F: the max face")
        .c(format!("ld r15, [r0 + #{}]", ram::C_ONE))
        .c(if exit {
            "(f) neg r15, r15"
        } else {
            "(!f) neg r15, r15"
        })
        .c(format!("st r15, [#{}]", ram::TMP0))
        .note("the normal's component")
        .c("mov r8, fb0")
        .c("sel r8, fb0, r8")
        .c(format!("sub r8, r8, r{oa}"))
        .c(if exit {
            "(!f) neg r8, r8"
        } else {
            "(f) neg r8, r8"
        })
        .note("|face - o_a|")
        .c(format!("abs r9, r{da}"));
    k.c("cmp.gt r9, #0")
        .c("(f) cmp.gt r8, #0")
        .c("ldacc r8, <<Q14")
        .c("msu out, r7, r9")
        .c("acch r10")
        .c("(f) cmp.lt r10, #0")
        .note("F: ahead, nearer than tbest");
    divide(k, 8, 9, 11, [10, 12, 13, 14, 15], g.approx);
    if exit {
        // more than SELF_LSB ahead along the ray (not along the axis:
        // a grazing ray may start within an LSB of the face's plane)
        self_margin(k, 14, g.datapath);
        k.c("(f) cmp.gt r11, r14");
    }
    k.c(format!("ldacc r{}, <<Q14", 1 + b))
        .c(format!("mac r12, r11, r{}, >>Q14", 4 + b))
        .c(format!("ldacc r{}, <<Q14", 1 + c))
        .c(format!("mac r13, r11, r{}, >>Q14", 4 + c))
        .c("(f) cmp.le fb0, r12")
        .c("(f) cmp.ge fb0, r12")
        .c("(f) cmp.le fb0, r13")
        .c("(f) cmp.ge fb0, r13")
        .note("F: within the other slabs");
    if two {
        k.c("mov r8, fb0");
        if !exit {
            k.c(format!("ld r14, [r0 + #{}]", ram::ORIG_OBJ))
                .c("(f) cmp.ne r8, r14")
                .note("not the box the ray leaves");
        }
    }
    k.c("(f) mov r7, r11")
        .c(format!("ld r15, [r0 + #{}]", ram::TMP0))
        .c(format!("(f) st r15, [#{}]", ram::HIT_N + a))
        .c(format!("(f) st r0, [#{}]", ram::HIT_N + b))
        .c(format!("(f) st r0, [#{}]", ram::HIT_N + c));
    if two {
        // HIT_BACK_OBJ: the box on an exit face, else -1.
        k.c(format!("(f) st r8, [#{}]", ram::HIT_OBJ));
        if exit {
            k.c(format!("(f) st r8, [#{}]", ram::HIT_BACK_OBJ));
        } else {
            k.c("movb r9, #-1")
                .c(format!("(f) st r9, [#{}]", ram::HIT_BACK_OBJ));
        }
    } else {
        k.c(format!("(f) st fb0, [#{}]", ram::HIT_OBJ));
    }
    k.c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
}

/// The axis-aligned box ([`super::ChipPrimitive`]).
pub struct AaBox;

impl super::ChipPrimitive for AaBox {
    fn names(&self) -> [&'static str; 2] {
        ["box", "glass_box"]
    }

    fn layout(&self, sides: Sides, _fit: &Fit, _fan: usize, _caps: bool) -> Layout {
        layout(sides)
    }

    fn kernels(&self, sides: Sides, g: &Gen, _fit: &Fit) -> Vec<(&'static str, K)> {
        vec![(kernel_name(sides), kernel(g, sides))]
    }

    fn broadcast(&self, sides: Sides, t: &mut Code, _at: &str, _fit: &Fit, _caps: bool) {
        super::one(t, kernel_name(sides));
    }

    fn test_cost(&self, g: &Gen, _fit: &Fit) -> TestCost {
        TestCost::of(&kernel(g, Sides::Front))
    }

    /// The normal is exact (an axis).
    fn error_bound(&self) -> ErrorBound {
        ErrorBound::lsb(6.0, 1e-6)
    }

    fn write(&self, w: &mut W, o: &Object) -> Result<(), RecordError> {
        let Some(b) = o.shape.as_box() else {
            return Err(RecordError::mismatch("box"));
        };
        write(w, o.sides, b.min, b.max, o.id, o.mat);
        Ok(())
    }
}
