//! The BSP tree of the paper (Sung and Shirley's BSP as used by Du et al.):
//! an axis-aligned binary space partition of the scene's bounding box.
//!
//! Every node keeps the list of all objects under it (an object whose
//! bounding box straddles a plane goes to both sides), because the chip's
//! traversal tests every object under a node when its 64 rays disagree
//! (ray incoherence, paper Fig. 4). Two split rules:
//! - [`SplitRule::Median`], the paper's: the spatial median of the node's
//!   box, the axis cycling x, y, z with depth; a node becomes a leaf when it
//!   holds at most `max_leaf` objects or is at `max_depth`, or after three
//!   splits in a row (one per axis) that separated nothing.
//!
//! An object goes to every child cell it may meet: its bounding box and,
//! with [`Bsp::build_with`], a finer conservative test (the scene compiler
//! uses [`crate::scene::Shape::may_overlap`]: a triangle goes only to the
//! cells it meets).
//! - [`SplitRule::Sah`]: the surface area heuristic (pbrt's kd-tree costs:
//!   traversal 1, intersection 80, empty bonus 0.5) over 32 candidate planes
//!   per axis; a node also becomes a leaf when no split is cheaper.
//! - [`SplitRule::Chip`]: the surface area heuristic with the chip's own
//!   costs ([`ChipCosts`]: the array cycles of a node visit, of a leaf's
//!   overhead and of each object's test and record move), over the
//!   objects' own bounds as candidate planes (up to [`CHIP_CANDIDATES`]
//!   per axis), with no empty bonus; a leaf also must fit the FB bank its
//!   block is moved into ([`ChipCosts::leaf_words`]).
//!
//! Nodes are numbered in depth-first pre-order, root 0, so the leaves are
//! in left-to-right order and the objects under any node are those of a
//! contiguous run of leaves (the compact layout of `scene_image` uses it).

use crate::scene::Aabb;

/// Deepest BSP the compiler builds (the packet traversal keeps one
/// interval slot per level in every RC's RAM).
pub const MAX_BSP_DEPTH: u32 = 32;

/// How a node's splitting plane is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SplitRule {
    /// Spatial median, axes cycling with depth (the paper's).
    Median,
    /// Surface area heuristic (pbrt's costs).
    Sah,
    /// Surface area heuristic with the chip's costs ([`ChipCosts`]).
    Chip,
    /// Chosen by the user of the tree (the ray tracer: the paper's median
    /// for the paper's traversal; for the packet traversal the fastest of
    /// its candidate trees on a probe of the frame). Built as `Median`.
    Auto,
}

/// Build parameters.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct BspParams {
    /// Deepest level; the root is level 0. The paper: 15. 0: chosen by
    /// the user of the tree (the ray tracer: [`auto_depth`] for the packet
    /// traversal, 15 for the paper's); built as 15.
    pub max_depth: u32,
    /// A node with this many objects or fewer is a leaf. The paper: 5.
    pub max_leaf: usize,
    pub rule: SplitRule,
    /// If non-zero, split planes are rounded to multiples of this (the LSB
    /// of the scene's fixed-point format), so the chip's planes are exact.
    pub snap: f64,
}

impl Default for BspParams {
    fn default() -> Self {
        BspParams {
            max_depth: 15,
            max_leaf: 5,
            rule: SplitRule::Median,
            snap: 0.0,
        }
    }
}

/// The costs [`SplitRule::Chip`] weighs, in array cycles of a packet (the
/// ray tracer derives them from its kernels' lengths and its TinyRISC
/// loops' cycle constants: `tracer::layout::packet_nodes::chip_costs`).
#[derive(Clone, Debug, PartialEq)]
pub struct ChipCosts {
    /// An inner node's visit: its kernel and TinyRISC's decision.
    pub node: f64,
    /// A leaf's visit besides its objects: TinyRISC's leaf loop and the
    /// DMA's set-up.
    pub leaf: f64,
    /// Per object: its test (kernels and TinyRISC's loop around them) and
    /// moving its record into the FB.
    pub object: Vec<f64>,
    /// Per object: FB words of its record.
    pub words: Vec<usize>,
    /// The most record words a leaf may hold (its block fills at most one
    /// FB bank; 0: no limit). A node over it is split even where the cost
    /// says otherwise, down to `max_depth`.
    pub leaf_words: usize,
}

