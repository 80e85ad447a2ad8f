//! Golden firmware: the programs the generator emits for the default scene
//! and two SPD scenes (256x256, the default options: the packet traversal,
//! and the paper's traversal on tetra-1), checked in under
//! `firmware/golden/`. A change to the generator shows up here as a diff
//! of the firmware itself; when it is intended, regenerate them with
//! `UPDATE_GOLDEN=1 cargo test -p morphosys-tb --test golden` and commit
//! the new files with the change.

use std::path::PathBuf;

use firmware::scene::Scene;
use firmware::tracer::{Numerics, Options, Traversal};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// (golden file, scene path from the repository root, traversal)
const GOLDEN: [(&str, &str, Traversal); 3] = [
    ("default.s", "scenes/default.toml", Traversal::Packet),
    ("jacks-1.s", "scenes/spd/jacks-1.nff", Traversal::Packet),
    (
        "tetra-1-paper.s",
        "scenes/spd/tetra-1.nff",
        Traversal::Paper,
    ),
];

#[test]
fn the_generated_firmware_is_the_golden_one() {
    let update = std::env::var_os("UPDATE_GOLDEN").is_some();
    let mut failures = Vec::new();
    for (file, scene_path, traversal) in GOLDEN {
        let mut scene = Scene::load(&root().join(scene_path)).unwrap();
        // As `morphosys render` names it when run from the repository root.
        scene.source = scene_path.to_string();
        let opt = Options {
            traversal,
            ..Options::default()
        };
        let fw = tb::render::choose_firmware(
            &scene,
            &opt,
            &Numerics::default(),
            &rtl::Timing::default(),
        )
        .unwrap();
        let path = root().join("firmware/golden").join(file);
        if update {
            std::fs::write(&path, &fw.source).unwrap();
            continue;
        }
        let golden = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (UPDATE_GOLDEN=1 writes it)", path.display()));
        if golden != fw.source {
            let (g, n): (Vec<&str>, Vec<&str>) =
                (golden.lines().collect(), fw.source.lines().collect());
            let first = g
                .iter()
                .zip(&n)
                .position(|(a, b)| a != b)
                .unwrap_or(g.len().min(n.len()));
            let show = |v: &[&str]| {
                v.iter()
                    .enumerate()
                    .skip(first.saturating_sub(2))
                    .take(6)
                    .map(|(k, l)| format!("    {:5} | {l}", k + 1))
                    .collect::<Vec<_>>()
                    .join("\n")
            };
            failures.push(format!(
                "firmware/golden/{file} ({scene_path}, {traversal} traversal): the generator's output differs from line {} on ({} lines, golden {}):\n  golden:\n{}\n  generated:\n{}",
                first + 1,
                n.len(),
                g.len(),
                show(&g),
                show(&n)
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{}\n(if the change is intended: UPDATE_GOLDEN=1 cargo test -p morphosys-tb --test golden)",
        failures.join("\n\n")
    );
}
