//! The two BSP traversals (`--traversal paper|packet`): the paper's
//! reproduces its published cycle counts exactly, both find the same hits
//! up to ties, and the packet traversal culls rays per cell.

use std::path::PathBuf;

use firmware::scene::Scene;
use firmware::tracer::{Numerics, Options, Traversal};
use tb::reference::{self, shapes, NO_HIT};
use tb::render::{render_chip, RenderSettings};

fn scene_path(name: &str) -> PathBuf {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    for p in [
        root.join("scenes").join(name),
        root.join("scenes/spd").join(name),
    ] {
        if p.is_file() {
            return p;
        }
    }
    panic!("scene {name} not found under scenes/ or scenes/spd/");
}

fn load(name: &str) -> Scene {
    Scene::load(&scene_path(name)).unwrap()
}

fn opts(w: u32, h: u32, traversal: Traversal) -> Options {
    Options {
        width: w,
        height: h,
        traversal,
        ..Options::default()
    }
}

/// The cycle counts published for the paper's traversal (README,
/// docs/tracer.md), with the kernels as they were then (`--normals
/// coarse`), the frame counted as one chip renders it: the firmware's own
/// count of the frame (its `rdcyc` at the end of the tile loop) must keep
/// them, and the simulator's count, which the render reports, stays within
/// a few cycles of it.
#[test]
fn paper_traversal_keeps_its_cycle_counts() {
    let coarse = Numerics {
        normals: firmware::tracer::Normals::Coarse,
        ..Numerics::default()
    };
    for (name, cycles) in [
        ("jacks-1.nff", 3_032_550u64),
        ("tetra-1.nff", 1_230_766),
        ("default.toml", 8_525_576),
    ] {
        let r = render_chip(
            &load(name),
            &opts(256, 256, Traversal::Paper),
            &RenderSettings {
                numerics: coarse,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(r.firmware_cycles, cycles, "{name}");
        assert!(
            r.cycles.abs_diff(cycles) <= 16,
            "{name}: the simulator counted {}",
            r.cycles
        );
    }
}

/// Pixels whose eye ray hits different objects under the two traversals
/// must be ties: both objects meet the (f64) eye ray at distances within a
/// few LSB of the chip's format of each other (the traversals test objects
/// in different orders, and the first of two equal `t` wins).
fn same_hits_up_to_ties(name: &str, w: u32, h: u32) {
    let scene = load(name);
    let paper = render_chip(&scene, &opts(w, h, Traversal::Paper), &Default::default()).unwrap();
    let packet = render_chip(&scene, &opts(w, h, Traversal::Packet), &Default::default()).unwrap();
    let lsb = (-(packet.firmware.frac as f64)).exp2();
    let mut differ = 0;
    for j in 0..h {
        for i in 0..w {
            let p = (j * w + i) as usize;
            let (a, b) = (paper.hits[p], packet.hits[p]);
            if a == b {
                continue;
            }
            differ += 1;
            let ray = reference::eye_ray(&scene, w, h, i, j);
            let t = |id: u32| {
                if id == NO_HIT {
                    return None;
                }
                shapes::intersect(
                    &scene.objects[id as usize].shape,
                    &ray,
                    0.0,
                    f64::INFINITY,
                    true,
                )
                .map(|s| s.t)
            };
            match (t(a), t(b)) {
                (Some(ta), Some(tb)) => assert!(
                    (ta - tb).abs() <= 16.0 * lsb,
                    "{name} pixel ({i}, {j}): paper hits object {a} at {ta}, packet object {b} at {tb}: not a tie"
                ),
                _ => panic!(
                    "{name} pixel ({i}, {j}): paper hits {a:?}, packet {b:?}, and the f64 ray misses one of them"
                ),
            }
        }
    }
    eprintln!("{name}: {differ} of {} pixels hit another object", w * h);
    assert!(
        differ * 1000 <= (w * h) as usize,
        "{name}: {differ} of {} pixels hit another object",
        w * h
    );
}

#[test]
fn same_hits_on_the_default_scene() {
    same_hits_up_to_ties("default.toml", 64, 64);
}

#[test]
fn same_hits_on_the_spd_size_1_scenes() {
    for name in [
        "balls-1.nff",
        "gears-1.nff",
        "jacks-1.nff",
        "lattice-1.nff",
        "mount-1.nff",
        "rings-1.nff",
        "tetra-1.nff",
        "tree-1.nff",
    ] {
        same_hits_up_to_ties(name, 48, 48);
    }
}

/// Two large spheres side by side facing the eye, each hiding a row of
/// small spheres that recedes behind it; the left half of the image sees
/// one, the right half the other, so at the root split the packet's rays
/// disagree. The paper's traversal then tests every object under the root
/// with every ray; the packet traversal sends each half down its own side,
/// where the large sphere ends every ray's interval before the row. Both
/// measures fall: objects broadcast per packet pass and tests per ray.
#[test]
fn rays_that_miss_a_subtree_do_not_test_it() {
    let mut nff = String::from(
        "v\nfrom 0 0 12\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 8 8\nb 0 0 0\nl 0 10 12\nf 1 0 0 1 0 0 0 0\n",
    );
    for x in [-2.5, 2.5] {
        nff.push_str(&format!("s {x} 0 1 2.4\n"));
    }
    for k in 0..10 {
        for x in [-2.5, 2.5] {
            nff.push_str(&format!("s {x} 0 {} 0.8\n", -2.0 * k as f64 - 3.0));
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rows.nff");
    std::fs::write(&path, nff).unwrap();
    let scene = Scene::load(&path).unwrap();
    // Depth 1: no reflection level (which the paper's traversal traces
    // even where no ray reflects, in passes without tests).
    let o = |traversal| Options {
        depth: 1,
        ..opts(8, 8, traversal)
    };
    let paper = render_chip(&scene, &o(Traversal::Paper), &Default::default()).unwrap();
    let packet = render_chip(&scene, &o(Traversal::Packet), &Default::default()).unwrap();
    let (a, b) = (paper.tests_per_ray(), packet.tests_per_ray());
    let (ba, bb) = (
        paper.objects_tested_per_ray(),
        packet.objects_tested_per_ray(),
    );
    eprintln!(
        "ray-object tests per ray: paper {a:.2}, packet {b:.2}; objects broadcast per packet pass: {ba:.2}, {bb:.2}"
    );
    assert_eq!(paper.hits, packet.hits);
    assert!(
        a >= 20.0,
        "the paper's traversal tests all 22 objects: {a:.2}"
    );
    assert!(b * 3.0 < a, "tests per ray: packet {b:.2}, paper {a:.2}");
    assert!(
        bb * 3.0 < ba,
        "broadcast per pass: packet {bb:.2}, paper {ba:.2}"
    );
}

/// shells-1 fits no 16-bit format: its hit maps on the 32-bit chip.
#[test]
fn same_hits_on_shells_on_the_32_bit_chip() {
    let scene = load("shells-1.nff");
    let o = |t| Options {
        datapath: firmware::tracer::Datapath::W32,
        ..opts(48, 48, t)
    };
    let paper = render_chip(&scene, &o(Traversal::Paper), &Default::default()).unwrap();
    let packet = render_chip(&scene, &o(Traversal::Packet), &Default::default()).unwrap();
    let differ = paper
        .hits
        .iter()
        .zip(&packet.hits)
        .filter(|(a, b)| a != b)
        .count();
    eprintln!("shells-1 48x48 (32-bit): {differ} pixels differ");
    assert!(differ <= 2, "shells-1: {differ} pixels hit another object");
}

/// The streamed layout (nodes in main memory, leaf blocks moved into FB
/// bank 1): both traversals find the same hits up to ties there too.
#[test]
fn streamed_traversals_find_the_same_hits() {
    for name in ["default.toml", "jacks-1.nff", "rings-1.nff"] {
        let scene = load(name);
        let (w, h) = (32, 32);
        let paper = tb::render::render_chip(
            &scene,
            &opts(w, h, Traversal::Paper),
            &RenderSettings {
                streamed: true,
                ..Default::default()
            },
        )
        .unwrap();
        let packet = tb::render::render_chip(
            &scene,
            &opts(w, h, Traversal::Packet),
            &RenderSettings {
                streamed: true,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(packet.firmware.layout.stream.is_some());
        let differ = paper
            .hits
            .iter()
            .zip(&packet.hits)
            .filter(|(a, b)| a != b)
            .count();
        eprintln!("{name} streamed: {differ} of {} pixels differ", w * h);
        assert!(differ <= 2, "{name}: {differ} pixels hit another object");
    }
}

/// A leaf whose records do not fit FB bank 1 (16K words) is moved and
/// tested in pieces: 4,400 spheres under a BSP of depth 1 (two leaves of
/// 2,200 spheres, 17,600 words each).
#[test]
fn a_leaf_larger_than_the_bank_is_streamed_in_pieces() {
    let mut nff = String::from(
        "v\nfrom 0 -3 30\nat 0 0 0\nup 0 1 0\nangle 30\nhither 1\nresolution 8 8\nb 0.1 0.1 0.1\nl 10 10 30\nf 1 1 0 0.8 0.2 10 0 0\n",
    );
    for i in 0..22 {
        for j in 0..20 {
            for k in 0..10 {
                nff.push_str(&format!(
                    "s {} {} {} 0.2\n",
                    0.5 * i as f64 - 5.25,
                    0.5 * j as f64 - 4.75,
                    -0.5 * k as f64
                ));
            }
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("block.nff");
    std::fs::write(&path, nff).unwrap();
    let scene = Scene::load(&path).unwrap();
    let mut o = opts(8, 8, Traversal::Packet);
    o.bsp.max_depth = 1;
    let (chip, rep) = tb::render::render(&scene, &o, &Default::default()).unwrap();
    let st = chip.firmware.layout.stream.as_ref().expect("streamed");
    assert!(st.extra_pieces >= 2, "{} extra pieces", st.extra_pieces);
    assert!(st.largest_block <= firmware::tracer::layout::STREAM_BANK);
    let (psnr, agree) = (
        rep.json["psnr_db"].as_f64().unwrap(),
        rep.json["hit_agreement"].as_f64().unwrap(),
    );
    eprintln!(
        "pieces: {} extra, {psnr:.2} dB, {agree:.4}",
        st.extra_pieces
    );
    assert!(psnr >= 30.0 && agree >= 0.98, "{psnr:.2} dB, {agree:.4}");
    // The paper's streamed layout has no pieces: it refuses the scene.
    let paper = Options {
        traversal: Traversal::Paper,
        ..o
    };
    match firmware::tracer::build(&scene, &paper) {
        Ok(_) => panic!("the paper's streamed layout took a leaf larger than FB bank 1"),
        Err(e) => assert!(e.contains("FB bank 1 holds"), "{e}"),
    }
}

/// The streamed packet traversal moves a leaf's records in pieces that
/// alternate between FB bank 1 and the top of bank 0, each piece moving
/// while the one before it is tested: the same objects are tested in the
/// same order whatever the pieces, so the image is identical to whole
/// leaves', and the array waits less for the DMA.
#[test]
fn leaf_pieces_move_while_the_tests_run() {
    use firmware::tracer::LeafPieces;
    let scene = load("rings-1.nff");
    let render = |pieces: LeafPieces| {
        let o = Options {
            pieces,
            ..opts(32, 32, Traversal::Packet)
        };
        let settings = RenderSettings {
            streamed: true,
            ..Default::default()
        };
        tb::render::render_chip(&scene, &o, &settings).unwrap()
    };
    let whole = render(LeafPieces::two(LeafPieces::MAX, LeafPieces::MAX));
    for pieces in [
        LeafPieces::default(),
        LeafPieces::two(8, 64),
        LeafPieces {
            first: 8,
            second: Some(16),
            rest: 64,
        },
    ] {
        let cut = render(pieces);
        let st = cut.firmware.layout.stream.as_ref().expect("streamed");
        eprintln!(
            "rings-1 32x32 streamed, pieces {pieces}: {} extra pieces, DMA stall {} cycles (whole leaves: {} extra, {})",
            st.extra_pieces,
            cut.stats.dma_stall_cycles,
            whole.firmware.layout.stream.as_ref().unwrap().extra_pieces,
            whole.stats.dma_stall_cycles
        );
        assert!(st.extra_pieces > 20, "{} extra pieces", st.extra_pieces);
        assert!(cut.rgb8 == whole.rgb8, "pieces {pieces}: the image changed");
        assert!(cut.hits == whole.hits, "pieces {pieces}: the hits changed");
        assert!(
            cut.stats.dma_stall_cycles * 10 < whole.stats.dma_stall_cycles * 8,
            "pieces {pieces}: DMA stall {} cycles against {} with whole leaves",
            cut.stats.dma_stall_cycles,
            whole.stats.dma_stall_cycles
        );
    }
}

/// `scene` rendered with `o` on a pbrt SAH tree, resident or streamed.
fn render_sah(scene: &Scene, mut o: Options, streamed: bool) -> tb::render::ChipRender {
    o.bsp.rule = firmware::bsp::SplitRule::Sah;
    let s = RenderSettings {
        streamed,
        ..Default::default()
    };
    render_chip(scene, &o, &s).unwrap()
}

/// Glass of every type (a smooth triangle, a sphere, a cylinder) over
/// opaque spheres and a wall, lit by three lights.
fn glass_three_lights() -> Scene {
    firmware::scene::nff::parse(
        "v\nfrom 0 0 8\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.01\nresolution 32 32\n\
         b 0.1 0.2 0.3\nl 4 5 9\nl -5 3 6\nl 0 -6 7\n\
         f 1 1 1 0.1 0.1 30 0.9 1.5\npp 3\n-2 -2 1 -0.2 0 1\n2 -2 1 0.2 0 1\n0 2 1 0 0.2 1\n\
         s 1.5 1 0 0.5\nc\n-1.5 1 0 0.4\n-1.5 2 0 0.2\n\
         f 0.8 0.4 0.2 0.6 0.4 10 0 0\ns 0 0 -1 1\ns 1 -1 -0.5 0.4\n\
         f 0.3 0.8 0.3 0.7 0.3 20 0 0\np 4\n-4 -3 -3\n4 -3 -3\n4 3 -3\n-4 3 -3\n",
        "glass.nff",
    )
    .unwrap()
}

/// Merged shadow packets (`--shadow-packets merged`): the reflection
/// levels' shadow rays of all the lights move into as few packets as hold
/// them, and the answers move back to the RCs that spawned the rays. Each
/// ray is traced alone in an RC as before, so the image, the eye rays'
/// hits and the ray census are those of a packet per light, in fewer
/// passes: on rings-1 (three lights, mirrors), and on glass of every type
/// lit by three lights to depth 5 in 4x4 tiles (two-sided objects: the
/// object a ray leaves moves with it) on both chips.
#[test]
fn merged_shadow_packets_trace_the_same_rays() {
    use firmware::tracer::ShadowPackets;
    let glass = glass_three_lights();
    let rings = load("rings-1.nff");
    let cases = [
        ("rings-1", &rings, 64, 2, rtl::rc::Datapath::W16),
        ("glass", &glass, 16, 5, rtl::rc::Datapath::W16),
        ("glass", &glass, 16, 5, rtl::rc::Datapath::W32),
    ];
    for (name, scene, ways, depth, datapath) in cases {
        let render = |shadows| {
            let o = Options {
                ways,
                depth,
                datapath,
                shadows,
                ..opts(48, 48, Traversal::Packet)
            };
            render_chip(scene, &o, &RenderSettings::default()).unwrap()
        };
        let light = render(ShadowPackets::PerLight);
        let merged = render(ShadowPackets::Merged);
        let what = format!("{name}, {ways} ways, depth {depth}, {datapath}");
        assert_eq!(light.firmware.shadows, ShadowPackets::PerLight, "{what}");
        assert_eq!(merged.firmware.shadows, ShadowPackets::Merged, "{what}");
        eprintln!(
            "{what}: {} passes, {} cycles with a packet per light; merged {} passes, {} cycles",
            light.passes, light.cycles, merged.passes, merged.cycles
        );
        assert!(merged.rgb8 == light.rgb8, "{what}: the image changed");
        assert!(merged.hits == light.hits, "{what}: the hits changed");
        assert_eq!(merged.ray_census(), light.ray_census(), "{what}");
        assert!(
            light.ray_census()[1] > 1000,
            "{what}: {:?}",
            light.ray_census()
        );
        assert!(
            merged.passes < light.passes,
            "{what}: {} passes merged, {} with a packet per light",
            merged.passes,
            light.passes
        );
    }
}

/// Object tests in parts: a test's kernel runs up to a cut, and the rest
/// only where some awake ray can still hit the object, whether the
/// broadcast unit ends the run at a `cut` context (`--test-cuts on`, the
/// default) or TinyRISC broadcasts the parts after a status read
/// (`tinyrisc`). The rest can only narrow F and writes nothing else where
/// F is clear, so the frame is the one of whole tests, bit for bit, in
/// fewer cycles, and fewer with the cut contexts than with TinyRISC's
/// parts: every type with a cut (spheres, cylinders and cones with and
/// without caps, rectangles, triangles, smooth triangles, polygons opaque
/// and glass, glass rectangles and triangles), resident and streamed, on
/// both chips. With the cut contexts `k_phong` also runs a material at a
/// time, each block ending at its cut where no lit RC has its material
/// (the default scene's and the glass scene's several materials): the
/// same frame.
#[test]
fn object_tests_in_parts_trace_the_same_rays() {
    use firmware::tracer::TestCuts;
    let parts = firmware::scene::native::parse(
        "[camera]\nfrom = [4.0, -6.0, 3.0]\nat = [0.0, 0.0, 0.5]\nup = [0.0, 0.0, 1.0]\n\
         angle = 45.0\nresolution = [32, 32]\n\
         [[light]]\nposition = [5.0, -3.0, 8.0]\n[[light]]\nposition = [-4.0, -5.0, 6.0]\n\
         [material.m]\ncolor = [0.8, 0.5, 0.3]\nkd = 0.6\nks = 0.4\nshine = 20\n\
         [[object]]\ntype = \"cone\"\nmaterial = \"m\"\nbase = [-1.5, 0.0, 0.0]\n\
         base_radius = 0.6\napex = [-1.5, 0.3, 1.8]\napex_radius = 0.2\ncaps = true\n\
         [[object]]\ntype = \"cone\"\nmaterial = \"m\"\nbase = [1.5, 1.0, 0.0]\n\
         base_radius = 0.5\napex = [1.2, 1.0, 1.5]\napex_radius = 0.1\n\
         [[object]]\ntype = \"cylinder\"\nmaterial = \"m\"\nbase = [0.0, 1.5, 0.0]\n\
         apex = [0.5, 1.5, 1.2]\nradius = 0.3\n\
         [[object]]\ntype = \"polygon\"\nmaterial = \"m\"\n\
         vertices = [[-3.0, -3.0, -0.2], [3.0, -3.0, -0.2], [3.0, 3.0, -0.2], [0.0, 1.0, -0.2], [-3.0, 3.0, -0.2]]\n\
         [[object]]\ntype = \"sphere\"\nmaterial = \"m\"\ncenter = [0.5, -0.5, 0.6]\nradius = 0.6\n",
        "parts.toml",
    )
    .unwrap();
    let glass = firmware::scene::nff::parse(
        "v\nfrom 0 0 8\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.01\nresolution 32 32\n\
         b 0.1 0.2 0.3\nl 4 5 9\nl -5 3 6\n\
         f 1 1 1 0.1 0.1 30 0.9 1.5\np 5\n-2 -2 1\n2 -2 1\n2 1 1\n0 2 1\n-2 1 1\n\
         p 4\n-3 -1 2\n-1 -1 2\n-1 1 2.5\n-3 1 2.5\np 3\n1 -1 2\n3 -1 2\n2 1 2.5\n\
         f 0.8 0.4 0.2 0.6 0.4 10 0 0\ns 0 0 -1 1\ns 1 -1 -0.5 0.4\n\
         f 0.3 0.8 0.3 0.7 0.3 20 0 0\np 4\n-4 -3 -3\n4 -3 -3\n4 3 -3\n-4 3 -3\n",
        "glass.nff",
    )
    .unwrap();
    let (default, rings, torus) = (
        load("default.toml"),
        load("rings-1.nff"),
        load("torus-pp.nff"),
    );
    let w16 = rtl::rc::Datapath::W16;
    let cases = [
        ("default", &default, false, w16),
        ("default", &default, true, rtl::rc::Datapath::W32),
        ("cones, caps, polygon", &parts, false, w16),
        ("cones, caps, polygon", &parts, true, w16),
        ("glass polygon, rectangle, triangle", &glass, false, w16),
        ("rings-1", &rings, true, w16),
        ("torus-pp", &torus, false, w16),
    ];
    for (name, scene, streamed, datapath) in cases {
        let render = |test_cuts| {
            let o = Options {
                datapath,
                depth: 3,
                test_cuts,
                ..opts(32, 32, Traversal::Packet)
            };
            render_sah(scene, o, streamed)
        };
        let (on, risc, off) = (
            render(TestCuts::On),
            render(TestCuts::Tinyrisc),
            render(TestCuts::Off),
        );
        let what = format!(
            "{name}, {}, {datapath}",
            if streamed { "streamed" } else { "resident" }
        );
        let lay =
            |r: &tb::render::ChipRender| (r.firmware.layout.test_cuts, r.firmware.layout.cut_runs);
        assert_eq!(
            (lay(&on), lay(&risc), lay(&off)),
            ((true, true), (true, false), (false, false))
        );
        eprintln!(
            "{what}: {} cycles in parts cut by the array, {} steered by TinyRISC, {} whole",
            on.cycles, risc.cycles, off.cycles
        );
        for (how, r) in [("cut contexts", &on), ("TinyRISC's parts", &risc)] {
            assert!(r.rgb8 == off.rgb8, "{what}, {how}: the image changed");
            assert!(r.hits == off.hits, "{what}, {how}: the hits changed");
            assert_eq!(r.ray_census(), off.ray_census(), "{what}, {how}");
        }
        assert!(
            on.cycles < risc.cycles && risc.cycles < off.cycles,
            "{what}: {} with cut contexts, {} in TinyRISC's parts, {} whole",
            on.cycles,
            risc.cycles,
            off.cycles
        );
    }
}

/// The child order (`--child-order`): which child of a node a packet
/// whose awake rays go both ways along its axis visits first decides only
/// where the rays find their hits, so every fixed order finds the
/// majority's hits, image and rays bit for bit, in other cycles: rings-1
/// (mirrors, three lights, merged shadow packets), streamed, and glass of
/// every type to depth 5 (refracted rays, two-sided objects) on both
/// chips.
#[test]
fn child_orders_find_the_same_hits() {
    use firmware::tracer::{ChildOrder, ShadowPackets};
    let glass = glass_three_lights();
    let rings = load("rings-1.nff");
    let w16 = rtl::rc::Datapath::W16;
    let cases = [
        ("rings-1", &rings, false, 2, w16),
        ("rings-1", &rings, true, 2, w16),
        ("glass", &glass, false, 5, w16),
        ("glass", &glass, false, 5, rtl::rc::Datapath::W32),
    ];
    for (name, scene, streamed, depth, datapath) in cases {
        let render = |child_order| {
            // A tree walked to its leaves (a scene this small may
            // otherwise be one leaf, with no order to take).
            let o = Options {
                depth,
                datapath,
                child_order,
                shadows: ShadowPackets::Merged,
                collapse: firmware::tracer::Collapse::Objects(0),
                ..opts(32, 32, Traversal::Packet)
            };
            render_sah(scene, o, streamed)
        };
        let what = format!(
            "{name}, {}, {datapath}",
            if streamed { "streamed" } else { "resident" }
        );
        let majority = render(ChildOrder::MAJORITY);
        assert_eq!(
            majority.firmware.child_order,
            ChildOrder::MAJORITY,
            "{what}"
        );
        let mut cycles = vec![majority.cycles];
        for spec in ["uuu,uuu", "ddd,ddd", "udm,dum"] {
            let order: ChildOrder = spec.parse().unwrap();
            let r = render(order);
            assert_eq!(r.firmware.child_order, order, "{what}");
            assert_eq!(r.firmware.child_order.to_string(), spec, "{what}");
            assert!(r.rgb8 == majority.rgb8, "{what}, {spec}: the image changed");
            assert!(r.hits == majority.hits, "{what}, {spec}: the hits changed");
            assert_eq!(r.ray_census(), majority.ray_census(), "{what}, {spec}");
            cycles.push(r.cycles);
        }
        eprintln!("{what}: cycles with majority, uuu,uuu, ddd,ddd, udm,dum: {cycles:?}");
        assert!(
            cycles.iter().any(|&c| c != cycles[0]),
            "{what}: every order took the same cycles ({cycles:?}): the order is not applied"
        );
    }
}

/// `tracer::with_child_order` (how `--child-order auto` tries orders on
/// the probe without laying the scene out again) gives the program and
/// data image a build for that order gives, resident and streamed.
#[test]
fn another_child_order_is_the_build_for_it() {
    use firmware::tracer::{build_streamed_with, build_with, with_child_order, ChildOrder};
    let nm = Numerics::default();
    for (name, streamed) in [
        ("rings-1.nff", false),
        ("rings-1.nff", true),
        ("gears-1.nff", true),
    ] {
        let scene = load(name);
        let o = opts(32, 32, Traversal::Packet);
        let build = |o: &Options| {
            if streamed {
                build_streamed_with(&scene, o, &nm)
            } else {
                build_with(&scene, o, &nm)
            }
            .unwrap()
        };
        let base = build(&o);
        for spec in ["uud,dmu", "majority"] {
            let order: ChildOrder = spec.parse().unwrap();
            let other = with_child_order(&scene, &base, &o, &nm, order).unwrap();
            let built = build(&Options {
                child_order: order,
                ..o
            });
            assert_eq!(other.child_order, order, "{name}, {spec}");
            assert!(
                other.source == built.source,
                "{name}, {spec}: another program"
            );
            assert!(other.fb == built.fb, "{name}, {spec}: another data image");
        }
    }
}

/// What `--child-order auto` serves: a mirror sphere before a wall, seen
/// from the side opposite the wall. A reflected ray can hit only the wall
/// (the sphere is convex), so every secondary ray that hits goes towards
/// it (up along y), while those from the sphere's middle go back towards
/// the eye (down along y) and miss; the rule serves the ones that hit.
#[test]
fn the_rays_that_end_decide_the_child_order() {
    use firmware::tracer::{AxisOrder, ChildOrder};
    let scene = firmware::scene::nff::parse(
        "v\nfrom 0 -6 0\nat 0 0 0\nup 0 0 1\nangle 30\nhither 0.01\nresolution 64 64\n\
         b 0 0 0\nl 0 -5 5\n\
         f 0.8 0.8 0.8 0.5 0.5 10 0 0\ns 0 0 0 1\n\
         f 0.3 0.8 0.3 0.9 0 1 0 0\np 4\n-20 8 -20\n20 8 -20\n20 8 20\n-20 8 20\n",
        "mirror.nff",
    )
    .unwrap();
    let w = reference::ray_ways(&scene, 64, 64, 2, 1);
    let [down, up] = w.secondary[1];
    let [down_hit, up_hit] = w.secondary_hit[1];
    eprintln!("along y: {down} reflected rays down ({down_hit} hit), {up} up ({up_hit} hit)");
    assert_eq!(
        down_hit, 0,
        "a reflected ray going away from the wall hit something"
    );
    assert!(up_hit > 0 && up_hit <= up, "{up_hit} of {up}");
    assert!(down > 0, "no reflected ray goes back towards the eye");
    let order = ChildOrder::from_hits(
        (&w.secondary_hit, &w.secondary),
        (&w.shadow_blocked, &w.shadow),
    );
    let (closest, _) = order.rules();
    assert_eq!(closest[1], AxisOrder::Up, "{order}");
}

/// The packet traversal's `majority` (which child a pass visits first
/// along each axis: the one most of the awake rays meet first), run on the
/// model against a plain count: `r8 = 1` exactly when more of the awake
/// rays (r11, r12) are among those going down (r1, r2) than not. Masks
/// of every density, ties (32 of 64) and the extremes.
#[test]
fn majority_counts_the_rays_going_down() {
    use firmware::tracer::emit::{Code, R1, R11, R12, R13, R2, R7, R8};
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    let mut cases: Vec<(u64, u64)> = vec![
        (u64::MAX, u64::MAX),
        (u64::MAX, 0),
        (u64::MAX, 0xffff_ffff),
        (u64::MAX, 0xffff_ffff_0000_0000),
        (u64::MAX, 0x5555_5555_5555_5555),
        (1, 1),
        (1, 0),
        (0x8000_0000_0000_0000, 0x8000_0000_0000_0000),
        (0xff00_ff00_ff00_ff00, 0xff00_0000_ff00_0000),
        (0xff00_ff00_ff00_ff00, 0x0000_ff00_0000_ff00),
    ];
    for _ in 0..300 {
        let awake = match next() % 4 {
            0 => u64::MAX,
            1 => next() & next(),
            _ => next(),
        };
        let down = match next() % 3 {
            0 => next(),
            1 => next() | next(),
            _ => next() & next(),
        } & awake;
        cases.push((awake, down));
    }
    let mut t = Code::new();
    t.directive(".text").label("_start");
    for (i, &(awake, down)) in cases.iter().enumerate() {
        let expect = (awake.count_ones() < 2 * down.count_ones()) as u32;
        t.li(R13, i)
            .li(R1, down as u32)
            .li(R2, (down >> 32) as u32)
            .li(R11, awake as u32)
            .li(R12, (awake >> 32) as u32)
            .jal("majority")
            .li(R7, expect)
            .bne(R8, R7, "fail");
    }
    t.li(R1, 1).halt();
    t.label("fail").li(R1, 0xbad).halt();
    firmware::tracer::traversal::child_order::majority(&mut t);
    let img = firmware::asm::assemble(&t.text(), "majority-test.s").unwrap();
    let out = tb::cmd_run::run_image(&img, rtl::Timing::default(), 1_000_000, None).unwrap();
    out.result.as_ref().unwrap();
    if out.reg(1) != 1 {
        let (awake, down) = cases[out.reg(13) as usize];
        panic!(
            "majority of awake {awake:#018x}, down {down:#018x}: r8 = {}",
            out.reg(8)
        );
    }
}

/// A streamed leaf whose first piece is one large record of an object in
/// several leaves (over the further pieces' size: with `--leaf-pieces
/// 8,16`, SPD gears' rectangles of 20 words and faces of 57) is moved
/// only once the mailbox scan finds the object untested by some awake
/// ray (`LEAF_LATE`): the frame is the one of further pieces large
/// enough for every record (`--leaf-pieces 8,2048`: no leaf late), pixel
/// for pixel, on both chips.
#[test]
fn large_first_pieces_move_only_when_tested() {
    use firmware::tracer::{ChildOrder, LeafPieces, ShadowPackets};
    let scene = load("gears-1.nff");
    for datapath in [rtl::rc::Datapath::W16, rtl::rc::Datapath::W32] {
        let render = |rest| {
            let o = Options {
                datapath,
                child_order: ChildOrder::MAJORITY,
                shadows: ShadowPackets::PerLight,
                pieces: LeafPieces::two(8, rest),
                ..opts(48, 48, Traversal::Packet)
            };
            render_sah(&scene, o, true)
        };
        let (late, whole) = (render(16), render(2048));
        let n = |r: &tb::render::ChipRender| r.firmware.layout.stream.as_ref().unwrap().late_leaves;
        eprintln!(
            "gears-1, {datapath}: {} late leaves, {} cycles; with 8,2048: {} late, {} cycles",
            n(&late),
            late.cycles,
            n(&whole),
            whole.cycles
        );
        assert!(
            n(&late) > 0,
            "{datapath}: no leaf moves its first piece late"
        );
        assert_eq!(n(&whole), 0, "{datapath}");
        assert!(late.rgb8 == whole.rgb8, "{datapath}: the image changed");
        assert!(late.hits == whole.hits, "{datapath}: the hits changed");
        assert_eq!(late.ray_census(), whole.ray_census(), "{datapath}");
    }
}

/// A streamed layout keeps banded polygons' sub-edges apart from their
/// records, in main memory, and moves a packet's bands of them by DMA
/// once the bisection has found them (`polygon::Form::Apart`), instead of
/// moving them in the record with every leaf piece that holds it
/// (`SubEdges::InRecords`, the resident layout's form). The same frame
/// either way, pixel for pixel: SPD gears-1's faces (144 vertices, 16
/// bands; in fewer cycles) on both chips, and a 20-pointed star (one
/// band: no probe runs before the sub-edges' DMA, which must wait for the
/// array) over a 64-gon floor (which makes the records large enough to
/// keep the sub-edges apart) with object tests whole, in TinyRISC's parts
/// and cut by the array.
#[test]
fn sub_edges_apart_trace_the_same_rays() {
    use firmware::tracer::{SubEdges, TestCuts};
    let mut star = String::from(
        "v\nfrom 0 -6 4\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\nresolution 32 32\n\
         b 0.1 0.2 0.3\nl 4 -5 9\nl -5 -3 6\nf 0.8 0.5 0.3 0.6 0.4 20 0 0\np 20\n",
    );
    for k in 0..20 {
        let a = std::f64::consts::PI * k as f64 / 10.0;
        let r = if k % 2 == 0 { 2.0 } else { 1.0 };
        star.push_str(&format!("{} {} 0\n", r * a.cos(), r * a.sin()));
    }
    // A 64-gon floor under it: records over `polygon::APART_FROM` words.
    star.push_str("f 0.3 0.8 0.3 0.7 0.3 20 0 0\ns 0.5 0.5 0.6 0.5\ns -0.8 0.2 0.4 0.3\np 64\n");
    for k in 0..64 {
        let a = std::f64::consts::PI * k as f64 / 32.0;
        star.push_str(&format!("{} {} -0.5\n", 3.0 * a.cos(), 3.0 * a.sin()));
    }
    let star = firmware::scene::nff::parse(&star, "star.nff").unwrap();
    let gears = load("gears-1.nff");
    let w16 = rtl::rc::Datapath::W16;
    let cases = [
        ("gears-1", &gears, w16, TestCuts::On),
        ("gears-1", &gears, rtl::rc::Datapath::W32, TestCuts::On),
        ("star", &star, w16, TestCuts::Off),
        ("star", &star, w16, TestCuts::Tinyrisc),
        ("star", &star, w16, TestCuts::On),
    ];
    for (name, scene, datapath, test_cuts) in cases {
        let render = |sub_edges| {
            let o = Options {
                datapath,
                sub_edges,
                test_cuts,
                ..opts(48, 48, Traversal::Packet)
            };
            render_sah(scene, o, true)
        };
        let what = format!("{name}, {datapath}, tests {test_cuts}");
        let (apart, inside) = (render(SubEdges::Apart), render(SubEdges::InRecords));
        let (al, il) = (&apart.firmware.layout, &inside.firmware.layout);
        use firmware::tracer::primitives::polygon::Form;
        assert_eq!(al.fit.polygon_form, Form::Apart, "{what}");
        assert_eq!(il.fit.polygon_form, Form::Banded, "{what}");
        let fans = al
            .stream
            .as_ref()
            .and_then(|st| st.fans)
            .expect("the sub-edges' place");
        eprintln!(
            "{what}, 48x48 streamed: sub-edges apart {} cycles (a {}-word buffer), in the records {}",
            apart.cycles, fans.words, inside.cycles
        );
        assert!(apart.rgb8 == inside.rgb8, "{what}: the image changed");
        assert!(apart.hits == inside.hits, "{what}: the hits changed");
        assert_eq!(apart.ray_census(), inside.ray_census(), "{what}");
        if name == "gears-1" {
            // What the form is for: faces of 172 sub-edges in many leaves.
            assert!(apart.cycles < inside.cycles, "{what}");
        }
    }
}
