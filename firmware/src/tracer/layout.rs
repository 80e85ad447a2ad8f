//! The frame-buffer image the tracer reads (FB set 0, word addresses):
//!
//! ```text
//! 0     RSQ table (128) | RCP table (128) | 1.0 | 32767      init stream
//! EYE   px0, py0 (written per tile), from.xyz, (A, B, C) x 3  eye stream
//! POST  background.rgb, (material id, ks) per material
//! LIGHT per light: position.xyz
//! SHADE per light, per material: id, then per channel kd c lc, ks lc
//! objects, grouped by type, fixed record size per type (kernels.rs;
//!     polygons padded to the largest fan of the scene)
//! BSP nodes (paper's Fig. 5): flags (bit 15 leaf, bits 1..0 axis), split,
//!     left, right (FB addresses), cell bounds widened by 2 LSB (6 words),
//!     one membership bit vector per type present (bit 15 of word 0 = the
//!     type's object 0);
//!     or, compact (`NodeLayout::Compact`), an inner node's flags, split,
//!     left, right or a leaf's flags and cell bounds, then per type present
//!     the number of the node's objects of that type and their slot
//!     indices, ascending (nodes of varying size)
//! mailboxes: one word per object, the number of the pass that last
//!     tested it (object merging)
//! ```
//!
//! A scene whose image does not fit FB set 0 gets the streamed layout
//! ([`Stream`]): only the part up to SHADE stays in the FB (bank 0, plus
//! one split word); nodes, per-leaf blocks of records and mailboxes go to
//! main memory, and bank 1 is the streaming buffer.

use crate::scene::{PrimType, Scene, Shape, Vec3};
use crate::scene_image::{SceneImage, Q_MATERIAL, Q_UNIT};

use super::kernels::Inside;
use super::{NodeLayout, Options, Traversal};

pub const FB_LIMIT: usize = 0x8000;
/// Head words of a Fig. 5 node: flags, split, left, right, cell bounds.
pub const NODE_HEAD: usize = 10;
/// Head words of a compact inner node (flags, split, left, right) and
/// leaf (flags, cell bounds); the index lists follow.
pub const COMPACT_INNER_HEAD: usize = 4;
pub const COMPACT_LEAF_HEAD: usize = 7;

/// Head words of a compact node.
pub fn compact_head(leaf: bool) -> usize {
    if leaf {
        COMPACT_LEAF_HEAD
    } else {
        COMPACT_INNER_HEAD
    }
}

/// The chip's object types, in test order (object test reordering).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChipType {
    Sphere,
    Cylinder,
    Box,
    Rectangle,
    Triangle,
    Polygon,
    /// Cones with unequal radii (tested after the cylinders).
    Cone,
    /// Triangles with vertex normals (NFF `pp`): the planar test, then the
    /// normals interpolated at the hit ([`super::kernels::smooth_triangle`]).
    SmoothTriangle,
    /// Spheres of a transmitting material: two-sided, for rays that enter
    /// and leave them ([`super::kernels::sphere_two_sided`]).
    GlassSphere,
    /// Rectangles, triangles and polygons of a transmitting material
    /// (two-sided: [`super::kernels::planar_two_sided`],
    /// [`super::kernels::polygon_head_two_sided`]).
    GlassRectangle,
    GlassTriangle,
    GlassPolygon,
    /// Boxes of a transmitting material: entry and exit faces
    /// ([`super::kernels::aabox_two_sided`]), the record twice.
    GlassBox,
    /// Cylinders of a transmitting material: the body twice (outside and
    /// inside, [`super::kernels::cylinder_side`]), two-sided caps.
    GlassCylinder,
    /// Cones of a transmitting material, as the cylinders
    /// ([`super::kernels::cone_side`]).
    GlassCone,
    /// Smooth triangles of a transmitting material
    /// ([`super::kernels::smooth_triangle_two_sided`]).
    GlassSmoothTriangle,
}

impl ChipType {
    pub const ALL: [ChipType; 16] = [
        ChipType::Sphere,
        ChipType::GlassSphere,
        ChipType::Cylinder,
        ChipType::Cone,
        ChipType::Box,
        ChipType::Rectangle,
        ChipType::Triangle,
        ChipType::SmoothTriangle,
        ChipType::Polygon,
        ChipType::GlassRectangle,
        ChipType::GlassTriangle,
        ChipType::GlassPolygon,
        ChipType::GlassBox,
        ChipType::GlassCylinder,
        ChipType::GlassCone,
        ChipType::GlassSmoothTriangle,
    ];
    pub fn name(self) -> &'static str {
        match self {
            ChipType::Sphere => "sphere",
            ChipType::Cylinder => "cylinder",
            ChipType::Box => "box",
            ChipType::Rectangle => "rectangle",
            ChipType::Triangle => "triangle",
            ChipType::Polygon => "polygon",
            ChipType::Cone => "cone",
            ChipType::SmoothTriangle => "smooth_triangle",
            ChipType::GlassSphere => "glass_sphere",
            ChipType::GlassRectangle => "glass_rectangle",
            ChipType::GlassTriangle => "glass_triangle",
            ChipType::GlassPolygon => "glass_polygon",
            ChipType::GlassBox => "glass_box",
            ChipType::GlassCylinder => "glass_cylinder",
            ChipType::GlassCone => "glass_cone",
            ChipType::GlassSmoothTriangle => "glass_smooth_triangle",
        }
    }
    /// The chip type of an object: its primitive's, with smooth triangles
    /// and transmitting (two-sided) spheres apart.
    fn of_object(s: &Shape, transmits: bool) -> Option<ChipType> {
        match s {
            Shape::Triangle {
                normals: Some(_), ..
            } if transmits => Some(ChipType::GlassSmoothTriangle),
            Shape::Triangle {
                normals: Some(_), ..
            } => Some(ChipType::SmoothTriangle),
            Shape::Sphere { .. } if transmits => Some(ChipType::GlassSphere),
            Shape::Rectangle { .. } if transmits => Some(ChipType::GlassRectangle),
            Shape::Triangle { .. } if transmits => Some(ChipType::GlassTriangle),
            Shape::Polygon { .. } if transmits => Some(ChipType::GlassPolygon),
            Shape::Box { .. } if transmits => Some(ChipType::GlassBox),
            Shape::Cone { .. } if transmits && s.prim_type() == PrimType::Cylinder => {
                Some(ChipType::GlassCylinder)
            }
            Shape::Cone { .. } if transmits => Some(ChipType::GlassCone),
            _ => ChipType::of(s.prim_type()),
        }
    }
    /// Types whose kernels test both sides (the reference's rule for
    /// transmitting objects) and refract.
    pub fn refracts(self) -> bool {
        matches!(
            self,
            ChipType::GlassSphere
                | ChipType::GlassRectangle
                | ChipType::GlassTriangle
                | ChipType::GlassPolygon
                | ChipType::GlassBox
                | ChipType::GlassCylinder
                | ChipType::GlassCone
                | ChipType::GlassSmoothTriangle
        )
    }
    fn of(p: PrimType) -> Option<ChipType> {
        Some(match p {
            PrimType::Sphere => ChipType::Sphere,
            PrimType::Cylinder => ChipType::Cylinder,
            PrimType::Cone => ChipType::Cone,
            PrimType::Box => ChipType::Box,
            PrimType::Rectangle => ChipType::Rectangle,
            PrimType::Triangle => ChipType::Triangle,
            PrimType::Polygon => ChipType::Polygon,
        })
    }
}

pub const SPHERE_WORDS: usize = 8;
/// Sphere record with the centre's remainder ([`super::kernels::sphere_with`]).
pub const SPHERE_FINE_WORDS: usize = 11;
/// Spheres get the fine record when the smallest is under this many LSB in
/// radius (the rounding of the centre, up to 0.87 LSB, is then over 1.4% of
/// the radius).
pub const SPHERE_FINE_BELOW_LSB: f64 = 64.0;
pub const PLANAR_WORDS: usize = 20;
/// Smooth triangle: the planar record with the vertex normals (per axis
/// `n0, n1, n2`, Q1.14) before the face normal at its end.
pub const SMOOTH_WORDS: usize = PLANAR_WORDS + 9;
pub const CYL_BODY_WORDS: usize = 36;
/// The cylinder body without the base's remainders (fine normals off).
pub const CYL_BODY_WORDS_COARSE: usize = 34;

/// Words of a cylinder body ([`super::kernels::cylinder`]).
pub const fn cyl_body_words(fine_normals: bool) -> usize {
    if fine_normals {
        CYL_BODY_WORDS
    } else {
        CYL_BODY_WORDS_COARSE
    }
}

/// Cylinder group: caps flag, body, base cap, apex cap.
pub const fn cyl_words(fine_normals: bool) -> usize {
    1 + cyl_body_words(fine_normals) + 2 * PLANAR_WORDS
}
pub const CONE_BODY_WORDS: usize = 40;
/// Cone group: caps flag, body, base cap, apex cap (as the cylinder's).
pub const CONE_WORDS: usize = 1 + CONE_BODY_WORDS + 2 * PLANAR_WORDS;
pub const BOX_WORDS: usize = 24;
/// Polygon record: edge count, head, one part per non-horizontal edge of the
/// crossing test (padded to the scene's largest polygon), tail.
pub const POLY_HEAD_WORDS: usize = 15;
pub const POLY_EDGE_WORDS: usize = 5;
pub const POLY_TAIL_WORDS: usize = 5;

