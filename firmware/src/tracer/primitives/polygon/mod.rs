//! Polygon, convex or concave, by the even-odd rule as the reference
//! (`scene/shape/polygon.rs`), by the crossing test in
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
//! **Banded record** (the packet traversal, where the scene has a polygon
//! of [`BANDED_FROM`] edges or more): the polygon's projected rows are cut
//! into up to [`BANDS`] bands `[Y_b, Y_b+1)` (integer LSB, about
//! [`EDGES_PER_BAND`] edges each), and each edge into one **sub-edge** per
//! band its rows meet: the rows it straddles clipped to the band (`ya`,
//! `yb`), with the edge's own line for the crossing (`xi, yi, s ey, s ex`).
//! A point's row lies in one band, where its sub-edges straddle it exactly
//! where the edge does, so the parity over the sub-edges of the bands that
//! hold the packet's points is the parity over every edge: the same bit
//! for bit. Record (`1 + 15 + 2 (BANDS + 1) + 1 + 6 fan + 5` words, `fan`
//! the scene's most sub-edges): the band count (`POLY_NB`), the head, the
//! band bounds `Y_0..Y_nb` (`POLY_BOUNDS`), per band the word offset of
//! its first sub-edge from `POLY_FAN` and the end's (`POLY_STARTS`), the
//! tail's offset in the record (`POLY_TAIL`), the sub-edges by band
//! (`POLY_FAN`, 6 words each: `xi, ya - 1, yb - 1, yi, s ey, s ex`), the tail.
//! TinyRISC finds the lowest and the highest band holding a point of an
//! awake ray whose plane hit is valid, by bisection over the bands (a
//! 4-context probe and an `rcany` each, `k_polygon_below` /
//! `k_polygon_above`), and runs only the sub-edges from the one to the
//! other (`k_polygon_band_edge`, 11 contexts).
//!
//! **Sub-edges apart** (a streamed layout's banded records over
//! [`APART_FROM`] words, [`Form::Apart`]): the record that moves with a
//! leaf's piece stops after the table: in place of the sub-edges, the
//! main-memory place of the polygon's sub-edges (`POLY_FANS_AT`, in
//! [`FAN_UNIT`]-byte units from `FANS`, once per polygon however many
//! leaves it is in), then the tail (`1 + 15 + 2 (BANDS + 1) + 1 + 1 + 5`
//! words, 57 for SPD gears' faces against 1,088). Once the bisection has
//! found the bands and the array is done, TinyRISC moves only their
//! sub-edges by DMA into `FAN_BUF` (the top of FB bank 1) and runs them
//! from there: a packet whose points lie in two of a face's 16 bands
//! moves an eighth of its sub-edges, and a face no awake ray's plane hit
//! reaches moves none.
//!
//! **Two-sided** (a transmitting polygon): the head's plane test on both
//! sides and the planar kernels' two-sided commit in the tail.
//!
//! **Local positions** (`Fit::local`, [`kernels`]): the head carries the
//! plane's offset below the LSB after the vertex and `U`, `V` again at
//! its end (22 words); the edges are relative to the rounded `v0` in
//! `2^-POLY_K` LSB ([`fine_k`], cut under [`FINE_EDGE_MAX`]) with the rows
//! first (`yi, yj, xi, s ey, s ex`; sub-edges `ya - 1, yb - 1, xi, yi, s
//! ey, s ex`). The one-sided head finds `t` and the hit point to 2^-14
//! LSB and leaves `-px`, `-py` in that unit (rounded up) with the parts
//! below (r9, r15); the crossing test is exact with them; the tail
//! commits `t` and the point the head left. The two-sided head is the
//! scene format's, its point in the edges' unit without a remainder.
//!
//! **Registers**: r1..r7 the ray (r7 the new `tbest` where F); r8 the
//! parity and r9 `t` across the runs; r10, r11 `-px`, `-py` across the
//! runs; r12..r15 temporaries; RAM `TMP0` (valid), `TMP3` (two-sided:
//! back).
//!
//! **Error** against the f64 polygon: its `error_bound` (below), which
//! `tb/tests/kernels.rs` holds both chips to on a convex, a concave and a
//! gear-like polygon.

