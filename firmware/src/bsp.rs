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
mod tests {
    use super::*;
    use crate::scene::Vec3;

    fn cube(c: [f64; 3], r: f64) -> Aabb {
        let c = Vec3::from(c);
        Aabb {
            min: c - Vec3::ONE * r,
            max: c + Vec3::ONE * r,
        }
    }

    /// A uniform random number in [0, 1) per call, from `seed` (an LCG).
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut x = seed;
        move || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn median_split_by_hand() {
        // Eight small cubes, one in each octant of [-4, 4]^3, and one
        // straddling the x = 0 plane. max_leaf 1: x splits at 0, y at 0,
        // z at 0; the straddler follows both sides of x.
        let mut ob = Vec::new();
        for &x in &[-2.0, 2.0] {
            for &y in &[-2.0, 2.0] {
                for &z in &[-2.0, 2.0] {
                    ob.push(cube([x, y, z], 0.5));
                }
            }
        }
        ob.push(cube([0.0, -2.0, -2.0], 0.5));
        let world = cube([0.0, 0.0, 0.0], 4.0);
        let t = Bsp::build(
            &ob,
            world,
            BspParams {
                max_leaf: 1,
                ..BspParams::default()
            },
        );
        let root = &t.nodes[0];
        let s = root.split.unwrap();
        assert_eq!((s.axis, s.position), (0, 0.0));
        assert_eq!(root.objects.len(), 9);
        assert_eq!(t.nodes[s.children[0] as usize].objects, vec![0, 1, 2, 3, 8]);
        assert_eq!(t.nodes[s.children[1] as usize].objects, vec![4, 5, 6, 7, 8]);
        let left = t.nodes[s.children[0] as usize].split.unwrap();
        assert_eq!((left.axis, left.position), (1, 0.0));
        // The leaf at (-2, 2, 2) holds only its own cube, after the x, y
        // and z splits.
        let leaf = t.leaf_at([-2.0, 2.0, 2.0]);
        assert_eq!(t.nodes[leaf as usize].objects, vec![3]);
        assert_eq!(t.nodes[leaf as usize].depth, 3);
        // Pre-order: a node's children come after it.
        for (i, n) in t.nodes.iter().enumerate() {
            if let Some(s) = n.split {
                assert!(s.children[0] as usize == i + 1 && s.children[1] as usize > i);
            }
        }
        let st = t.stats();
        assert!(st.max_depth <= 15);
    }

    #[test]
    fn depth_and_leaf_limits() {
        // 100 identical objects can never be separated: stops at max_depth.
        let ob = vec![cube([0.1, 0.1, 0.1], 0.01); 100];
        let t = Bsp::build(
            &ob,
            cube([0.0, 0.0, 0.0], 1.0),
            BspParams {
                max_depth: 4,
                ..BspParams::default()
            },
        );
        assert_eq!(t.stats().max_depth, 4);
        // 5 objects: the root is already a leaf.
        let t = Bsp::build(&ob[..5], cube([0.0, 0.0, 0.0], 1.0), BspParams::default());
        assert_eq!(t.nodes.len(), 1);
    }

