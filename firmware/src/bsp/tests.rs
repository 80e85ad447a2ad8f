//! The BSP builder's trees: a median split worked by hand, the depth and leaf limits, the
//! same tree on any thread count, SAH isolating a cluster, the chip-cost split's plane the
//! cheapest and its leaves within an FB bank.

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