mod broadcast;
mod kernels;

pub use broadcast::{broadcast, broadcast_edges};
use kernels::{band_edge, edge, head, probe, tail};

use super::super::emit::{Code, Name, Reg, K};
use super::planar;
use super::record::{Field, Layout, W};
use super::{CutTest, ErrorBound, Fit, Gen, Object, RecordError, Sides, TestCost};
use crate::scene::{Shape, Vec3};

/// The record's fields. A plain record: the edge count, the head, the
/// edges, the tail; a banded one: the band count, the head, the bands'
/// table (bounds, starts, the tail's offset), the sub-edges (or, apart,
/// where they are in main memory), the tail.
pub const POLY_EDGES: Field = Field::named("POLY_EDGES", "polygon record: number of edges (words)");
pub const POLY_NB: Field = Field::named("POLY_NB", "banded polygon record: number of bands");
pub const POLY_HEAD: Field = Field::named("POLY_HEAD", "polygon record: the head kernel's stream");
pub const POLY_BOUNDS: Field = Field::named("POLY_BOUNDS", "  the bands' bounds Y_0..Y_nb");
pub const POLY_STARTS: Field = Field::named(
    "POLY_STARTS",
    "  per band its first sub-edge (words from POLY_FAN), and the end",
);
pub const POLY_STARTS_APART: Field = Field::named(
    "POLY_STARTS",
    "  per band its first sub-edge (words from the first), and the end",
);
pub const POLY_TAIL: Field = Field::named("POLY_TAIL", "  the tail's offset");
pub const POLY_FANS_AT: Field = Field::named(
    "POLY_FANS_AT",
    "  its sub-edges in main memory: FAN_UNIT-byte units from FANS",
);
pub const POLY_FAN: Field = Field::named("POLY_FAN", "polygon record: the first edge's stream");
pub const POLY_BAND_FAN: Field = Field::named("POLY_FAN", "  the first sub-edge's stream");
pub const TAIL: Field = Field::part(
    "tail",
    "the face normal, obj, mat (the tail kernel's stream)",
);

/// The words of an edge's and a sub-edge's stream (header constants).
pub const POLY_EDGE_WORDS: Name = Name::new(
    "POLY_EDGE_WORDS",
    EDGE_WORDS as u32,
    "words of an edge's stream",
);
pub const POLY_BAND_EDGE_WORDS: Name = Name::new(
    "POLY_BAND_EDGE_WORDS",
    BAND_EDGE_WORDS as u32,
    "words of a sub-edge's stream",
);

/// Words of the head, one edge and the tail.
pub const HEAD_WORDS: usize = 15;
pub const EDGE_WORDS: usize = 5;
pub const TAIL_WORDS: usize = 5;

/// Words of a sub-edge of a banded record.
pub const BAND_EDGE_WORDS: usize = 6;

/// The most bands of a banded record.
pub const BANDS: usize = 16;

/// Records are banded (the packet traversal) where the scene has a
/// polygon of this many edges or more.
pub const BANDED_FROM: usize = 16;

/// Edges per band aimed at.
pub const EDGES_PER_BAND: usize = 16;

/// Words of the banded record's table: the bounds, the starts, the tail's
/// offset.
const TABLE_WORDS: usize = 2 * (BANDS + 1) + 1;

/// A streamed layout keeps banded records' sub-edges apart where the
/// records would be over this many words (the further leaf pieces'
/// default size): such a record moves alone, and a packet runs a few of
/// its bands. Smaller ones move with their pieces, overlapped with the
/// tests, for less than the sub-edges' own DMA would cost.
pub const APART_FROM: usize = 256;

/// Bytes of the unit `POLY_FANS_AT` counts in (sub-edges apart): each
/// polygon's sub-edges start on a multiple of it in main memory, so a
/// 16-bit word reaches 2 MiB of them.
pub const FAN_UNIT: usize = 64;

/// The record forms of a polygon.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Form {
    /// Every edge in the record.
    #[default]
    Plain,
    /// Sub-edges by band, in the record.
    Banded,
    /// Sub-edges by band in main memory, moved by DMA for the bands a
    /// packet's points lie in (streamed layouts).
    Apart,
}

