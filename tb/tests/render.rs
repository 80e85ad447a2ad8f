//! The ray tracer on the simulated chip, at small sizes: image quality
//! against the float reference, determinism, the number of ways, and the
//! `morphosys render` command line.

mod common;
use common::morphosys;
use std::path::PathBuf;

use firmware::scene::Scene;
use firmware::tracer::Options;
use tb::render::render;

fn scene_path(name: &str) -> PathBuf {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    for p in [
        root.join("scenes").join(name),
        root.join("scenes/spd").join(name),
        PathBuf::from("/work/shared/scenes").join(name),
    ] {
        if p.is_file() {
            return p;
        }
    }
    panic!("scene {name} not found under scenes/, scenes/spd/ or the shared scenes");
}

fn load(name: &str) -> Scene {
    Scene::load(&scene_path(name)).unwrap()
}

fn opts(w: u32, h: u32) -> Options {
    Options {
        width: w,
        height: h,
        ..Options::default()
    }
}

fn check_quality(name: &str, w: u32, h: u32, min_psnr: f64, min_hits: f64) {
    let scene = load(name);
    let (_, rep) = render(&scene, &opts(w, h), &Default::default()).unwrap();
    let j = &rep.json;
    let psnr = j["psnr_db"].as_f64().unwrap();
    let hits = j["hit_agreement"].as_f64().unwrap();
    eprintln!(
        "{name} {w}x{h}: {} cycles, {:.2} dB, hit agreement {hits:.4}",
        j["cycles"], psnr
    );
    assert!(psnr >= min_psnr, "{name}: PSNR {psnr:.2} dB < {min_psnr}");
    assert!(
        hits >= min_hits,
        "{name}: hit agreement {hits:.4} < {min_hits}"
    );
}

#[test]
fn default_scene_matches_the_reference() {
    check_quality("default.toml", 48, 40, 30.0, 0.98);
}

#[test]
fn jacks_matches_the_reference() {
    check_quality("jacks-1.nff", 48, 48, 30.0, 0.98);
}

#[test]
fn tetra_matches_the_reference() {
    check_quality("tetra-1.nff", 48, 48, 30.0, 0.98);
}

/// The disc, the primitive `docs/adding-a-primitive.md` walks through
/// (opaque, glass and mirror ones): its scene against the reference on
/// both chips, under both traversals.
#[test]
fn discs_match_the_reference() {
    use firmware::tracer::{Datapath, Traversal};
    let scene = load("discs.toml");
    for traversal in [Traversal::Packet, Traversal::Paper] {
        for (datapath, min_psnr, min_hits) in
            [(Datapath::W16, 38.0, 0.995), (Datapath::W32, 60.0, 0.999)]
        {
            let o = Options {
                datapath,
                traversal,
                depth: 3,
                ..opts(40, 40)
            };
            let (_, rep) = render(&scene, &o, &Default::default()).unwrap();
            let psnr = rep.json["psnr_db"].as_f64().unwrap();
            let hits = rep.json["hit_agreement"].as_f64().unwrap();
            eprintln!("discs 40x40 {traversal:?} {datapath}: {psnr:.2} dB, hits {hits:.4}");
            assert!(
                psnr >= min_psnr && hits >= min_hits,
                "{traversal:?} {datapath}: {psnr:.2} dB, hits {hits:.4}"
            );
        }
    }
}

/// A streamed scene's node records count at most `STREAMED_TYPES` object
/// types: one with more (the default scene's five, discs, glass ones) is
/// refused with the types named under both traversals, never a panic or
/// a count written over the next field; resident, it renders.
#[test]
fn a_streamed_scene_of_too_many_types_is_refused() {
    use firmware::scene::{AaBox, Disc, Object, Shape, Sphere, Vec3};
    use firmware::tracer::layout::STREAMED_TYPES;
    use firmware::tracer::Traversal;
    let mut scene = load("default.toml");
    let glass = scene.materials.len();
    let mut m = scene.materials[0].clone();
    (m.t, m.ior) = (0.7, 1.4);
    scene.materials.push(m);
    let disc = |z: f64| {
        Shape::from(Disc {
            center: Vec3::new(-2.0, 2.0, z),
            normal: Vec3::new(0.0, -1.0, 0.3),
            radius: 0.4,
        })
    };
    let sphere = Shape::from(Sphere {
        center: Vec3::new(2.0, 2.0, 0.5),
        radius: 0.4,
        inside: false,
    });
    let aabox = Shape::from(AaBox {
        min: Vec3::new(-2.5, -2.0, 0.0),
        max: Vec3::new(-2.0, -1.5, 0.5),
    });
    for (shape, material) in [
        (disc(0.6), 0),
        (disc(1.6), glass),
        (sphere, glass),
        (aabox, glass),
    ] {
        scene.objects.push(Object {
            shape,
            material,
            line: 1,
        });
    }
    for traversal in [Traversal::Packet, Traversal::Paper] {
        let o = Options {
            traversal,
            ..opts(16, 16)
        };
        let streamed = tb::render::RenderSettings {
            streamed: true,
            ..Default::default()
        };
        let e = tb::render::render_chip(&scene, &o, &streamed)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!(
                "at most {STREAMED_TYPES} object types; it has 9 ("
            )) && e.contains("glass_disc"),
            "{traversal:?}: {e}"
        );
        tb::render::render_chip(&scene, &o, &Default::default()).unwrap();
    }
}

