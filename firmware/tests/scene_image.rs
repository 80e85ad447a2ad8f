//! The compiled scene image, decoded word by word and checked against
//! hand-computed values, and the BSP membership of every node checked
//! against a brute-force walk of the planes stored in the image.

use firmware::bsp::{BspParams, SplitRule};
use firmware::scene::{native, Aabb, Scene, Shape, Sphere, Triangle, Vec3};
use firmware::scene_image::{compile, CompileOptions, NodeFormat, MAGIC, NO_CHILD};

const HEAD: &str = "[camera]\nfrom = [0, 0, 10]\nat = [0, 0, 0]\nup = [0, 1, 0]\nangle = 45\n\
                    [[light]]\nposition = [1, 2, 3]\n[material.m]\ncolor = [1, 0.5, 0.25]\nkd = 0.75\nks = 0.25\nshine = 20\n";

fn scene(objects: &str) -> Scene {
    native::parse(&format!("{HEAD}{objects}"), "test.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn sphere(c: [f64; 3], r: f64) -> String {
    format!(
        "[[object]]\ntype = \"sphere\"\nmaterial = \"m\"\ncenter = [{}, {}, {}]\nradius = {r}\n",
        c[0], c[1], c[2]
    )
}

fn addr(w: &[u16], at: usize) -> usize {
    ((w[at] as usize) << 16) | w[at + 1] as usize
}

#[test]
fn small_scene_by_hand() {
    let tri = "[[object]]\ntype = \"triangle\"\nmaterial = \"m\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n";
    let s = scene(&(sphere([1.0, 2.0, 3.0], 0.5) + &sphere([-1.5, 0.25, 0.0], 1.0) + tri));
    let img = compile(&s, &CompileOptions::default()).unwrap();
    let w = &img.words;
    let r = &img.report;
    // Largest coordinate 10 (the camera); one guard bit: 20 < 2^5, so
    // Q5.10, LSB 1/1024.
    assert_eq!(r.format, "Q5.10");
    assert_eq!(w[0], MAGIC);
    assert_eq!(w[2], 10);
    // Every coordinate here is a multiple of 1/1024: no error.
    assert_eq!(r.max_quantization_error, 0.0);
    // Smallest feature: the sphere of radius 0.5 = 512 LSB (the
    // triangle's height is 0.707).
    assert_eq!(r.smallest_feature_lsb, 512.0);
    assert_eq!(w[9], 2, "spheres");
    assert_eq!(w[9 + 5], 1, "triangles");
    // Sphere records: cx cy cz r material flags.
    let sp = addr(w, 22);
    assert_eq!(&w[sp..sp + 6], &[1024, 2048, 3072, 512, 0, 0]);
    assert_eq!(
        &w[sp + 6..sp + 12],
        &[(-1536i16) as u16, 256, 0, 1024, 0, 0]
    );
    let tr = addr(w, 22 + 2 * 5);
    assert_eq!(&w[tr..tr + 10], &[0, 0, 0, 1024, 0, 0, 0, 1024, 0, 0]);
    // Material: colour, kd, ks, t, ior in Q3.12, then shine.
    let m = addr(w, 20);
    assert_eq!(&w[m..m + 8], &[4096, 2048, 1024, 3072, 1024, 0, 4096, 20]);
    // Three objects <= 5 per leaf: the root is a leaf; Fig. 5 node: flags,
    // plane, two children, then one bit vector per type present, object 0
    // in the most significant bit.
    assert_eq!(r.layout, NodeFormat::BitVectors);
    let n = addr(w, 38);
    assert_eq!(
        &w[n..n + 6],
        &[0x8000, 0, NO_CHILD, NO_CHILD, 0xC000, 0x8000]
    );
    assert_eq!(n + 6, w.len());
    assert!(r.fits_fb_bank);
    // Triangle-only: 2 spheres x 224 + 1.
    assert_eq!(r.triangle_only.triangles, 449);
}

/// Objects under each node, decoded from the image, against the objects
/// whose bounds reach into the node's region (the planes of its ancestors,
/// as stored in the image).
fn check_membership(s: &Scene, img: &firmware::scene_image::SceneImage) {
    let w = &img.words;
    let frac = w[2] as i32;
    let lsb = (-(frac as f64)).exp2();
    let nodes = w[4] as usize;
    let node_words = w[6] as usize;
    let base = addr(w, 38);
    let compact = w[3] == 1;
    let counts: Vec<usize> = (0..7).map(|t| w[9 + t] as usize).collect();
    let present: Vec<usize> = (0..7).filter(|&t| counts[t] > 0).collect();
    // Scene object of (type, index).
    let mut slot_object = std::collections::HashMap::new();
    for (i, (t, k)) in img.object_slots.iter().enumerate() {
        slot_object.insert((t.index(), *k as usize), i);
    }
    // Walk: (node, list of (axis, pos, above)).
    let mut stack = vec![(0usize, Vec::<(usize, f64, bool)>::new())];
    let mut seen = 0;
    while let Some((k, planes)) = stack.pop() {
        seen += 1;
        let rec = &w[base + k * node_words..base + (k + 1) * node_words];
        let mut got: Vec<usize> = Vec::new();
        if compact {
            let start = ((rec[4] as usize) << 16) | rec[5] as usize;
            let count = ((rec[6] as usize) << 16) | rec[7] as usize;
            let lists = addr(w, 40);
            for &e in &w[lists + start..lists + start + count] {
                got.push(slot_object[&((e >> 13) as usize, (e & 0x1FFF) as usize)]);
            }
        } else {
            let mut at = 4;
            for &t in &present {
                for k in 0..counts[t] {
                    if rec[at + k / 16] & (0x8000 >> (k % 16)) != 0 {
                        got.push(slot_object[&(t, k)]);
                    }
                }
                at += counts[t].div_ceil(16);
            }
        }
        got.sort();
        got.dedup();
        // The node's cell: the scene's box (snapped out to the format)
        // cut by the ancestors' planes, with the compiler's 2-LSB margin.
        let mut cell = s
            .objects
            .iter()
            .fold(Aabb::EMPTY, |a, o| a.union(o.shape.bounds()));
        for a in 0..3 {
            let (lo, hi) = (cell.min.axis(a), cell.max.axis(a));
            set_axis(&mut cell.min, a, (lo / lsb).floor() * lsb);
            set_axis(&mut cell.max, a, (hi / lsb).ceil() * lsb);
        }
        for &(ax, pos, above) in &planes {
            if above {
                set_axis(&mut cell.min, ax, pos);
            } else {
                set_axis(&mut cell.max, ax, pos);
            }
        }
        let m = Vec3::ONE * (2.0 * lsb);
        let cell = Aabb {
            min: cell.min - m,
            max: cell.max + m,
        };
        let want: Vec<usize> = (0..s.objects.len())
            .filter(|&i| {
                let b = s.objects[i].shape.bounds();
                planes.iter().all(|&(ax, pos, above)| {
                    if above {
                        b.max.axis(ax) >= pos
                    } else {
                        b.min.axis(ax) <= pos
                    }
                }) && s.objects[i].shape.may_overlap(&cell)
            })
            .collect();
        assert_eq!(got, want, "node {k}");
        if rec[0] & 0x8000 == 0 {
            let ax = (rec[0] & 3) as usize;
            let pos = rec[1] as i16 as f64 * lsb;
            for (c, above) in [(rec[2], false), (rec[3], true)] {
                let mut p = planes.clone();
                p.push((ax, pos, above));
                stack.push((c as usize, p));
            }
        } else {
            assert_eq!((rec[2], rec[3]), (NO_CHILD, NO_CHILD));
        }
    }
    assert_eq!(seen, nodes);
}

fn grid_scene(n: usize) -> Scene {
    let mut objs = String::new();
    for i in 0..n {
        let (x, y, z) = (
            (i % 13) as f64 * 0.5 - 3.0,
            ((i / 13) % 11) as f64 * 0.5 - 2.5,
            (i / 143) as f64 * 0.5 - 2.0,
        );
        objs += &sphere([x, y, z], 0.2 + 0.01 * (i % 7) as f64);
    }
    objs +=
        "[[object]]\ntype = \"box\"\nmaterial = \"m\"\nmin = [-4, -4, -3]\nmax = [4, 4, -2.5]\n";
    scene(&objs)
}

#[test]
fn bit_vector_membership_matches_planes() {
    let s = grid_scene(60);
    let img = compile(&s, &CompileOptions::default()).unwrap();
    assert_eq!(img.report.layout, NodeFormat::BitVectors);
    assert!(img.report.bsp.nodes > 7);
    check_membership(&s, &img);
    let sah = CompileOptions {
        bsp: BspParams {
            rule: SplitRule::Sah,
            ..BspParams::default()
        },
        ..CompileOptions::default()
    };
    check_membership(&s, &compile(&s, &sah).unwrap());
}

#[test]
fn thousands_of_objects_choose_index_lists() {
    let s = grid_scene(2000);
    let img = compile(&s, &CompileOptions::default()).unwrap();
    assert_eq!(
        img.report.layout,
        NodeFormat::IndexLists,
        "{}",
        img.report.layout_reason
    );
    assert!(
        img.report.index_list_layout_words.unwrap() < img.report.bitvector_layout_words.unwrap()
    );
    check_membership(&s, &img);
    // Forcing bit vectors gives the same membership.
    let forced = CompileOptions {
        layout: Some(NodeFormat::BitVectors),
        ..CompileOptions::default()
    };
    check_membership(&s, &compile(&s, &forced).unwrap());
}

#[test]
fn refuses_what_it_cannot_represent() {
    // Too large: a coordinate of 20000 needs 16 bits of integer.
    let s = scene(&sphere([20000.0, 0.0, 0.0], 1.0));
    let e = compile(&s, &CompileOptions::default()).unwrap_err();
    assert!(e.to_string().contains("cannot represent"), "{e}");
    assert_eq!(e.line, 13, "{e}");
    // Too small: a sphere of radius 0.001 in a scene spanning 1000 (Q11.4
    // with the guard bit, LSB 1/16): 0.016 LSB.
    let s = scene(&(sphere([1000.0, 0.0, 0.0], 1.0) + &sphere([0.0, 0.0, 0.0], 0.001)));
    let e = compile(&s, &CompileOptions::default()).unwrap_err();
    assert!(
        e.message.contains("Q11.4") && e.message.contains("sphere"),
        "{e}"
    );
    assert_eq!(e.line, 18, "{e}");
}

#[test]
fn spd_scenes_compile() {
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/spd");
    let balls = Scene::load(&dir.join("balls-4.nff")).unwrap();
    let img = compile(&balls, &CompileOptions::default()).unwrap();
    let r = &img.report;
    // The floor reaches 12: with the guard bit 24 < 32, so Q5.10; the
    // smallest sphere (radius 0.00617284) is 6.3 LSB.
    assert_eq!(r.format, "Q5.10");
    assert!((r.smallest_feature_lsb - 0.00617284 * 1024.0).abs() < 1e-9);
    assert!(r.max_quantization_error <= 0.5 / 1024.0);
    assert_eq!(r.layout, NodeFormat::IndexLists);
    assert!(r.bsp.max_depth <= 15);
    check_membership(&balls, &img);
}

fn set_axis(v: &mut Vec3, a: usize, x: f64) {
    match a {
        0 => v.x = x,
        1 => v.y = x,
        _ => v.z = x,
    }
}

/// `Shape::may_overlap` against sampling: whenever a point of a triangle
/// (a dense barycentric grid) or of a sphere (its centre and the point
/// nearest the box centre) lies inside a box, the test must say "may
/// overlap"; and triangles built to miss the box by a margin must be
/// rejected (the test is not just "true").
#[test]
fn may_overlap_is_conservative_and_rejects_clear_misses() {
    let mut seed = 12345u64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let (mut rejected, mut sampled_hits) = (0, 0);
    for _ in 0..3000 {
        let c = Vec3::new(rnd(), rnd(), rnd()) * 0.5;
        let h = Vec3::new(rnd().abs(), rnd().abs(), rnd().abs()) * 0.4 + Vec3::ONE * 0.01;
        let b = Aabb {
            min: c - h,
            max: c + h,
        };
        let v = [
            Vec3::new(rnd(), rnd(), rnd()),
            Vec3::new(rnd(), rnd(), rnd()),
            Vec3::new(rnd(), rnd(), rnd()),
        ];
        let t = Shape::from(Triangle { v, normals: None });
        let inside =
            |p: Vec3| (0..3).all(|a| p.axis(a) >= b.min.axis(a) && p.axis(a) <= b.max.axis(a));
        let n = 40;
        let mut any = false;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, w) = (i as f64 / n as f64, j as f64 / n as f64);
                if inside(v[0] + (v[1] - v[0]) * u + (v[2] - v[0]) * w) {
                    any = true;
                }
            }
        }
        let may = t.may_overlap(&b);
        if any {
            sampled_hits += 1;
            assert!(may, "triangle {v:?} has a point in {b:?}");
        }
        if !may {
            rejected += 1;
        }
    }
    assert!(
        sampled_hits > 300 && rejected > 300,
        "{sampled_hits} {rejected}"
    );
    // A triangle whose bounding box covers the box but which passes 0.2
    // beside it (the plane x + y + z = 2.2 against the unit cube).
    let t = Shape::from(Triangle {
        v: [
            Vec3::new(2.2, 0.0, 0.0),
            Vec3::new(0.0, 2.2, 0.0),
            Vec3::new(0.0, 0.0, 2.2),
        ],
        normals: None,
    });
    let unit = Aabb {
        min: Vec3::new(0.0, 0.0, 0.0),
        max: Vec3::ONE * 0.7,
    };
    assert!(t.bounds().overlaps(&unit) && !t.may_overlap(&unit));
    // Spheres: the exact distance test.
    let s = |x: f64| {
        Shape::from(Sphere {
            center: Vec3::new(x, 0.35, 0.35),
            radius: 0.3,
            inside: false,
        })
    };
    assert!(s(0.95).may_overlap(&unit) && !s(1.05).may_overlap(&unit));
}