/// One type present in the scene.
#[derive(Clone, Debug)]
pub struct TypeInfo {
    pub ty: ChipType,
    /// Scene object indices, in slot order.
    pub objects: Vec<usize>,
    pub first: usize,
    pub size: usize,
    /// Offset of the type's bit vector in a Fig. 5 node.
    pub bv_offset: usize,
    pub bv_words: usize,
    pub mailbox: usize,
    /// Polygons: edges per record (the largest polygon's non-horizontal
    /// edges in its projection).
    pub fan: usize,
}

/// The laid-out image and everything the generator needs to know of it.
#[derive(Clone, Debug)]
pub struct Layout {
    /// FB words as values: 16-bit on the 16-bit chip; on the 32-bit chip
    /// numeric words use the whole word and the others (flags, addresses,
    /// bit vectors, counts) are the 16-bit words sign-extended.
    pub fb: Vec<i32>,
    pub frac: u32,
    pub eye: usize,
    pub post: usize,
    /// FB address of the refraction table (`id, T, 1/ior, ior` per
    /// transmitting material) and its entries; `refract`: the scene has
    /// refracting objects (the ray tree branches).
    pub transmit: usize,
    pub transmit_materials: usize,
    pub refract: bool,
    pub lights: Vec<usize>,
    pub shades: Vec<usize>,
    pub types: Vec<TypeInfo>,
    pub root: usize,
    /// Words (32-bit words when streamed) of a node; 0 for compact nodes,
    /// whose size varies.
    pub node_words: usize,
    /// The node format of the resident layout (the option; the streamed
    /// layout has per-leaf lists whichever it is).
    pub node_layout: NodeLayout,
    /// The traversal the nodes are laid out for.
    pub traversal: Traversal,
    /// Packet traversal: FB address of the root cell widened by
    /// [`super::kernels::P_TOL`] (6 words: per axis min, max).
    pub root_box: usize,
    /// Packet traversal: the tree it walks is a single leaf.
    pub root_leaf: bool,
    /// Packet traversal: the expected array cycles of a packet's walk from
    /// the root, by the surface-area cost model of [`super::Collapse::Auto`]
    /// (0 for the paper's traversal).
    pub expected_cost: f64,
    /// FB words the resident image needs with this node format (tables to
    /// mailboxes), whether or not it fits and was used.
    pub resident_words: usize,
    /// Of those, the BSP nodes.
    pub resident_node_words: usize,
    pub mailbox: usize,
    pub objects: usize,
    pub materials: usize,
    /// Phong exponents: integer part and fraction (see [`split_shine`]).
    pub shines: Vec<(u32, f64)>,
    /// Scale shifts of the kernels.
    pub kd: u32,
    pub ks_sphere: u32,
    pub ks_cyl: u32,
    /// Extra fraction bits of the sphere kernel's perpendicular vector.
    pub ep_sphere: u32,
    /// Sphere records carry the centre's rounding remainder and the radius
    /// with `ep_sphere` extra bits ([`SPHERE_FINE_BELOW_LSB`]).
    pub sphere_fine: bool,
    /// Fine normals ([`super::Normals`], resolved for the datapath): the
    /// sphere and cylinder kernels and the cylinder record.
    pub fine_normals: bool,
    /// The same for the cylinder kernel.
    pub ep_cyl: u32,
    /// Scale shift of the cone kernel's `invS` and extra fraction bits of
    /// its perpendicular vector.
    pub ks_cone: u32,
    pub ep_cone: u32,
    pub kt_rect: u32,
    pub kt_tri: u32,
    pub kt_disc: u32,
    /// Light records carry a scale shift (some light is too far for
    /// `light - P` to fit the format, [`light_shift`]).
    pub light_shifted: bool,
    /// The streamed layout (scenes that do not fit FB set 0), or `None`
    /// when the whole scene is resident in the FB.
    pub stream: Option<Stream>,
}

/// FB bank 1 (set 0): the streaming buffer of the streamed layout.
pub const STREAM_BANK: usize = 0x4000;
/// Words at the start of a streamed leaf block: the cell bounds.
pub const BLOCK_HEAD: usize = 6;
/// Bytes of a node record in main memory (streamed layout).
pub const NODE_BYTES: usize = 64;

/// The streamed layout: the scene lives in main memory and TinyRISC moves
/// each leaf's block (cell bounds, then the records of its objects grouped
/// by type) into FB bank 1 by DMA when the traversal reaches it.
///
/// Node record (32-bit words, main memory): flags (-32768 leaf, else the
/// split axis), split (scene format), left, right (byte addresses), block
/// address, block words, list address, then per type present the number
/// of the leaf's objects of that type (words 7..13), their total (word 14).
/// List: per object, the byte address
/// of its mailbox half-word (number of the pass that last tested it).
#[derive(Clone, Debug)]
pub struct Stream {
    /// Main-memory byte address of [`Stream::image`].
    pub base: u32,
    pub image: Vec<u8>,
    pub root: u32,
    pub mailbox: u32,
    /// FB word (bank 0) the split value of the node being classified is
    /// written to.
    pub split_slot: usize,
    pub nodes: usize,
    pub largest_block: usize,
    /// Packet traversal: leaf blocks beyond one per leaf (a leaf whose
    /// records exceed FB bank 1 is moved in pieces).
    pub extra_pieces: usize,
}

/// Reciprocal square root table of `n` entries (a power of two up to 128):
/// entry k = 1/sqrt(X) for X = (k + 0.5) 2^(15 - log2 n) in Q.11, Q1.14
/// (saturated at the bottom, where it is never used).
pub fn rsq_table(n: usize) -> Vec<i32> {
    rsq_table_for(n, 0)
}

/// [`rsq_table`] with `x` extra fraction bits (16 on the 32-bit chip: the
/// same entries in Q1.30, indexed by X in Q.27).
pub fn rsq_table_for(n: usize, x: u32) -> Vec<i32> {
    let w = 32768.0 / n as f64;
    let one = ((14 + x) as f64).exp2();
    (0..n)
        .map(|k| {
            let v = (k as f64 + 0.5) * w / 2048.0;
            ((1.0 / v.sqrt()) * one).round().min(word_max(x)) as i32
        })
        .collect()
}

/// Reciprocal table of `n` entries: entry k = 2^29 / d for
/// d = 2^14 + (k + 0.5) 2^14 / n.
pub fn rcp_table(n: usize) -> Vec<i32> {
    rcp_table_for(n, 0)
}

/// [`rcp_table`] with `x` extra fraction bits: `2^(29 + 2x) / d` for
/// `d = 2^(14 + x) + (k + 0.5) 2^(14 + x) / n`.
pub fn rcp_table_for(n: usize, x: u32) -> Vec<i32> {
    let w = 16384.0 / n as f64;
    (0..n)
        .map(|k| {
            let d = 16384.0 + (k as f64 + 0.5) * w;
            (((29 + x) as f64).exp2() / d).round().min(word_max(x)) as i32
        })
        .collect()
}

/// The two 128-word table slots at the start of the init stream (RC RAM
/// `RSQ` and `RCP`): tables of `n` entries, the rest of each slot zero.
pub fn table_slots(n: usize) -> Vec<i32> {
    table_slots_for(n, 0)
}

/// [`table_slots`] with `x` extra fraction bits (the 32-bit chip: 16).
pub fn table_slots_for(n: usize, x: u32) -> Vec<i32> {
    let mut v = vec![0i32; 256];
    v[..n].copy_from_slice(&rsq_table_for(n, x));
    v[128..128 + n].copy_from_slice(&rcp_table_for(n, x));
    v
}

/// The largest word value with `x` extra bits (16-bit: 32767).
fn word_max(x: u32) -> f64 {
    ((15 + x) as f64).exp2() - 1.0
}

struct W {
    fb: Vec<i32>,
    s: f64,
    /// Extra bits of the datapath (0 or 16).
    x: u32,
}

impl W {
    fn max(&self) -> f64 {
        word_max(self.x)
    }
    /// Round and saturate to the word.
    fn sat(&self, v: f64) -> i32 {
        v.round().clamp(-self.max() - 1.0, self.max()) as i32
    }
    fn push(&mut self, v: f64) {
        let v = self.sat(v);
        self.fb.push(v);
    }
    /// A 16-bit structural word (flags, bit vectors), sign-extended.
    fn word16(&mut self, v: u16) {
        self.fb.push(v as i16 as i32);
    }
    /// One in Q1.14 (16-bit chip) or Q1.30.
    fn one(&self) -> f64 {
        ((14 + self.x) as f64).exp2()
    }
    fn coord(&mut self, x: f64) {
        self.push(x * self.s);
    }
    fn point(&mut self, v: Vec3) {
        for x in v.to_array() {
            self.coord(x);
        }
    }
    fn unit(&mut self, v: Vec3) {
        let k = Q_UNIT.lsb().recip() * (self.x as f64).exp2();
        for x in v.to_array() {
            self.push(x * k);
        }
    }
    /// One component of a unit vector (Q1.14).
    fn unit_axis(&mut self, x: f64) {
        self.push(x * Q_UNIT.lsb().recip() * (self.x as f64).exp2());
    }
    fn col(&mut self, x: f64) {
        self.push(x * Q_MATERIAL.lsb().recip() * (self.x as f64).exp2());
    }
    fn raw(&mut self, x: i64) {
        self.push(x as f64);
    }
    fn scaled(&mut self, v: Vec3, scale: f64) {
        for x in v.to_array() {
            self.push(x * scale);
        }
    }
}