/// Each chip's frame rate at its own clock: the 16-bit chip at the
/// paper's 300 MHz, the 32-bit one at the slower clock its synthesized
/// path allows (the committed synthesis: `morphosys cost`), a timing
/// file's `clock_hz` where it sets one; the paper's 300 MHz figure beside.
#[test]
fn each_chip_is_quoted_at_its_own_clock() {
    use firmware::tracer::Datapath;
    let scene = load("default.toml");
    let cost = tb::cost::Synthesis::committed();
    let mut clocks = Vec::new();
    for (datapath, given) in [
        (Datapath::W16, None),
        (Datapath::W32, None),
        (Datapath::W32, Some(250_000_000u64)),
    ] {
        let o = Options {
            datapath,
            ..opts(16, 16)
        };
        let mut s = tb::render::RenderSettings::default();
        if let Some(hz) = given {
            s.timing.clock_hz = hz;
            s.clock_given = true;
        }
        let (_, rep) = render(&scene, &o, &s).unwrap();
        let j = &rep.json;
        let (clock, cycles) = (
            j["clock_mhz"].as_f64().unwrap(),
            j["cycles"].as_f64().unwrap(),
        );
        let want = given.map_or(cost.clock_mhz(datapath), |hz| hz as f64 / 1e6);
        assert_eq!(clock, want, "{datapath}");
        let fps = j["fps"].as_f64().unwrap();
        assert!(
            (fps - clock * 1e6 / cycles).abs() < 1e-9 * fps,
            "{datapath}: {fps}"
        );
        let paper = j["fps_at_300mhz"].as_f64().unwrap();
        assert!((paper - 300e6 / cycles).abs() < 1e-9 * paper);
        assert!(j["clock"].as_str().unwrap().contains(if given.is_some() {
            "timing file"
        } else {
            "chip's clock"
        }));
        clocks.push(clock);
    }
    assert_eq!(clocks[0], 300.0);
    assert!(clocks[1] < 250.0 && clocks[1] > 100.0, "{clocks:?}");
}

#[test]
fn json_has_every_key_and_sane_figures() {
    let scene = load("default.toml");
    let (chip, rep) = render(&scene, &opts(24, 16), &Default::default()).unwrap();
    let j = &rep.json;
    for k in [
        "cycles",
        "fps_at_300mhz",
        "width",
        "height",
        "ways",
        "psnr_db",
        "hit_agreement",
        "active_rc_fraction",
        "dma_stall_cycles",
        "objects_tested_per_ray",
        "host_seconds",
        "array_cycles_per_host_second",
    ] {
        assert!(!j[k].is_null(), "missing key {k}");
    }
    // Every render option the JSON reports, under the table's key.
    use tb::render_options::{Json, RENDER_OPTIONS};
    for r in RENDER_OPTIONS {
        if !matches!(r.json, Json::Apart) {
            assert!(
                !j[r.key()].is_null(),
                "--{}: missing key {}",
                r.long,
                r.key()
            );
        }
    }
    assert_eq!(j["width"], 24);
    assert_eq!(j["height"], 16);
    assert_eq!(j["ways"], 64);
    let f = j["active_rc_fraction"].as_f64().unwrap();
    assert!(f > 0.0 && f <= 1.0);
    assert!(chip.cycles > chip.startup_cycles);
    assert!(j["objects_tested_per_ray"].as_f64().unwrap() > 0.0);
    // The kernels of the types present only: the default scene has all
    // five of the paper's types, jacks (spheres, cylinders) has no planar kernel.
    let names: Vec<&str> = chip
        .firmware
        .kernels
        .iter()
        .map(|(n, _)| n.as_str())
        .collect();
    for k in [
        "k_sphere",
        "k_cylinder",
        "k_box",
        "k_rectangle",
        "k_triangle",
    ] {
        assert!(names.contains(&k), "{k} not loaded");
    }
    let jacks = tracer_kernels("jacks-1.nff");
    assert!(jacks.contains(&"k_sphere".to_string()) && jacks.contains(&"k_cylinder".to_string()));
    assert!(
        !jacks.contains(&"k_rectangle".to_string()) && !jacks.contains(&"k_triangle".to_string())
    );
}

fn tracer_kernels(name: &str) -> Vec<String> {
    let fw = firmware::tracer::build(&load(name), &opts(8, 8)).unwrap();
    fw.kernels.into_iter().map(|(n, _)| n).collect()
}

#[test]
fn image_and_cycles_do_not_depend_on_host_threads() {
    let scene = load("default.toml");
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        // 9 x 8 tiles: one work item on one thread, 9 on two.
        pool.install(|| {
            tb::render::render_chip(&scene, &opts(72, 64), &Default::default()).unwrap()
        })
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.item_seconds.len(), 1);
    assert!(b.item_seconds.len() >= 2);
    assert_eq!(a.rgb8, b.rgb8);
    assert_eq!(a.hits, b.hits);
    assert_eq!(a.cycles, b.cycles);
    assert_eq!(a.firmware_cycles, b.firmware_cycles);
    assert_eq!(a.stats, b.stats);
}

