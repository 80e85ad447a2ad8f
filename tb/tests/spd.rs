//! The ported SPD generators (firmware::scene::spd) against the C programs:
//! the generated NFF is byte-identical to the files the C programs printed
//! (scenes/spd/balls-4, tetra-6, tetra-1, jacks-1), and the object counts
//! for sizes 1 to 4 follow the formulas in the header of each SPD program.

use std::path::PathBuf;

use firmware::scene::{spd, PrimType, Rectangle, Scene, Shape};

fn bundled(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/spd")
        .join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Compare line by line so a failure names the first differing line.
fn assert_same_text(generated: &str, expected: &str, what: &str) {
    for (i, (g, e)) in generated.lines().zip(expected.lines()).enumerate() {
        assert_eq!(g, e, "{what}: line {} differs", i + 1);
    }
    assert_eq!(
        generated.lines().count(),
        expected.lines().count(),
        "{what}: line count"
    );
    assert_eq!(generated, expected, "{what}: whitespace");
}

#[test]
fn generated_files_match_the_c_programs_output() {
    for (name, size) in [("balls", 4), ("tetra", 6), ("tetra", 1), ("jacks", 1)] {
        let file = format!("{name}-{size}.nff");
        assert_same_text(&spd::generate(name, size).unwrap(), &bundled(&file), &file);
    }
}

#[test]
fn bundled_size_1_files_are_the_generators_output() {
    // The size-1 files bundled for every ported generator were written by
    // `morphosys spd NAME --size 1 --out scenes/spd/NAME-1.nff`.
    for name in spd::names() {
        let file = format!("{name}-1.nff");
        assert_same_text(&spd::generate(name, 1).unwrap(), &bundled(&file), &file);
    }
}

/// Counts of NFF entities in the text: spheres, cones/cylinders, and
/// polygons by vertex count (3 and more than 3), plus the lights.
#[derive(Debug, PartialEq, Default)]
struct Counts {
    spheres: usize,
    cones: usize,
    triangles: usize,
    polygons: usize,
    lights: usize,
}

fn count(text: &str) -> Counts {
    let mut c = Counts::default();
    for line in text.lines() {
        let mut t = line.split_whitespace();
        match t.next() {
            Some("s") => c.spheres += 1,
            Some("c") => c.cones += 1,
            Some("l") => c.lights += 1,
            Some("p") | Some("pp") => {
                let n: usize = t.next().unwrap().parse().unwrap();
                if n == 3 {
                    c.triangles += 1
                } else {
                    c.polygons += 1
                }
            }
            _ => {}
        }
    }
    c
}

fn counts(name: &str, size: u32) -> (Counts, Scene) {
    let text = spd::generate(name, size).unwrap();
    let scene = spd::scene(name, size).unwrap_or_else(|e| panic!("{e}"));
    let c = count(&text);
    assert_eq!(
        scene.objects.len(),
        c.spheres + c.cones + c.triangles + c.polygons,
        "{name}-{size}: every entity becomes one object"
    );
    assert_eq!(scene.lights.len(), c.lights, "{name}-{size}: lights");
    (c, scene)
}

#[test]
fn object_counts_follow_the_spd_formulas() {
    for sf in 1..=4u32 {
        let n = sf as usize;
        // balls.c: spheres = sum of 9**n for n = 0..SF, one square floor.
        let (c, _) = counts("balls", sf);
        let spheres: usize = (0..=sf).map(|k| 9usize.pow(k)).sum();
        assert_eq!(
            (c.spheres, c.polygons, c.lights),
            (spheres, 1, 3),
            "balls {sf}"
        );
        // tetra.c: 4**SF triangles.
        let (c, _) = counts("tetra", sf);
        assert_eq!(
            (c.triangles, c.spheres + c.polygons, c.lights),
            (4usize.pow(sf), 0, 1),
            "tetra {sf}"
        );
        // rings.c: spheres = cylinders = 5*SF*(SF+1)*(2*SF+1), one square.
        let (c, s) = counts("rings", sf);
        let r = 5 * n * (n + 1) * (2 * n + 1);
        assert_eq!(
            (c.spheres, c.cones, c.polygons, c.lights),
            (r, r, 1, 3),
            "rings {sf}"
        );
        assert_eq!(s.type_counts()[PrimType::Cylinder.index()], r);
        // gears.c: SF**3 gears, 2 concave faces and 4*TEETH (TEETH = 36)
        // rectangles each, plus the ground square.
        let (c, _) = counts("gears", sf);
        let g = n.pow(3);
        assert_eq!(
            (c.polygons, c.lights),
            (2 * g + 144 * g + 1, 5),
            "gears {sf}"
        );
        // lattice.c: (SF+1)**3 spheres, 3*SF*(SF+1)**2 cylinders (the
        // table: 12, 54, 144 for sizes 1, 2, 3).
        let (c, _) = counts("lattice", sf);
        assert_eq!(
            (c.spheres, c.cones, c.lights),
            ((n + 1).pow(3), 3 * n * (n + 1).pow(2), 6),
            "lattice {sf}"
        );
        // mount.c: 2 * 4**SF triangles and 4 spheres.
        let (c, _) = counts("mount", sf);
        assert_eq!(
            (c.triangles, c.spheres, c.lights),
            (2 * 4usize.pow(sf), 4, 1),
            "mount {sf}"
        );
        // tree.c: 2**(SF+1) - 1 cones and as many spheres, one square.
        let (c, s) = counts("tree", sf);
        let t = 2usize.pow(sf + 1) - 1;
        assert_eq!(
            (c.cones, c.spheres, c.polygons, c.lights),
            (t, t, 1, 7),
            "tree {sf}"
        );
        assert_eq!(s.type_counts()[PrimType::Cone.index()], t);
        // shells.c documents 180 * 2**SF spheres; its loop runs from
        // -steps*2/3 to steps/3 inclusive, which is one sphere more
        // (steps = 180 * 2**SF). No floor square is written.
        let (c, _) = counts("shells", sf);
        assert_eq!(
            (c.spheres, c.polygons, c.lights),
            (180 * 2usize.pow(sf) + 1, 0, 1),
            "shells {sf}"
        );
    }
    // jacks.c gives no formula; each jack is 3 cylinders and 6 spheres and
    // each level puts a jack in the 8 octants of every jack of the level
    // before: sum of 8**k jacks for k = 0..SF-1.
    for sf in 1..=3u32 {
        let (c, _) = counts("jacks", sf);
        let jacks: usize = (0..sf).map(|k| 8usize.pow(k)).sum();
        assert_eq!((c.cones, c.spheres), (3 * jacks, 6 * jacks), "jacks {sf}");
    }
}

#[test]
fn generated_scenes_are_what_the_files_describe() {
    // A generated Scene equals the one read from the bundled file.
    let s = spd::scene("balls", 4).unwrap();
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/spd/balls-4.nff");
    let mut f = Scene::load(&p).unwrap();
    f.source = s.source.clone();
    assert_eq!(s, f);
    // and the floor of balls is the rectangle the NFF reader makes of it.
    assert!(matches!(
        s.objects[0].shape,
        Shape::Rectangle(Rectangle { .. })
    ));
}
