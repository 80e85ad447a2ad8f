//! The SPD's published ray statistics (scenes/spd/README.md): a correct
//! classical ray tracer lands within about 10% of them. 512x512 image, rays
//! through pixel corners (513x513 eye rays), maximum depth 5.

use std::path::PathBuf;

use firmware::scene::Scene;
use tb::reference::{render, Options, RayStats};

fn spd_scene(name: &str) -> Scene {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/spd")
        .join(name);
    Scene::load(&p).unwrap_or_else(|e| panic!("{e}"))
}

fn spd_stats(name: &str) -> RayStats {
    let opt = Options {
        width: 512,
        height: 512,
        max_depth: 5,
        corners: true,
        progress: false,
    };
    render(&spd_scene(name), &opt).stats
}

fn within_10_percent(what: &str, got: u64, published: u64) {
    let (g, p) = (got as f64, published as f64);
    if published == 0 {
        assert_eq!(got, 0, "{what}: got {got}, published 0");
    } else {
        assert!(
            (g - p).abs() <= 0.10 * p,
            "{what}: got {got}, published {published} ({:+.1}%)",
            100.0 * (g - p) / p
        );
    }
}

#[test]
fn balls_4_matches_published_figures() {
    let s = spd_stats("balls-4.nff");
    eprintln!("balls-4: {s:?}");
    assert_eq!(s.eye_rays, 513 * 513);
    within_10_percent("eye rays that hit", s.eye_hit_rays, 263169);
    within_10_percent("reflection rays", s.reflect_rays, 175095);
    within_10_percent("refraction rays", s.refract_rays, 0);
    within_10_percent("shadow rays", s.shadow_rays, 954368);
}

#[test]
fn tetra_6_matches_published_figures() {
    let s = spd_stats("tetra-6.nff");
    eprintln!("tetra-6: {s:?}");
    assert_eq!(s.eye_rays, 513 * 513);
    within_10_percent("eye rays that hit", s.eye_hit_rays, 49788);
    within_10_percent("reflection rays", s.reflect_rays, 0);
    within_10_percent("refraction rays", s.refract_rays, 0);
    within_10_percent("shadow rays", s.shadow_rays, 46112);
}