impl Form {
    /// Sub-edges by band (in the record or apart).
    pub fn banded(self) -> bool {
        self != Form::Plain
    }
}

/// Whether a streamed layout keeps the sub-edges of banded records of
/// `banded_words` words apart ([`APART_FROM`]).
pub fn keeps_apart(banded_words: usize) -> bool {
    banded_words > APART_FROM
}

/// Words of the head; `fine` (local positions): with the plane's offset
/// below the LSB ([`planar::PLANE_REM`]) after the vertex and the axes
/// `U`, `V` again after them (the hit point's remainder projected).
fn head_words(fine: bool) -> usize {
    HEAD_WORDS + 7 * fine as usize
}

/// The record with room for `fan` edges (sub-edges where banded; none
/// where they are apart).
pub fn layout(fan: usize, form: Form) -> Layout {
    layout_as(fan, form, false)
}

/// [`layout`], the head `fine` ([`head_words`]).
fn layout_as(fan: usize, form: Form, fine: bool) -> Layout {
    let table = [(POLY_BOUNDS, BANDS + 1), (POLY_TAIL, 1)];
    let head = (POLY_HEAD, head_words(fine));
    match form {
        Form::Plain => Layout::new([
            (POLY_EDGES, 1),
            head,
            (POLY_FAN, fan * EDGE_WORDS),
            (TAIL, TAIL_WORDS),
        ]),
        Form::Banded => Layout::new([
            (POLY_NB, 1),
            head,
            table[0],
            (POLY_STARTS, BANDS + 1),
            table[1],
            (POLY_BAND_FAN, fan * BAND_EDGE_WORDS),
            (TAIL, TAIL_WORDS),
        ]),
        Form::Apart => Layout::new([
            (POLY_NB, 1),
            head,
            table[0],
            (POLY_STARTS_APART, BANDS + 1),
            table[1],
            (POLY_FANS_AT, 1),
            (TAIL, TAIL_WORDS),
        ]),
    }
}

/// Words of a record with room for `fan` edges.
pub fn words(fan: usize, form: Form) -> usize {
    layout(fan, form).words()
}

/// The header lines of the record's fields and of an edge's words.
pub fn header(form: Form) -> Vec<String> {
    header_as(form, false)
}