/// FB words as the bytes DMA moves: 2 per word (16-bit chip, `x` = 0) or
/// 4 (32-bit chip), little-endian.
pub fn fb_word_bytes(words: &[i32], x: u32) -> Vec<u8> {
    if x == 0 {
        words
            .iter()
            .flat_map(|w| (*w as i16).to_le_bytes())
            .collect()
    } else {
        words.iter().flat_map(|w| w.to_le_bytes()).collect()
    }
}

/// A polygon's normal, as NFF and the reference take it: from its first
/// three vertices.
fn polygon_normal(v: &[Vec3]) -> Vec3 {
    (v[1] - v[0]).cross(v[2] - v[0]).normalized()
}

/// The crossing test's data of a polygon: the two axes it is projected on
/// (the normal's dominant axis dropped) and, per non-horizontal edge
/// `vi -> vj` (vertices quantized to the scene format `s`, relative to
/// `v0`), `[xi, yi, yj, s ey, s ex]` with `s = sign(ey)`.
fn polygon_edges(v: &[Vec3], s: f64) -> ((usize, usize), Vec<[i64; 5]>) {
    let n = polygon_normal(v);
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

/// A planar record's geometry: normal, origin vertex, edge duals.
#[derive(Clone, Copy)]
struct Planar {
    n: Vec3,
    v0: Vec3,
    eu: Vec3,
    ew: Vec3,
    kind: Inside,
}

fn triangle_planar(a: Vec3, b: Vec3, c: Vec3, n: Vec3) -> Planar {
    let (e1, e2) = (b - a, c - a);
    let x = e2.cross(n);
    let y = n.cross(e1);
    let (dx, dy) = (e1.dot(x), e2.dot(y));
    if dx.abs() < 1e-300 || dy.abs() < 1e-300 {
        // Degenerate: a record that never hits (zero normal).
        return Planar {
            n: Vec3::ZERO,
            v0: a,
            eu: Vec3::ZERO,
            ew: Vec3::ZERO,
            kind: Inside::Triangle,
        };
    }
    Planar {
        n,
        v0: a,
        eu: x * (1.0 / dx),
        ew: y * (1.0 / dy),
        kind: Inside::Triangle,
    }
}

fn rect_planar(corner: Vec3, e1: Vec3, e2: Vec3, n: Vec3) -> Planar {
    Planar {
        n,
        v0: corner,
        eu: e1 * (1.0 / e1.dot(e1)),
        ew: e2 * (1.0 / e2.dot(e2)),
        kind: Inside::Rectangle,
    }
}

fn perpendicular(a: Vec3) -> Vec3 {
    let t = if a.x.abs() < 0.6 {
        Vec3::new(1.0, 0.0, 0.0)
    } else {
        Vec3::new(0.0, 1.0, 0.0)
    };
    a.cross(t).normalized()
}

fn disc(center: Vec3, e1: Vec3, e2: Vec3, r: f64, n: Vec3) -> Planar {
    Planar {
        n,
        v0: center,
        eu: e1 * (1.0 / r),
        ew: e2 * (1.0 / r),
        kind: Inside::Disc,
    }
}

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

/// A cone's record geometry (see [`super::kernels::cone`]), in scene LSBs
/// where not a ratio.
struct ConeFit {
    /// The middle of the axis, rounded to the scene format (LSBs).
    m_q: Vec3,
    e1: Vec3,
    e2: Vec3,
    a: Vec3,
    /// Cosine and sine of the half-angle, `tan = (ra - rb) / h`.
    c: f64,
    s: f64,
    /// Bounding radius about `m_q` (whole LSBs) and the kernel's unit 2 R.
    r: f64,
    big_s: f64,
    /// `c (rb + ra) / 2 / S` and `(h / 2 + 1 LSB) / S`.
    g: f64,
    hh: f64,
}

impl ConeFit {
    fn of(base: Vec3, rb: f64, apex: Vec3, ra: f64, scale: f64) -> ConeFit {
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
        // middle; 2 LSB more cover the rounding of M.
        let bound = ((h / 2.0).powi(2) + rb.max(ra).powi(2)).sqrt() * scale;
        let r = (bound + 2.0).ceil();
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
}

/// The scene's distinct materials, and per scene material its index among
/// them (materials equal in every field are one).
fn distinct_materials(scene: &Scene) -> (Vec<usize>, Vec<crate::scene::Material>) {
    let key = |m: &crate::scene::Material| {
        [
            m.color.x, m.color.y, m.color.z, m.kd, m.ks, m.shine, m.t, m.ior,
        ]
        .map(f64::to_bits)
    };
    let mut seen = std::collections::HashMap::new();
    let mut mats = Vec::new();
    let of = scene
        .materials
        .iter()
        .map(|m| {
            *seen.entry(key(m)).or_insert_with(|| {
                mats.push(m.clone());
                mats.len() - 1
            })
        })
        .collect();
    (of, mats)
}

/// Largest shift `k` with `m * 2^k` within the word (`<= 2^(15+x) - 1`:
/// 32767 on the 16-bit chip), clamped to 0..=max.
fn fit_shift_w(m: f64, max: u32, x: u32) -> u32 {
    if m <= 0.0 {
        return max;
    }
    let k = (word_max(x) / m).log2().floor();
    k.clamp(0.0, max as f64) as u32
}

/// Largest absolute coordinate of the eye and of every object's bounds.
fn extent(scene: &Scene) -> f64 {
    let mut m: f64 = scene.camera.from.max_abs();
    for o in &scene.objects {
        let b = o.shape.bounds();
        m = m.max(b.min.max_abs()).max(b.max.max_abs());
    }
    m
}

/// The tracer's coordinate format: the finest `Qm.n` in which every object
/// and the eye fit with two guard bits (so that differences of points and
/// distances across the scene fit); never coarser than the scene
/// compiler's format (whose BSP planes are snapped to its LSB, hence exact
/// in a finer one). Lights do not take part: only their difference to a
/// point of the scene is ever formed, at a coarser scale when needed
/// ([`light_shift`]).
pub fn fit_frac(scene: &Scene, compiler_frac: u32, guard_bits: u32) -> u32 {
    let m = extent(scene);
    (compiler_frac..=14)
        .rev()
        .find(|&n| m * (guard_bits as f64).exp2() < ((15 - n) as f64).exp2() * 0.999)
        .unwrap_or(compiler_frac)
}

/// Scale of a light in the shadow-ray kernel: the smallest `k` for which
/// `(light - P) / 2^k` fits the format `frac` for every point `P` of the
/// scene (`|P| <= m`, [`extent`]). The light is stored divided by `2^k`
/// and the kernel forms `light / 2^k - P / 2^k`; its direction is all a
/// shadow ray needs. A light with `k > 0` lies outside the box `[-m, m]^3`
/// that holds every object (`l + m >= 2^(15 - frac) > 2 m`), so no object
/// lies beyond it along the shadow ray and the ray's segment may end at
/// "no hit" (32767) instead of at the light.
pub fn light_shift(position: Vec3, m: f64, frac: u32) -> Option<u32> {
    light_shift_w(position, m, frac, 0)
}

/// [`light_shift`] for words with `x` extra bits (`frac` includes them).
pub fn light_shift_w(position: Vec3, m: f64, frac: u32, x: u32) -> Option<u32> {
    let range = ((15 + x - frac) as f64).exp2() * 0.999;
    let l = position.max_abs();
    (0..=15u32).find(|&k| (l + m) < range * (k as f64).exp2())
}

/// Lay out the scene.
pub fn build(
    scene: &Scene,
    image: &SceneImage,
    opt: &Options,
    guard_bits: u32,
    fine_normals: bool,
    force_stream: bool,
) -> Result<Layout, String> {
    if !force_stream {
        let lay = build_as(scene, image, opt, guard_bits, fine_normals, false, false)?;
        if lay.stream.is_none() {
            return Ok(lay);
        }
    }
    // A streamed scene has thousands of objects, many of them a few LSB
    // small: it is laid out again in the finest format with one guard bit
    // (differences of two points of the scene still fit), the compiler's
    // rule, and sphere records carry the unrounded radius's reciprocal.
    build_as(
        scene,
        image,
        opt,
        guard_bits.min(1),
        fine_normals,
        true,
        true,
    )
}

/// Lay out the scene for the packet traversal. `fine`: the format of the
/// streamed layout (one guard bit, unrounded sphere radii), which the
/// paper's layout takes for scenes it streams; the packet traversal's
/// nodes are much smaller, so it keeps resident many scenes the paper's
/// layout streams, but its format follows the paper's decision (the same
/// numbers, hence the same hits up to ties). Streamed when it does not fit
/// FB set 0 or with `force_stream`.
pub fn build_packet(
    scene: &Scene,
    image: &SceneImage,
    opt: &Options,
    guard_bits: u32,
    fine_normals: bool,
    force_stream: bool,
    fine: bool,
) -> Result<Layout, String> {
    let g = if fine { guard_bits.min(1) } else { guard_bits };
    build_as(scene, image, opt, g, fine_normals, fine, force_stream)
}

fn build_as(
    scene: &Scene,
    image: &SceneImage,
    opt: &Options,
    guard_bits: u32,
    fine_normals: bool,
    fine: bool,
    streamed: bool,
) -> Result<Layout, String> {
    // The 32-bit chip: every format gets `xb` more fraction bits.
    let xb = opt.datapath.bits() - 16;
    let fit_shift = |m: f64, max: u32| fit_shift_w(m, max, xb);
    let frac = fit_frac(scene, image.report.frac_bits, guard_bits) + xb;
    let s = (frac as f64).exp2();
    let err = |line: usize, m: String| {
        if line > 0 {
            format!("{}:{line}: {m}", scene.source)
        } else {
            format!("{}: {m}", scene.source)
        }
    };

    // Objects by chip type.
    let mut by: Vec<Vec<usize>> = vec![Vec::new(); ChipType::ALL.len()];
    let mut slot = vec![(0usize, 0usize); scene.objects.len()];
    for (i, o) in scene.objects.iter().enumerate() {
        let Some(t) = ChipType::of_object(&o.shape, scene.materials[o.material].t > 0.0) else {
            return Err(err(
                o.line,
                "internal: a primitive type with no chip kernel".into(),
            ));
        };
        let ti = t as usize;
        slot[i] = (ti, by[ti].len());
        by[ti].push(i);
    }
    // Materials: identical ones are one (an NFF file repeats its `f` line
    // for every object: SPD rings, 841 lines, 7 materials); the kernels
    // shade per distinct material.
    let (mat_of, mats) = distinct_materials(scene);
    if mats.len() > 1000 || scene.lights.len() > 64 {
        return Err(err(
            0,
            "more than 1000 distinct materials or 64 lights".into(),
        ));
    }

    // Planar geometry of every record, to fit the kernels' scale shifts.
    let mut planars: Vec<Vec<Planar>> = vec![Vec::new(); scene.objects.len()];
    let mut fan = 0usize;
    let mut r_min_sph = f64::INFINITY;
    let mut r_min_cyl = f64::INFINITY;
    let mut cone_s_min = f64::INFINITY;
    let mut cone_r_max = 1.0f64;
    for (i, o) in scene.objects.iter().enumerate() {
        match &o.shape {
            Shape::Sphere { radius, .. } => r_min_sph = r_min_sph.min(radius.abs() * s),
            Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
                ..
            } if o.shape.prim_type() == PrimType::Cone => {
                let f = ConeFit::of(*base, *base_radius, *apex, *apex_radius, s);
                cone_s_min = cone_s_min.min(f.big_s);
                cone_r_max = cone_r_max.max(f.r);
                let disc_or_none = |c: Vec3, r: f64, n: Vec3| {
                    if r * s >= 0.5 {
                        disc(c, f.e1, f.e2, r, n)
                    } else {
                        // The tip of a pointed cone: a record that never hits.
                        Planar {
                            n: Vec3::ZERO,
                            v0: c,
                            eu: Vec3::ZERO,
                            ew: Vec3::ZERO,
                            kind: Inside::Disc,
                        }
                    }
                };
                planars[i] = vec![
                    disc_or_none(*base, *base_radius, -f.a),
                    disc_or_none(*apex, *apex_radius, f.a),
                ];
            }
            Shape::Cone {
                base,
                base_radius,
                apex,
                ..
            } => {
                r_min_cyl = r_min_cyl.min(base_radius.abs() * s);
                let a = (*apex - *base).normalized();
                let e1 = perpendicular(a);
                let e2 = a.cross(e1);
                let r = base_radius.abs();
                planars[i] = vec![disc(*base, e1, e2, r, -a), disc(*apex, e1, e2, r, a)];
            }
            Shape::Box { .. } => {}
            Shape::Rectangle {
                corner,
                edge1,
                edge2,
            } => {
                planars[i] = vec![rect_planar(
                    *corner,
                    *edge1,
                    *edge2,
                    edge1.cross(*edge2).normalized(),
                )]
            }
            Shape::Triangle { v, .. } => {
                let n = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
                planars[i] = vec![triangle_planar(v[0], v[1], v[2], n)];
            }
            Shape::Polygon { v, .. } => {
                fan = fan.max(polygon_edges(v, s).1.len());
            }
        }
    }
    let mut m = [0.0f64; 3];
    for p in planars.iter().flatten() {
        let k = match p.kind {
            Inside::Rectangle => 0,
            Inside::Triangle => 1,
            Inside::Disc => 2,
        };
        for x in p.eu.to_array().into_iter().chain(p.ew.to_array()) {
            m[k] = m[k].max(x.abs() * ((14 + xb) as f64 - frac as f64).exp2());
        }
    }
    let kt = [
        fit_shift(m[0], 24 + xb),
        fit_shift(m[1], 24 + xb),
        fit_shift(m[2], 24 + xb),
    ];
    let ks_of = |rmin: f64| {
        if rmin.is_finite() {
            fit_shift(((14 + xb) as f64).exp2() / rmin, 16 + xb)
        } else {
            8
        }
    };
    let (ks_sphere, ks_cyl) = (ks_of(r_min_sph), ks_of(r_min_cyl));
    // Extra fraction bits of the sphere's perpendicular vector: up to 4, as
    // long as twice the largest radius still fits.
    let r_max_sph = scene
        .objects
        .iter()
        .filter_map(|o| match o.shape {
            Shape::Sphere { radius, .. } => Some(radius.abs() * s),
            _ => None,
        })
        .fold(1.0f64, f64::max);
    let ep_sphere = fit_shift(2.0 * r_max_sph, 4);
    let sphere_fine = r_min_sph < SPHERE_FINE_BELOW_LSB;
    let r_max_cyl = scene
        .objects
        .iter()
        .filter_map(|o| match o.shape {
            Shape::Cone { base_radius, .. } => Some(base_radius.abs() * s),
            _ => None,
        })
        .fold(1.0f64, f64::max);
    let ep_cyl = fit_shift(2.0 * r_max_cyl, 4);
    // Cones: invS = 2^(14+ks) / S fits for the smallest S; the
    // perpendicular vector saturates only beyond twice the largest R.
    let ks_cone = ks_of(cone_s_min);
    let ep_cone = fit_shift(2.0 * cone_r_max, 4);

    let mut w = W {
        fb: Vec::new(),
        s,
        x: xb,
    };
    // Init stream.
    w.fb.extend(table_slots_for(128, xb));
    w.push(w.one());
    w.push(w.max());

    // Camera: D(i, j) = A + i B + j C.
    let c = &scene.camera;
    let (wd, hd) = (opt.width.max(1), opt.height.max(1));
    let ww = (c.at - c.from).normalized();
    let uu = ww.cross(c.up).normalized();
    let vv = uu.cross(ww);
    let half = (c.angle.to_radians() / 2.0).tan();
    let (ax, ay) = if wd >= hd {
        (wd as f64 / hd as f64, 1.0)
    } else {
        (1.0, hd as f64 / wd as f64)
    };
    let mut a = ww;
    let mut b = Vec3::ZERO;
    let mut cc = Vec3::ZERO;
    if wd > 1 {
        a = a - uu * (ax * half);
        b = uu * (ax * half * 2.0 / (wd - 1) as f64);
    }
    if hd > 1 {
        a = a + vv * (ay * half);
        cc = vv * (-ay * half * 2.0 / (hd - 1) as f64);
    }
    let max_bc = b.max_abs().max(cc.max_abs());
    let kd = fit_shift(max_bc, 28 + xb).max(13 + xb);
    let corner_far = a + b * (wd - 1) as f64 + cc * (hd - 1) as f64;
    if a.max_abs() >= 3.9 || corner_far.max_abs() >= 3.9 {
        return Err(err(0, {
            let aspect = ax.max(ay);
            let long = 2.0 * (aspect * half).atan().to_degrees();
            if aspect > 1.0 {
                format!(
                        "a {wd}x{hd} image ({aspect:.1}:1) with the camera angle {} across its shorter side spans {long:.0} degrees across its longer: too wide for the chip's Q2.13 eye-ray directions (at most about 150 degrees); a squarer image or a narrower angle fits",
                        c.angle
                    )
            } else {
                format!(
                        "camera angle {} too wide for the chip's Q2.13 eye-ray directions (at most about 150 degrees)",
                        c.angle
                    )
            }
        }));
    }
    let eye = w.fb.len();
    w.raw(0);
    w.raw(0);
    w.point(c.from);
    for k in 0..3 {
        w.push(a.axis(k) * w.one() / 2.0);
        w.push(b.axis(k) * (kd as f64).exp2());
        w.push(cc.axis(k) * (kd as f64).exp2());
    }

    // Post: background, (id, ks) per material.
    let post = w.fb.len();
    for x in scene.background.to_array() {
        w.col(x);
    }
    for (i, mt) in mats.iter().enumerate() {
        w.raw(i as i64);
        w.col(mt.ks);
    }
    // Refraction: per transmitting material `id, T, 1/ior, ior` (the
    // stream of `k_tset`), only when a refracting object uses one.
    let refract = by.iter().enumerate().any(|(t, v)| {
        !v.is_empty()
            && ChipType::ALL
                .iter()
                .any(|c| *c as usize == t && c.refracts())
    });
    let transmit = w.fb.len();
    let mut transmit_materials = 0;
    if refract {
        for (i, mt) in mats.iter().enumerate().filter(|(_, m)| m.t > 0.0) {
            w.raw(i as i64);
            w.col(mt.t);
            w.col(1.0 / mt.ior);
            w.col(mt.ior);
            transmit_materials += 1;
        }
    }
    // Lights and shading coefficients.
    let nl = scene.lights.len().max(1) as f64;
    let m = extent(scene);
    let mut shifts = Vec::new();
    for l in &scene.lights {
        shifts.push(light_shift_w(l.position, m, frac, xb).ok_or_else(|| {
            err(
                0,
                format!(
                    "light at {:?} too far from the scene for the format's differences",
                    l.position.to_array()
                ),
            )
        })?);
    }
    let light_shifted = shifts.iter().any(|&k| k > 0);
    let mut lights = Vec::new();
    for (l, &k) in scene.lights.iter().zip(&shifts) {
        lights.push(w.fb.len());
        if light_shifted {
            w.raw(k as i64);
        }
        w.point(l.position * (-(k as f64)).exp2());
    }
    let mut shades = Vec::new();
    for l in &scene.lights {
        shades.push(w.fb.len());
        let lc = l.color.unwrap_or(Vec3::ONE * (1.0 / nl.sqrt()));
        for (i, mt) in mats.iter().enumerate() {
            w.raw(i as i64);
            let (_, f) = split_shine(mt.shine);
            if f > 0.0 {
                w.push(f * w.one());
                w.push((1.0 - f) * w.one());
            }
            // Per channel: kd c lc, then ks lc (the kernel's read order).
            let k = mt.color.mul_elem(lc) * mt.kd;
            let sp = lc * mt.ks;
            for c in 0..3 {
                w.col(k.axis(c));
                w.col(sp.axis(c));
            }
        }
    }
    let shines: Vec<(u32, f64)> = mats.iter().map(|m| split_shine(m.shine)).collect();

    // Object records.
    let write_planar = |w: &mut W, p: &Planar, obj: usize, mat: usize| {
        let k = match p.kind {
            Inside::Rectangle => kt[0],
            Inside::Triangle => kt[1],
            Inside::Disc => kt[2],
        };
        let sc = ((14 + xb) as f64 - frac as f64 + k as f64).exp2();
        w.unit(p.n);
        w.point(p.v0);
        w.point(p.v0);
        w.scaled(p.eu, sc);
        w.scaled(p.ew, sc);
        w.unit(p.n);
        w.raw(obj as i64);
        w.raw(mat as i64);
    };
    // Packet traversal: the root cell widened by the traversal's tolerance
    // (the stream of its pass-start kernel), resident in either layout.
    let packet = opt.traversal == Traversal::Packet;
    let root_box = if packet {
        let at = w.fb.len();
        let b = image.bsp.nodes[0].bounds;
        let tol = super::kernels::P_TOL as f64;
        for a in 0..3 {
            w.push((b.min.axis(a) * s).floor() - tol);
            w.push((b.max.axis(a) * s).ceil() + tol);
        }
        at
    } else {
        0
    };
    let records_start = w.fb.len();
    let mut types = Vec::new();
    let mut bv_offset = NODE_HEAD;
    let mut mailbox_slots = 0;
    for t in ChipType::ALL {
        let objs = &by[t as usize];
        if objs.is_empty() {
            continue;
        }
        let size = match t {
            ChipType::Sphere | ChipType::GlassSphere if sphere_fine => SPHERE_FINE_WORDS,
            ChipType::Sphere | ChipType::GlassSphere => SPHERE_WORDS,
            ChipType::Cylinder => cyl_words(fine_normals),
            ChipType::GlassCylinder => cyl_words(fine_normals) + cyl_body_words(fine_normals),
            ChipType::GlassCone => CONE_WORDS + CONE_BODY_WORDS,
            ChipType::Cone => CONE_WORDS,
            ChipType::Box => BOX_WORDS,
            ChipType::GlassBox => 2 * BOX_WORDS,
            ChipType::Rectangle
            | ChipType::Triangle
            | ChipType::GlassRectangle
            | ChipType::GlassTriangle => PLANAR_WORDS,
            ChipType::SmoothTriangle | ChipType::GlassSmoothTriangle => SMOOTH_WORDS,
            ChipType::Polygon | ChipType::GlassPolygon => {
                1 + POLY_HEAD_WORDS + fan * POLY_EDGE_WORDS + POLY_TAIL_WORDS
            }
        };
        let first = w.fb.len();
        for &i in objs {
            let o = &scene.objects[i];
            let start = w.fb.len();
            match (&o.shape, t) {
                (
                    Shape::Cone {
                        base,
                        base_radius,
                        apex,
                        apex_radius,
                        inside,
                        caps,
                    },
                    ChipType::Cone | ChipType::GlassCone,
                ) => {
                    let f = ConeFit::of(*base, *base_radius, *apex, *apex_radius, s);
                    let inv_s = ((14 + xb + ks_cone) as f64).exp2() / f.big_s;
                    if inv_s < 256.0 || f.r > 16383.0 * (xb as f64).exp2() {
                        return Err(err(
                            o.line,
                            format!(
                                "cone too large for the chip's cone kernel next to the scene's smallest cone (bounding radius {:.0} LSB)",
                                f.r
                            ),
                        ));
                    }
                    let sg = if *inside { -1.0 } else { 1.0 };
                    let one = w.one();
                    w.raw(*caps as i64);
                    // A transmitting cone: the body twice, the second seen
                    // from the other side.
                    let sides: &[f64] = if t == ChipType::GlassCone {
                        &[1.0, -1.0]
                    } else {
                        &[1.0]
                    };
                    for &side in sides {
                        let sg = sg * side;
                        w.push(f.m_q.x);
                        w.push(f.m_q.y);
                        w.push(f.m_q.z);
                        w.push(inv_s);
                        for _ in 0..2 {
                            w.scaled(f.e1, one * f.c);
                            w.scaled(f.e2, one * f.c);
                            w.unit(f.a);
                        }
                        w.push(one * f.s);
                        w.push(one * f.g);
                        w.push(one * sg);
                        w.raw(f.r as i64);
                        w.push(one * f.hh);
                        w.push(one * -sg * f.c);
                        w.push(one * -sg * f.s);
                        for c in 0..3 {
                            w.push(one * f.e1.axis(c));
                            w.push(one * f.e2.axis(c));
                            w.push(one * f.a.axis(c));
                        }
                        w.raw(i as i64);
                        w.raw(mat_of[o.material] as i64);
                    }
                    for p in &planars[i] {
                        let mut p = *p;
                        p.n = p.n * sg;
                        write_planar(&mut w, &p, i, mat_of[o.material]);
                    }
                }
                (
                    Shape::Sphere {
                        center,
                        radius,
                        inside,
                    },
                    _,
                ) => {
                    let rq = (radius.abs() * s).round().max(1.0);
                    let invr = ((14 + xb + ks_sphere) as f64).exp2()
                        / if fine || sphere_fine {
                            radius.abs() * s
                        } else {
                            rq
                        };
                    let sg = if *inside { -1.0 } else { 1.0 };
                    w.point(*center);
                    if sphere_fine {
                        for x in center.to_array() {
                            let hi = w.sat(x * s) as f64;
                            w.push((x * s - hi) * w.one());
                        }
                        w.push(radius.abs() * s * (ep_sphere as f64).exp2());
                    } else {
                        w.push(rq);
                    }
                    w.push(invr);
                    w.push(sg * w.one());
                    w.raw(i as i64);
                    w.raw(mat_of[o.material] as i64);
                }
                (
                    Shape::Cone {
                        base,
                        base_radius,
                        apex,
                        inside,
                        caps,
                        ..
                    },
                    _,
                ) => {
                    let axis = *apex - *base;
                    let h = axis.length();
                    let av = axis * (1.0 / h);
                    let e1 = perpendicular(av);
                    let e2 = av.cross(e1);
                    let rs = base_radius.abs() * s;
                    // Fine normals: the radius with `ep` extra bits and its
                    // reciprocal unrounded; otherwise both of the rounded
                    // radius.
                    let rq = rs.round().max(1.0);
                    let invr =
                        ((14 + xb + ks_cyl) as f64).exp2() / if fine_normals { rs } else { rq };
                    // The base's rounding remainder along e1 and e2.
                    let bq = Vec3::from(base.to_array().map(|x| w.sat(x * s) as f64));
                    let brem = *base * s - bq;
                    let sg = if *inside { -1.0 } else { 1.0 };
                    w.raw(*caps as i64);
                    // A transmitting cylinder: the body twice, the second
                    // seen from the other side.
                    let sides: &[f64] = if t == ChipType::GlassCylinder {
                        &[1.0, -1.0]
                    } else {
                        &[1.0]
                    };
                    for &side in sides {
                        let sg = sg * side;
                        w.point(*base);
                        w.unit(e1);
                        if fine_normals {
                            w.push(brem.dot(e1) * w.one());
                        }
                        w.unit(e2);
                        if fine_normals {
                            w.push(brem.dot(e2) * w.one());
                        }
                        w.unit(e1);
                        w.unit(e2);
                        w.push(invr);
                        if fine_normals {
                            w.push(rs * (ep_cyl as f64).exp2());
                        } else {
                            w.push(rq);
                        }
                        w.push(sg * w.one());
                        w.point(*base);
                        w.unit(av);
                        w.raw((h * s).round() as i64 + 2);
                        w.push(sg * w.one());
                        for c in 0..3 {
                            w.push(e1.axis(c) * w.one());
                            w.push(e2.axis(c) * w.one());
                        }
                        w.raw(i as i64);
                        w.raw(mat_of[o.material] as i64);
                    }
                    for p in &planars[i] {
                        let mut p = *p;
                        p.n = p.n * sg;
                        write_planar(&mut w, &p, i, mat_of[o.material]);
                    }
                }
                (Shape::Box { min, max }, _) => {
                    let q = |x: f64| (x * s).round() as i64;
                    // A transmitting box: the sections twice (entry, exit).
                    let copies = if t == ChipType::GlassBox { 2 } else { 1 };
                    for a in (0..3).cycle().take(3 * copies) {
                        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                        w.raw(q(min.axis(a)));
                        w.raw(q(max.axis(a)));
                        w.raw(q(min.axis(b)) - 1);
                        w.raw(q(max.axis(b)) + 1);
                        w.raw(q(min.axis(c)) - 1);
                        w.raw(q(max.axis(c)) + 1);
                        w.raw(i as i64);
                        w.raw(mat_of[o.material] as i64);
                    }
                }
                (Shape::Polygon { v, .. }, _) => {
                    let n = polygon_normal(v);
                    let ((ua, va), edges) = polygon_edges(v, s);
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
                    w.raw(i as i64);
                    w.raw(mat_of[o.material] as i64);
                    w.fb.resize(start + size, 0);
                }
                (
                    Shape::Triangle {
                        normals: Some(ns), ..
                    },
                    ChipType::SmoothTriangle | ChipType::GlassSmoothTriangle,
                ) => {
                    // The planar record up to its face normal, the unit
                    // vertex normals by axis (the kernel's read order), then
                    // the face normal, obj, mat.
                    let p = &planars[i][0];
                    write_planar(&mut w, p, i, mat_of[o.material]);
                    w.fb.truncate(w.fb.len() - 5);
                    let ns = ns.map(|n| n.normalized());
                    for c in 0..3 {
                        for n in &ns {
                            w.unit_axis(n.axis(c));
                        }
                    }
                    w.unit(p.n);
                    w.raw(i as i64);
                    w.raw(mat_of[o.material] as i64);
                }
                _ => {
                    for p in &planars[i] {
                        write_planar(&mut w, p, i, mat_of[o.material]);
                    }
                }
            }
            debug_assert_eq!(w.fb.len() - start, size, "{t:?}");
            if w.fb.len() - start != size {
                return Err(format!(
                    "internal: {} record of {} words, expected {size}",
                    t.name(),
                    w.fb.len() - start
                ));
            }
        }
        let bv_words = objs.len().div_ceil(16);
        types.push(TypeInfo {
            ty: t,
            objects: objs.clone(),
            first,
            size,
            bv_offset,
            bv_words,
            mailbox: mailbox_slots,
            fan,
        });
        bv_offset += bv_words;
        mailbox_slots += objs.len();
    }

    let nodes = &image.bsp.nodes;
    let fin = Finish {
        frac,
        eye,
        post,
        lights,
        shades,
        objects: scene.objects.len(),
        materials: mats.len(),
        transmit,
        transmit_materials,
        refract,
        shines,
        kd,
        ks_sphere,
        ks_cyl,
        ep_sphere,
        sphere_fine,
        fine_normals,
        ep_cyl,
        ks_cone,
        ep_cone,
        kt,
        light_shifted,
        node_layout: opt.layout,
        traversal: opt.traversal,
        root_box,
        collapse: opt.collapse,
        cost: if packet {
            object_costs(
                scene,
                s,
                ks_sphere,
                ep_sphere,
                sphere_fine,
                ks_cyl,
                ep_cyl,
                ks_cone,
                ep_cone,
                fine_normals,
            )
        } else {
            Vec::new()
        },
    };
    if packet {
        return packet_nodes(w, fin, types, nodes, &slot, records_start, streamed, &err);
    }
    // BSP nodes: Fig. 5 (fixed size) or compact (head, then per type a
    // count and the slot indices).
    let node_layout = opt.layout;
    let node_words = match node_layout {
        NodeLayout::Fig5 => bv_offset,
        NodeLayout::Compact => 0,
    };
    let mut node_at = Vec::with_capacity(nodes.len() + 1);
    node_at.push(0usize);
    for n in nodes {
        let size = match node_layout {
            NodeLayout::Fig5 => node_words,
            NodeLayout::Compact => compact_head(n.split.is_none()) + types.len() + n.objects.len(),
        };
        node_at.push(node_at.last().copied().unwrap_or(0) + size);
    }
    let node_section = node_at[nodes.len()];
    let root = w.fb.len();
    let addr = |k: u32| root + node_at[k as usize];
    let total = root + node_section + mailbox_slots;
    let mut stream = None;
    if total > FB_LIMIT || streamed {
        // Streamed: only the tables, camera, lights and shading stay in the
        // FB (bank 0); objects, nodes and mailboxes go to main memory.
        let records = w.fb.split_off(records_start);
        let split_slot = w.fb.len();
        w.raw(0);
        if w.fb.len() > STREAM_BANK {
            return Err(err(
                0,
                format!(
                    "the resident part of the streamed layout needs {} FB words; bank 0 holds {STREAM_BANK}",
                    w.fb.len()
                ),
            ));
        }
        let base = super::mem::STREAM;
        let nn = nodes.len();
        let lists_at = NODE_BYTES * nn;
        let list_bytes: usize = nodes
            .iter()
            .filter(|n| n.split.is_none())
            .map(|n| 4 * n.objects.len())
            .sum();
        let blocks_at = lists_at + list_bytes;
        let mut node_img = vec![0u8; lists_at];
        let mut lists: Vec<u8> = Vec::with_capacity(list_bytes);
        let mut blocks: Vec<u8> = Vec::new();
        let mut largest = 0usize;
        // Mailbox addresses are known once the blocks are laid out: lay
        // the blocks out first, patch the lists after.
        let mut list_objs: Vec<usize> = Vec::new();
        for (k, n) in nodes.iter().enumerate() {
            let mut f = [0i32; 16];
            match n.split {
                Some(sp) => {
                    f[0] = sp.axis as i32;
                    f[1] = w.sat(sp.position * s);
                    f[2] = (base as usize + NODE_BYTES * sp.children[0] as usize) as i32;
                    f[3] = (base as usize + NODE_BYTES * sp.children[1] as usize) as i32;
                }
                None => {
                    f[0] = -32768;
                    let list_addr = base as usize + lists_at + 4 * list_objs.len();
                    let mut words: Vec<i32> = Vec::new();
                    for v in n.bounds.min.to_array() {
                        words.push(w.sat((v * s).floor() - 2.0));
                    }
                    for v in n.bounds.max.to_array() {
                        words.push(w.sat((v * s).ceil() + 2.0));
                    }
                    for (j, ti) in types.iter().enumerate() {
                        let mut cnt = 0;
                        for &o in &n.objects {
                            let (t, q) = slot[o as usize];
                            if t == ti.ty as usize {
                                let at = ti.first - records_start + q * ti.size;
                                words.extend_from_slice(&records[at..at + ti.size]);
                                list_objs.push(o as usize);
                                cnt += 1;
                            }
                        }
                        f[7 + j] = cnt;
                    }
                    if !n.objects.is_empty() {
                        if words.len() > STREAM_BANK {
                            return Err(err(
                                0,
                                format!(
                                    "a BSP leaf of {} objects needs {} FB words; FB bank 1 holds {STREAM_BANK}",
                                    n.objects.len(),
                                    words.len()
                                ),
                            ));
                        }
                        largest = largest.max(words.len());
                        f[4] = (base as usize + blocks_at + blocks.len()) as i32;
                        f[5] = words.len() as i32;
                        f[14] = n.objects.len() as i32;
                        f[6] = list_addr as i32;
                        blocks.extend(fb_word_bytes(&words, xb));
                    }
                }
            }
            for (i, x) in f.iter().enumerate() {
                node_img[NODE_BYTES * k + 4 * i..NODE_BYTES * k + 4 * i + 4]
                    .copy_from_slice(&x.to_le_bytes());
            }
        }
        let mb_at = (blocks_at + blocks.len()).next_multiple_of(4);
        let mailbox = base as usize + mb_at;
        for &o in &list_objs {
            lists.extend(((mailbox + 2 * o) as u32).to_le_bytes());
        }
        let mut image = node_img;
        image.extend(lists);
        image.extend(blocks);
        image.resize(mb_at, 0);
        let end = base as usize + mb_at + 2 * scene.objects.len();
        if end > super::mem::STREAM_END as usize {
            return Err(err(
                0,
                format!(
                    "the streamed scene needs {} bytes of main memory; {} are reserved",
                    end - base as usize,
                    super::mem::STREAM_END - base
                ),
            ));
        }
        stream = Some(Stream {
            base,
            image,
            root: base,
            mailbox: mailbox as u32,
            split_slot,
            nodes: nn,
            largest_block: largest,
            extra_pieces: 0,
        });
    }
    if let Some(st) = stream {
        let (root, mailbox) = (st.root as usize, st.mailbox as usize);
        return Ok(fin.layout(
            w.fb,
            types,
            root,
            NODE_BYTES / 4,
            total,
            node_section,
            mailbox,
            Some(st),
        ));
    }
    for n in nodes {
        match n.split {
            Some(sp) => {
                w.raw(sp.axis as i64);
                w.coord(sp.position);
                w.raw(addr(sp.children[0]) as i64);
                w.raw(addr(sp.children[1]) as i64);
            }
            None => {
                w.word16(0x8000);
                if node_layout == NodeLayout::Fig5 {
                    w.raw(0);
                    w.raw(0);
                    w.raw(0);
                }
            }
        }
        // Cell bounds: every Fig. 5 node; compact, leaves only (the only
        // nodes whose bounds a kernel reads).
        if node_layout == NodeLayout::Fig5 || n.split.is_none() {
            for v in n.bounds.min.to_array() {
                w.push((v * s).floor() - 2.0);
            }
            for v in n.bounds.max.to_array() {
                w.push((v * s).ceil() + 2.0);
            }
        }
        for ti in &types {
            // The node's objects of this type, ascending (the order the
            // Fig. 6 loop meets them in).
            let ks = n.objects.iter().filter_map(|&o| {
                let (t, k) = slot[o as usize];
                (t == ti.ty as usize).then_some(k)
            });
            match node_layout {
                NodeLayout::Fig5 => {
                    let words = crate::scene_image::membership_words(ti.bv_words * 16, ks);
                    for b in words {
                        w.word16(b);
                    }
                }
                NodeLayout::Compact => {
                    let at = w.fb.len();
                    w.raw(0);
                    for k in ks {
                        w.raw(k as i64);
                    }
                    w.fb[at] = (w.fb.len() - at - 1) as i32;
                }
            }
        }
    }
    debug_assert_eq!(w.fb.len(), root + node_section);
    let mailbox = w.fb.len();
    w.fb.resize(mailbox + mailbox_slots, 0);
    for t in &mut types {
        t.mailbox += mailbox;
    }
    Ok(fin.layout(
        w.fb,
        types,
        root,
        node_words,
        total,
        node_section,
        mailbox,
        None,
    ))
}

/// What every node format's [`Layout`] shares (the part laid out before
/// the BSP nodes).
struct Finish {
    frac: u32,
    eye: usize,
    post: usize,
    transmit: usize,
    transmit_materials: usize,
    refract: bool,
    lights: Vec<usize>,
    shades: Vec<usize>,
    objects: usize,
    materials: usize,
    shines: Vec<(u32, f64)>,
    kd: u32,
    ks_sphere: u32,
    ks_cyl: u32,
    ep_sphere: u32,
    sphere_fine: bool,
    fine_normals: bool,
    ep_cyl: u32,
    ks_cone: u32,
    ep_cone: u32,
    kt: [u32; 3],
    light_shifted: bool,
    node_layout: NodeLayout,
    traversal: Traversal,
    root_box: usize,
    collapse: super::Collapse,
    /// Per scene object, the array cycles of its test (kernel contexts and
    /// the TinyRISC loop around them).
    cost: Vec<f64>,
}

impl Finish {
    #[allow(clippy::too_many_arguments)]
    fn layout(
        self,
        fb: Vec<i32>,
        types: Vec<TypeInfo>,
        root: usize,
        node_words: usize,
        resident_words: usize,
        resident_node_words: usize,
        mailbox: usize,
        stream: Option<Stream>,
    ) -> Layout {
        Layout {
            fb,
            frac: self.frac,
            eye: self.eye,
            post: self.post,
            transmit: self.transmit,
            transmit_materials: self.transmit_materials,
            refract: self.refract,
            lights: self.lights,
            shades: self.shades,
            types,
            root,
            node_words,
            node_layout: self.node_layout,
            traversal: self.traversal,
            root_box: self.root_box,
            root_leaf: false,
            expected_cost: 0.0,
            resident_words,
            resident_node_words,
            mailbox,
            objects: self.objects,
            materials: self.materials,
            shines: self.shines,
            kd: self.kd,
            ks_sphere: self.ks_sphere,
            ks_cyl: self.ks_cyl,
            ep_sphere: self.ep_sphere,
            sphere_fine: self.sphere_fine,
            fine_normals: self.fine_normals,
            ep_cyl: self.ep_cyl,
            ks_cone: self.ks_cone,
            ep_cone: self.ep_cone,
            kt_rect: self.kt[0],
            kt_tri: self.kt[1],
            kt_disc: self.kt[2],
            light_shifted: self.light_shifted,
            stream,
        }
    }
}

/// Array cycles a packet spends on an inner node (its kernel and
/// TinyRISC's decision), for [`super::Collapse::Auto`].
const PK_NODE_COST: f64 = 60.0;

/// Per scene object, the array cycles of one test: its kernels' contexts
/// (caps and polygon edges included) and about 12 cycles of TinyRISC's
/// loop (mailbox and issue) that the array does not always hide.
#[allow(clippy::too_many_arguments)]
fn object_costs(
    scene: &Scene,
    s: f64,
    ks_sphere: u32,
    ep_sphere: u32,
    fine: bool,
    ks_cyl: u32,
    ep_cyl: u32,
    ks_cone: u32,
    ep_cone: u32,
    fine_normals: bool,
) -> Vec<f64> {
    use super::kernels as k;
    let nr = 2u32;
    let sphere = k::sphere_with(ks_sphere, ep_sphere, nr, fine, fine_normals).len();
    let disc = k::planar(Inside::Disc, 8, nr).len();
    let cyl = k::cylinder(ks_cyl, ep_cyl, nr, fine_normals).len();
    let cone = k::cone(ks_cone, ep_cone, nr).len();
    let boxk = k::aabox(nr).len();
    let planar = k::planar(Inside::Triangle, 8, nr).len();
    let (ph, pe, pt) = (
        k::polygon_head(nr).len(),
        k::polygon_edge().len(),
        k::polygon_tail().len(),
    );
    scene
        .objects
        .iter()
        .map(|o| {
            let c = match &o.shape {
                Shape::Sphere { .. } => sphere,
                Shape::Cone { caps, .. } => {
                    let body = if o.shape.prim_type() == PrimType::Cone {
                        cone
                    } else {
                        cyl
                    };
                    body + if *caps { 2 * disc } else { 0 }
                }
                Shape::Box { .. } => boxk,
                Shape::Rectangle { .. } | Shape::Triangle { .. } => planar,
                Shape::Polygon { v, .. } => ph + pt + pe * polygon_edges(v, s).1.len(),
            };
            c as f64 + 12.0
        })
        .collect()
}

/// Words of a packet-traversal inner node: axis, parent's slot, split,
/// own slot, left, right (FB addresses, or byte addresses when streamed).
pub const PK_INNER: usize = 6;
/// Words before a resident packet leaf's lists: flags, parent's slot,
/// object count, objects with a mailbox (in more than one leaf).
pub const PK_LEAF_HEAD: usize = 4;
/// Bytes of a packet-traversal mailbox in main memory: the pass that last
/// tested the object, and which rays did (64-bit mask), padded.
pub const PK_MAILBOX_BYTES: usize = 16;

/// RC RAM address of the interval slot of BSP depth `d`.
fn pk_slot(d: u32) -> i64 {
    (super::kernels::ram::P_SLOT + 2 * d.min(super::kernels::ram::P_SLOTS - 1)) as i64
}

/// The BSP nodes for the packet traversal ([`Traversal::Packet`]): inner
/// nodes carry their stack slots instead of the objects under them, leaves
/// per type present a count and the FB addresses of their objects' records;
/// no mailboxes. Resident when it fits FB set 0, else streamed (node
/// records in main memory, each leaf's records a block moved into FB bank 1,
/// a block larger than the bank cut into pieces).
#[allow(clippy::too_many_arguments)]
fn packet_nodes(
    mut w: W,
    fin: Finish,
    types: Vec<TypeInfo>,
    nodes: &[crate::bsp::Node],
    slot: &[(usize, usize)],
    records_start: usize,
    streamed: bool,
    err: &dyn Fn(usize, String) -> String,
) -> Result<Layout, String> {
    // The tree the traversal walks: a subtree with at most `collapse`
    // objects under it is one leaf of those objects (testing them all with
    // the rays that reach it costs less than walking it).
    let mut tree: Vec<crate::bsp::Node> = Vec::with_capacity(nodes.len());
    // Expected cost (array cycles) of a packet that reaches node k:
    // walking (a node visit, then each child with the probability that a
    // ray through the cell meets the child's, its surface area over the
    // cell's) or testing everything under it.
    let test_all =
        |n: &crate::bsp::Node| -> f64 { n.objects.iter().map(|&o| fin.cost[o as usize]).sum() };
    let mut keep = vec![true; nodes.len()];
    fn expect(
        nodes: &[crate::bsp::Node],
        k: usize,
        test_all: &dyn Fn(&crate::bsp::Node) -> f64,
        keep: &mut [bool],
    ) -> f64 {
        let n = &nodes[k];
        let all = test_all(n);
        let Some(sp) = n.split else { return all };
        let area = n.bounds.surface_area().max(1e-300);
        let mut walk = PK_NODE_COST;
        for c in sp.children {
            let ch = &nodes[c as usize];
            walk += (ch.bounds.surface_area() / area).min(1.0)
                * expect(nodes, c as usize, test_all, keep);
        }
        if all <= walk {
            keep[k] = false;
            all
        } else {
            walk
        }
    }
    let mut model_keep = vec![true; nodes.len()];
    let expected_cost = expect(nodes, 0, &test_all, &mut model_keep);
    let collapse = match fin.collapse {
        super::Collapse::Auto => {
            keep = model_keep;
            // The root is walked whenever the BSP has one split: the pass's
            // start clips the rays to the root cell, which culls the rays
            // that miss the scene (the surface-area weights assume every
            // ray meets the cell).
            keep[0] = true;
            usize::MAX
        }
        super::Collapse::Objects(c) => c,
    };
    fn walk(
        nodes: &[crate::bsp::Node],
        k: usize,
        collapse: usize,
        keep: &[bool],
        out: &mut Vec<crate::bsp::Node>,
    ) -> u32 {
        let n = &nodes[k];
        let at = out.len();
        out.push(crate::bsp::Node {
            split: None,
            ..n.clone()
        });
        if let Some(sp) = n.split {
            if keep[k] && (collapse == usize::MAX || n.objects.len() > collapse) {
                let l = walk(nodes, sp.children[0] as usize, collapse, keep, out);
                let r = walk(nodes, sp.children[1] as usize, collapse, keep, out);
                out[at].split = Some(crate::bsp::Split {
                    children: [l, r],
                    ..sp
                });
            }
        }
        at as u32
    }
    walk(nodes, 0, collapse, &keep, &mut tree);
    let nodes = &tree[..];
    // An object in one leaf only is met once per pass (each node is
    // visited at most once): it needs no mailbox.
    let mut refs = vec![0u32; fin.objects];
    for n in nodes.iter().filter(|n| n.split.is_none()) {
        for &o in &n.objects {
            refs[o as usize] += 1;
        }
    }
    let size = |n: &crate::bsp::Node| match n.split {
        Some(_) => PK_INNER,
        None => PK_LEAF_HEAD + types.len() + 2 * n.objects.len(),
    };
    let mut node_at = Vec::with_capacity(nodes.len() + 1);
    node_at.push(0usize);
    for n in nodes {
        node_at.push(node_at.last().copied().unwrap_or(0) + size(n));
    }
    let node_section = node_at[nodes.len()];
    let root = w.fb.len();
    let total = root + node_section;
    let parent_slot = |n: &crate::bsp::Node| {
        if n.depth == 0 {
            0
        } else {
            pk_slot(n.depth - 1)
        }
    };
    // A leaf's objects of each type, in slot order.
    let per_type = |n: &crate::bsp::Node| -> Vec<Vec<usize>> {
        types
            .iter()
            .map(|ti| {
                n.objects
                    .iter()
                    .filter_map(|&o| {
                        let (t, q) = slot[o as usize];
                        (t == ti.ty as usize).then_some(q)
                    })
                    .collect()
            })
            .collect()
    };
    if total <= FB_LIMIT && !streamed {
        for n in nodes {
            match n.split {
                Some(sp) => {
                    w.raw(sp.axis as i64);
                    w.raw(parent_slot(n));
                    w.coord(sp.position);
                    w.raw(pk_slot(n.depth));
                    w.raw((root + node_at[sp.children[0] as usize]) as i64);
                    w.raw((root + node_at[sp.children[1] as usize]) as i64);
                }
                None => {
                    w.word16(0x8000);
                    w.raw(parent_slot(n));
                    w.raw(n.objects.len() as i64);
                    w.raw(n.objects.iter().filter(|&&o| refs[o as usize] > 1).count() as i64);
                    for (ti, qs) in types.iter().zip(per_type(n)) {
                        w.raw(qs.len() as i64);
                        for q in qs {
                            let o = ti.objects[q];
                            w.raw((ti.first + q * ti.size) as i64);
                            w.raw(if refs[o] > 1 { o as i64 } else { -1 });
                        }
                    }
                }
            }
        }
        debug_assert_eq!(w.fb.len(), total);
        // The mailboxes (main memory, TinyRISC's), where the streamed
        // image would start.
        let mailbox = super::mem::STREAM as usize;
        let mut lay = fin.layout(w.fb, types, root, 0, total, node_section, mailbox, None);
        lay.root_leaf = nodes[0].split.is_none();
        lay.expected_cost = expected_cost;
        return Ok(lay);
    }
    // Streamed: records, nodes and leaf blocks leave the FB.
    let records = w.fb.split_off(records_start);
    let split_slot = w.fb.len();
    w.raw(0); // split
    w.raw(0); // its slot
    w.raw(0); // a popped node's parent slot
    if w.fb.len() > STREAM_BANK {
        return Err(err(
            0,
            format!(
                "the resident part of the streamed layout needs {} FB words; bank 0 holds {STREAM_BANK}",
                w.fb.len()
            ),
        ));
    }
    let base = super::mem::STREAM as usize;
    // Leaf pieces: a leaf's records (grouped by type) cut where a block
    // would exceed FB bank 1; each piece is a node record of its own,
    // chained from the leaf (word 6).
    let mut pieces: Vec<Vec<(usize, usize)>> = Vec::new(); // (type index, slot) per piece
    let mut first_piece = vec![usize::MAX; nodes.len()];
    for (k, n) in nodes.iter().enumerate() {
        if n.split.is_some() || n.objects.is_empty() {
            continue;
        }
        first_piece[k] = pieces.len();
        let mut cur: Vec<(usize, usize)> = Vec::new();
        let mut words = 0usize;
        for (j, qs) in per_type(n).into_iter().enumerate() {
            for q in qs {
                let sz = types[j].size;
                if sz > STREAM_BANK {
                    return Err(err(
                        0,
                        format!(
                            "a {} record of {sz} words exceeds FB bank 1",
                            types[j].ty.name()
                        ),
                    ));
                }
                if words + sz > STREAM_BANK {
                    pieces.push(std::mem::take(&mut cur));
                    words = 0;
                }
                cur.push((j, q));
                words += sz;
            }
        }
        pieces.push(cur);
    }
    let nn = nodes.len();
    let lists_at = NODE_BYTES * (nn + pieces.len());
    let list_bytes: usize = pieces.iter().map(|p| 4 * p.len()).sum();
    let blocks_at = lists_at + list_bytes;
    let mut img = vec![0u8; blocks_at];
    let mut lists: Vec<u32> = Vec::new();
    let mut blocks: Vec<u8> = Vec::new();
    let mut largest = 0usize;
    let put = |img: &mut Vec<u8>, rec: usize, f: &[i32; 16]| {
        for (i, x) in f.iter().enumerate() {
            img[NODE_BYTES * rec + 4 * i..NODE_BYTES * rec + 4 * i + 4]
                .copy_from_slice(&x.to_le_bytes());
        }
    };
    // Piece records: block address and words, next piece, per-type counts.
    let mut piece_rec = vec![[0i32; 16]; pieces.len()];
    for (p, pc) in pieces.iter().enumerate() {
        let mut words: Vec<i32> = Vec::new();
        let mut counts = [0i32; 7];
        for &(j, q) in pc {
            let ti = &types[j];
            let at = ti.first - records_start + q * ti.size;
            words.extend_from_slice(&records[at..at + ti.size]);
            counts[j] += 1;
        }
        largest = largest.max(words.len());
        let f = &mut piece_rec[p];
        f[0] = -32768;
        f[2] = (base + lists_at + 4 * lists.len()) as i32;
        for &(j, q) in pc {
            lists.push(types[j].objects[q] as u32);
        }
        f[4] = (base + blocks_at + blocks.len()) as i32;
        f[5] = words.len() as i32;
        f[7..14].copy_from_slice(&counts);
        f[14] = pc.len() as i32;
        f[15] = pc
            .iter()
            .filter(|&&(j, q)| refs[types[j].objects[q]] > 1)
            .count() as i32;
        blocks.extend(fb_word_bytes(&words, w.x));
    }
    // Chain the pieces of each leaf (a leaf's pieces are consecutive).
    for k in 0..nn {
        let first = first_piece[k];
        if first == usize::MAX {
            continue;
        }
        let end = first_piece[k + 1..]
            .iter()
            .copied()
            .find(|&p| p != usize::MAX)
            .unwrap_or(pieces.len());
        for (p, rec) in piece_rec.iter_mut().enumerate().take(end - 1).skip(first) {
            rec[6] = (base + NODE_BYTES * (nn + p + 1)) as i32;
        }
    }
    // The mailboxes follow the image; the lists hold their addresses.
    let mailbox = (base + blocks_at + blocks.len()).next_multiple_of(PK_MAILBOX_BYTES);
    for (i, o) in lists.iter().enumerate() {
        let a = if refs[*o as usize] > 1 {
            (mailbox + PK_MAILBOX_BYTES * *o as usize) as u32
        } else {
            0
        };
        img[lists_at + 4 * i..lists_at + 4 * i + 4].copy_from_slice(&a.to_le_bytes());
    }
    for (k, n) in nodes.iter().enumerate() {
        let mut f = [0i32; 16];
        f[1] = parent_slot(n) as i32;
        match n.split {
            Some(sp) => {
                f[0] = sp.axis as i32;
                f[2] = w.sat(sp.position * w.s);
                f[3] = pk_slot(n.depth) as i32;
                f[4] = (base + NODE_BYTES * sp.children[0] as usize) as i32;
                f[5] = (base + NODE_BYTES * sp.children[1] as usize) as i32;
            }
            None => {
                f[0] = -32768;
                if first_piece[k] != usize::MAX {
                    // The leaf's record is its first piece's.
                    let p = piece_rec[first_piece[k]];
                    f[2] = p[2];
                    f[4..16].copy_from_slice(&p[4..16]);
                }
            }
        }
        put(&mut img, k, &f);
    }
    for (p, f) in piece_rec.iter().enumerate() {
        put(&mut img, nn + p, f);
    }
    img.extend(blocks);
    let end = mailbox + PK_MAILBOX_BYTES * fin.objects;
    if end > super::mem::STREAM_END as usize {
        return Err(err(
            0,
            format!(
                "the streamed scene needs {} bytes of main memory; {} are reserved",
                end - base,
                super::mem::STREAM_END as usize - base
            ),
        ));
    }
    let st = Stream {
        base: base as u32,
        image: img,
        root: base as u32,
        mailbox: mailbox as u32,
        split_slot,
        nodes: nn,
        largest_block: largest,
        extra_pieces: pieces.len() - first_piece.iter().filter(|&&p| p != usize::MAX).count(),
    };
    let root_leaf = nodes[0].split.is_none();
    let mut lay = fin.layout(
        w.fb,
        types,
        base,
        NODE_BYTES / 4,
        total,
        node_section,
        mailbox,
        Some(st),
    );
    lay.root_leaf = root_leaf;
    lay.expected_cost = expected_cost;
    Ok(lay)
}
