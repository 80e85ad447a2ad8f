//! What the compiler reports about a scene image: the format, the BSP,
//! the layout chosen and why, the footprint.

use crate::bsp::{BspParams, BspStats};

use super::NodeFormat;

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
    pub layout: NodeFormat,
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
                crate::bsp::SplitRule::Chip => "chip-cost SAH",
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
                NodeFormat::BitVectors => "fig5 (bit vectors)",
                NodeFormat::IndexLists => "compact (index lists)",
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
