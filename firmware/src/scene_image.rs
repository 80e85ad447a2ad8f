//! The compiled scene: a memory image of 16-bit words for the chip's frame
//! buffer, holding the scene in fixed point and the BSP tree in the paper's
//! Fig. 5 node layout. The layout is documented word by word in
//! `docs/scenes.md`; in short:
//!
//! ```text
//! header (48 words) | camera (15) | lights (6 each) | materials (8 each)
//! | objects, grouped by type (fixed size per type) | polygon vertices
//! | BSP nodes (fixed size) | index lists (compact layout only)
//! ```
//!
//! Coordinates are signed 16-bit fixed point `Qm.n` (`m` integer bits, `n`
//! fraction bits, `m + n = 15`), `n` fitted to the scene: the largest `n`
//! for which every coordinate, with `guard_bits` of headroom (so that the
//! difference of two points also fits), is representable. Colours and
//! material coefficients are Q3.12, unit vectors Q1.14.
//!
//! A node holds its two child node indices and, for each primitive type
//! present, a membership bit vector (bit k, most significant first, set
//! when object k of that type lies under the node: the paper's Fig. 6 loop
//! tests the sign bit and shifts left). When those vectors would make the
//! image larger than the compact alternative (thousands of objects), each
//! node instead holds a range of a shared list of 16-bit object references
//! `(type << 13) | index`: the nodes are in depth-first order, so the
//! objects under a node are those of a contiguous run of leaves.

use bitvec::prelude::*;

use crate::bsp::{Bsp, BspParams, BspStats};
use crate::scene::{Aabb, PrimType, Scene, SceneError, Shape, Vec3};

/// Words in the whole frame buffer: 2 sets x 2 banks x 16K.
pub const FB_WORDS: usize = 4 * 16 * 1024;
/// Words in one FB bank.
pub const FB_BANK_WORDS: usize = 16 * 1024;
pub const MAGIC: u16 = 0x4D53; // "MS"
pub const VERSION: u16 = 1;
pub const HEADER_WORDS: usize = 48;
pub const CAMERA_WORDS: usize = 15;
pub const LIGHT_WORDS: usize = 6;
pub const MATERIAL_WORDS: usize = 8;
/// Child index of a leaf.
pub const NO_CHILD: u16 = 0xFFFF;
/// Deepest BSP the compiler builds (the packet traversal keeps one
/// interval slot per level in every RC's RAM).
pub const MAX_BSP_DEPTH: u32 = 32;
/// Compact layout: object index bits of a list entry.
pub const LIST_INDEX_BITS: u32 = 13;

/// A Fig. 5 membership bit vector: one bit per object of a type (`count`
/// of them), bit 15 of word 0 the type's first object, set for `members`;
/// `count.div_ceil(16)` words. Both the compiled scene image and the
/// tracer's FB image build their node bit vectors with it.
pub fn membership_words(count: usize, members: impl IntoIterator<Item = usize>) -> Vec<u16> {
    let mut bits: BitVec<u16, Msb0> = BitVec::repeat(false, count.div_ceil(16) * 16);
    for k in members {
        bits.set(k, true);
    }
    bits.into_vec()
}

/// Words of one object record, by type.
pub fn record_words(t: PrimType) -> usize {
    match t {
        PrimType::Sphere => 6,
        PrimType::Cylinder => 9,
        PrimType::Cone => 10,
        PrimType::Box => 7,
        PrimType::Rectangle => 10,
        PrimType::Triangle => 10,
        PrimType::Polygon => 4,
    }
}

/// Which node layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Layout {
    /// Fig. 5: one membership bit vector per primitive type in every node.
    BitVectors,
    /// Per node, a range of a shared list of object references.
    IndexLists,
}

/// Compiler options.
#[derive(Clone, Copy, Debug)]
pub struct CompileOptions {
    pub bsp: BspParams,
    /// None: the smaller of the two.
    pub layout: Option<Layout>,
    /// Bits of headroom above the largest coordinate.
    pub guard_bits: u32,
    /// Refuse a scene whose smallest feature is below this many LSBs.
    pub min_feature_lsb: f64,
    /// Fraction bits the chip's own records carry beyond this image's
    /// (16 for the 32-bit datapath, whose tracer lays the objects out
    /// again with 16 more): the smallest-feature and degeneracy checks then
    /// apply at the chip's precision, not at the 16-bit image's.
    pub target_extra_frac: u32,
}