impl ChipCosts {
    /// Costs for `objects` objects alike: pbrt's proportions (a node 1, an
    /// object 80), no leaf overhead, no size limit.
    pub fn uniform(objects: usize) -> ChipCosts {
        ChipCosts {
            node: 1.0,
            leaf: 0.0,
            object: vec![80.0; objects],
            words: vec![1; objects],
            leaf_words: 0,
        }
    }
}

/// Candidate planes per axis of [`SplitRule::Chip`] at a node: every
/// object's bounds where the node holds few enough, else this many spread
/// evenly over them.
pub const CHIP_CANDIDATES: usize = 256;

/// One node.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub bounds: Aabb,
    pub depth: u32,
    /// All objects under this node, ascending.
    pub objects: Vec<u32>,
    /// `None` for a leaf.
    pub split: Option<Split>,
}

/// An inner node's plane and children.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Split {
    pub axis: u8,
    pub position: f64,
    /// Children below (`[0]`) and above (`[1]`) the plane.
    pub children: [u32; 2],
}

/// The whole tree; `nodes[0]` is the root.
#[derive(Clone, Debug)]
pub struct Bsp {
    pub nodes: Vec<Node>,
    pub params: BspParams,
    /// The tree would have more than [`NODE_BUDGET`] nodes: its building
    /// stopped there (every node after the budget a leaf), so `nodes` is
    /// not the tree `params` asked for, only enough to say it is too large.
    pub over_budget: bool,
}

/// The most nodes a tree is built to (node indices are 16-bit in the
/// scene image): beyond it, a deep median tree of overlapping objects
/// (SPD shells at `--max-depth 30`) would take more host memory than
/// there is before the image could refuse it.
pub const NODE_BUDGET: usize = 1 << 16;

/// Summary figures of a tree.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct BspStats {
    pub nodes: usize,
    pub leaves: usize,
    pub empty_leaves: usize,
    pub max_depth: u32,
    pub max_leaf_objects: usize,
    /// Object references summed over leaves.
    pub leaf_references: usize,
}

impl Bsp {
    /// Build over objects with these bounding boxes, inside `bounds`.
    pub fn build(object_bounds: &[Aabb], bounds: Aabb, params: BspParams) -> Bsp {
        Bsp::build_with(object_bounds, bounds, params, &|_, _| true)
    }

    /// Build with a finer test of which cells an object meets: object `i`
    /// goes to a child when its bounding box meets the child's box and
    /// `meets(i, box)` (which must be conservative: false only when the
    /// object and the box are apart).
    pub fn build_with(
        object_bounds: &[Aabb],
        bounds: Aabb,
        params: BspParams,
        meets: &(dyn Fn(u32, &Aabb) -> bool + Sync),
    ) -> Bsp {
        Bsp::build_costed(object_bounds, bounds, params, meets, None)
    }

    /// [`Bsp::build_with`], with the costs [`SplitRule::Chip`] weighs
    /// (`None`: [`ChipCosts::uniform`]; other rules ignore them).
    pub fn build_costed(
        object_bounds: &[Aabb],
        bounds: Aabb,
        params: BspParams,
        meets: &(dyn Fn(u32, &Aabb) -> bool + Sync),
        costs: Option<&ChipCosts>,
    ) -> Bsp {
        let all: Vec<u32> = (0..object_bounds.len() as u32).collect();
        let mut params = params;
        if params.max_depth == 0 {
            params.max_depth = 15;
        }
        let uniform;
        let costs = match costs {
            Some(c) => c,
            None => {
                uniform = ChipCosts::uniform(object_bounds.len());
                &uniform
            }
        };
        let ctx = Ctx {
            ob: object_bounds,
            p: &params,
            meets,
            costs,
            made: std::sync::atomic::AtomicUsize::new(0),
        };
        let nodes = build(&ctx, bounds, all, 0, 0);
        // Deterministic on any number of threads: the tree is built as
        // asked until the budget is reached, which it is exactly when the
        // whole tree has more nodes.
        let over_budget = ctx.made.into_inner() > NODE_BUDGET;
        Bsp {
            nodes,
            params,
            over_budget,
        }
    }