    /// A tree big enough to be built on several threads is the same on 1
    /// and 4, numbered in pre-order, and keeps every object under the
    /// root in the leaves its box meets.
    #[test]
    fn the_same_tree_on_any_number_of_threads() {
        let mut u = uniform(7);
        let mut next = || u() * 18.0 - 9.0;
        let ob: Vec<Aabb> = (0..700)
            .map(|_| cube([next(), next(), next()], 0.05 + next().abs() / 40.0))
            .collect();
        let world = cube([0.0, 0.0, 0.0], 10.0);
        for rule in [SplitRule::Median, SplitRule::Sah, SplitRule::Chip] {
            let params = BspParams {
                rule,
                max_depth: 20,
                ..BspParams::default()
            };
            let on = |threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| Bsp::build(&ob, world, params))
            };
            let (one, four) = (on(1), on(4));
            assert!(one.nodes.len() > 100, "{rule:?}: {} nodes", one.nodes.len());
            assert!(one.nodes == four.nodes, "{rule:?}: the trees differ");
            for (i, n) in one.nodes.iter().enumerate() {
                if let Some(s) = n.split {
                    assert_eq!(s.children[0] as usize, i + 1);
                    assert!(s.children[1] as usize > i + 1);
                    assert_eq!(one.nodes[s.children[0] as usize].depth, n.depth + 1);
                    assert_eq!(one.nodes[s.children[1] as usize].depth, n.depth + 1);
                }
            }
            // Each object is in the leaf holding its box's centre.
            for (k, b) in ob.iter().enumerate() {
                let leaf = one.leaf_at(b.center().to_array());
                assert!(
                    one.nodes[leaf as usize].objects.contains(&(k as u32)),
                    "object {k}"
                );
            }
        }
    }

    #[test]
    fn sah_isolates_a_cluster() {
        // 49 tiny objects on a 7x7 grid in the plane x = 9 and one at
        // x = -9: SAH cuts off the empty middle, not the middle of the box.
        let mut ob: Vec<Aabb> = (0..49)
            .map(|i| {
                cube(
                    [9.0, (i % 7) as f64 * 3.0 - 9.0, (i / 7) as f64 * 3.0 - 9.0],
                    0.001,
                )
            })
            .collect();
        ob.push(cube([-9.0, 0.0, 0.0], 0.001));
        let t = Bsp::build(
            &ob,
            cube([0.0, 0.0, 0.0], 10.0),
            BspParams {
                rule: SplitRule::Sah,
                ..BspParams::default()
            },
        );
        let s = t.nodes[0].split.unwrap();
        assert_eq!(s.axis, 0);
        assert!(s.position > 5.0, "{}", s.position);
    }

    /// The chip rule's plane is the cheapest by its cost, computed here
    /// object by object at every candidate (an O(n^2) count, not the
    /// builder's sorted prefix sums), on random boxes of random costs.
    #[test]
    fn chip_split_is_the_cheapest_plane() {
        let mut next = uniform(11);
        for _ in 0..40 {
            let n = 2 + (next() * 60.0) as usize;
            let ob: Vec<Aabb> = (0..n)
                .map(|_| {
                    let c = [
                        next() * 16.0 - 8.0,
                        next() * 16.0 - 8.0,
                        next() * 16.0 - 8.0,
                    ];
                    cube(c, 0.05 + next() * 2.0)
                })
                .collect();
            let costs = ChipCosts {
                node: 10.0 + next() * 100.0,
                leaf: next() * 50.0,
                object: (0..n).map(|_| 20.0 + next() * 200.0).collect(),
                words: vec![1; n],
                leaf_words: 0,
            };
            let bounds = cube([0.0, 0.0, 0.0], 8.0);
            let objects: Vec<u32> = (0..n as u32).collect();
            let area = bounds.surface_area();
            let cost_at = |axis: usize, pos: f64| {
                let (mut below, mut above) = (costs.leaf, costs.leaf);
                for (i, b) in ob.iter().enumerate() {
                    if b.min.axis(axis).max(-8.0) <= pos {
                        below += costs.object[i];
                    }
                    if b.max.axis(axis).min(8.0) >= pos {
                        above += costs.object[i];
                    }
                }
                costs.node
                    + (child_box(bounds, axis, pos, false).surface_area() * below
                        + child_box(bounds, axis, pos, true).surface_area() * above)
                        / area
            };
            let mut best = f64::INFINITY;
            for axis in 0..3 {
                for b in &ob {
                    for pos in [b.min.axis(axis), b.max.axis(axis)] {
                        if pos > -8.0 && pos < 8.0 {
                            best = best.min(cost_at(axis, pos));
                        }
                    }
                }
            }
            let leaf = costs.leaf + costs.object.iter().sum::<f64>();
            match chip_split(&ob, &objects, bounds, &costs) {
                Some((axis, pos)) => {
                    let got = cost_at(axis, pos);
                    assert!((got - best).abs() <= 1e-9 * best, "{got} against {best}");
                    assert!(got < leaf, "split at {got}, the leaf costs {leaf}");
                }
                None => assert!(best >= leaf, "a leaf, but a plane costs {best} < {leaf}"),
            }
        }
    }

    /// Objects the cost would keep in one leaf (the node costs more than
    /// any split saves) are split until each leaf's records fit the bank.
    #[test]
    fn chip_leaves_fit_the_bank() {
        let ob: Vec<Aabb> = (0..64)
            .map(|i| {
                cube(
                    [
                        (i % 4) as f64 * 4.0 - 6.0,
                        (i / 4 % 4) as f64 * 4.0 - 6.0,
                        (i / 16) as f64 * 4.0 - 6.0,
                    ],
                    0.5,
                )
            })
            .collect();
        let world = cube([0.0, 0.0, 0.0], 8.0);
        let costs = |leaf_words| ChipCosts {
            node: 1e9,
            leaf: 0.0,
            object: vec![1.0; 64],
            words: vec![10; 64],
            leaf_words,
        };
        let params = BspParams {
            rule: SplitRule::Chip,
            max_leaf: 1,
            max_depth: 20,
            snap: 0.0,
        };
        let one = Bsp::build_costed(&ob, world, params, &|_, _| true, Some(&costs(0)));
        assert_eq!(one.nodes.len(), 1, "the node's cost keeps one leaf");
        let fit = Bsp::build_costed(&ob, world, params, &|_, _| true, Some(&costs(100)));
        for n in fit.nodes.iter().filter(|n| n.split.is_none()) {
            assert!(
                n.objects.len() * 10 <= 100,
                "a leaf of {} objects",
                n.objects.len()
            );
        }
        assert!(fit.stats().leaves >= 7);
    }
}