impl Default for CompileOptions {
    fn default() -> Self {
        CompileOptions {
            bsp: BspParams::default(),
            layout: None,
            guard_bits: 1,
            min_feature_lsb: 2.0,
            target_extra_frac: 0,
        }
    }
}

/// A signed 16-bit fixed-point format with `frac` fraction bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct QFormat {
    pub frac: u32,
}

impl QFormat {
    pub fn name(&self) -> String {
        format!("Q{}.{}", 15 - self.frac, self.frac)
    }
    pub fn lsb(&self) -> f64 {
        (-(self.frac as f64)).exp2()
    }
    /// Nearest representable value, or None when out of range.
    pub fn quantize(&self, x: f64) -> Option<i16> {
        let q = (x / self.lsb()).round();
        (q >= i16::MIN as f64 && q <= i16::MAX as f64).then_some(q as i16)
    }
    pub fn value(&self, q: i16) -> f64 {
        q as f64 * self.lsb()
    }
}

/// Colours and material coefficients.
pub const Q_MATERIAL: QFormat = QFormat { frac: 12 };
/// Unit vectors.
pub const Q_UNIT: QFormat = QFormat { frac: 14 };

/// The triangle-only version of a scene, for comparison.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TriangleOnly {
    pub triangles: usize,
    pub object_words: usize,
    /// Words of one node's bit vectors.
    pub bitvector_words_per_node: usize,
}

/// What the compiler reports.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Report {
    pub scene: String,
    pub format: String,
    pub frac_bits: u32,
    pub lsb: f64,
    pub guard_bits: u32,
    pub max_abs_coordinate: f64,
    pub max_quantization_error: f64,
    pub max_quantization_error_lsb: f64,
    pub smallest_feature: f64,
    pub smallest_feature_lsb: f64,
    /// Where the smallest feature is: `file:line (type)`.
    pub smallest_feature_at: String,
    pub objects: usize,
    /// Objects of each type present, by name.
    pub type_counts: Vec<(String, usize)>,
    pub bsp: BspStats,
    pub bsp_params: BspParams,
    pub layout: Layout,
    pub layout_reason: String,
    pub bitvector_layout_words: Option<usize>,
    pub index_list_layout_words: Option<usize>,
    pub node_words: usize,
    pub object_words: usize,
    pub total_words: usize,
    pub fb_words: usize,
    pub fits_fb: bool,
    pub fits_fb_bank: bool,
    pub triangle_only: TriangleOnly,
    pub notes: Vec<String>,
}

/// The image and its report.
#[derive(Clone, Debug)]
pub struct SceneImage {
    pub words: Vec<u16>,
    pub report: Report,
    /// For each scene object, its type and index within the type.
    pub object_slots: Vec<(PrimType, u32)>,
    pub bsp: Bsp,
}

impl SceneImage {
    /// The image as little-endian bytes.
    pub fn to_le_bytes(&self) -> Vec<u8> {
        self.words.iter().flat_map(|w| w.to_le_bytes()).collect()
    }
}

/// Triangles in the documented tessellation of a shape: spheres 16
/// segments x 8 rings (224), cylinders and cones 16 segments (32, plus 16
/// per cap), boxes 12, rectangles 2, polygons n - 2.
pub fn tessellated_triangles(s: &Shape) -> usize {
    match s {
        Shape::Sphere { .. } => 224,
        Shape::Cone {
            caps,
            base_radius,
            apex_radius,
            ..
        } => {
            let capn = if *caps {
                16 * ((*base_radius > 0.0) as usize + (*apex_radius > 0.0) as usize)
            } else {
                0
            };
            32 + capn
        }
        Shape::Box { .. } => 12,
        Shape::Rectangle { .. } => 2,
        Shape::Triangle { .. } => 1,
        Shape::Polygon { v, .. } => v.len() - 2,
    }
}

/// The smallest length that defines a shape.
pub fn smallest_feature(s: &Shape) -> f64 {
    fn edges_and_height(v: &[Vec3]) -> f64 {
        let mut m = f64::INFINITY;
        let mut longest: f64 = 0.0;
        for k in 0..v.len() {
            let e = (v[(k + 1) % v.len()] - v[k]).length();
            m = m.min(e);
            longest = longest.max(e);
        }
        let area2 = (v[1] - v[0]).cross(v[2] - v[0]).length();
        m.min(area2 / longest)
    }
    match s {
        Shape::Sphere { radius, .. } => *radius,
        Shape::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
            ..
        } => {
            let r = base_radius.max(*apex_radius);
            r.min((*apex - *base).length())
        }
        Shape::Box { min, max } => {
            let e = *max - *min;
            e.x.min(e.y).min(e.z)
        }
        Shape::Rectangle { edge1, edge2, .. } => edge1.length().min(edge2.length()),
        Shape::Triangle { v, .. } => edges_and_height(v),
        Shape::Polygon { v, .. } => edges_and_height(v),
    }
}

