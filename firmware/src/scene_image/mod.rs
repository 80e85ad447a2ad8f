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

mod fit;
mod report;
mod sections;

use bitvec::prelude::*;

use crate::bsp::{Bsp, BspParams};
use crate::scene::{Aabb, Polygon, PrimType, Scene, SceneError, Vec3};

pub use fit::{
    dequantized, fitted_frac, local_exponent, local_frame, smallest_feature, tessellated_triangles,
    LOCAL_E_MAX,
};
pub use report::{Report, TriangleOnly};
use sections::Writer;

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
pub use crate::bsp::MAX_BSP_DEPTH;
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
        PrimType::Disc => 8,
    }
}

/// Which node layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum NodeFormat {
    /// Fig. 5: one membership bit vector per primitive type in every node.
    BitVectors,
    /// Per node, a range of a shared list of object references.
    IndexLists,
}

/// Compiler options.
#[derive(Clone, Debug)]
pub struct CompileOptions {
    pub bsp: BspParams,
    /// The costs an [`crate::bsp::SplitRule::Chip`] tree weighs (`None`:
    /// [`crate::bsp::ChipCosts::uniform`]).
    pub chip_costs: Option<std::sync::Arc<crate::bsp::ChipCosts>>,
    /// None: the smaller of the two.
    pub layout: Option<NodeFormat>,
    /// Bits of headroom above the largest coordinate.
    pub guard_bits: u32,
    /// Refuse a scene whose smallest feature is below this many LSBs.
    pub min_feature_lsb: f64,
    /// Fraction bits the chip's own records carry beyond this image's
    /// (16 for the 32-bit datapath, whose tracer lays the objects out
    /// again with 16 more): the smallest-feature and degeneracy checks then
    /// apply at the chip's precision, not at the 16-bit image's.
    pub target_extra_frac: u32,
    /// Local positions: the chip tests spheres and flat triangles in
    /// frames of their own ([`fit::local_frame`], `2^e` times finer than
    /// the format, [`fit::local_exponent`]): their features are checked at
    /// their frame's precision, and one too large for a frame is refused.
    pub local_frames: bool,
}

