//! Every SPD scene imports with the primitive counts its README lists, and
//! a malformed scene is reported with its file and line.

use std::path::PathBuf;

use firmware::scene::{PrimType, Rectangle, Scene, Shape};

fn spd(name: &str) -> Scene {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/spd")
        .join(name);
    Scene::load(&p).unwrap_or_else(|e| panic!("{e}"))
}

fn count(s: &Scene, t: PrimType) -> usize {
    s.objects
        .iter()
        .filter(|o| o.shape.prim_type() == t)
        .count()
}

#[test]
fn spd_scenes_import_with_published_counts() {
    // scenes/spd/README.md: jacks-1 6 spheres, 3 cylinders, 1 light.
    let j = spd("jacks-1.nff");
    assert_eq!(
        (
            count(&j, PrimType::Sphere),
            count(&j, PrimType::Cylinder),
            j.objects.len(),
            j.lights.len()
        ),
        (6, 3, 9, 1)
    );
    assert_eq!(j.camera.resolution, (256, 256));
    assert_eq!(j.camera.angle, 25.0);
    // tetra-1: 4 triangles, 1 light.
    let t = spd("tetra-1.nff");
    assert_eq!(
        (
            count(&t, PrimType::Triangle),
            t.objects.len(),
            t.lights.len()
        ),
        (4, 4, 1)
    );
    // balls-4: 7381 spheres and 1 polygon (a rectangle), 3 lights.
    let b = spd("balls-4.nff");
    assert_eq!(
        (count(&b, PrimType::Sphere), b.objects.len(), b.lights.len()),
        (7381, 7382, 3)
    );
    assert!(matches!(
        b.objects[0].shape,
        Shape::Rectangle(Rectangle { .. })
    ));
    assert_eq!(b.materials[b.objects[1].material].ks, 0.5);
    assert_eq!(b.background.z, 0.753);
    // tetra-6: 4096 triangles, 1 light.
    let t = spd("tetra-6.nff");
    assert_eq!(
        (
            count(&t, PrimType::Triangle),
            t.objects.len(),
            t.lights.len()
        ),
        (4096, 4096, 1)
    );
}

fn load_text(name: &str, text: &str) -> Result<Scene, String> {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join(name);
    std::fs::write(&p, text).unwrap();
    Scene::load(&p).map_err(|e| {
        e.to_string()
            .replace(&dir.path().display().to_string(), "DIR")
    })
}

const VIEW: &str = "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0.01\nresolution 8 8\n";

#[test]
fn malformed_scenes_name_file_and_line() {
    let cases = [
        (
            "s 1 2\n",
            "DIR/bad.nff:8: unexpected end of file: expected sphere centre z",
        ),
        ("s 1 2 x 4\n", "DIR/bad.nff:8:7: expected sphere centre z"),
        (
            "s 1 2 3 inf\n",
            "DIR/bad.nff:8:9: expected sphere radius, found the non-finite number",
        ),
        ("s 1 2 3 0\n", "DIR/bad.nff:8:1: sphere has radius 0"),
        (
            "c\n0 0 0 1\n0 0 0 1\n",
            "DIR/bad.nff:8:1: cone/cylinder base and apex are coincident",
        ),
        (
            "p 3\n0 0 0\n1 1 1\n2 2 2\n",
            // skipped; nothing else: refused
            "DIR/bad.nff:8: nothing to render: the only object is a degenerate polygon (collinear",
        ),
        (
            "p 4\n0 0 0\n1 0 0\n1 1 0\n0 1 5\n",
            "DIR/bad.nff:8:1: polygon vertex 4 is not in the plane",
        ),
        (
            "p two\n",
            "DIR/bad.nff:8:3: expected the number of vertices",
        ),
        ("l 1 2 3 1 1\n", "DIR/bad.nff:8:9: expected a light colour"),
        ("zz\n", "DIR/bad.nff:8:1: unknown entity 'zz'"),
    ];
    for (body, want) in cases {
        let e = load_text("bad.nff", &format!("{VIEW}{body}")).unwrap_err();
        assert!(e.starts_with(want), "{body:?}: got {e}, want {want}");
    }
    let e = load_text(
        "bad.toml",
        "[camera]\nfrom = [0, 0, 10]\nat = [0, 0, 0]\nup = [0, 1, 0]\nangle = \"wide\"\n",
    )
    .unwrap_err();
    assert!(e.starts_with("DIR/bad.toml:5:"), "{e}");
    let e = load_text("bad.txt", "").unwrap_err();
    assert!(e.contains("expected a .nff or .toml"), "{e}");
}
