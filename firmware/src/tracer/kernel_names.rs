//! The names of the RC kernels: their labels in context memory (`k_NAME`
//! .. `k_NAME_end`), what the TinyRISC code broadcasts them by, what the
//! profile charges cycles to and what the render driver watches.

const AXES: [&str; 3] = ["x", "y", "z"];

/// Start-up: every RC's RAM tables and constants.
pub const INIT: &str = "k_init";
/// Row-mode group: row (or column) i gets r8 = i.
pub const ROW_INDEX: &str = "k_row_index";
/// r8 into `LANE_ROW`, `LANE_COL`.
pub const STORE_ROW: &str = "k_store_row";
pub const STORE_COL: &str = "k_store_col";
/// The RCs outside the tile sleep for good.
pub const LANES: &str = "k_lanes";
/// Every RC of the tile awake again after a pass.
pub const WAKE: &str = "k_wake_tile";
/// The tile's eye rays.
pub const EYE: &str = "k_eye";
/// After a closest-hit pass: the hits' shading state (eye rays, later levels).
pub const POST_EYE: &str = "k_post_eye";
pub const POST: &str = "k_post";
/// Shadow rays towards one light; its Phong terms after the pass.
pub const SHADOW: &str = "k_shadow_rays";
pub const PHONG: &str = "k_phong";

/// Merged shadow packets ([`super::shadows`]): the RC's number; a lit
/// RC's N.L and R.V kept per light; a shadow ray's words out; a packet's
/// loads, its RCs with no ray asleep, its answers; a light's answers back.
pub const LANE_ID: &str = "k_lane_id";
pub const SHADOW_KEEP: &str = "k_shadow_keep";
pub fn ray_word(i: u32) -> String {
    format!("k_ray_word{i}")
}
pub const SHADOW_SAVE: &str = "k_shadow_save";
pub const SHADOW_CLEAR: &str = "k_shadow_clear";
pub const SHADOW_LOAD: &str = "k_shadow_load";
pub const SHADOW_GO: &str = "k_shadow_go";
pub const SHADOW_SEEN: &str = "k_shadow_seen";
pub const SHADOW_LIT: &str = "k_shadow_lit";

/// The pixel's output words: red, green, blue, the eye ray's object.
pub fn out(i: u32) -> &'static str {
    ["k_out_red", "k_out_green", "k_out_blue", "k_out_object"][i as usize]
}

/// Level `l`'s reflected rays, and back from them.
pub fn reflect(l: u32) -> String {
    format!("k_reflect{l}")
}
pub fn reflected(l: u32) -> String {
    format!("k_reflected{l}")
}
/// Level `l`'s refracted rays: prepared before its reflection, traced
/// after it, and back from them.
pub fn refract_prepare(l: u32) -> String {
    format!("k_refract_prepare{l}")
}
pub fn refract(l: u32) -> String {
    format!("k_refract{l}")
}
pub fn refracted(l: u32) -> String {
    format!("k_refracted{l}")
}

/// F = the ray goes down along `axis`.
pub fn sign(axis: u8) -> String {
    format!("k_sign_{}", AXES[axis as usize])
}

/// The paper's traversal: a segment against a split plane, and above it.
pub fn classify(axis: u8) -> String {
    format!("k_classify_{}", AXES[axis as usize])
}
pub const CLASSIFY_ABOVE: &str = "k_classify_above";
/// After a leaf: the rays with their hit in the cell (closest hit; the
/// streamed traversal's outside unordered subtrees) or with any hit sleep.
pub const LEAF_CLOSEST: &str = "k_leaf_closest";
pub const LEAF_CLOSEST_ORDERED: &str = "k_leaf_closest_ordered";
pub const LEAF_ANY: &str = "k_leaf_any";
/// The streamed traversal's count of unordered subtrees entered against
/// the ray's direction.
pub const UNORDERED_NONE: &str = "k_unordered_none";
pub fn unordered_enter(axis: u8) -> String {
    format!("k_unordered_enter_{}", AXES[axis as usize])
}
pub fn unordered_leave(axis: u8) -> String {
    format!("k_unordered_leave_{}", AXES[axis as usize])
}

/// The packet traversal: a pass's start, an inner node (the child below or
/// above the plane first), the second child's fates, a pop, the any-hit
/// leaf.
pub const PASS_START: &str = "k_pass_start";
pub fn node(axis: u8, first_above: bool) -> String {
    format!(
        "k_node_{}_{}",
        AXES[axis as usize],
        if first_above {
            "above_first"
        } else {
            "below_first"
        }
    )
}
pub const SECOND_TOO: &str = "k_second_too";
pub const FIRST_OR_SLEEP: &str = "k_first_or_sleep";
pub const TAKE_SECOND: &str = "k_take_second";
pub const PUSH_SECOND: &str = "k_push_second";
pub const POP_NODE: &str = "k_pop_node";
pub const DONE_WITH_HIT: &str = "k_done_with_hit";
