//! `morphosys regroup`: what regrouping rays into other packets could buy,
//! estimated on the host before any firmware is written.
//!
//! The f64 reference traces a SIZE x SIZE frame (default 128) to depth 2:
//! eye rays, their shadow rays, the mirror rays and their shadow rays. A
//! packet's cost is estimated as the packet traversal's object tests: the
//! objects of every leaf of a pbrt SAH tree that some ray of the packet
//! reaches before its hit (shadow rays: before their first occluder), each
//! broadcast once to the packet. Per kind of ray it prints that cost with
//! the chip's packets (an 8x8 tile, one packet per light), relative to it
//! with those packets split into their four 4x4 quadrants traced in turn,
//! and with the rays regrouped: every light's rays of a tile together, of
//! 4 tiles, of the frame, sorted by origin (Morton order in the scene's
//! box) or by origin then direction, in packets of 64, and, as a bound no
//! firmware reaches, the frame's rays sorted by the leaves they reach.
//! Under each grouping it prints the simd efficiency the chip would count:
//! the tests the rays need over the tests broadcast times their packet's
//! rays.
use crate::reference::{eye_ray, shapes::Ray, Tracer};
use anyhow::{anyhow, Result};
use firmware::bsp::{auto_depth, Bsp, BspParams, SplitRule};
use firmware::scene::{Aabb, Scene, Vec3};
use std::collections::{BTreeMap, HashSet};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct RegroupArgs {
    /// Scene file (.nff or .toml); default scenes/default.toml
    pub scene: Option<PathBuf>,
    /// Image side in pixels: a multiple of 8, 8..=1024 (square)
    #[arg(long, value_name = "N", default_value = "128", value_parser = parse_side)]
    pub size: u32,
}

fn parse_side(s: &str) -> std::result::Result<u32, String> {
    s.parse::<u32>()
        .ok()
        .filter(|n| (8..=1024).contains(n) && n % 8 == 0)
        .ok_or_else(|| format!("'{s}': expected a multiple of 8, 8..=1024"))
}

/// A ray of the frame: its pixel, which of the pixel's rays of its kind it
/// is (the light, for shadow rays), and the segment it traces.
struct Seg {
    pixel: (u32, u32),
    light: usize,
    o: Vec3,
    d: Vec3,
    tmax: f64,
}

/// The leaves a segment reaches, front to back.
fn leaves(bsp: &Bsp, s: &Seg, out: &mut Vec<u32>) {
    let b = bsp.nodes[0].bounds;
    let o = [s.o.x, s.o.y, s.o.z];
    let d = [s.d.x, s.d.y, s.d.z];
    let (lo, hi) = ([b.min.x, b.min.y, b.min.z], [b.max.x, b.max.y, b.max.z]);
    let (mut t0, mut t1) = (0.0f64, s.tmax);
    for a in 0..3 {
        let (n, f) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
        t0 = t0.max(n.min(f));
        t1 = t1.min(n.max(f));
    }
    if t0 > t1 {
        return;
    }
    let mut stack = vec![(0u32, t0, t1)];
    while let Some((i, t0, t1)) = stack.pop() {
        let Some(sp) = bsp.nodes[i as usize].split else {
            out.push(i);
            continue;
        };
        let a = sp.axis as usize;
        let t = (sp.position - o[a]) / d[a];
        let below = o[a] < sp.position || (o[a] == sp.position && d[a] <= 0.0);
        let (near, far) = if below {
            (sp.children[0], sp.children[1])
        } else {
            (sp.children[1], sp.children[0])
        };
        if t > t1 || t <= 0.0 {
            stack.push((near, t0, t1));
        } else if t < t0 {
            stack.push((far, t0, t1));
        } else {
            stack.push((far, t, t1));
            stack.push((near, t0, t));
        }
    }
}