/// A frame cut into work items of one tile each (every one after its
/// warm-up tile on a fresh chip) is the frame of one chip running every
/// tile: the same image, cycles and every statistic, on both traversals,
/// both datapaths, a streamed scene, and scenes whose RCs keep hit records
/// from tile to tile (refraction: mount, gears).
#[test]
fn a_frame_cut_at_every_tile_is_one_chips_frame() {
    use firmware::tracer::{Datapath, Traversal};
    let cases: [(&str, Traversal, Datapath, bool); 9] = [
        ("default.toml", Traversal::Packet, Datapath::W16, false),
        ("default.toml", Traversal::Paper, Datapath::W16, false),
        ("default.toml", Traversal::Packet, Datapath::W32, false),
        ("mount-1.nff", Traversal::Packet, Datapath::W16, false),
        ("mount-1.nff", Traversal::Paper, Datapath::W16, false),
        ("gears-1.nff", Traversal::Packet, Datapath::W16, false),
        ("tetra-1.nff", Traversal::Packet, Datapath::W16, true),
        ("rings-1.nff", Traversal::Packet, Datapath::W32, true),
        ("jacks-1.nff", Traversal::Paper, Datapath::W16, true),
    ];
    for (name, traversal, datapath, streamed) in cases {
        let scene = load(name);
        let o = Options {
            traversal,
            datapath,
            ..opts(40, 24)
        };
        let render = |item_tiles| {
            let s = tb::render::RenderSettings {
                streamed,
                item_tiles,
                ..Default::default()
            };
            tb::render::render_chip(&scene, &o, &s).unwrap()
        };
        let (one, cut) = (render(Some(usize::MAX)), render(Some(1)));
        let what = format!("{name} {traversal:?} {datapath:?} streamed {streamed}");
        assert_eq!(cut.item_seconds.len(), 15, "{what}");
        assert_eq!(one.rgb8, cut.rgb8, "{what}");
        assert_eq!(one.hits, cut.hits, "{what}");
        assert_eq!(one.stats, cut.stats, "{what}");
        assert_eq!(one.firmware_cycles, cut.firmware_cycles, "{what}");
        assert_eq!(
            (one.object_tests(), one.passes),
            (cut.object_tests(), cut.passes),
            "{what}"
        );
        assert_eq!(one.leaf_cache, cut.leaf_cache, "{what}");
    }
}

/// A frame of more tiles than a chip's tile list holds (4 ways at
/// 216x216: 11,664 tiles of 2x2 pixels) runs as one item with its list fed
/// in chunks, and is the frame cut into items of 1,000 tiles; under the
/// paper's traversal its 93,312 passes wrap the 16-bit pass numbers twice
/// (the packet traversal, which skips the passes no ray needs, renders
/// 304x304, 23,104 tiles, to wrap them), the mailboxes cleared where one
/// chip's count says, and the items in which they wrap run again from one
/// chip's pass number: the same either way.
#[test]
fn long_tile_lists_and_wrapping_pass_numbers_keep_the_frame() {
    use firmware::tracer::Traversal;
    let scene = load("default.toml");
    for (traversal, side) in [(Traversal::Packet, 304), (Traversal::Paper, 216)] {
        let o = Options {
            traversal,
            ways: 4,
            ..opts(side, side)
        };
        let render = |item_tiles| {
            let s = tb::render::RenderSettings {
                item_tiles,
                ..Default::default()
            };
            tb::render::render_chip(&scene, &o, &s).unwrap()
        };
        let (one, cut) = (render(Some(usize::MAX)), render(Some(1000)));
        let tiles = (side as usize / 2).pow(2);
        assert_eq!(one.tiles, tiles);
        assert_eq!(one.rgb8, cut.rgb8, "{traversal:?}");
        assert_eq!(one.hits, cut.hits, "{traversal:?}");
        assert_eq!(one.stats, cut.stats, "{traversal:?}");
        assert_eq!(one.firmware_cycles, cut.firmware_cycles, "{traversal:?}");
        assert_eq!(
            cut.item_seconds.len(),
            tiles.div_ceil(1000),
            "{traversal:?}"
        );
        match traversal {
            Traversal::Paper => assert_eq!(one.passes, 93_312),
            _ => assert!(one.passes > 65_536, "{} passes", one.passes),
        }
    }
}

#[test]
fn every_number_of_ways_gives_the_same_image_and_more_ways_are_faster() {
    let scene = load("default.toml");
    let mut prev: Option<(Vec<u8>, u64)> = None;
    for ways in [4, 8, 16, 32, 64] {
        let o = Options {
            ways,
            ..opts(16, 16)
        };
        let c = tb::render::render_chip(&scene, &o, &Default::default()).unwrap();
        if let Some((img, cycles)) = &prev {
            assert_eq!(&c.rgb8, img, "{ways} ways: another image");
            assert!(c.cycles < *cycles, "{ways} ways not faster");
        }
        prev = Some((c.rgb8, c.cycles));
    }
}

#[test]
fn bad_options_are_errors_not_panics() {
    let scene = load("default.toml");
    for (ways, depth) in [(3, 2), (128, 2), (64, 0), (64, 99)] {
        let o = Options {
            ways,
            depth,
            ..opts(8, 8)
        };
        let e = tb::render::render_chip(&scene, &o, &Default::default()).unwrap_err();
        assert!(e.to_string().contains("--"), "{e}");
    }
}

