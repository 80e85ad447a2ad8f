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
//!
//! Nodes are numbered in depth-first pre-order, root 0, so the leaves are
//! in left-to-right order and the objects under any node are those of a
//! contiguous run of leaves (the compact layout of `scene_image` uses it).

use crate::scene::Aabb;

/// How a node's splitting plane is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SplitRule {
    /// Spatial median, axes cycling with depth (the paper's).
    Median,
    /// Surface area heuristic.
    Sah,
    /// Chosen by the user of the tree (the ray tracer: the paper's median
    /// for the paper's traversal; for the packet traversal the cheaper of
    /// median and SAH trees by its cost model). Built as `Median`.
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
}

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
        let all: Vec<u32> = (0..object_bounds.len() as u32).collect();
        let mut params = params;
        if params.max_depth == 0 {
            params.max_depth = 15;
        }
        let ctx = Ctx {
            ob: object_bounds,
            p: &params,
            meets,
        };
        let nodes = build(&ctx, bounds, all, 0, 0);
        Bsp { nodes, params }
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
        .clamp(15.0, crate::scene_image::MAX_BSP_DEPTH as f64) as u32
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
    if objects.len() <= p.max_leaf || depth >= p.max_depth || futile >= FUTILE_SPLITS {
        return leaf(objects);
    }
    let choice = match p.rule {
        SplitRule::Median | SplitRule::Auto => {
            let axis = (depth % 3) as usize;
            Some((axis, bounds.center().axis(axis)))
        }
        SplitRule::Sah => sah_split(ob, &objects, bounds),
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
        let mut x = 7u64;
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64 * 18.0 - 9.0
        };
        let ob: Vec<Aabb> = (0..700)
            .map(|_| cube([next(), next(), next()], 0.05 + next().abs() / 40.0))
            .collect();
        let world = cube([0.0, 0.0, 0.0], 10.0);
        for rule in [SplitRule::Median, SplitRule::Sah] {
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
}
