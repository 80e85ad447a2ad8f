//! Whitted on the chip: what the chip cannot render as the
//! scene asks is named in a warning (stderr and the JSON's `warnings`),
//! degenerate polygons are skipped by both renderers alike, and the chip's
//! ray census agrees with the f64 reference's independent count.

mod common;
use common::morphosys;
use std::path::Path;

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

const HEAD: &str = "v\nfrom 0 0 8\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.01\nresolution 32 32\n\
                    b 0.1 0.2 0.3\nl 4 5 9\n";

/// Render `text` (an NFF scene) at 32x32, depth `depth`: the JSON, stderr.
fn render(text: &str, depth: u32) -> (serde_json::Value, String) {
    render_with(text, &["--size", "32x32", "--depth", &depth.to_string()])
}

/// Render `text` (an NFF scene) with `args`: the JSON, stderr.
fn render_with(text: &str, args: &[&str]) -> (serde_json::Value, String) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.nff"), text).unwrap();
    let mut a = vec!["render", "s.nff", "--out", "s.png", "--json", "s.json"];
    a.extend_from_slice(args);
    let (ok, out, err) = morphosys(dir.path(), &a);
    assert!(ok, "{out}{err}");
    (json(&dir.path().join("s.json")), err)
}

/// Chip and reference counts of `kind` within `tol` (a fraction); the
/// reference's rays whose colour reaches a pixel (the SPD also counts
/// reflections of weight 0, which the chip does not trace).
fn census_close(j: &serde_json::Value, kind: &str, tol: f64) {
    let live = format!("live_{kind}");
    let r = &j["reference_rays"];
    let (c, r) = (
        j[kind].as_f64().unwrap(),
        r.get(&live).unwrap_or(&r[kind]).as_f64().unwrap(),
    );
    assert!((c - r).abs() <= tol * r, "{kind}: chip {c}, reference {r}");
}

#[test]
fn degenerate_triangles_are_skipped_and_the_rest_rendered() {
    // Lines 10, 11 (material, sphere), 12-15 a good triangle, 16-19 a
    // collinear one, 20-23 one with two coincident vertices.
    let text = format!(
        "{HEAD}f 0.8 0.4 0.2 1 0 0 0 0\ns 0.8 0 0 1\np 3\n-2.5 -1 0\n-0.5 -1 0\n-1.5 1 0\n\
         p 3\n0 0 1\n1 1 1\n2 2 1\np 3\n0 -2 1\n0 -2 1\n1 -1 1\n"
    );
    let (j, err) = render(&text, 2);
    assert!(
        err.contains("s.nff:16: warning: skipped 2 degenerate polygons"),
        "{err}"
    );
    let w = j["warnings"].as_array().unwrap();
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!(w[0]["feature"], "degenerate");
    assert_eq!(
        (w[0]["line"].as_u64(), w[0]["count"].as_u64()),
        (Some(16), Some(2))
    );
    // The rest renders, as the reference (which skipped the same) does.
    assert!(j["psnr_db"].as_f64().unwrap() > 33.0, "{j}");
    assert!(j["hit_agreement"].as_f64().unwrap() > 0.99, "{j}");
    // Nothing else left: refused with the line, no image.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("e.nff"),
        format!("{HEAD}p 3\n0 0 1\n1 1 1\n2 2 1\n"),
    )
    .unwrap();
    let (ok, _, err) = morphosys(dir.path(), &["render", "e.nff", "--out", "e.png"]);
    assert!(!ok);
    assert!(err.contains("e.nff:10: nothing to render"), "{err}");
    assert!(!dir.path().join("e.png").exists());
}

/// Every primitive type refracts on the chip: a scene of glass of each
/// kind (here a smooth pp triangle, the last to get its two-sided kernel)
/// renders with no warning, and its refracted rays are the reference's.
#[test]
fn glass_of_every_type_renders_without_warnings() {
    let text = format!(
        "{HEAD}f 1 1 1 0.1 0.1 30 0.9 1.5\npp 3\n-2 -2 1 -0.2 0 1\n2 -2 1 0.2 0 1\n0 2 1 0 0.2 1\n\
         s 1.5 1 0 0.5\nc\n-1.5 1 0 0.4\n-1.5 2 0 0.2\nf 0.8 0.4 0.2 1 0 0 0 0\ns 0 0 -1 1\n"
    );
    let (j, err) = render(&text, 3);
    assert!(!err.contains("warning"), "{err}");
    assert_eq!(j["warnings"].as_array().map(|w| w.len()), Some(0), "{j}");
    assert!(j["refract_rays"].as_u64().unwrap() > 300, "{j}");
    census_close(&j, "refract_rays", 0.1);
    assert!(j["psnr_db"].as_f64().unwrap() >= 27.0, "{j}");
}