/// The scene-coordinate values (points and radii) a shape's record holds.
fn coordinates(s: &Shape) -> Vec<f64> {
    let mut out = Vec::new();
    let mut p = |v: Vec3| out.extend_from_slice(&v.to_array());
    match s {
        Shape::Sphere { center, .. } => p(*center),
        Shape::Cone { base, apex, .. } => {
            p(*base);
            p(*apex)
        }
        Shape::Box { min, max } => {
            p(*min);
            p(*max)
        }
        // The edges are differences of two points: the guard bit covers them
        // (checked in `fit`).
        Shape::Rectangle { corner, .. } => p(*corner),
        Shape::Triangle { v, .. } => v.iter().for_each(|v| p(*v)),
        Shape::Polygon { v, .. } => v.iter().for_each(|v| p(*v)),
    }
    match s {
        Shape::Sphere { radius, .. } => out.push(*radius),
        Shape::Cone {
            base_radius,
            apex_radius,
            ..
        } => {
            out.push(*base_radius);
            out.push(*apex_radius)
        }
        _ => {}
    }
    out
}

/// The fraction bits of the format [`compile`] fits to `scene` with
/// `guard_bits`, if it can represent the scene (no BSP built).
pub fn fitted_frac(scene: &Scene, guard_bits: u32) -> Option<u32> {
    let opt = CompileOptions {
        guard_bits,
        ..CompileOptions::default()
    };
    fit(scene, &opt).ok().map(|(q, _)| q.frac)
}

/// Fit the format, or say why the scene cannot be represented.
fn fit(scene: &Scene, opt: &CompileOptions) -> Result<(QFormat, f64), SceneError> {
    let err = |line: usize, message: String| SceneError {
        file: scene.source.clone(),
        line,
        col: 0,
        message,
    };
    let mut max_abs: f64 = 0.0;
    let mut max_line = 0;
    let mut see = |x: f64, line: usize| {
        if x.abs() > max_abs {
            max_abs = x.abs();
            max_line = line;
        }
    };
    for o in &scene.objects {
        coordinates(&o.shape)
            .into_iter()
            .for_each(|x| see(x, o.line));
    }
    let c = &scene.camera;
    c.from
        .to_array()
        .into_iter()
        .chain(c.at.to_array())
        .for_each(|x| see(x, 0));
    for l in &scene.lights {
        l.position.to_array().into_iter().for_each(|x| see(x, 0));
    }
    // Largest n with max_abs * 2^guard < 2^(15 - n).
    let need = max_abs * (opt.guard_bits as f64).exp2();
    let frac = (0..=15u32).rev().find(|&n| need < ((15 - n) as f64).exp2());
    let Some(frac) = frac else {
        return Err(err(
            max_line,
            format!(
                "cannot represent the scene in 16-bit fixed point: a coordinate reaches {max_abs}, and with {} guard bit(s) \
                 the largest allowed is {}",
                opt.guard_bits,
                (15.0 - opt.guard_bits as f64).exp2()
            ),
        ));
    };
    let q = QFormat { frac };
    for o in &scene.objects {
        if let Shape::Rectangle { edge1, edge2, .. } = &o.shape {
            if edge1
                .to_array()
                .into_iter()
                .chain(edge2.to_array())
                .any(|x| q.quantize(x).is_none())
            {
                return Err(err(
                    o.line,
                    format!(
                        "rectangle edge does not fit in {} (use a guard bit)",
                        q.name()
                    ),
                ));
            }
        }
    }
    Ok((q, max_abs))
}

struct Writer {
    words: Vec<u16>,
    q: QFormat,
    max_err: f64,
}