    pub fn stats(&self) -> BspStats {
        let mut s = BspStats {
            nodes: self.nodes.len(),
            ..BspStats::default()
        };
        for n in &self.nodes {
            s.max_depth = s.max_depth.max(n.depth);
            if n.split.is_none() {
                s.leaves += 1;
                s.empty_leaves += n.objects.is_empty() as usize;
                s.max_leaf_objects = s.max_leaf_objects.max(n.objects.len());
                s.leaf_references += n.objects.len();
            }
        }
        s
    }

    /// The leaf containing point `p` (ties go above the plane).
    pub fn leaf_at(&self, p: [f64; 3]) -> u32 {
        let mut i = 0u32;
        while let Some(s) = self.nodes[i as usize].split {
            i = s.children[(p[s.axis as usize] >= s.position) as usize];
        }
        i
    }
}

/// A depth limit that grows with the scene, `8 + 1.3 log2(objects)` (pbrt's
/// rule for kd-trees), between 15 and 32.
pub fn auto_depth(objects: usize) -> u32 {
    (8.0 + 1.3 * (objects.max(1) as f64).log2())
        .round()
        .clamp(15.0, MAX_BSP_DEPTH as f64) as u32
}

fn child_box(b: Aabb, axis: usize, pos: f64, above: bool) -> Aabb {
    let mut c = b;
    let set = |v: &mut crate::scene::Vec3| match axis {
        0 => v.x = pos,
        1 => v.y = pos,
        _ => v.z = pos,
    };
    if above {
        set(&mut c.min)
    } else {
        set(&mut c.max)
    }
    c
}

struct Ctx<'a> {
    ob: &'a [Aabb],
    p: &'a BspParams,
    meets: &'a (dyn Fn(u32, &Aabb) -> bool + Sync),
    costs: &'a ChipCosts,
    /// Nodes made so far, against [`NODE_BUDGET`].
    made: std::sync::atomic::AtomicUsize,
}

/// Nodes of at least this many objects sort them into their children on
/// several threads, and build the two subtrees side by side (the tree is
/// the same on any number of threads).
const PARALLEL_OBJECTS: usize = 128;

/// Splits in a row that separated nothing (both children kept every
/// object) after which a node becomes a leaf: one per axis, so a cell
/// where more than `max_leaf` objects meet at a point or an edge is not
/// split down to `max_depth` for nothing.
const FUTILE_SPLITS: u32 = 3;