/// The ray-object tests the rays need: the objects of every leaf each
/// ray reaches (`reach[ray]`), summed over the rays.
fn needed_tests(reach: &[Vec<u32>], objects: impl Fn(u32) -> usize) -> usize {
    reach.iter().flatten().map(|&l| objects(l)).sum()
}

/// What a grouping of the rays into packets (`packets[p]`: indices into
/// `reach`) broadcasts: the object tests (each packet's union of leaves'
/// objects, once per packet) and those times the rays of their packet,
/// the lanes offered as `simd_efficiency` counts them on the chip.
fn broadcast(
    packets: &[Vec<usize>],
    reach: &[Vec<u32>],
    objects: impl Fn(u32) -> usize,
) -> (usize, usize) {
    packets.iter().fold((0, 0), |(tests, lanes), p| {
        let u: HashSet<u32> = p.iter().flat_map(|&k| reach[k].iter().copied()).collect();
        let n: usize = u.into_iter().map(&objects).sum();
        (tests + n, lanes + n * p.len())
    })
}

/// The groupings `regroup` prices: the chip's tiles, their quadrants, a
/// tile merged, 4 tiles, the frame, the frame by origin and direction, the
/// frame by leaves.
const GROUPINGS: usize = 7;

/// A kind of rays' two rows: the rays, the chip's packets' tests and the
/// other groupings' relative to them; then each grouping's simd
/// efficiency (`groupings[g]`: tests broadcast, lanes offered).
fn print_rows(name: &str, count: &str, groupings: &[(usize, usize)], needed: usize) {
    let share = |num: f64, den: usize, unit: &str, digits: usize| {
        if den == 0 {
            String::from("-")
        } else {
            format!("{:.*}{unit}", digits, num / den as f64)
        }
    };
    let base = groupings[0].0;
    let mut line = format!("{name:<22} {count:>7} {base:>11}");
    for &(tests, _) in &groupings[1..] {
        line += &format!(" {:>11}", share(tests as f64, base, "x", 2));
    }
    println!("{line}");
    let mut line = format!("{:<22} {:>7}", "  simd efficiency", "");
    for &(_, lanes) in groupings {
        line += &format!(" {:>11}", share(100.0 * needed as f64, lanes, "%", 1));
    }
    println!("{line}");
}

fn morton(x: u32, y: u32, z: u32, bits: u32) -> u64 {
    (0..bits).rev().fold(0u64, |m, b| {
        m << 3 | ((x >> b & 1) as u64) << 2 | ((y >> b & 1) as u64) << 1 | (z >> b & 1) as u64
    })
}

/// `morphosys regroup`.
/// The frame's ray segments at `size` x `size`, depth 2, by kind: the eye
/// rays, the shadow rays of their hits, the mirror rays, the shadow rays
/// of the mirror rays' hits; each to its first hit (or the light).
fn segments(scene: &Scene, tracer: &Tracer, size: u32, eps: f64) -> [Vec<Seg>; 4] {
    // The segment to the first occluder, or to the light.
    let shadow = |pixel, p: Vec3, n: Vec3, out: &mut Vec<Seg>| {
        for (light, l) in scene.lights.iter().enumerate() {
            let to = l.position - p;
            let (dist, d) = (to.length(), to.normalized());
            if n.dot(d) > 0.0 {
                let o = p + n * eps;
                let tmax = tracer
                    .closest(&Ray { o, d })
                    .map_or(dist, |h| h.1.t.min(dist));
                out.push(Seg {
                    pixel,
                    light,
                    o,
                    d,
                    tmax,
                });
            }
        }
    };
    let mut kinds: [Vec<Seg>; 4] = Default::default();
    for py in 0..size {
        for px in 0..size {
            let pixel = (px, py);
            let r = eye_ray(scene, size, size, px, py);
            let hit = tracer.closest(&r);
            let tmax = hit.map_or(f64::INFINITY, |h| h.1.t);
            kinds[0].push(Seg {
                pixel,
                light: 0,
                o: r.o,
                d: r.d,
                tmax,
            });
            let Some((id, h)) = hit else { continue };
            let p = r.at(h.t);
            let n = if h.front { h.ns } else { -h.ns };
            shadow(pixel, p, n, &mut kinds[1]);
            if scene.materials[scene.objects[id].material].ks > 0.0 {
                let d = (r.d - n * (2.0 * r.d.dot(n))).normalized();
                let m = Ray { o: p + n * eps, d };
                let hit = tracer.closest(&m);
                let tmax = hit.map_or(f64::INFINITY, |h| h.1.t);
                kinds[2].push(Seg {
                    pixel,
                    light: 0,
                    o: m.o,
                    d,
                    tmax,
                });
                if let Some((_, h)) = hit {
                    let n = if h.front { h.ns } else { -h.ns };
                    shadow(pixel, m.at(h.t), n, &mut kinds[3]);
                }
            }
        }
    }
    kinds
}