#[test]
fn render_command_writes_png_json_asm_and_vcd() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = morphosys(
        dir.path(),
        &[
            "render",
            "--size",
            "16x8",
            "--out",
            "c.png",
            "--json",
            "c.json",
            "--emit-asm",
            "c.s",
            "--vcd",
            "c.vcd",
            "--trace-cycles",
            "200",
            "--trace-scope",
            "tinyrisc",
        ],
    );
    assert!(ok, "{out}\n{err}");
    assert!(out.contains("fps at 300 MHz"), "{out}");
    for f in ["c.png", "c.json", "c.s", "c.vcd"] {
        assert!(dir.path().join(f).is_file(), "{f} not written");
    }
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("c.json")).unwrap()).unwrap();
    assert_eq!(j["width"], 16);
    assert!(j["cycles"].as_u64().unwrap() > 0);
    // The emitted source assembles on its own.
    firmware::asm::assemble_file(&dir.path().join("c.s")).unwrap();
    let (ok, _, err) = morphosys(dir.path(), &["render", "--size", "8x8", "--ways", "5"]);
    assert!(!ok);
    assert!(err.contains("'--ways <N>'") && err.contains("'5'"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    let (ok, _, err) = morphosys(dir.path(), &["render", "missing.nff", "--size", "8x8"]);
    assert!(!ok && err.contains("missing.nff"), "{err}");
    // The 32-bit chip: `--datapath 32`, reported as `datapath_bits`; any
    // other width is one line of error naming the argument.
    let (ok, out, err) = morphosys(
        dir.path(),
        &[
            "render",
            "--size",
            "8x8",
            "--datapath",
            "32",
            "--json",
            "d.json",
        ],
    );
    assert!(ok, "{out}\n{err}");
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("d.json")).unwrap()).unwrap();
    assert_eq!(j["datapath_bits"], 32);
    assert_eq!(j["format"], "Q5.26");
    assert_eq!(j["width"], 8);
    let (ok, _, err) = morphosys(dir.path(), &["render", "--size", "8x8", "--datapath", "24"]);
    assert!(
        !ok && err.contains("--datapath") && err.contains("24"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}

#[test]
fn numerical_knobs_render_and_trade_accuracy() {
    use firmware::tracer::Numerics;
    let scene = load("default.toml");
    let reference = tb::reference::render(
        &scene,
        &tb::reference::Options {
            width: 32,
            height: 32,
            max_depth: 2,
            corners: false,
            progress: false,
        },
    )
    .to_rgb8();
    let psnr = |nm: Numerics| {
        let c = tb::render::render_chip(
            &scene,
            &opts(32, 32),
            &tb::render::RenderSettings {
                numerics: nm,
                ..Default::default()
            },
        )
        .unwrap();
        tb::metrics::psnr(&c.rgb8, &reference)
    };
    let best = psnr(Numerics::default());
    let no_newton = psnr(Numerics {
        newton_steps: 0,
        ..Numerics::default()
    });
    let coarse = psnr(Numerics {
        guard_bits: 4,
        ..Numerics::default()
    });
    eprintln!("PSNR: default {best:.2}, no Newton step {no_newton:.2}, 4 guard bits {coarse:.2}");
    assert!(best >= 30.0 && best > no_newton && best >= coarse - 0.5);
    let bad = Numerics {
        newton_steps: 9,
        ..Numerics::default()
    };
    assert!(tb::render::render_chip(
        &scene,
        &opts(8, 8),
        &tb::render::RenderSettings {
            numerics: bad,
            ..Default::default()
        }
    )
    .is_err());
}

/// A scene that does not fit the FB is streamed from main memory (leaf
/// blocks by DMA into FB bank 1); the same firmware path on a small scene
/// must give the resident image's quality.
#[test]
fn large_scene_is_streamed_and_matches_the_reference() {
    let scene = load("balls-4.nff");
    let fw = firmware::tracer::build(&scene, &opts(16, 16)).unwrap();
    let st = fw.layout.stream.as_ref().expect("balls-4 must be streamed");
    assert!(fw.fb.len() <= firmware::tracer::layout::STREAM_BANK);
    assert!(st.largest_block <= firmware::tracer::layout::STREAM_BANK);
    check_quality("balls-4.nff", 16, 16, 20.0, 0.98);
}

#[test]
fn streamed_layout_matches_the_resident_one_on_a_small_scene() {
    let scene = load("jacks-1.nff");
    let o = opts(24, 24);
    let reference = tb::reference::render(
        &scene,
        &tb::reference::Options {
            width: 24,
            height: 24,
            max_depth: o.depth,
            corners: false,
            progress: false,
        },
    );
    let resident = tb::render::render_chip(&scene, &o, &Default::default()).unwrap();
    let streamed = tb::render::render_chip(
        &scene,
        &o,
        &tb::render::RenderSettings {
            streamed: true,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(resident.firmware.layout.stream.is_none());
    assert!(streamed.firmware.layout.stream.is_some());
    let r8 = reference.to_rgb8();
    let (pr, ps) = (
        tb::metrics::psnr(&resident.rgb8, &r8),
        tb::metrics::psnr(&streamed.rgb8, &r8),
    );
    let (hr, hs) = (
        tb::metrics::hit_agreement(&resident.hits, &reference.hits),
        tb::metrics::hit_agreement(&streamed.hits, &reference.hits),
    );
    eprintln!("jacks-1 24x24: resident {pr:.2} dB {hr:.4}, streamed {ps:.2} dB {hs:.4}");
    assert!(
        ps >= 30.0 && ps >= pr - 2.0,
        "streamed {ps:.2} dB, resident {pr:.2} dB"
    );
    assert!(hs >= 0.98 && hs >= hr - 0.005);
}

/// The 32-bit chip (every format 16 fraction bits finer than the 16-bit
/// chip's): 32x32 renders of the small scenes (tree-1: cones) against the float
/// reference, at 50 dB or more (the 16-bit chip's bar is 30 dB), and at
/// least as close to the reference as the 16-bit chip at the same size.
#[test]
fn the_32_bit_chip_renders_the_small_scenes_closer_to_the_reference() {
    use firmware::tracer::Datapath;
    for name in ["default.toml", "jacks-1.nff", "tetra-1.nff", "tree-1.nff"] {
        let scene = load(name);
        let o16 = opts(32, 32);
        let o32 = Options {
            datapath: Datapath::W32,
            ..o16
        };
        let (_, r16) = render(&scene, &o16, &Default::default()).unwrap();
        let (c32, r32) = render(&scene, &o32, &Default::default()).unwrap();
        assert_eq!(c32.firmware.datapath, Datapath::W32);
        let f = |r: &tb::render::RenderReport, k: &str| r.json[k].as_f64().unwrap();
        let (p16, p32) = (f(&r16, "psnr_db"), f(&r32, "psnr_db"));
        let (h16, h32) = (f(&r16, "hit_agreement"), f(&r32, "hit_agreement"));
        eprintln!(
            "{name} 32x32: 16-bit {p16:.2} dB {h16:.4}, 32-bit {p32:.2} dB {h32:.4} ({} cycles, {})",
            r32.json["cycles"], r32.json["format"]
        );
        assert!(p32 >= 50.0, "{name}: 32-bit chip {p32:.2} dB");
        assert!(h32 >= 0.999, "{name}: 32-bit chip hit agreement {h32:.4}");
        assert!(p32 >= p16 && h32 >= h16, "{name}: 32-bit worse than 16-bit");
    }
}

/// The streamed layout on the 32-bit chip (4-byte FB words in the leaf
/// blocks moved by DMA).
#[test]
fn streamed_layout_on_the_32_bit_chip() {
    use firmware::tracer::Datapath;
    let scene = load("jacks-1.nff");
    let o = Options {
        datapath: Datapath::W32,
        ..opts(24, 24)
    };
    let reference = tb::reference::render(
        &scene,
        &tb::reference::Options {
            width: 24,
            height: 24,
            max_depth: o.depth,
            corners: false,
            progress: false,
        },
    );
    let streamed = tb::render::render_chip(
        &scene,
        &o,
        &tb::render::RenderSettings {
            streamed: true,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(streamed.firmware.layout.stream.is_some());
    let p = tb::metrics::psnr(&streamed.rgb8, &reference.to_rgb8());
    let h = tb::metrics::hit_agreement(&streamed.hits, &reference.hits);
    eprintln!("jacks-1 24x24 streamed, 32-bit: {p:.2} dB {h:.4}");
    assert!(p >= 45.0 && h >= 0.999, "{p:.2} dB {h:.4}");
}

/// `morphosys sweep` runs the paper's configuration on both datapath widths
/// (the `datapath` knob, `datapath_bits` column) and charts them.
#[test]
fn sweep_has_the_datapath_width_series() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_path("tetra-1.nff");
    let (ok, out, err) = morphosys(
        dir.path(),
        &[
            "sweep",
            scene.to_str().unwrap(),
            "--only",
            "knobs",
            "--size",
            "16x16",
            "--out-dir",
            "sw",
        ],
    );
    assert!(ok, "{out}\n{err}");
    let mut rd = csv::Reader::from_path(dir.path().join("sw/results.csv")).unwrap();
    let head = rd.headers().unwrap().clone();
    let col = |n: &str| head.iter().position(|h| h == n).unwrap();
    let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    let by = |bits: &str| {
        rows.iter()
            .find(|r| &r[col("knob")] == "datapath" && &r[col("value")] == bits)
            .unwrap_or_else(|| panic!("no datapath {bits} row"))
            .clone()
    };
    let (r16, r32) = (by("16"), by("32"));
    assert_eq!(
        (&r16[col("datapath_bits")], &r32[col("datapath_bits")]),
        ("16", "32")
    );
    // the same integer bits, 16 more fraction bits
    let (i16b, f16b) = r16[col("format")][1..].split_once('.').unwrap();
    let (i32b, f32b) = r32[col("format")][1..].split_once('.').unwrap();
    assert_eq!(i16b, i32b);
    assert_eq!(
        f32b.parse::<u32>().unwrap(),
        f16b.parse::<u32>().unwrap() + 16
    );
    let p = |r: &csv::StringRecord| r[col("psnr_db")].parse::<f64>().unwrap();
    assert!(p(&r32) >= p(&r16), "{} < {}", p(&r32), p(&r16));
    // every other knob runs on the 16-bit chip
    assert!(rows
        .iter()
        .filter(|r| &r[col("knob")] != "datapath")
        .all(|r| &r[col("datapath_bits")] == "16"));
    assert!(dir.path().join("sw/pareto.png").is_file());
    // The silicon's cost: the array's transistors and the estimated clock
    // of each width, from the committed synthesis read here as JSON.
    let cost: serde_json::Value = serde_json::from_str(tb::cost::COMMITTED).unwrap();
    let unit = |name: &str, bits: u64| {
        cost["units"]
            .as_array()
            .unwrap()
            .iter()
            .find(|u| u["unit"] == name && u["datapath_bits"] == bits)
            .unwrap()
            .clone()
    };
    let depth = |bits: u64| {
        unit("rc", bits)["path_depth"].as_f64().unwrap()
            + unit("rc_interconnect", bits)["path_depth"]
                .as_f64()
                .unwrap()
    };
    for (r, bits) in [(&r16, 16u64), (&r32, 32)] {
        let rc = unit("rc", bits);
        let array = 64 * (rc["transistors"].as_u64().unwrap() + 512 * bits * 6)
            + unit("rc_interconnect", bits)["transistors"]
                .as_u64()
                .unwrap();
        assert_eq!(r[col("array_transistors")], array.to_string());
        let clock = 300.0 * depth(16) / depth(bits);
        let got = r[col("clock_mhz_estimate")].parse::<f64>().unwrap();
        assert!((got - clock).abs() < 1e-9, "{got} {clock}");
        let fps = r[col("fps_at_300mhz")].parse::<f64>().unwrap();
        let per = r[col("fps_per_m_transistors")].parse::<f64>().unwrap();
        assert!((per - fps * clock / 300.0 / (array as f64 / 1e6)).abs() < 1e-6 * per);
    }
    assert!(dir.path().join("sw/pareto_cost.png").is_file());
}

/// balls-4 (7,382 objects, streamed) on the 32-bit chip: its smallest
/// spheres, a few LSB of the 16-bit format (about 20 dB there), are
/// resolved (the 16-bit chip's bar for it is 20 dB).
#[test]
fn large_scene_on_the_32_bit_chip() {
    use firmware::tracer::Datapath;
    let scene = load("balls-4.nff");
    let o = Options {
        datapath: Datapath::W32,
        ..opts(16, 16)
    };
    let (chip, rep) = render(&scene, &o, &Default::default()).unwrap();
    assert!(chip.firmware.layout.stream.is_some());
    let psnr = rep.json["psnr_db"].as_f64().unwrap();
    let hits = rep.json["hit_agreement"].as_f64().unwrap();
    eprintln!("balls-4 16x16, 32-bit: {psnr:.2} dB {hits:.4}");
    assert!(psnr >= 40.0 && hits >= 0.99, "{psnr:.2} dB {hits:.4}");
}

/// A light far outside the scene (tetra-1's light moved to 400 units) does
/// not coarsen the coordinate format: the shadow-ray kernel forms
/// `light / 2^k - P / 2^k`. The image still matches the reference.
#[test]
fn a_far_light_keeps_the_fine_format() {
    let mut scene = load("tetra-1.nff");
    scene.lights[0].position = scene.lights[0].position * 22.0;
    assert!(scene.lights[0].position.max_abs() > 390.0);
    let (chip, rep) = render(&scene, &opts(32, 32), &Default::default()).unwrap();
    assert!(chip.firmware.layout.light_shifted);
    assert_eq!(rep.json["format"], "Q4.11", "the light set the format");
    let psnr = rep.json["psnr_db"].as_f64().unwrap();
    eprintln!("far light: {psnr:.2} dB");
    assert!(psnr >= 30.0, "far light: PSNR {psnr:.2} dB");
}

/// Every chip type in one scene (the default scene's five, plus a capped
/// cone with unequal radii left of the big sphere and a concave polygon on
/// the floor in front, both in view): resident with either node
/// layout and streamed (the streamed node record then counts seven types),
/// each against the f64 reference. Cone kernels load only where there are
/// cones.
#[test]
fn all_seven_chip_types_resident_compact_and_streamed() {
    use firmware::scene::{Cone, Object, Polygon, Shape, Vec3};
    use firmware::tracer::NodeLayout;
    let mut scene = load("default.toml");
    scene.objects.push(Object {
        shape: Shape::from(Cone {
            base: Vec3::new(-1.5, -1.0, 0.0),
            base_radius: 0.45,
            apex: Vec3::new(-1.3, -0.8, 1.3),
            apex_radius: 0.15,
            inside: false,
            caps: true,
        }),
        material: 2,
        line: 0,
    });
    scene.objects.push(Object {
        shape: Shape::from(Polygon {
            v: vec![
                Vec3::new(1.6, -4.4, 0.02),
                Vec3::new(2.8, -4.4, 0.02),
                Vec3::new(2.8, -3.2, 0.02),
                Vec3::new(2.2, -3.8, 0.02),
                Vec3::new(1.6, -3.2, 0.02),
            ],
            normals: None,
        }),
        material: 0,
        line: 0,
    });
    let (w, h) = (32, 32);
    let reference = tb::reference::render(
        &scene,
        &tb::reference::Options {
            width: w,
            height: h,
            max_depth: 2,
            corners: false,
            progress: false,
        },
    );
    let r8 = reference.to_rgb8();
    let compact = Options {
        layout: NodeLayout::Compact,
        ..opts(w, h)
    };
    let runs = [
        (
            "fig5",
            tb::render::render_chip(&scene, &opts(w, h), &Default::default()).unwrap(),
        ),
        (
            "compact",
            tb::render::render_chip(&scene, &compact, &Default::default()).unwrap(),
        ),
        (
            "streamed",
            tb::render::render_chip(
                &scene,
                &opts(w, h),
                &tb::render::RenderSettings {
                    streamed: true,
                    ..Default::default()
                },
            )
            .unwrap(),
        ),
    ];
    for (name, r) in &runs {
        assert_eq!(r.firmware.layout.types.len(), 7, "{name}");
        assert_eq!(r.firmware.layout.stream.is_some(), *name == "streamed");
        let names: Vec<&str> = r.firmware.kernels.iter().map(|(n, _)| n.as_str()).collect();
        assert!(names.contains(&"k_cone") && names.contains(&"k_disc"));
        let psnr = tb::metrics::psnr(&r.rgb8, &r8);
        let hits = tb::metrics::hit_agreement(&r.hits, &reference.hits);
        eprintln!("seven types {w}x{h} {name}: {psnr:.2} dB, hit agreement {hits:.4}");
        assert!(
            psnr >= 30.0 && hits >= 0.99,
            "{name}: {psnr:.2} dB, {hits:.4}"
        );
    }
    assert!(!tracer_kernels("jacks-1.nff").contains(&"k_cone".to_string()));
}

/// The table-size knob reaches every kernel that takes a reciprocal or a
/// square root: with the smallest tables (and the Newton-Raphson steps
/// that make up for them) a scene of cones and their end caps renders
/// within 1.5 dB of the full tables. A kernel that indexed a small table
/// as if it had 128 entries would read the zeros past its end.
#[test]
fn every_table_size_reaches_every_kernel() {
    use firmware::tracer::Numerics;
    let scene = load("tree-1.nff");
    let psnr = |table_entries: u32| {
        let nm = Numerics {
            table_entries,
            ..Numerics::default()
        };
        let (_, rep) = tb::render::render(
            &scene,
            &opts(64, 64),
            &tb::render::RenderSettings {
                numerics: nm,
                ..Default::default()
            },
        )
        .unwrap();
        rep.json["psnr_db"].as_f64().unwrap()
    };
    let full = psnr(128);
    for n in [16, 32, 64] {
        let p = psnr(n);
        eprintln!("tree-1 64x64: {n} entries {p:.2} dB, 128 entries {full:.2} dB");
        assert!(
            p >= full - 1.5,
            "tree-1 with {n}-entry tables: {p:.2} dB against {full:.2} dB with 128"
        );
    }
}

/// `morphosys render --plain` steps every cycle through the plain model:
/// the default scene and jacks-1 at 32x32 under both traversals, and
/// jacks-1 on the 32-bit chip, give the fast paths' image, hit map, every
/// JSON figure but host time, and a waveform window byte for byte.
#[test]
fn render_plain_equals_the_fast_paths() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let cases: [(&str, &[&str]); 5] = [
        ("default.toml", &["--traversal", "packet"]),
        ("default.toml", &["--traversal", "paper"]),
        ("jacks-1.nff", &["--traversal", "packet"]),
        ("jacks-1.nff", &["--traversal", "paper"]),
        ("jacks-1.nff", &["--datapath", "32"]),
    ];
    for (scene, extra) in cases {
        let s = scene_path(scene);
        let s = s.to_str().unwrap();
        let mut outs = Vec::new();
        for mode in ["fast", "plain"] {
            let (png, json, hits, vcd) = (
                format!("{mode}.png"),
                format!("{mode}.json"),
                format!("{mode}.hits"),
                format!("{mode}.vcd"),
            );
            let mut args = vec![
                "render",
                s,
                "--size",
                "32x32",
                "--out",
                &png,
                "--json",
                &json,
                "--hits",
                &hits,
                "--vcd",
                &vcd,
                "--trace-from",
                "3000",
                "--trace-cycles",
                "4000",
            ];
            args.extend_from_slice(extra);
            if mode == "plain" {
                args.push("--plain");
            }
            let (ok, _, err) = morphosys(d, &args);
            assert!(ok, "{scene} {extra:?} {mode}: {err}");
            let mut j: serde_json::Value =
                serde_json::from_slice(&std::fs::read(d.join(&json)).unwrap()).unwrap();
            assert_eq!(j["stepping"], mode);
            for k in [
                "host_seconds",
                "host_chip_seconds",
                "array_cycles_per_host_second",
                "argv",
                "stepping",
            ] {
                j.as_object_mut().unwrap().remove(k);
            }
            outs.push((
                std::fs::read(d.join(&png)).unwrap(),
                std::fs::read(d.join(&hits)).unwrap(),
                j,
                std::fs::read(d.join(&vcd)).unwrap(),
            ));
        }
        let (f, p) = (&outs[0], &outs[1]);
        assert!(f.2["cycles"].as_u64().unwrap() > 10_000);
        assert_eq!(f.2, p.2, "{scene} {extra:?}: JSON");
        assert!(f.0 == p.0, "{scene} {extra:?}: image");
        assert!(f.1 == p.1, "{scene} {extra:?}: hit map");
        assert!(
            f.3.len() > 10_000 && f.3 == p.3,
            "{scene} {extra:?}: waveform"
        );
    }
}

/// `simd_efficiency`: with one object every ray of every pass reaches its
/// cell, so every test the array spends a lane on is needed (1 exactly,
/// with partial tiles at the frame's edges, both traversals); on rings-1
/// (61 objects) most are not, and the JSON's counts agree.
#[test]
fn simd_efficiency_is_one_with_one_object() {
    /// The cycles of the profile's kernels whose names `pick` takes.
    fn kernel_cycles(j: &serde_json::Value, pick: &dyn Fn(&str) -> bool) -> u64 {
        j["profile"]["kernels"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|k| pick(k["name"].as_str().unwrap()))
            .map(|k| k["cycles"].as_u64().unwrap())
            .sum()
    }
    /// The causes add up to the profile's cycles, the busy ones to its
    /// kernels', the DMA wait is the chip's stall count.
    fn assert_causes_sum(j: &serde_json::Value) {
        let c = &j["profile"]["causes"];
        let f = |k: &str| c[k].as_u64().unwrap();
        let busy = kernel_cycles(j, &|_| true);
        assert_eq!(
            f("tests_needed") + f("divergence_waste") + f("traversal_and_shading"),
            busy
        );
        assert_eq!(
            busy + f("dma_wait") + f("control_idle"),
            j["profile"]["cycles"].as_u64().unwrap()
        );
        assert_eq!(f("dma_wait"), j["dma_stall_cycles"].as_u64().unwrap());
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("one.nff"),
        "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0.1\nresolution 32 32\n\
         b 0.1 0.1 0.1\nl 2 2 4\nf 0.8 0.4 0.2 0.7 0.3 10 0 1\n\
         p 4\n-10 -10 0\n10 -10 0\n10 10 0\n-10 10 0\n",
    )
    .unwrap();
    for traversal in ["packet", "paper"] {
        let (ok, _, err) = morphosys(
            dir.path(),
            &[
                "render",
                "one.nff",
                "--size",
                "28x20",
                "--traversal",
                traversal,
                "--profile",
                "--json",
                "j.json",
            ],
        );
        assert!(ok, "{err}");
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("j.json")).unwrap())
                .unwrap();
        assert_eq!(j["simd_efficiency"], 1.0, "{traversal}");
        assert!(j["ray_object_tests"].as_u64().unwrap() > 0);
        // The profile's causes: no divergence, and the tests' cycles are
        // the rectangle kernel's (the square is one for the chip).
        let c = &j["profile"]["causes"];
        assert_eq!(c["divergence_waste"], 0, "{traversal}");
        assert_eq!(
            c["tests_needed"].as_u64().unwrap(),
            kernel_cycles(&j, &|n| n == "k_rectangle"),
            "{traversal}"
        );
        assert_causes_sum(&j);
    }
    let rings = scene_path("rings-1.nff");
    let (ok, _, err) = morphosys(
        dir.path(),
        &[
            "render",
            rings.to_str().unwrap(),
            "--size",
            "32x32",
            "--profile",
            "--json",
            "r.json",
        ],
    );
    assert!(ok, "{err}");
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    // Spheres, cylinders (their caps too) and the rectangle are the
    // tests; split by the efficiency.
    let c = &j["profile"]["causes"];
    let tests = kernel_cycles(&j, &|n| {
        ["k_sphere", "k_cylinder", "k_disc", "k_rectangle"].contains(&n)
    });
    let (needed, waste) = (
        c["tests_needed"].as_u64().unwrap(),
        c["divergence_waste"].as_u64().unwrap(),
    );
    assert_eq!(needed + waste, tests);
    let eff = j["simd_efficiency"].as_f64().unwrap();
    assert!((needed as f64 - eff * tests as f64).abs() <= 1.0);
    assert_causes_sum(&j);
    let (tests, offered) = (
        j["ray_object_tests"].as_u64().unwrap(),
        j["object_tests_offered"].as_u64().unwrap(),
    );
    let e = j["simd_efficiency"].as_f64().unwrap();
    assert!(
        tests < offered && e > 0.0 && e < 1.0,
        "{tests} {offered} {e}"
    );
    assert_eq!(e, tests as f64 / offered as f64);
    let share = j["dma_stall_share"].as_f64().unwrap();
    assert_eq!(
        share,
        j["dma_stall_cycles"].as_f64().unwrap() / j["cycles"].as_f64().unwrap()
    );
}

/// `render --profile` checks the packet traversal's cost model against the
/// frame: a node visit, a leaf's loop and TinyRISC's share of an object
/// test, measured from the chip's cycles, each within a factor of two of
/// the constants the chip split and the collapse weigh (a firmware change
/// that leaves the model stale fails here). A resident scene counts no
/// leaves; the paper's traversal has no such model.
#[test]
fn the_profile_checks_the_cost_model_against_the_frame() {
    let dir = tempfile::tempdir().unwrap();
    let balls = scene_path("balls-4.nff");
    let rings = scene_path("rings-1.nff");
    let json = |args: &[&str]| -> serde_json::Value {
        let mut a = vec!["render", "--size", "32x32", "--profile", "--json", "j.json"];
        a.extend_from_slice(args);
        let (ok, out, err) = morphosys(dir.path(), &a);
        assert!(ok, "{err}");
        assert!(
            out.contains("cost model (chip split)") == (args.len() == 1),
            "{out}"
        );
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("j.json")).unwrap()).unwrap()
    };
    let j = json(&[balls.to_str().unwrap()]);
    assert_eq!(j["fb_layout"], "streamed");
    let c = &j["profile"]["cost_model"];
    for item in ["node_visit", "leaf_loop", "object_risc"] {
        let (measured, model) = (
            c[item].as_f64().unwrap(),
            c["model"][item].as_f64().unwrap(),
        );
        assert!(
            measured > model / 2.0 && measured < model * 2.0,
            "{item}: measured {measured}, model {model}"
        );
    }
    let j = json(&[rings.to_str().unwrap()]);
    assert_eq!(j["fb_layout"], "resident");
    assert!(j["profile"]["cost_model"]["leaf_loop"].is_null());
    assert!(j["profile"]["cost_model"]["node_visit"].as_f64().unwrap() > 0.0);
    let j = json(&[rings.to_str().unwrap(), "--traversal", "paper"]);
    assert!(j["profile"].get("cost_model").is_none());
}

