//! The two node layouts of the resident scene image: the paper's Fig. 5 bit
//! vectors and the compact index lists (`--layout fig5|compact`). They name
//! the same objects in the same order, so the chip must produce the same
//! image, the same hit map and the same object tests with either, and both
//! must meet the quality bar against the f64 reference renderer.

use std::path::PathBuf;
use std::process::Command;

use firmware::scene::{native, Scene};
use firmware::tracer::layout::{COMPACT_INNER_HEAD, COMPACT_LEAF_HEAD, NODE_HEAD};
use firmware::tracer::{NodeLayout, Options};

fn load(name: &str) -> Scene {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let p = [root.join(name), root.join("spd").join(name)]
        .into_iter()
        .find(|p| p.is_file())
        .unwrap_or_else(|| panic!("scene {name} not found"));
    Scene::load(&p).unwrap()
}

/// 40 spheres (three bit-vector words per node, the last one partial),
/// 12 triangles and a concave polygon floor: every type walk of the Fig. 6
/// loop crosses word boundaries and skips runs of zero bits.
fn grid() -> Scene {
    let mut t = String::from(
        r#"
background = [0.1, 0.1, 0.2]
[camera]
from = [0.0, -9.0, 6.0]
at = [0.0, 0.0, 0.5]
up = [0.0, 0.0, 1.0]
angle = 45.0
[[light]]
position = [4.0, -6.0, 9.0]
[material.white]
color = [0.8, 0.8, 0.8]
kd = 0.8
ks = 0.2
shine = 20
[material.mirror]
color = [0.9, 0.9, 0.9]
kd = 0.3
ks = 0.7
shine = 100
[[object]]
type = "polygon"
material = "white"
vertices = [[-6, -6, 0], [6, -6, 0], [6, 6, 0], [0, 2, 0], [-6, 6, 0]]
"#,
    );
    for i in 0..40 {
        let (x, y) = ((i % 8) as f64 - 3.5, (i / 8) as f64 - 2.0);
        let m = if i % 3 == 0 { "mirror" } else { "white" };
        t.push_str(&format!(
            "[[object]]\ntype = \"sphere\"\nmaterial = \"{m}\"\ncenter = [{x}, {y}, 0.45]\nradius = 0.35\n"
        ));
    }
    for i in 0..12 {
        let x = i as f64 - 5.5;
        t.push_str(&format!(
            "[[object]]\ntype = \"triangle\"\nmaterial = \"white\"\nvertices = [[{x}, 3.2, 0.0], [{}, 3.2, 0.0], [{x}, 3.6, 1.2]]\n",
            x + 0.8
        ));
    }
    native::parse(&t, "grid.toml").unwrap()
}

/// The node layouts are the paper's traversal's (the packet traversal's
/// leaves are always lists).
fn opts(w: u32, h: u32, layout: NodeLayout) -> Options {
    Options {
        width: w,
        height: h,
        layout,
        traversal: firmware::tracer::Traversal::Paper,
        ..Options::default()
    }
}

/// Render with both layouts: same image, hit map and object tests, and
/// both close to the reference.
fn same_image(name: &str, scene: &Scene, w: u32, h: u32) {
    let reference = tb::reference::render(
        scene,
        &tb::reference::Options {
            width: w,
            height: h,
            max_depth: 2,
            corners: false,
            progress: false,
        },
    );
    let r8 = reference.to_rgb8();
    let mut renders = Vec::new();
    for l in NodeLayout::ALL {
        let c = tb::render::render_chip(scene, &opts(w, h, l), &Default::default()).unwrap();
        assert!(
            c.firmware.layout.stream.is_none(),
            "{name} must be resident"
        );
        assert_eq!(c.firmware.layout.node_layout, l);
        let psnr = tb::metrics::psnr(&c.rgb8, &r8);
        let hits = tb::metrics::hit_agreement(&c.hits, &reference.hits);
        eprintln!(
            "{name} {w}x{h} {l}: {} cycles, {} FB words, {} object tests, {psnr:.2} dB, hits {hits:.4}",
            c.cycles,
            c.firmware.fb.len(),
            c.object_tests()
        );
        assert!(psnr >= 30.0, "{name} {l}: PSNR {psnr:.2} dB < 30");
        assert!(hits >= 0.98, "{name} {l}: hit agreement {hits:.4} < 0.98");
        renders.push(c);
    }
    let (a, b) = (&renders[0], &renders[1]);
    assert!(
        a.rgb8 == b.rgb8,
        "{name}: the layouts give different images"
    );
    assert!(
        a.hits == b.hits,
        "{name}: the layouts give different hit maps"
    );
    assert_eq!(a.object_tests(), b.object_tests(), "{name}: object tests");
    assert_eq!(a.passes, b.passes, "{name}: ray passes");
}