/// The subtree of the node of box `bounds` holding `objects`, in
/// depth-first pre-order (its root first, children numbered within it).
fn build(cx: &Ctx, bounds: Aabb, objects: Vec<u32>, depth: u32, futile: u32) -> Vec<Node> {
    use rayon::prelude::*;
    let (ob, p) = (cx.ob, cx.p);
    let leaf = |objects| {
        vec![Node {
            bounds,
            depth,
            objects,
            split: None,
        }]
    };
    let made = cx.made.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    if objects.len() <= p.max_leaf
        || depth >= p.max_depth
        || futile >= FUTILE_SPLITS
        || made >= NODE_BUDGET
    {
        return leaf(objects);
    }
    let choice = match p.rule {
        SplitRule::Median | SplitRule::Auto => {
            let axis = (depth % 3) as usize;
            Some((axis, bounds.center().axis(axis)))
        }
        SplitRule::Sah => sah_split(ob, &objects, bounds),
        SplitRule::Chip => chip_split(ob, &objects, bounds, cx.costs),
    };
    let Some((axis, mut pos)) = choice else {
        return leaf(objects);
    };
    if p.snap > 0.0 {
        pos = (pos / p.snap).round() * p.snap;
    }
    let (lo, hi) = (bounds.min.axis(axis), bounds.max.axis(axis));
    if !(pos > lo && pos < hi) {
        return leaf(objects); // the box is too thin to split (at the snapped precision)
    }
    let (bl, bh) = (
        child_box(bounds, axis, pos, false),
        child_box(bounds, axis, pos, true),
    );
    let is_below = |&i: &u32| ob[i as usize].min.axis(axis) <= pos && (cx.meets)(i, &bl);
    let is_above = |&i: &u32| ob[i as usize].max.axis(axis) >= pos && (cx.meets)(i, &bh);
    let n = objects.len();
    let parallel = n >= PARALLEL_OBJECTS;
    let (below, above): (Vec<u32>, Vec<u32>) = if parallel {
        rayon::join(
            || objects.par_iter().copied().filter(is_below).collect(),
            || objects.par_iter().copied().filter(is_above).collect(),
        )
    } else {
        (
            objects.iter().copied().filter(is_below).collect(),
            objects.iter().copied().filter(is_above).collect(),
        )
    };
    let futile = if below.len() == n && above.len() == n {
        futile + 1
    } else {
        0
    };
    let (l, r) = if parallel {
        rayon::join(
            || build(cx, bl, below, depth + 1, futile),
            || build(cx, bh, above, depth + 1, futile),
        )
    } else {
        (
            build(cx, bl, below, depth + 1, futile),
            build(cx, bh, above, depth + 1, futile),
        )
    };
    // Below's subtree right after this node, above's after it.
    let r_at = 1 + l.len() as u32;
    let mut nodes = Vec::with_capacity(1 + l.len() + r.len());
    nodes.push(Node {
        bounds,
        depth,
        objects,
        split: Some(Split {
            axis: axis as u8,
            position: pos,
            children: [1, r_at],
        }),
    });
    for (sub, at) in [(l, 1), (r, r_at)] {
        nodes.extend(sub.into_iter().map(|mut node| {
            if let Some(s) = &mut node.split {
                s.children = s.children.map(|c| c + at);
            }
            node
        }));
    }
    nodes
}

/// The cheapest SAH plane, or None when a leaf is cheaper.
fn sah_split(ob: &[Aabb], objects: &[u32], bounds: Aabb) -> Option<(usize, f64)> {
    const TRAVERSE: f64 = 1.0;
    const INTERSECT: f64 = 80.0;
    const EMPTY_BONUS: f64 = 0.5;
    const BINS: usize = 32;
    let n = objects.len();
    let area = bounds.surface_area();
    let leaf_cost = INTERSECT * n as f64;
    if area <= 0.0 {
        return None;
    }
    let mut best: Option<(f64, usize, f64)> = None;
    for axis in 0..3 {
        let (lo, hi) = (bounds.min.axis(axis), bounds.max.axis(axis));
        if hi <= lo {
            continue;
        }
        let mut mins: Vec<f64> = objects
            .iter()
            .map(|&i| ob[i as usize].min.axis(axis))
            .collect();
        let mut maxs: Vec<f64> = objects
            .iter()
            .map(|&i| ob[i as usize].max.axis(axis))
            .collect();
        mins.sort_by(f64::total_cmp);
        maxs.sort_by(f64::total_cmp);
        for b in 1..BINS {
            let pos = lo + (hi - lo) * b as f64 / BINS as f64;
            let n_below = mins.partition_point(|&m| m <= pos);
            let n_above = n - maxs.partition_point(|&m| m < pos);
            let (a_below, a_above) = (
                child_box(bounds, axis, pos, false).surface_area(),
                child_box(bounds, axis, pos, true).surface_area(),
            );
            let bonus = if n_below == 0 || n_above == 0 {
                EMPTY_BONUS
            } else {
                0.0
            };
            let cost = TRAVERSE
                + (1.0 - bonus) * INTERSECT * (a_below * n_below as f64 + a_above * n_above as f64)
                    / area;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, pos));
            }
        }
    }
    match best {
        Some((cost, axis, pos)) if cost < leaf_cost => Some((axis, pos)),
        _ => None,
    }
}