/// Local positions (`--positions local`) on the 16-bit chip: SPD shells,
/// whose smallest spheres are 0.22 LSB of its format and which the
/// scene's one format refuses, renders against the reference; on SPD
/// balls (its spheres 6 to 500 LSB in radius, a mirror each) the eye rays'
/// directions and the spheres' hit points to a fraction of an LSB beat
/// the scene's format in PSNR and hit agreement.
#[test]
fn local_positions_render_what_one_format_cannot() {
    use firmware::tracer::{Datapath, Positions};
    let o = |positions| Options {
        datapath: Datapath::W16,
        depth: 2,
        positions,
        ..opts(32, 32)
    };
    let spd = |name| {
        let size = firmware::scene::spd::default_size(name).unwrap();
        firmware::scene::spd::scene(name, size).unwrap()
    };
    let shells = spd("shells");
    let Err(e) = render(&shells, &o(Positions::Global), &Default::default()) else {
        panic!("shells in the scene's one format: rendered");
    };
    assert!(e.to_string().contains("below the 2 LSB minimum"), "{e}");
    let (_, rep) = render(&shells, &o(Positions::Local), &Default::default()).unwrap();
    let psnr = rep.json["psnr_db"].as_f64().unwrap();
    eprintln!(
        "shells 32x32 local: {psnr:.2} dB, hits {}",
        rep.json["hit_agreement"]
    );
    assert!(psnr >= 40.0, "shells local: {psnr:.2} dB");
    let balls = spd("balls");
    let figures = |p| {
        let (_, rep) = render(&balls, &o(p), &Default::default()).unwrap();
        let j = &rep.json;
        (
            j["psnr_db"].as_f64().unwrap(),
            j["hit_agreement"].as_f64().unwrap(),
        )
    };
    let (g, l) = (figures(Positions::Global), figures(Positions::Local));
    eprintln!("balls 32x32: global {g:?}, local {l:?}");
    assert!(
        l.0 >= g.0 + 5.0 && l.1 >= 0.998 && l.1 >= g.1,
        "balls: global {g:?}, local {l:?}"
    );
}