fn header_as(form: Form, fine: bool) -> Vec<String> {
    let mut v = Layout::header(&[layout_as(0, form, fine)]);
    v.push(if form.banded() {
        POLY_BAND_EDGE_WORDS.define()
    } else {
        POLY_EDGE_WORDS.define()
    });
    v
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
const BAND_EDGE: &str = "k_polygon_band_edge";
const BELOW: &str = "k_polygon_below";
const ABOVE: &str = "k_polygon_above";

/// The kernels of a polygon's test, in load order: the head, the edge
/// (banded records: the sub-edge and the two probes), the tail.
pub fn kernels(g: &Gen, s: Sides, form: Form) -> Vec<(&'static str, K)> {
    kernels_as(g, s, form, false)
}

/// [`kernels`] of records whose head is `fine` ([`head_words`]: local
/// positions): one side, the head's plane test [`plane_hit_fine`], `t`
/// and the hit point to 2^-14 LSB before the crossing test, which takes
/// the point's remainder ([`head_fine`], [`edge`]); two sides, the scene
/// format's test past the words it does not use, its point without a
/// remainder.
fn kernels_as(g: &Gen, s: Sides, form: Form, fine: bool) -> Vec<(&'static str, K)> {
    let mut v = vec![(head_name(s), head(g, s, fine))];
    if form.banded() {
        v.push((BAND_EDGE, band_edge(fine)));
        v.push((BELOW, probe(false)));
        v.push((ABOVE, probe(true)));
    } else {
        v.push((EDGE, edge(fine)));
    }
    v.push((tail_name(s), tail(s, fine)));
    v
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
    edges_as(v, s, None)
}

/// [`edges`]; `fine` (the crossing test with the point's remainder,
/// [`edge`]) with its scale `k`: the vertices relative to `v0` rounded to
/// the LSB in `2^-k` LSB, and an edge with `|ex| + |ey|` of
/// [`FINE_EDGE_MAX`] or more cut into parts under it at rounded points
/// between its ends.
pub fn edges_as(v: &[Vec3], s: f64, fine: Option<u32>) -> ((usize, usize), Vec<[i64; 5]>) {
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
    let sk = (fine.unwrap_or(0) as f64).exp2();
    let q = |p: Vec3, a: usize| ((p.axis(a) * s - (v[0].axis(a) * s).round()) * sk).round() as i64;
    let p2 = |p: Vec3| (q(p, ua), q(p, va));
    let mut edges = Vec::new();
    for k in 0..v.len() {
        let ((xi, yi), (xj, yj)) = (p2(v[k]), p2(v[(k + 1) % v.len()]));
        let long = (xj - xi).abs() + (yj - yi).abs();
        let parts = if fine.is_some() {
            long / FINE_EDGE_MAX + 1
        } else {
            1
        };
        let at = |m: i64| {
            let f = m as f64 / parts as f64;
            let r = |a: i64, b: i64| a + ((b - a) as f64 * f).round() as i64;
            (r(xi, xj), r(yi, yj))
        };
        for m in 0..parts {
            let ((xi, yi), (xj, yj)) = (at(m), at(m + 1));
            let (ex, ey) = (xj - xi, yj - yi);
            if ey != 0 {
                let sg = ey.signum();
                edges.push([xi, yi, yj, sg * ey, sg * ex]);
            }
        }
    }
    ((ua, va), edges)
}

/// The longest edge (`|ex| + |ey|`, units) of a fine record: the crossing
/// test's integer part saturates in the word only where the point lies
/// farther from the edge's line than its fraction can reach ([`edge`]).
pub const FINE_EDGE_MAX: i64 = 32000;

/// The scale `k` of the fine records' crossing test (local positions):
/// the vertices relative to the first in `2^-k` LSB, up to
/// [`FINE_K_MAX`], for every polygon of `polygons` (`s` LSB per unit) one
/// that keeps its vertices within 16,000 units of the first.
pub fn fine_k<'a>(polygons: impl Iterator<Item = &'a [Vec3]>, s: f64) -> u32 {
    polygons
        .map(|v| {
            let span = v
                .iter()
                .flat_map(|p| (0..3).map(move |a| (p.axis(a) - v[0].axis(a)).abs()))
                .fold(0.0, f64::max)
                * s
                + 1.0;
            (0..=FINE_K_MAX)
                .rev()
                .find(|&k| span * (k as f64).exp2() <= 16000.0)
                .unwrap_or(0)
        })
        .min()
        .unwrap_or(0)
}

/// The finest scale of [`fine_k`]: 2^-8 LSB.
pub const FINE_K_MAX: u32 = 8;

/// An edge's words in the record: `xi, yi, yj, s ey, s ex`; `fine`, the
/// rows first ([`edge`]): `yi, yj, xi, s ey, s ex`.
fn edge_words(e: &[i64; 5], fine: bool) -> [i64; 5] {
    if fine {
        [e[1], e[2], e[0], e[3], e[4]]
    } else {
        *e
    }
}

/// A polygon's bands (from its [`edges`]): the bounds `Y_0 < .. < Y_nb`
/// of its rows (integer LSB relative to `v0`) and per band its
/// sub-edges, `[xi, ya, yb, yi, s ey, s ex]`: the rows `[ya, yb)` the edge
/// straddles within the band, the edge's line. Each band about
/// [`EDGES_PER_BAND`] edges tall, at most [`BANDS`].
pub fn bands(edges: &[[i64; 5]]) -> (Vec<i64>, Vec<Vec<[i64; 6]>>) {
    // An edge straddles the rows [min(yi, yj), max(yi, yj)).
    let rows = |e: &[i64; 5]| (e[1].min(e[2]), e[1].max(e[2]));
    let lo = edges.iter().map(|e| rows(e).0).min().unwrap_or(0);
    let hi = edges.iter().map(|e| rows(e).1).max().unwrap_or(1);
    let nb = (edges.len() / EDGES_PER_BAND)
        .clamp(1, BANDS)
        .min((hi - lo).max(1) as usize) as i64;
    let bounds: Vec<i64> = (0..=nb).map(|b| lo + (hi - lo) * b / nb).collect();
    let sub = bounds
        .windows(2)
        .map(|y| {
            edges
                .iter()
                .filter_map(|e| {
                    let (a, b) = rows(e);
                    let (ya, yb) = (a.max(y[0]), b.min(y[1]));
                    (ya < yb).then_some([e[0], ya, yb, e[1], e[3], e[4]])
                })
                .collect()
        })
        .collect();
    (bounds, sub)
}