#[test]
fn default_scene_is_the_same_with_either_layout() {
    same_image("default.toml", &load("default.toml"), 40, 32);
}

#[test]
fn spd_scenes_are_the_same_with_either_layout() {
    same_image("jacks-1.nff", &load("jacks-1.nff"), 32, 32);
    same_image("tetra-1.nff", &load("tetra-1.nff"), 32, 32);
}

#[test]
fn multi_word_bit_vectors_and_their_lists_give_the_same_image() {
    same_image("grid", &grid(), 32, 32);
}

/// Decode both node images and check each against the BSP's own object
/// sets: the Fig. 5 vector's set bits and the compact list are exactly the
/// node's objects of each type, ascending.
#[test]
fn both_node_images_name_exactly_the_bsp_objects() {
    let scene = grid();
    let fw = |l| firmware::tracer::build(&scene, &opts(32, 32, l)).unwrap();
    let (f5, cp) = (fw(NodeLayout::Fig5), fw(NodeLayout::Compact));
    let image = firmware::scene_image::compile(
        &scene,
        &firmware::scene_image::CompileOptions {
            layout: Some(firmware::scene_image::NodeFormat::BitVectors),
            guard_bits: 2,
            ..Default::default()
        },
    )
    .unwrap();
    let nodes = &image.bsp.nodes;
    assert!(nodes.len() > 3);
    let (l5, lc) = (&f5.layout, &cp.layout);
    assert_eq!(l5.types.len(), 3);
    // Node addresses: fixed-size Fig. 5 nodes; compact nodes one after the
    // other (4 head words for an inner node, 7 for a leaf, then per type a
    // count and the indices).
    let a5: Vec<usize> = (0..nodes.len())
        .map(|k| l5.root + k * l5.node_words)
        .collect();
    let mut ac = vec![lc.root];
    for n in nodes {
        let head = if n.split.is_some() {
            COMPACT_INNER_HEAD
        } else {
            COMPACT_LEAF_HEAD
        };
        ac.push(ac.last().unwrap() + head + lc.types.len() + n.objects.len());
    }
    assert_eq!(
        ac[nodes.len()],
        lc.mailbox,
        "the compact nodes end at the mailboxes"
    );
    assert_eq!(a5[nodes.len() - 1] + l5.node_words, l5.mailbox);
    for (i, n) in nodes.iter().enumerate() {
        let (h5, hc) = (&f5.fb[a5[i]..], &cp.fb[ac[i]..]);
        // Flags, split (inner) and cell bounds (leaves) agree; children
        // point at the nodes.
        assert_eq!(h5[0], hc[0]);
        let mut p = match n.split {
            Some(sp) => {
                assert_eq!(h5[1], hc[1]);
                for c in 0..2 {
                    let child = sp.children[c] as usize;
                    assert_eq!(h5[2 + c] as usize, a5[child]);
                    assert_eq!(hc[2 + c] as usize, ac[child]);
                }
                COMPACT_INNER_HEAD
            }
            None => {
                assert_eq!(h5[4..NODE_HEAD], hc[1..COMPACT_LEAF_HEAD]);
                COMPACT_LEAF_HEAD
            }
        };
        for (j, t) in l5.types.iter().enumerate() {
            let want: Vec<usize> = n
                .objects
                .iter()
                .filter_map(|&o| t.objects.iter().position(|&x| x == o as usize))
                .collect();
            let bits: Vec<usize> = (0..t.objects.len())
                .filter(|&k| h5[t.bv_offset + k / 16] & (0x8000 >> (k % 16)) != 0)
                .collect();
            assert_eq!(bits, want, "Fig. 5 node {i}, type {j}");
            let cnt = hc[p] as usize;
            let list: Vec<usize> = hc[p + 1..p + 1 + cnt].iter().map(|&k| k as usize).collect();
            assert_eq!(list, want, "compact node {i}, type {j}");
            p += 1 + cnt;
        }
    }
    assert_eq!(lc.resident_node_words, lc.mailbox - lc.root);
    assert_eq!(l5.resident_node_words, nodes.len() * l5.node_words);
    // Records, tables and mailboxes are the same.
    assert_eq!(f5.fb[..l5.root], cp.fb[..lc.root]);
    assert_eq!(f5.fb.len() - l5.mailbox, cp.fb.len() - lc.mailbox);
}

#[test]
fn a_streamed_scene_streams_with_either_layout() {
    // balls-4 (7382 objects) fits FB set 0 with neither node format: the
    // streamed layout, which has per-leaf lists whichever is asked for.
    let scene = load("balls-4.nff");
    for l in NodeLayout::ALL {
        let fw = firmware::tracer::build(&scene, &opts(16, 16, l)).unwrap();
        assert!(fw.layout.stream.is_some(), "{l}");
        assert!(fw.layout.resident_words > 0x8000, "{l}");
    }
}