impl Writer {
    fn word(&mut self, w: u16) {
        self.words.push(w);
    }
    fn coord(&mut self, x: f64) {
        // `fit` guarantees the range.
        let q = self
            .q
            .quantize(x)
            .unwrap_or(if x < 0.0 { i16::MIN } else { i16::MAX });
        self.max_err = self.max_err.max((self.q.value(q) - x).abs());
        self.words.push(q as u16);
    }
    fn point(&mut self, v: Vec3) {
        self.coord(v.x);
        self.coord(v.y);
        self.coord(v.z);
    }
    fn fixed(&mut self, f: QFormat, x: f64) {
        let q = f
            .quantize(x)
            .unwrap_or(if x < 0.0 { i16::MIN } else { i16::MAX });
        self.words.push(q as u16);
    }
    fn addr(&mut self, at: usize, value: usize) {
        self.words[at] = (value >> 16) as u16;
        self.words[at + 1] = value as u16;
    }
}

/// Compile a scene into its memory image.
pub fn compile(scene: &Scene, opt: &CompileOptions) -> Result<SceneImage, SceneError> {
    scene.validate()?;
    let err = |line: usize, message: String| SceneError {
        file: scene.source.clone(),
        line,
        col: 0,
        message,
    };
    if !(0..=MAX_BSP_DEPTH).contains(&opt.bsp.max_depth) || opt.bsp.max_leaf == 0 {
        return Err(err(
            0,
            format!(
                "BSP max depth {} must be 1..={MAX_BSP_DEPTH} (0: automatic) and max objects per leaf {} at least 1",
                opt.bsp.max_depth, opt.bsp.max_leaf
            ),
        ));
    }
    if scene.objects.is_empty() {
        return Err(err(0, "the scene has no objects".into()));
    }
    let (q, max_abs) = fit(scene, opt)?;
    let lsb = q.lsb();
    let mut notes = Vec::new();

    // Smallest feature, and a check that quantizing breaks nothing.
    let mut small = (f64::INFINITY, 0usize, "");
    for o in &scene.objects {
        let f = smallest_feature(&o.shape);
        if f < small.0 {
            small = (f, o.line, o.shape.prim_type().name());
        }
    }
    let at = format!("{}:{} ({})", scene.source, small.1, small.2);
    if small.0 < opt.min_feature_lsb * lsb * (-(opt.target_extra_frac as f64)).exp2() {
        return Err(err(
            small.1,
            format!(
                "cannot represent the scene in 16-bit fixed point: it spans +-{max_abs}, so the format is {} (LSB {lsb}), \
                 and this {} has a feature of {} = {:.2} LSB, below the {} LSB minimum",
                q.name(),
                small.2,
                small.0,
                small.0 / lsb,
                opt.min_feature_lsb
            ),
        ));
    }

    // Objects grouped by type.
    let mut by_type: Vec<Vec<usize>> = vec![Vec::new(); 7];
    let mut object_slots = Vec::with_capacity(scene.objects.len());
    for (i, o) in scene.objects.iter().enumerate() {
        let t = o.shape.prim_type();
        object_slots.push((t, by_type[t.index()].len() as u32));
        by_type[t.index()].push(i);
    }
    let present: Vec<PrimType> = PrimType::ALL
        .into_iter()
        .filter(|t| !by_type[t.index()].is_empty())
        .collect();
    // Every count the image holds in a 16-bit field, checked, never wrapped.
    const FIELD: usize = u16::MAX as usize;
    for t in &present {
        let v = &by_type[t.index()];
        if v.len() > FIELD {
            return Err(err(
                scene.objects[v[FIELD]].line,
                format!(
                    "the scene has {} {}s; the image counts each type in 16 bits (at most {FIELD}); this is the first one past that",
                    v.len(),
                    t.name()
                ),
            ));
        }
    }
    for (n, what) in [
        (scene.lights.len(), "lights"),
        (scene.materials.len(), "materials"),
    ] {
        if n > FIELD {
            return Err(err(
                0,
                format!(
                    "the scene has {n} {what}; the image counts them in 16 bits (at most {FIELD})"
                ),
            ));
        }
    }
    for o in &scene.objects {
        if let Shape::Polygon { v, .. } = &o.shape {
            if v.len() > FIELD {
                return Err(err(
                    o.line,
                    format!("a polygon of {} vertices; the image counts them in 16 bits (at most {FIELD})", v.len()),
                ));
            }
        }
    }

    // The BSP, its planes snapped to the format.
    let bounds: Vec<Aabb> = scene.objects.iter().map(|o| o.shape.bounds()).collect();
    let world = bounds.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
    let snap_out = |b: Aabb| Aabb {
        min: Vec3::new(
            (b.min.x / lsb).floor() * lsb,
            (b.min.y / lsb).floor() * lsb,
            (b.min.z / lsb).floor() * lsb,
        ),
        max: Vec3::new(
            (b.max.x / lsb).ceil() * lsb,
            (b.max.y / lsb).ceil() * lsb,
            (b.max.z / lsb).ceil() * lsb,
        ),
    };
    // An object goes to the cells it may meet, with 2 LSB to spare for the
    // kernels' rounding.
    let meets = |i: u32, b: &Aabb| {
        let m = Vec3::ONE * (2.0 * lsb);
        scene.objects[i as usize].shape.may_overlap(&Aabb {
            min: b.min - m,
            max: b.max + m,
        })
    };
    let bsp = Bsp::build_with(
        &bounds,
        snap_out(world),
        BspParams {
            snap: lsb,
            ..opt.bsp
        },
        &meets,
    );
    if bsp.nodes.len() > NO_CHILD as usize {
        return Err(err(
            0,
            format!(
                "the BSP has {} nodes; node indices are 16-bit (at most 65535)",
                bsp.nodes.len()
            ),
        ));
    }
    let stats = bsp.stats();

    // Layout sizes.
    let bv_per_node: usize = present
        .iter()
        .map(|t| by_type[t.index()].len().div_ceil(16))
        .sum();
    if 4 + bv_per_node > FIELD {
        return Err(err(
            0,
            format!(
                "a Fig. 5 node of this scene needs {} words (its bit vectors); the image's words-per-node field is 16 bits (at most {FIELD})",
                4 + bv_per_node
            ),
        ));
    }
    let bv_words = bsp.nodes.len() * (4 + bv_per_node);
    let max_per_type = present
        .iter()
        .map(|t| by_type[t.index()].len())
        .max()
        .unwrap_or(0);
    let il_words =
        (max_per_type <= 1 << LIST_INDEX_BITS).then(|| bsp.nodes.len() * 8 + stats.leaf_references);
    let (layout, reason) = match (opt.layout, il_words) {
        (Some(Layout::IndexLists), None) => {
            return Err(err(
                0,
                format!("the index-list layout holds at most {} objects per type; this scene has {max_per_type}", 1 << LIST_INDEX_BITS),
            ))
        }
        (Some(l), _) => (l, "chosen by option".to_string()),
        (None, Some(il)) if il < bv_words => (
            Layout::IndexLists,
            format!("index lists ({il} words) are smaller than bit vectors ({bv_words} words, {bv_per_node} per node)"),
        ),
        (None, _) => (
            Layout::BitVectors,
            format!("bit vectors ({bv_words} words, {bv_per_node} per node) are no larger than index lists"),
        ),
    };

    // Header, patched once the sections are placed.
    let mut w = Writer {
        words: vec![0; HEADER_WORDS],
        q,
        max_err: 0.0,
    };
    w.words[0] = MAGIC;
    w.words[1] = VERSION;
    w.words[2] = q.frac as u16;
    w.words[3] = match layout {
        Layout::BitVectors => 0,
        Layout::IndexLists => 1,
    };
    w.words[4] = bsp.nodes.len() as u16;
    w.words[5] = 0; // root node index
    w.words[6] = match layout {
        Layout::BitVectors => 4 + bv_per_node,
        Layout::IndexLists => 8,
    } as u16;
    // (each count checked above)
    w.words[7] = scene.lights.len() as u16;
    w.words[8] = scene.materials.len() as u16;
    for t in PrimType::ALL {
        w.words[9 + t.index()] = by_type[t.index()].len() as u16;
    }
    // 16..: 32-bit section addresses: camera, lights, materials, objects of
    // each of the 7 types, polygon vertices, nodes, lists.
    const A_CAMERA: usize = 16;
    const A_LIGHTS: usize = 18;
    const A_MATERIALS: usize = 20;
    const A_OBJECTS: usize = 22; // 7 pairs
    const A_VERTICES: usize = 36;
    const A_NODES: usize = 38;
    const A_LISTS: usize = 40;

    // Camera.
    let at_camera = w.words.len();
    w.addr(A_CAMERA, at_camera);
    let c = &scene.camera;
    w.point(c.from);
    w.point(c.at);
    let up = c.up.normalized();
    for x in up.to_array() {
        w.fixed(Q_UNIT, x);
    }
    w.fixed(Q_MATERIAL, (c.angle.to_radians() / 2.0).tan());
    if (c.angle.to_radians() / 2.0).tan() >= 8.0 {
        notes.push("camera angle too wide for Q3.12 tan(angle/2): clamped".into());
    }
    w.word(c.resolution.0.min(u16::MAX as u32) as u16);
    w.word(c.resolution.1.min(u16::MAX as u32) as u16);
    for x in scene.background.to_array() {
        w.fixed(Q_MATERIAL, x);
    }
    // Lights.
    let n_lights = scene.lights.len().max(1) as f64;
    let at_lights = w.words.len();
    w.addr(A_LIGHTS, at_lights);
    for l in &scene.lights {
        w.point(l.position);
        for x in l.color.unwrap_or(Vec3::ONE / n_lights.sqrt()).to_array() {
            w.fixed(Q_MATERIAL, x);
        }
    }
    // Materials.
    let at_materials = w.words.len();
    w.addr(A_MATERIALS, at_materials);
    for m in &scene.materials {
        for x in [m.color.x, m.color.y, m.color.z, m.kd, m.ks, m.t, m.ior] {
            if x.abs() >= 8.0 {
                notes.push(format!("material value {x} is out of Q3.12 range: clamped"));
            }
            w.fixed(Q_MATERIAL, x);
        }
        if m.shine > u16::MAX as f64 {
            notes.push(format!(
                "Phong exponent {} clamped to {}",
                m.shine,
                u16::MAX
            ));
        }
        w.word(m.shine.round().clamp(0.0, u16::MAX as f64) as u16);
    }
    // Objects.
    let mut polygon_vertices: Vec<Vec3> = Vec::new();
    let mut polygon_fixups = Vec::new();
    let at_objects = w.words.len();
    for t in PrimType::ALL {
        let here = w.words.len();
        w.addr(A_OBJECTS + 2 * t.index(), here);
        for &i in &by_type[t.index()] {
            let o = &scene.objects[i];
            let mat = o.material.min(u16::MAX as usize) as u16;
            let start = w.words.len();
            match &o.shape {
                Shape::Sphere {
                    center,
                    radius,
                    inside,
                } => {
                    w.point(*center);
                    w.coord(*radius);
                    w.word(mat);
                    w.word(*inside as u16);
                }
                Shape::Cone {
                    base,
                    base_radius,
                    apex,
                    apex_radius,
                    inside,
                    caps,
                } => {
                    w.point(*base);
                    w.point(*apex);
                    w.coord(*base_radius);
                    if t == PrimType::Cone {
                        w.coord(*apex_radius);
                    }
                    w.word(mat);
                    w.word(*inside as u16 | (*caps as u16) << 1);
                }
                Shape::Box { min, max } => {
                    w.point(*min);
                    w.point(*max);
                    w.word(mat);
                }
                Shape::Rectangle {
                    corner,
                    edge1,
                    edge2,
                } => {
                    w.point(*corner);
                    w.point(*edge1);
                    w.point(*edge2);
                    w.word(mat);
                }
                Shape::Triangle { v, .. } => {
                    v.iter().for_each(|v| w.point(*v));
                    w.word(mat);
                }
                Shape::Polygon { v, .. } => {
                    w.word(mat);
                    w.word(v.len() as u16); // checked above
                    polygon_fixups.push((w.words.len(), polygon_vertices.len()));
                    w.word(0);
                    w.word(0);
                    polygon_vertices.extend_from_slice(v);
                }
            }
            debug_assert_eq!(w.words.len() - start, record_words(t));
            // A record that quantizing made degenerate cannot be traced.
            let dq = dequantized(&o.shape, q);
            // (Rounding may tilt a rectangle's edges or a polygon's vertices
            // off the plane by a fraction of an LSB: harmless.)
            if let Some(why) = dq
                .degeneracy()
                .filter(|_| opt.target_extra_frac == 0)
                .filter(|m| !m.contains("perpendicular") && !m.contains("not in the plane"))
            {
                return Err(err(
                    o.line,
                    format!(
                        "cannot represent this object in {}: after rounding, {why}",
                        q.name()
                    ),
                ));
            }
        }
    }
    let at_vertices = w.words.len();
    w.addr(A_VERTICES, at_vertices);
    for (at, first) in polygon_fixups {
        w.addr(at, at_vertices + 3 * first);
    }
    for v in polygon_vertices {
        w.point(v);
    }
    let object_words = w.words.len() - at_objects;

    // Nodes.
    let at_nodes = w.words.len();
    w.addr(A_NODES, at_nodes);
    let node_head = |w: &mut Writer, n: &crate::bsp::Node| match n.split {
        Some(s) => {
            w.word(s.axis as u16 | ((n.depth as u16) << 4));
            w.coord(s.position);
            w.word(s.children[0] as u16);
            w.word(s.children[1] as u16);
        }
        None => {
            w.word(0x8000 | ((n.depth as u16) << 4));
            w.word(0);
            w.word(NO_CHILD);
            w.word(NO_CHILD);
        }
    };
    let slot = |i: u32| object_slots[i as usize];
    match layout {
        Layout::BitVectors => {
            for n in &bsp.nodes {
                node_head(&mut w, n);
                for t in &present {
                    let members = n
                        .objects
                        .iter()
                        .map(|&i| slot(i))
                        .filter(|(ot, _)| ot == t)
                        .map(|(_, k)| k as usize);
                    w.words
                        .extend(membership_words(by_type[t.index()].len(), members));
                }
            }
            w.addr(A_LISTS, 0);
        }
        Layout::IndexLists => {
            // Leaf lists in node (depth-first) order; an inner node's range
            // runs from its first leaf's start to its last leaf's end.
            let mut ranges = vec![(0usize, 0usize); bsp.nodes.len()];
            let mut list: Vec<u16> = Vec::with_capacity(stats.leaf_references);
            for (k, n) in bsp.nodes.iter().enumerate() {
                if n.split.is_none() {
                    let start = list.len();
                    let mut entries: Vec<u16> = n
                        .objects
                        .iter()
                        .map(|&i| slot(i))
                        .map(|(t, k)| ((t.index() as u16) << LIST_INDEX_BITS) | k as u16)
                        .collect();
                    entries.sort_unstable();
                    list.extend(entries);
                    ranges[k] = (start, list.len());
                }
            }
            for k in (0..bsp.nodes.len()).rev() {
                if let Some(s) = bsp.nodes[k].split {
                    ranges[k] = (
                        ranges[s.children[0] as usize].0,
                        ranges[s.children[1] as usize].1,
                    );
                }
            }
            for (k, n) in bsp.nodes.iter().enumerate() {
                node_head(&mut w, n);
                let (s, e) = ranges[k];
                w.word((s >> 16) as u16);
                w.word(s as u16);
                w.word(((e - s) >> 16) as u16);
                w.word((e - s) as u16);
            }
            let at_lists = w.words.len();
            w.addr(A_LISTS, at_lists);
            w.words.extend(list);
        }
    }
    let node_words = w.words.len() - at_nodes;

    let triangles: usize = scene
        .objects
        .iter()
        .map(|o| tessellated_triangles(&o.shape))
        .sum();
    let total = w.words.len();
    let report = Report {
        scene: scene.source.clone(),
        format: q.name(),
        frac_bits: q.frac,
        lsb,
        guard_bits: opt.guard_bits,
        max_abs_coordinate: max_abs,
        max_quantization_error: w.max_err,
        max_quantization_error_lsb: w.max_err / lsb,
        smallest_feature: small.0,
        smallest_feature_lsb: small.0 / lsb,
        smallest_feature_at: at,
        objects: scene.objects.len(),
        type_counts: present
            .iter()
            .map(|t| (t.name().to_string(), by_type[t.index()].len()))
            .collect(),
        bsp: stats,
        bsp_params: BspParams {
            snap: lsb,
            ..opt.bsp
        },
        layout,
        layout_reason: reason,
        bitvector_layout_words: Some(bv_words),
        index_list_layout_words: il_words,
        node_words,
        object_words,
        total_words: total,
        fb_words: FB_WORDS,
        fits_fb: total <= FB_WORDS,
        fits_fb_bank: total <= FB_BANK_WORDS,
        triangle_only: TriangleOnly {
            triangles,
            object_words: triangles * record_words(PrimType::Triangle),
            bitvector_words_per_node: triangles.div_ceil(16),
        },
        notes,
    };
    Ok(SceneImage {
        words: w.words,
        report,
        object_slots,
        bsp,
    })
}