/// Sub-edges of a polygon's banded record.
pub fn band_edges(edges: &[[i64; 5]]) -> usize {
    bands(edges).1.iter().map(Vec::len).sum()
}

/// Write the record of polygon `v` into a record of `size` words (in
/// `form`; the sub-edges of `Form::Apart` into `w.fans`). Err: the
/// sub-edges apart are past what `POLY_FANS_AT` reaches. `fine`: the head
/// with the plane's offset below the LSB ([`head_words`]).
pub(crate) fn write_as(
    w: &mut W,
    v: &[Vec3],
    (size, form, scale): (usize, Form, Option<u32>),
    id: usize,
    mat: usize,
) -> Result<(), String> {
    let start = w.fb.len();
    let fine = scale.is_some();
    let n = normal(v);
    let ((ua, va), edges) = edges_as(v, w.s, scale);
    let banded = form.banded().then(|| bands(&edges));
    w.field(if form.banded() { POLY_NB } else { POLY_EDGES });
    w.raw(match &banded {
        Some((bounds, _)) => bounds.len() as i64 - 1,
        None => edges.len() as i64,
    });
    w.field(POLY_HEAD);
    w.unit(n);
    w.point(v[0]);
    if fine {
        planar::plane_rem(w, n, v[0]);
    }
    w.point(v[0]);
    let axis = |a: usize| {
        Vec3::new(
            (a == 0) as u8 as f64,
            (a == 1) as u8 as f64,
            (a == 2) as u8 as f64,
        )
    };
    for _ in 0..1 + fine as usize {
        w.unit(axis(ua));
        w.unit(axis(va));
    }
    if let Some((bounds, sub)) = &banded {
        let row = |w: &mut W, xs: &[i64], n: usize| {
            for k in 0..n {
                w.raw(*xs.get(k).unwrap_or(&0));
            }
        };
        w.field(POLY_BOUNDS);
        row(w, bounds, BANDS + 1);
        let mut at = vec![0i64];
        for b in sub {
            at.push(at.last().unwrap() + (b.len() * BAND_EDGE_WORDS) as i64);
        }
        w.field(if form == Form::Apart {
            POLY_STARTS_APART
        } else {
            POLY_STARTS
        });
        row(w, &at, BANDS + 1);
        let fan = 1 + head_words(fine) + TABLE_WORDS;
        if form == Form::Apart {
            // The tail after the sub-edges' place; the sub-edges on a
            // unit of their own in main memory.
            w.field(POLY_TAIL);
            w.raw(fan as i64 + 1);
            let unit = FAN_UNIT / w.word_bytes();
            let units = w.fans.len() / unit;
            if units > i16::MAX as usize {
                return Err(format!(
                    "the banded polygons' sub-edges take over {} KiB of main memory, more than POLY_FANS_AT reaches",
                    units * FAN_UNIT / 1024
                ));
            }
            w.field(POLY_FANS_AT);
            w.raw(units as i64);
            w.fan_most = w.fan_most.max(*at.last().unwrap() as usize);
            for x in sub.iter().flatten().flat_map(|e| sub_edge_words(e, fine)) {
                let v = w.sat(x as f64);
                w.fans.push(v);
            }
            w.fans.resize(w.fans.len().next_multiple_of(unit), 0);
        } else {
            w.field(POLY_TAIL);
            w.raw(fan as i64 + at.last().unwrap());
            w.field(POLY_BAND_FAN);
            for x in sub.iter().flatten().flat_map(|e| sub_edge_words(e, fine)) {
                w.raw(x);
            }
        }
    } else {
        w.field(POLY_FAN);
        for e in &edges {
            for x in edge_words(e, fine) {
                w.raw(x);
            }
        }
    }
    // The tail after the record's own edges; the record padded to its
    // layout's room for the scene's most edges.
    w.field(TAIL);
    w.unit(n);
    w.raw(id as i64);
    w.raw(mat as i64);
    w.fb.resize(start + size, 0);
    Ok(())
}