/// The object tests broadcast under each grouping of `segs` into packets
/// (and the tests the rays need), on the tree `bsp` of the scene's bounds
/// `sb`.
fn groupings(segs: &[Seg], bsp: &Bsp, sb: Aabb, size: u32) -> ([(usize, usize); GROUPINGS], usize) {
    let cell = |v: f64, lo: f64, hi: f64| {
        (((v - lo) / (hi - lo).max(1e-300)).clamp(0.0, 0.9999) * 1024.0) as u32
    };
    let dir = |v: f64| ((v * 0.5 + 0.5).clamp(0.0, 0.9999) * 32.0) as u32;
    let reach: Vec<Vec<u32>> = segs
        .iter()
        .map(|s| {
            let mut l = Vec::new();
            leaves(bsp, s, &mut l);
            l
        })
        .collect();
    let objects = |l: u32| bsp.nodes[l as usize].objects.len();
    let needed = needed_tests(&reach, objects);
    let cost = |packets: &[Vec<usize>]| broadcast(packets, &reach, objects);
    let tile = |s: &Seg| (s.pixel.1 / 8) * (size / 8) + s.pixel.0 / 8;
    let mut chip: BTreeMap<(u32, usize), Vec<usize>> = BTreeMap::new();
    for (k, s) in segs.iter().enumerate() {
        chip.entry((tile(s), s.light)).or_default().push(k);
    }
    let chip: Vec<Vec<usize>> = chip.into_values().collect();
    // Each of those packets split into its 4x4 quadrants, traced one
    // after another.
    let mut quads: BTreeMap<(u32, usize, u32), Vec<usize>> = BTreeMap::new();
    for (k, s) in segs.iter().enumerate() {
        let q = (s.pixel.1 % 8 / 4) * 2 + s.pixel.0 % 8 / 4;
        quads.entry((tile(s), s.light, q)).or_default().push(k);
    }
    let quads: Vec<Vec<usize>> = quads.into_values().collect();
    let regroup = |group: u32, with_dir: bool| -> Vec<Vec<usize>> {
        // Ties (eye rays share their origin) keep the tiles' order.
        let mut groups: BTreeMap<u32, Vec<(u64, u32, usize)>> = BTreeMap::new();
        for (k, s) in segs.iter().enumerate() {
            let (x, y, z) = (
                cell(s.o.x, sb.min.x, sb.max.x),
                cell(s.o.y, sb.min.y, sb.max.y),
                cell(s.o.z, sb.min.z, sb.max.z),
            );
            let key = if with_dir {
                morton(x >> 5, y >> 5, z >> 5, 5) << 15
                    | morton(dir(s.d.x), dir(s.d.y), dir(s.d.z), 5)
            } else {
                morton(x, y, z, 10)
            };
            groups
                .entry(tile(s) / group)
                .or_default()
                .push((key, tile(s), k));
        }
        let mut packets = Vec::new();
        for (_, mut g) in groups {
            g.sort_unstable();
            packets.extend(g.chunks(64).map(|c| c.iter().map(|x| x.2).collect()));
        }
        packets
    };
    // An oracle no firmware has: the frame's rays sorted by the
    // leaves they reach (front to back, leaves numbered in tree
    // order), which only tracing them tells.
    let oracle = {
        let mut order: Vec<usize> = (0..segs.len()).collect();
        order.sort_by(|&a, &b| reach[a].cmp(&reach[b]).then(a.cmp(&b)));
        order.chunks(64).map(|c| c.to_vec()).collect::<Vec<_>>()
    };
    let all = u32::MAX;
    let groupings: [(usize, usize); GROUPINGS] = [
        cost(&chip),
        cost(&quads),
        cost(&regroup(1, false)),
        cost(&regroup(4, false)),
        cost(&regroup(all, false)),
        cost(&regroup(all, true)),
        cost(&oracle),
    ];
    (groupings, needed)
}