/// The shape as the chip sees it: every coordinate rounded to `q`.
pub fn dequantized(s: &Shape, q: QFormat) -> Shape {
    let r = |x: f64| q.quantize(x).map_or(x, |v| q.value(v));
    let p = |v: Vec3| Vec3::new(r(v.x), r(v.y), r(v.z));
    match s {
        Shape::Sphere {
            center,
            radius,
            inside,
        } => Shape::Sphere {
            center: p(*center),
            radius: r(*radius),
            inside: *inside,
        },
        Shape::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
            inside,
            caps,
        } => Shape::Cone {
            base: p(*base),
            base_radius: r(*base_radius),
            apex: p(*apex),
            apex_radius: r(*apex_radius),
            inside: *inside,
            caps: *caps,
        },
        Shape::Box { min, max } => Shape::Box {
            min: p(*min),
            max: p(*max),
        },
        Shape::Rectangle {
            corner,
            edge1,
            edge2,
        } => Shape::Rectangle {
            corner: p(*corner),
            edge1: p(*edge1),
            edge2: p(*edge2),
        },
        Shape::Triangle { v, .. } => Shape::Triangle {
            v: v.map(p),
            normals: None,
        },
        Shape::Polygon { v, .. } => Shape::Polygon {
            v: v.iter().map(|v| p(*v)).collect(),
            normals: None,
        },
    }
}

