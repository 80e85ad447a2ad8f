//! Golden firmware: the programs the generator emits for the default scene
//! and three SPD scenes (256x256, the default options: the packet
//! traversal, the paper's traversal on tetra-1, and merged shadow packets
//! on rings-1), checked in under
//! `firmware/golden/`. A change to the generator shows up here as a diff
//! of the firmware itself; when it is intended, regenerate them with
//! `UPDATE_GOLDEN=1 cargo test -p morphosys-tb --test golden` and commit
//! the new files with the change.

use std::path::PathBuf;

use firmware::scene::Scene;
use firmware::tracer::{Numerics, Options, ShadowPackets, Traversal};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// (golden file, scene path from the repository root, traversal, shadow
/// packets)
const GOLDEN: [(&str, &str, Traversal, ShadowPackets); 4] = [
    (
        "default.s",
        "scenes/default.toml",
        Traversal::Packet,
        ShadowPackets::Auto,
    ),
    (
        "jacks-1.s",
        "scenes/spd/jacks-1.nff",
        Traversal::Packet,
        ShadowPackets::Auto,
    ),
    (
        "tetra-1-paper.s",
        "scenes/spd/tetra-1.nff",
        Traversal::Paper,
        ShadowPackets::Auto,
    ),
    (
        "rings-1-merged.s",
        "scenes/spd/rings-1.nff",
        Traversal::Packet,
        ShadowPackets::Merged,
    ),
];

#[test]
fn the_generated_firmware_is_the_golden_one() {
    let update = std::env::var_os("UPDATE_GOLDEN").is_some();
    let mut failures = Vec::new();
    for (file, scene_path, traversal, shadows) in GOLDEN {
        let mut scene = Scene::load(&root().join(scene_path)).unwrap();
        // As `morphosys render` names it when run from the repository root.
        scene.source = scene_path.to_string();
        let opt = Options {
            traversal,
            shadows,
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

/// The golden programs read as hand-written firmware: every RC RAM
/// address and every TinyRISC load/store offset by name (no `[#286]`, no
/// `[r0 + #256]`, no `lw r2, 8(r5)`), no instruction at column 0 (labels,
/// constants, data and directives only), and at least 15% of the lines
/// commented.
#[test]
fn the_golden_firmware_names_its_numbers() {
    let is_name = |s: &str| {
        s.chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
    };
    for (file, _, _, _) in GOLDEN {
        let path = root().join("firmware/golden").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        let mut problems = Vec::new();
        let (mut lines, mut commented) = (0usize, 0usize);
        for (k, line) in text.lines().enumerate() {
            lines += 1;
            commented += line.contains(';') as usize;
            let code = line.split(';').next().unwrap_or("");
            let at = |what: &str| format!("{file}:{}: {what}: {line}", k + 1);
            // RC memory operands: `[B]` or `[A + B]` with B an immediate.
            if let (Some(a), Some(b)) = (code.find('['), code.find(']')) {
                let inner = &code[a + 1..b];
                let imm = inner.rsplit('+').next().unwrap_or("").trim();
                if let Some(v) = imm.strip_prefix('#') {
                    if !is_name(v.trim()) {
                        problems.push(at("a bare RAM address"));
                    }
                }
            }
            let trimmed = code.trim_start();
            let word = trimmed.split_whitespace().next().unwrap_or("");
            // TinyRISC loads and stores: `OFFSET(rB)` with a named offset or none.
            if [
                "lw", "lh", "lhu", "lb", "lbu", "sw", "sh", "sb", "lfb", "sfb",
            ]
            .contains(&word)
            {
                if let Some(p) = code.find('(') {
                    let off = code[..p].rsplit(',').next().unwrap_or("").trim();
                    if !off.is_empty() && !is_name(off) {
                        problems.push(at("a bare load/store offset"));
                    }
                }
            }
            // Nothing but labels, constants, data, directives and
            // comments at column 0.
            if !code.is_empty() && !code.starts_with(char::is_whitespace) && !code.starts_with('.')
            {
                let label_only = code.trim_end().ends_with(':');
                let constant = code.contains('=');
                let data = code
                    .split_once(':')
                    .is_some_and(|(_, rest)| rest.trim_start().starts_with('.'));
                if !(label_only || constant || data) {
                    problems.push(at("an instruction at column 0"));
                }
            }
        }
        let share = commented as f64 / lines as f64;
        eprintln!("{file}: {lines} lines, {:.1}% commented", 100.0 * share);
        if share < 0.15 {
            problems.push(format!(
                "{file}: {:.1}% of the lines have a comment, under 15%",
                100.0 * share
            ));
        }
        assert!(problems.is_empty(), "{}", problems.join("\n"));
    }
}

/// `docs/tracer.md` reads the default scene's program ("One packet through
/// the program") in excerpts: each ```asm block is copied from
/// `firmware/golden/default.s`, runs of lines separated by `...` where
/// lines are left out. Each run must still be in the file, its lines
/// consecutive and the runs in the file's order, so the walkthrough cannot
/// drift from the program it describes.
#[test]
fn the_tracer_walkthrough_quotes_the_golden_program() {
    let doc = std::fs::read_to_string(root().join("docs/tracer.md")).unwrap();
    let golden = std::fs::read_to_string(root().join("firmware/golden/default.s")).unwrap();
    let lines: Vec<&str> = golden.lines().collect();
    let mut blocks = Vec::new();
    let mut current: Option<(usize, Vec<&str>)> = None;
    for (k, l) in doc.lines().enumerate() {
        match (&mut current, l.trim_end()) {
            (None, "```asm") => current = Some((k + 1, Vec::new())),
            (Some(_), "```") => blocks.push(current.take().unwrap()),
            (Some((_, v)), _) => v.push(l),
            _ => {}
        }
    }
    assert!(
        blocks.len() >= 8,
        "docs/tracer.md: {} asm excerpts; the walkthrough has more",
        blocks.len()
    );
    let mut failures = Vec::new();
    for (line, block) in &blocks {
        let mut from = 0;
        for run in block.split(|l| l.trim() == "...") {
            if run.is_empty() {
                continue;
            }
            match (from..lines.len().saturating_sub(run.len() - 1))
                .find(|&i| lines[i..i + run.len()] == run[..])
            {
                Some(i) => from = i + run.len(),
                None => failures.push(format!(
                    "docs/tracer.md:{}: the excerpt's lines from `{}` are not in firmware/golden/default.s (in this order, after the previous run)",
                    line + 1,
                    run[0].trim()
                )),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