/// A sub-edge's record words: `ya`, `yb` one LSB lower, so that `ya - py
/// > 0` is the sign bit of `(ya - 1) - py` clear, and the straddle test
/// one `xor` of two sign bits ([`band_edge`]); `fine`, the rows first.
fn sub_edge_words(e: &[i64; 6], fine: bool) -> [i64; 6] {
    if fine {
        [e[1] - 1, e[2] - 1, e[0], e[3], e[4], e[5]]
    } else {
        [e[0], e[1] - 1, e[2] - 1, e[3], e[4], e[5]]
    }
}

/// The polygon ([`super::ChipPrimitive`]): 4 or more coplanar vertices,
/// convex or concave.
pub struct Polygon;

impl super::ChipPrimitive for Polygon {
    fn names(&self) -> [&'static str; 2] {
        ["polygon", "glass_polygon"]
    }

    fn layout(&self, _sides: Sides, fit: &Fit, fan: usize, _caps: bool) -> Layout {
        layout_as(fan, fit.polygon_form, fit.local)
    }

    fn kernels(&self, sides: Sides, g: &Gen, fit: &Fit) -> Vec<(&'static str, K)> {
        kernels_as(g, sides, fit.polygon_form, fit.local)
    }

    fn broadcast(&self, sides: Sides, t: &mut Code, at: &str, fit: &Fit, _caps: bool) {
        broadcast(t, at, sides, fit.polygon_form)
    }

    fn cut_test(&self, sides: Sides, _fit: &Fit) -> Option<CutTest> {
        Some(CutTest {
            kernel: head_name(sides),
            field: POLY_HEAD.name,
            cuts: &[],
            then: Some("the plane hit before tbest"),
        })
    }

    fn broadcast_then(&self, sides: Sides, t: &mut Code, at: &str, rec: Reg, fit: &Fit) {
        broadcast_edges(t, at, sides, rec, fit.polygon_form);
    }

    fn record_header(&self, fit: &Fit, _sides: &[Sides], _caps: bool) -> Vec<String> {
        header_as(fit.polygon_form, fit.local)
    }

    fn fit_header(&self, fit: &Fit) -> Vec<String> {
        if !fit.local {
            return Vec::new();
        }
        vec![
            super::define(
                "POLY_K",
                fit.poly_k,
                "polygons: the crossing test in 2^-POLY_K LSB (local positions)",
            ),
            super::define(
                "POLY_KSH",
                14 - fit.poly_k,
                "polygons: 14 - POLY_K, the bits of the point's part below that unit",
            ),
        ]
    }

    /// The head whole, the tail, an edge per edge (plain records).
    fn test_cost(&self, g: &Gen, fit: &Fit) -> TestCost {
        let k: Vec<usize> = kernels_as(g, Sides::Front, Form::Plain, fit.local)
            .iter()
            .map(|(_, k)| k.len())
            .collect();
        TestCost {
            first: k[0],
            rest: k[2],
            each: k[1],
        }
    }

    fn cost_runs(&self, shape: &Shape, s: f64) -> usize {
        shape.as_polygon().map_or(0, |p| edges(&p.v, s).1.len())
    }

    fn fan(&self, shape: &Shape, s: f64, banded: bool) -> usize {
        let Some(p) = shape.as_polygon() else {
            return 0;
        };
        let e = edges(&p.v, s).1;
        if banded {
            band_edges(&e)
        } else {
            e.len()
        }
    }

    /// Concave outlines included; no crack between edges.
    fn error_bound(&self) -> ErrorBound {
        ErrorBound::lsb(12.0, 1e-3)
    }

    fn write(&self, w: &mut W, o: &Object) -> Result<(), RecordError> {
        let Some(p) = o.shape.as_polygon() else {
            return Err(RecordError::mismatch("polygon"));
        };
        let scale = o.fit.local.then_some(o.fit.poly_k);
        let f = (o.size, o.fit.polygon_form, scale);
        write_as(w, &p.v, f, o.id, o.mat).map_err(RecordError::Scene)
    }
}
