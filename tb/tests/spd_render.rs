//! Every size-1 SPD scene the chip can render, traced on the simulated chip
//! at 48x48 and measured against the f64 reference renderer: PSNR >= 30 dB
//! and eye-ray hit agreement >= 99% (issue 5's targets, the same for every
//! scene, none tuned to one).
//!
//! Left out, and why (docs/scenes.md has the figures):
//! - gears-1: the gear's top and bottom faces are concave 144-vertex
//!   polygons; the chip's polygon kernel (even-odd count over fan triangles
//!   in fixed point) misclassifies pixels along the fan's shared diagonals,
//!   so the faces show speckle (about 17.6 dB, 95% hit agreement at any
//!   size). A polygon-kernel issue, not a scene one.
//! - mount-1: 98.6% hit agreement at 64x64, all on silhouette and shared
//!   edges of the mountain's triangles (one-pixel rims); it meets the
//!   targets only at larger sizes (99.3% at 128x128).
//! - shells-1: spans +-100 (its light) yet has spheres of radius 0.0035,
//!   which the 16-bit fixed-point scene format cannot hold (compile error).
//! - tree-1: cones with unequal radii, which have no chip kernel.

use std::path::PathBuf;

use firmware::scene::Scene;
use firmware::tracer::Options;
use tb::cmd_render::render;

fn check(name: &str) {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/spd")
        .join(name);
    let scene = Scene::load(&p).unwrap_or_else(|e| panic!("{e}"));
    let opt = Options {
        width: 48,
        height: 48,
        ..Options::default()
    };
    let (_, rep) = render(&scene, &opt, false, None).unwrap();
    let j = &rep.json;
    let psnr = j["psnr_db"].as_f64().unwrap();
    let hits = j["hit_agreement"].as_f64().unwrap();
    eprintln!(
        "{name} 48x48: {} cycles, {psnr:.2} dB, hit agreement {hits:.4}",
        j["cycles"]
    );
    assert!(psnr >= 30.0, "{name}: PSNR {psnr:.2} dB < 30");
    assert!(hits >= 0.99, "{name}: hit agreement {hits:.4} < 0.99");
}

#[test]
fn balls_1() {
    check("balls-1.nff");
}

#[test]
fn jacks_1() {
    check("jacks-1.nff");
}

#[test]
fn lattice_1() {
    check("lattice-1.nff");
}

#[test]
fn rings_1() {
    check("rings-1.nff");
}

#[test]
fn tetra_1() {
    check("tetra-1.nff");
}