#[test]
fn render_refuses_an_unknown_layout() {
    let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .args(["render", "--size", "8x8", "--layout", "bitvector"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--layout") && err.contains("fig5") && err.contains("compact"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
}

/// `morphosys sweep --only sizes`: one row per SPD size and traversal, both
/// traversals rendering the same scene to the reference's quality, and the
/// scaling chart with each series' fitted slope.
#[test]
fn size_sweep_writes_rows_for_both_traversals_and_the_chart() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .args([
            "sweep",
            "--only",
            "sizes",
            "--families",
            "tetra",
            "--max-size",
            "2",
            "--family-size",
            "16x16",
            "--out-dir",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut rd = csv::Reader::from_path(dir.path().join("results.csv")).unwrap();
    let head = rd.headers().unwrap().clone();
    let col = |n: &str| head.iter().position(|h| h == n).unwrap();
    let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 4, "tetra 1 and 2, two traversals each");
    for pair in rows.chunks(2) {
        let (a, b) = (&pair[0], &pair[1]);
        assert_eq!(a[col("scene")], b[col("scene")]);
        assert_eq!(
            (&a[col("traversal")], &b[col("traversal")]),
            ("paper", "packet")
        );
        assert_eq!(&a[col("width")], "16");
        assert_eq!(&a[col("bsp_split")], "median");
        for r in pair {
            let psnr: f64 = r[col("psnr_db")].parse().unwrap();
            assert!(psnr >= 30.0, "{r:?}");
        }
    }
    let svg = std::fs::read_to_string(dir.path().join("scaling.svg")).unwrap();
    assert!(svg.contains("Cycles per frame against objects (16x16"));
    assert!(svg.contains("tetra, packet, slope "), "no fitted slope");
    assert!(svg.contains("tetra, paper, slope "), "no fitted slope");
}

#[test]
fn the_fitted_slope_is_the_power_law_exponent() {
    let pts: Vec<(f64, f64)> = [1.0, 8.0, 64.0, 512.0]
        .iter()
        .map(|&x: &f64| (x, 3.0 * x.powf(0.75)))
        .collect();
    let k = tb::cmd_sweep::loglog_slope(&pts).unwrap();
    assert!((k - 0.75).abs() < 1e-9, "{k}");
    assert_eq!(tb::cmd_sweep::loglog_slope(&pts[..1]), None);
}

/// Banded polygon records (`primitives::polygon`): a streamed layout keeps
/// the sub-edges apart from the record (`Form::Apart`), once per polygon
/// in main memory, so SPD gears at its default size is banded on both
/// chips (with the sub-edges in the records, copied into every leaf a
/// face crosses, its 32-bit image was over the main memory reserved for
/// it and it fell back to plain records), its faces' records 57 words,
/// the sub-edges' FB buffer one face's 172 sub-edges.
#[test]
fn gears_streamed_keeps_the_sub_edges_apart() {
    use firmware::tracer::primitives::{polygon, ChipType};
    let text = firmware::scene::spd::generate("gears", 4).unwrap();
    let scene = firmware::scene::nff::parse(&text, "gears.nff").unwrap();
    for datapath in [rtl::rc::Datapath::W16, rtl::rc::Datapath::W32] {
        let o = Options {
            datapath,
            traversal: firmware::tracer::Traversal::Packet,
            bsp: firmware::bsp::BspParams {
                rule: firmware::bsp::SplitRule::Median,
                ..Options::default().bsp
            },
            ..opts(16, 16, NodeLayout::Fig5)
        };
        let fw = firmware::tracer::build(&scene, &o)
            .unwrap_or_else(|e| panic!("gears, {datapath}: {e}"));
        let lay = &fw.layout;
        let st = lay.stream.as_ref().expect("streamed");
        assert!(lay.fit.polygon_form.banded(), "gears, {datapath}: banded");
        assert_eq!(
            lay.fit.polygon_form,
            polygon::Form::Apart,
            "gears, {datapath}: apart"
        );
        let face = lay
            .types
            .iter()
            .find(|t| t.ty == ChipType::Polygon)
            .expect("gears has polygons");
        assert_eq!(face.size, polygon::words(0, polygon::Form::Apart));
        assert_eq!(face.size, 57, "gears, {datapath}");
        // 144 edges, 172 sub-edges of 6 words in 16 bands.
        let fans = st.fans.expect("the sub-edges' place");
        assert_eq!(fans.words, 6 * 172, "gears, {datapath}");
    }
}