impl Default for CompileOptions {
    fn default() -> Self {
        CompileOptions {
            bsp: BspParams::default(),
            chip_costs: None,
            layout: None,
            guard_bits: 1,
            min_feature_lsb: 2.0,
            target_extra_frac: 0,
            local_frames: false,
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

/// Compile a scene into its memory image.
pub fn compile(scene: &Scene, opt: &CompileOptions) -> Result<SceneImage, SceneError> {
    scene.validate()?;
    let err = |line: usize, message: String| error(scene, line, message);
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
    let (q, max_abs) = fit::fit(scene, opt)?;
    let small = fit::smallest(scene, opt, q, max_abs)?;
    let groups = Groups::new(scene)?;
    let bsp = build_bsp(scene, opt, q)?;
    let stats = bsp.stats();
    let choice = choose_layout(scene, opt, &groups, &bsp)?;

    let mut notes = Vec::new();
    let mut w = Writer::new(q);
    sections::header(&mut w, scene, &groups, &bsp, &choice);
    sections::camera(&mut w, scene, &mut notes);
    sections::lights(&mut w, scene);
    sections::materials(&mut w, scene, &mut notes);
    let object_words = sections::objects(&mut w, scene, &groups, opt)?;
    let node_words = sections::nodes(&mut w, &bsp, &groups, choice.layout);

    let lsb = q.lsb();
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
        smallest_feature: small.size,
        smallest_feature_lsb: small.size / lsb,
        smallest_feature_at: format!("{}:{} ({})", scene.source, small.line, small.what),
        objects: scene.objects.len(),
        type_counts: groups
            .present
            .iter()
            .map(|t| (t.name().to_string(), groups.by_type[t.index()].len()))
            .collect(),
        bsp: stats,
        bsp_params: BspParams {
            snap: lsb,
            ..opt.bsp
        },
        layout: choice.layout,
        layout_reason: choice.reason,
        bitvector_layout_words: Some(choice.bv_words),
        index_list_layout_words: choice.il_words,
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
        object_slots: groups.object_slots,
        bsp,
    })
}

/// An error in `scene`'s file at `line` (0: the scene as a whole).
fn error(scene: &Scene, line: usize, message: String) -> SceneError {
    SceneError {
        file: scene.source.clone(),
        line,
        col: 0,
        message,
    }
}

/// Every count the image holds in a 16-bit field.
const FIELD: usize = u16::MAX as usize;

/// The scene's objects grouped by type.
struct Groups {
    /// Scene object indices, by type index.
    by_type: Vec<Vec<usize>>,
    /// For each scene object, its type and index within the type.
    object_slots: Vec<(PrimType, u32)>,
    /// The types with at least one object, in `PrimType::ALL` order.
    present: Vec<PrimType>,
}

impl Groups {
    /// The groups, with every count the image holds in 16 bits checked,
    /// never wrapped.
    fn new(scene: &Scene) -> Result<Groups, SceneError> {
        let mut by_type: Vec<Vec<usize>> = vec![Vec::new(); PrimType::ALL.len()];
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
        for t in &present {
            let v = &by_type[t.index()];
            if v.len() > FIELD {
                return Err(error(
                    scene,
                    scene.objects[v[FIELD]].line,
                    format!(
                        "the scene has {} {}; the image counts each type in 16 bits (at most {FIELD}); this is the first one past that",
                        v.len(),
                        t.plural()
                    ),
                ));
            }
        }
        for (n, what) in [
            (scene.lights.len(), "lights"),
            (scene.materials.len(), "materials"),
        ] {
            if n > FIELD {
                return Err(error(
                    scene,
                    0,
                    format!(
                        "the scene has {n} {what}; the image counts them in 16 bits (at most {FIELD})"
                    ),
                ));
            }
        }
        for o in &scene.objects {
            if let Some(Polygon { v, .. }) = o.shape.as_polygon() {
                if v.len() > FIELD {
                    return Err(error(
                        scene,
                        o.line,
                        format!("a polygon of {} vertices; the image counts them in 16 bits (at most {FIELD})", v.len()),
                    ));
                }
            }
        }
        Ok(Groups {
            by_type,
            object_slots,
            present,
        })
    }
}

/// The BSP over the objects' bounds, its planes snapped to the format.
fn build_bsp(scene: &Scene, opt: &CompileOptions, q: QFormat) -> Result<Bsp, SceneError> {
    let lsb = q.lsb();
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
    let bsp = Bsp::build_costed(
        &bounds,
        snap_out(world),
        BspParams {
            snap: lsb,
            ..opt.bsp
        },
        &meets,
        opt.chip_costs.as_deref(),
    );
    if bsp.over_budget {
        return Err(error(
            scene,
            0,
            format!(
                "the BSP ({:?} split, depth limit {}) grows past {} nodes; node indices are \
                 16-bit (at most 65535): lower --max-depth or raise --max-leaf",
                bsp.params.rule,
                bsp.params.max_depth,
                crate::bsp::NODE_BUDGET
            ),
        ));
    }
    if bsp.nodes.len() > NO_CHILD as usize {
        return Err(error(
            scene,
            0,
            format!(
                "the BSP has {} nodes; node indices are 16-bit (at most 65535)",
                bsp.nodes.len()
            ),
        ));
    }
    Ok(bsp)
}

/// The node layout, why, and both layouts' sizes.
struct LayoutChoice {
    layout: NodeFormat,
    reason: String,
    /// Bit-vector words in one Fig. 5 node.
    bv_per_node: usize,
    /// Words of the nodes in the Fig. 5 layout.
    bv_words: usize,
    /// Words of the nodes and lists in the compact layout, if it can hold
    /// the scene.
    il_words: Option<usize>,
}

/// The option's layout, or else the smaller of the two.
fn choose_layout(
    scene: &Scene,
    opt: &CompileOptions,
    g: &Groups,
    bsp: &Bsp,
) -> Result<LayoutChoice, SceneError> {
    let bv_per_node: usize = g
        .present
        .iter()
        .map(|t| g.by_type[t.index()].len().div_ceil(16))
        .sum();
    if 4 + bv_per_node > FIELD {
        return Err(error(
            scene,
            0,
            format!(
                "a Fig. 5 node of this scene needs {} words (its bit vectors); the image's words-per-node field is 16 bits (at most {FIELD})",
                4 + bv_per_node
            ),
        ));
    }
    let bv_words = bsp.nodes.len() * (4 + bv_per_node);
    let max_per_type = g
        .present
        .iter()
        .map(|t| g.by_type[t.index()].len())
        .max()
        .unwrap_or(0);
    let il_words = (max_per_type <= 1 << LIST_INDEX_BITS)
        .then(|| bsp.nodes.len() * 8 + bsp.stats().leaf_references);
    let (layout, reason) = match (opt.layout, il_words) {
        (Some(NodeFormat::IndexLists), None) => {
            return Err(error(
                scene,
                0,
                format!("the index-list layout holds at most {} objects per type; this scene has {max_per_type}", 1 << LIST_INDEX_BITS),
            ))
        }
        (Some(l), _) => (l, "chosen by option".to_string()),
        (None, Some(il)) if il < bv_words => (
            NodeFormat::IndexLists,
            format!("index lists ({il} words) are smaller than bit vectors ({bv_words} words, {bv_per_node} per node)"),
        ),
        (None, _) => (
            NodeFormat::BitVectors,
            format!("bit vectors ({bv_words} words, {bv_per_node} per node) are no larger than index lists"),
        ),
    };
    Ok(LayoutChoice {
        layout,
        reason,
        bv_per_node,
        bv_words,
        il_words,
    })
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