/// The cheapest plane by the chip's costs ([`SplitRule::Chip`]), or None
/// when a leaf is cheaper (and fits the bank). A packet reaching the node
/// pays `node`, then each child's leaf cost (`leaf` and its objects') with
/// the probability that a ray through the node's cell meets the child's
/// cell, their surface areas' ratio. The candidates are the objects'
/// bounds clipped to the cell (where an object's extent starts or ends:
/// the only places the counts change), at most [`CHIP_CANDIDATES`] per
/// axis.
fn chip_split(ob: &[Aabb], objects: &[u32], bounds: Aabb, c: &ChipCosts) -> Option<(usize, f64)> {
    let area = bounds.surface_area();
    if area <= 0.0 {
        return None;
    }
    let cost_of = |i: u32| c.object[i as usize];
    let all: f64 = objects.iter().map(|&i| cost_of(i)).sum();
    let words: usize = objects.iter().map(|&i| c.words[i as usize]).sum();
    let must_split = c.leaf_words > 0 && words > c.leaf_words;
    let leaf_cost = c.leaf + all;
    let mut best: Option<(f64, usize, f64)> = None;
    for axis in 0..3 {
        let (lo, hi) = (bounds.min.axis(axis), bounds.max.axis(axis));
        if hi <= lo {
            continue;
        }
        // (position, cost) of the objects' starts and ends in the cell,
        // sorted; prefix sums of their costs.
        let sorted = |end: bool| -> (Vec<f64>, Vec<f64>) {
            let mut v: Vec<(f64, f64)> = objects
                .iter()
                .map(|&i| {
                    let b = &ob[i as usize];
                    let x = if end {
                        b.max.axis(axis)
                    } else {
                        b.min.axis(axis)
                    };
                    (x.clamp(lo, hi), cost_of(i))
                })
                .collect();
            v.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut sum = 0.0;
            let mut prefix = Vec::with_capacity(v.len() + 1);
            prefix.push(0.0);
            for &(_, w) in &v {
                sum += w;
                prefix.push(sum);
            }
            (v.into_iter().map(|(x, _)| x).collect(), prefix)
        };
        let (mins, min_sum) = sorted(false);
        let (maxs, max_sum) = sorted(true);
        let mut cands: Vec<f64> = mins
            .iter()
            .chain(maxs.iter())
            .copied()
            .filter(|&x| x > lo && x < hi)
            .collect();
        cands.sort_by(f64::total_cmp);
        cands.dedup();
        if cands.len() > CHIP_CANDIDATES {
            let n = cands.len();
            cands = (0..CHIP_CANDIDATES)
                .map(|k| cands[(2 * k + 1) * n / (2 * CHIP_CANDIDATES)])
                .collect();
        }
        for pos in cands {
            // Below: the objects starting at or before the plane; above:
            // those ending at or after it.
            let below = min_sum[mins.partition_point(|&m| m <= pos)];
            let above = all - max_sum[maxs.partition_point(|&m| m < pos)];
            let (a_below, a_above) = (
                child_box(bounds, axis, pos, false).surface_area(),
                child_box(bounds, axis, pos, true).surface_area(),
            );
            let cost = c.node + (a_below * (c.leaf + below) + a_above * (c.leaf + above)) / area;
            if best.is_none_or(|(b, _, _)| cost < b) {
                best = Some((cost, axis, pos));
            }
        }
    }
    match best {
        Some((cost, axis, pos)) if cost < leaf_cost || must_split => Some((axis, pos)),
        _ => None,
    }
}

#[cfg(test)]
mod tests;