impl Report {
    /// A human-readable summary.
    pub fn text(&self) -> String {
        let mut s = String::new();
        let types: Vec<String> = self
            .type_counts
            .iter()
            .map(|(t, n)| format!("{n} {t}"))
            .collect();
        s += &format!(
            "scene: {} ({} objects: {})\n",
            self.scene,
            self.objects,
            types.join(", ")
        );
        s += &format!(
            "format: {} (LSB {}, {} guard bit{}; coordinates up to {})\n",
            self.format,
            self.lsb,
            self.guard_bits,
            if self.guard_bits == 1 { "" } else { "s" },
            self.max_abs_coordinate
        );
        s += &format!(
            "largest quantization error: {:.3e} ({:.3} LSB)\n",
            self.max_quantization_error, self.max_quantization_error_lsb
        );
        s += &format!(
            "smallest feature: {} = {:.1} LSB at {}\n",
            self.smallest_feature, self.smallest_feature_lsb, self.smallest_feature_at
        );
        s += &format!(
            "BSP ({} split, max depth {}, max {} per leaf): {} nodes, {} leaves ({} empty), depth {}, up to {} objects per leaf, {} leaf references\n",
            match self.bsp_params.rule {
                crate::bsp::SplitRule::Median => "median",
                crate::bsp::SplitRule::Sah => "SAH",
                crate::bsp::SplitRule::Auto => "auto",
            },
            self.bsp_params.max_depth,
            self.bsp_params.max_leaf,
            self.bsp.nodes,
            self.bsp.leaves,
            self.bsp.empty_leaves,
            self.bsp.max_depth,
            self.bsp.max_leaf_objects,
            self.bsp.leaf_references
        );
        s += &format!(
            "layout: {}: {}\n",
            match self.layout {
                Layout::BitVectors => "fig5 (bit vectors)",
                Layout::IndexLists => "compact (index lists)",
            },
            self.layout_reason
        );
        s += &format!(
            "footprint: {} words ({:.1} KiB): objects {}, nodes {}; FB holds {} words: {}\n",
            self.total_words,
            self.total_words as f64 * 2.0 / 1024.0,
            self.object_words,
            self.node_words,
            self.fb_words,
            if self.fits_fb_bank {
                "fits in one bank"
            } else if self.fits_fb {
                "fits in the FB (not in one bank)"
            } else {
                "does NOT fit: streamed by DMA"
            }
        );
        s += &format!(
            "triangle-only version: {} triangles, {} words of objects ({:.1}x native), {} bit-vector words per node\n",
            self.triangle_only.triangles,
            self.triangle_only.object_words,
            self.triangle_only.object_words as f64 / self.object_words.max(1) as f64,
            self.triangle_only.bitvector_words_per_node
        );
        for n in &self.notes {
            s += &format!("note: {n}\n");
        }
        s
    }
}

#[cfg(test)]
mod membership_tests {
    use super::membership_words;

    #[test]
    fn membership_words_put_the_first_object_in_bit_15_of_word_0() {
        // Against the shift arithmetic, independently.
        for count in [1usize, 15, 16, 17, 40] {
            let members: Vec<usize> = (0..count).filter(|k| k % 3 != 1).collect();
            let mut want = vec![0u16; count.div_ceil(16)];
            for &k in &members {
                want[k / 16] |= 0x8000 >> (k % 16);
            }
            assert_eq!(membership_words(count, members), want, "{count} objects");
        }
    }
}