pub fn command(a: RegroupArgs) -> Result<()> {
    let scene = crate::cmd_scene::load_scene(a.scene.as_deref())?;
    let size = a.size;
    let path = scene.source.clone();
    let tracer = Tracer::new(&scene);
    let bounds: Vec<_> = scene.objects.iter().map(|o| o.shape.bounds()).collect();
    let sb = scene.bounds();
    if sb.is_empty() || scene.objects.is_empty() {
        return Err(anyhow!("{path}: nothing to trace"));
    }
    let params = BspParams {
        max_depth: auto_depth(bounds.len()),
        max_leaf: 5,
        rule: SplitRule::Sah,
        snap: 0.0,
    };
    let bsp = Bsp::build(&bounds, sb, params);
    let eps = 1e-6 * sb.min.max_abs().max(sb.max.max_abs());
    let names = ["eye", "shadow (eye hits)", "mirror", "shadow (mirror hits)"];
    let kinds = segments(&scene, &tracer, size, eps);
    println!(
        "{path} at {size}x{size}, depth 2; pbrt SAH tree of {} nodes; object tests broadcast (fewer is better)",
        bsp.nodes.len()
    );
    println!(
        "{:<22} {:>7} {:>11} {:>11} {:>11} {:>11} {:>11} {:>11} {:>11}",
        "rays",
        "count",
        "8x8 tiles",
        "quadrants",
        "tile merged",
        "4 tiles",
        "frame",
        "frame o+d",
        "by leaves"
    );
    let mut total = [(0usize, 0usize); GROUPINGS];
    let mut total_needed = 0usize;
    for (name, segs) in names.iter().zip(&kinds) {
        let (groupings, needed) = groupings(segs, &bsp, sb, size);
        print_rows(name, &segs.len().to_string(), &groupings, needed);
        for (t, g) in total.iter_mut().zip(groupings) {
            t.0 += g.0;
            t.1 += g.1;
        }
        total_needed += needed;
    }
    print_rows("all rays", "", &total, total_needed);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Leaves of 3, 5 and 7 objects; rays reaching [0], [0, 1], [2] and
    /// [1, 2]: counted by hand.
    #[test]
    fn tests_and_lanes_are_counted_per_packet() {
        let objects = |l: u32| [3, 5, 7][l as usize];
        let reach = vec![vec![0], vec![0, 1], vec![2], vec![1, 2]];
        assert_eq!(needed_tests(&reach, objects), 3 + 8 + 7 + 12);
        // One packet: leaves 0, 1, 2 once each (15 tests) to 4 rays.
        assert_eq!(broadcast(&[vec![0, 1, 2, 3]], &reach, objects), (15, 60));
        // Two packets: {0, 1} reach leaves 0, 1 (8 tests, 2 rays), {2, 3}
        // leaves 1, 2 (12 tests, 2 rays).
        assert_eq!(
            broadcast(&[vec![0, 1], vec![2, 3]], &reach, objects),
            (20, 40)
        );
    }
}