/// The glass scenes' view: camera, light, background and the glass
/// material (Kd 0.1, Ks 0.2, T 0.85, ior 1.5); the objects follow.
const GLASS_HEAD: &str =
    "v\nfrom 0 0.5 6\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.01\nresolution 64 64\n\
                          b 0.2 0.3 0.5\nl 3 6 8\nf 1 1 1 0.1 0.2 60 0.85 1.5\n";

/// Render an NFF glass scene at 64x64, depth 5, on each datapath with its
/// PSNR floor: no warning, the floor held, the census within 10%.
fn glass_renders(text: &str, floors: [(&str, f64); 2]) {
    for (datapath, min_db) in floors {
        let (j, err) = render_with(
            text,
            &["--size", "64x64", "--depth", "5", "--datapath", datapath],
        );
        assert!(!err.contains("warning"), "{err}");
        let psnr = j["psnr_db"].as_f64().unwrap();
        assert!(psnr >= min_db, "{datapath}-bit: {psnr:.2} dB\n{j}");
        assert!(j["refract_rays"].as_u64().unwrap() > 200, "{j}");
        for k in ["eye_rays", "shadow_rays", "reflect_rays", "refract_rays"] {
            census_close(&j, k, 0.1);
        }
    }
}

/// A glass sphere before a checkered wall: seen through it, the wall
/// appears inverted and magnified, as in the reference; refracted rays to
/// depth 5 (the SPD's) on both datapaths.
#[test]
fn glass_sphere_before_a_checkered_wall() {
    // (16-bit: 29.5 dB at 64x64, 33.0 at 128x128: the sphere magnifies
    // direction rounding near its rim.)
    let text = format!("{GLASS_HEAD}s 0 0 0 1\n{}", checkered_wall());
    glass_renders(&text, [("16", 27.0), ("32", 60.0)]);
}

/// A glass slab (six rectangles, two-sided) before the checkered wall:
/// rays enter, are refracted or totally reflected inside, and leave, near
/// edges too (a ray starting on one face hits the next within an LSB of
/// its plane).
#[test]
fn glass_slab_before_a_checkered_wall() {
    let mut text = String::from(
        "v\nfrom 0.3 0.8 6\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.01\nresolution 64 64\n\
         b 0.2 0.3 0.5\nl 3 6 8\nf 1 1 1 0.1 0.2 60 0.85 1.5\n",
    );
    let (x0, x1, y0, y1, z0, z1) = (-1, 1, -1, 1, -0.3, 0.3);
    let faces = [
        [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],
        [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)],
        [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],
        [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)],
        [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)],
        [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],
    ];
    for f in faces {
        text += "p 4\n";
        for (x, y, z) in f {
            text += &format!("{x} {y} {z}\n");
        }
    }
    text += &checkered_wall();
    glass_renders(&text, [("16", 25.0), ("32", 60.0)]);
}

/// A wall of 64 squares at z = -3, red and white.
fn checkered_wall() -> String {
    let mut text = String::new();
    for (k, colour) in ["0.9 0.1 0.1", "0.9 0.9 0.9"].into_iter().enumerate() {
        text += &format!("f {colour} 1 0 0 0 1\n");
        for i in -4..4i32 {
            for j in -4..4i32 {
                if (i + j).rem_euclid(2) as usize == k {
                    let (a, b) = (i as f64, j as f64);
                    let (a1, b1) = (a + 1.0, b + 1.0);
                    text += &format!("p 4\n{a} {b} -3\n{a1} {b} -3\n{a1} {b1} -3\n{a} {b1} -3\n");
                }
            }
        }
    }
    text
}

/// A glass (open) cylinder across the view before the checkered wall: its
/// body from outside and from inside, as the reference's two-sided test.
#[test]
fn glass_cylinder_before_a_checkered_wall() {
    // (16-bit: 31.9 dB; 32-bit: the reference's image)
    let text = format!(
        "{GLASS_HEAD}c\n-1 -0.5 0 0.6\n1 0.5 0 0.6\n{}",
        checkered_wall()
    );
    glass_renders(&text, [("16", 28.0), ("32", 60.0)]);
}

/// A glass (open) cone across the view before the checkered wall, both
/// sides of its body.
#[test]
fn glass_cone_before_a_checkered_wall() {
    // (16-bit: 32.5 dB; 32-bit: 89.0)
    let text = format!(
        "{GLASS_HEAD}c\n-1 -0.5 0 0.8\n1 0.5 0 0.3\n{}",
        checkered_wall()
    );
    glass_renders(&text, [("16", 28.0), ("32", 60.0)]);
}

/// Rays inside a glass sphere meeting its surface at grazing angles are
/// totally reflected (no refracted ray), the others leave it: the camera
/// sits inside, near the top, looking along it.
#[test]
fn total_internal_reflection_at_grazing_angles() {
    let text = "v\nfrom 0 0 0.75\nat 1 0 0.75\nup 0 0 1\nangle 90\nhither 0.01\nresolution 64 64\n\
                b 0.2 0.3 0.5\nl 0 0 0.5\nf 1 1 1 0.1 0.3 40 0.8 1.5\ns 0 0 0 1\n\
                f 0.9 0.2 0.1 1 0 0 0 0\ns 3 0 0 1\ns 0 3 0 1\ns 0 -3 0 1\n";
    let (j, _) = render_with(
        text,
        &["--size", "64x64", "--depth", "3", "--datapath", "32"],
    );
    let r = &j["reference_rays"];
    let (refl, refr) = (
        r["reflect_rays"].as_u64().unwrap(),
        r["refract_rays"].as_u64().unwrap(),
    );
    // Some rays refract, many are totally reflected.
    assert!(refr > 1000 && refr < refl / 2, "{r}");
    census_close(&j, "refract_rays", 0.01);
    assert!(j["psnr_db"].as_f64().unwrap() >= 60.0, "{j}");
    let (j16, _) = render_with(
        text,
        &["--size", "64x64", "--depth", "3", "--datapath", "16"],
    );
    census_close(&j16, "refract_rays", 0.1);
}

/// The bundled `pp` mesh (a torus of 576 triangles with vertex normals):
/// shaded smoothly on the chip, as the reference does, and much closer to
/// it than the same mesh with face normals.
#[test]
fn smooth_shading_of_a_pp_mesh() {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/torus-pp.nff");
    let scene = firmware::scene::Scene::load(&path).unwrap();
    assert!(scene.warnings.is_empty());
    let opt = firmware::tracer::Options {
        width: 96,
        height: 96,
        ..Default::default()
    };
    let (_, smooth) = tb::render::render(&scene, &opt, &Default::default()).unwrap();
    let psnr_smooth = smooth.json["psnr_db"].as_f64().unwrap();
    assert_eq!(smooth.json["warnings"].as_array().map(|w| w.len()), Some(0));
    let mut flat = scene.clone();
    for o in &mut flat.objects {
        if let firmware::scene::Shape::Triangle(firmware::scene::Triangle { normals, .. }) =
            &mut o.shape
        {
            *normals = None;
        }
    }
    let (chip_flat, _) = tb::render::render(&flat, &opt, &Default::default()).unwrap();
    let psnr_flat = tb::metrics::psnr(&chip_flat.rgb8, &smooth.reference_rgb8);
    eprintln!("torus-pp 96x96: smooth {psnr_smooth:.2} dB, face normals {psnr_flat:.2} dB");
    assert!(psnr_smooth >= 33.0, "smooth: {psnr_smooth:.2} dB");
    assert!(
        psnr_smooth >= psnr_flat + 5.0,
        "smooth {psnr_smooth:.2} dB, flat {psnr_flat:.2} dB"
    );
}

/// A Phong exponent over the kernel's 4096 is named where it shows (Ks >
/// 0), not on the SPD's many Ks = 0 surfaces with exponent 100000.
#[test]
fn large_phong_exponents_are_named_where_they_show() {
    let (j, err) = render(
        &format!("{HEAD}f 0.8 0.4 0.2 0.7 0.3 100000 0 1\ns 0 0 0 1\n"),
        2,
    );
    assert!(
        err.contains("s.nff:11: warning: 1 object has a Phong exponent over 4096"),
        "{err}"
    );
    assert_eq!(j["warnings"][0]["feature"], "phong-exponent");
    let (j, err) = render(
        &format!("{HEAD}f 0.8 0.4 0.2 1 0 100000 0 1\ns 0 0 0 1\n"),
        2,
    );
    assert!(!err.contains("warning"), "{err}");
    assert_eq!(j["warnings"].as_array().map(|w| w.len()), Some(0));
}

#[test]
fn a_scene_the_chip_renders_as_asked_has_no_warnings() {
    let (j, err) = render(
        &format!("{HEAD}f 0.8 0.4 0.2 0.7 0.3 20 0 1\ns 0 0 0 1\n"),
        2,
    );
    assert!(!err.contains("warning"), "{err}");
    assert_eq!(j["warnings"].as_array().map(|w| w.len()), Some(0), "{j}");
}

#[test]
fn ray_census_agrees_with_the_reference() {
    // Two mirrors and a diffuse sphere at depth 4: eye, shadow and
    // reflected rays at every level, counted on the chip (RCs awake at each
    // pass's start) and by the f64 reference's own recursion.
    let text = format!(
        "{HEAD}l -6 2 6\nf 0.9 0.9 0.9 0.3 0.7 40 0 1\ns -1.2 0 0 1\ns 1.2 0.3 -0.5 1\n\
         f 0.2 0.8 0.3 1 0 0 0 1\np 4\n-6 -1.5 -6\n-6 -1.5 6\n6 -1.5 6\n6 -1.5 -6\n"
    );
    let (j, _) = render(&text, 4);
    let r = &j["reference_rays"];
    for k in ["eye_rays", "shadow_rays", "reflect_rays"] {
        assert!(r[k].as_f64().unwrap() > 100.0, "{k}: {r}");
        census_close(&j, k, 0.1);
    }
    // Every reflecting surface has Ks > 0: the SPD's count is the same.
    assert_eq!(r["reflect_rays"], r["live_reflect_rays"]);
    assert_eq!(j["eye_rays"], 1024);
    let mis = j["eye_misclassified"].as_f64().unwrap();
    assert!((mis - (1.0 - j["hit_agreement"].as_f64().unwrap())).abs() < 1e-12);
    assert!(mis < 0.01, "{j}");
}

/// A glass box (a native-format box, two-sided: entry and exit faces)
/// before a checkered wall of rectangles.
#[test]
fn glass_box_before_a_checkered_wall() {
    let mut text = String::from(
        "background = [0.2, 0.3, 0.5]\n[camera]\nfrom = [0.3, 0.8, 6.0]\nat = [0, 0, 0]\n\
         up = [0, 1, 0]\nangle = 40\nresolution = [64, 64]\n[[light]]\nposition = [3, 6, 8]\n\
         [material.glass]\ncolor = [1, 1, 1]\nkd = 0.1\nks = 0.2\nshine = 60\nt = 0.85\nior = 1.5\n\
         [material.red]\ncolor = [0.9, 0.1, 0.1]\n[material.white]\ncolor = [0.9, 0.9, 0.9]\n\
         [[object]]\ntype = \"box\"\nmaterial = \"glass\"\nmin = [-1, -1, -0.3]\nmax = [1, 1, 0.3]\n",
    );
    for i in -4..4i32 {
        for j in -4..4i32 {
            let m = if (i + j).rem_euclid(2) == 1 {
                "red"
            } else {
                "white"
            };
            text += &format!(
                "[[object]]\ntype = \"rectangle\"\nmaterial = \"{m}\"\ncorner = [{i}, {j}, -3]\n\
                 edge1 = [1, 0, 0]\nedge2 = [0, 1, 0]\n"
            );
        }
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("b.toml"), &text).unwrap();
    // (32-bit: 56.6 dB; the pixels left are on the box's edges, where a
    // ray leaving through the next face within SELF_LSB is not seen.)
    for (datapath, min_db) in [("16", 27.0), ("32", 50.0)] {
        let (ok, out, err) = morphosys(
            dir.path(),
            &[
                "render",
                "b.toml",
                "--size",
                "64x64",
                "--depth",
                "5",
                "--datapath",
                datapath,
                "--out",
                "b.png",
                "--json",
                "b.json",
            ],
        );
        assert!(ok, "{out}{err}");
        assert!(!err.contains("warning"), "{err}");
        let j = json(&dir.path().join("b.json"));
        let psnr = j["psnr_db"].as_f64().unwrap();
        assert!(psnr >= min_db, "{datapath}-bit: {psnr:.2} dB");
        for k in ["shadow_rays", "reflect_rays", "refract_rays"] {
            census_close(&j, k, 0.1);
        }
    }
}
