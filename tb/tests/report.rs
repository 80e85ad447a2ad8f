//! `docs/results.md` and the README's results table are what `morphosys
//! report` writes from the current build: the sections that run in CI's
//! time are regenerated here and must equal the committed documents byte
//! for byte (a change of cycles, PSNR or hit agreement anywhere in them
//! fails this test until `morphosys report --only SECTION` is run and the
//! documents committed).

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The first line where `a` and `b` differ, both shown.
fn first_difference(a: &str, b: &str) -> String {
    for (k, (x, y)) in a.lines().zip(b.lines()).enumerate() {
        if x != y {
            return format!("line {}:\n  committed:   {x}\n  regenerated: {y}", k + 1);
        }
    }
    format!(
        "the files differ in length ({} against {} lines)",
        a.lines().count(),
        b.lines().count()
    )
}

#[test]
fn the_checked_sections_are_what_report_writes() {
    let root = repo();
    let d = tempfile::tempdir().unwrap();
    let results = d.path().join("results.md");
    let readme = d.path().join("README.md");
    std::fs::copy(root.join("docs/results.md"), &results).unwrap();
    std::fs::copy(root.join("README.md"), &readme).unwrap();
    let checked: Vec<&str> = tb::cmd_report::sections()
        .into_iter()
        .filter(|s| s.checked)
        .map(|s| s.id)
        .collect();
    assert!(checked.contains(&"headline"));
    let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .current_dir(&root)
        .args(["--quiet", "report", "--only", &checked.join(",")])
        .arg("--out")
        .arg(&results)
        .arg("--readme")
        .arg(&readme)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for (committed, regenerated) in [
        (root.join("docs/results.md"), &results),
        (root.join("README.md"), &readme),
    ] {
        let a = std::fs::read_to_string(&committed).unwrap();
        let b = std::fs::read_to_string(regenerated).unwrap();
        assert!(
            a == b,
            "{} is not what `morphosys report --only {}` writes: {}",
            committed.display(),
            checked.join(","),
            first_difference(&a, &b)
        );
    }
}

/// `--only` names sections that exist, and a document without a
/// section's markers is refused before any render runs.
#[test]
fn report_refuses_unknown_sections_and_documents_without_markers() {
    let root = repo();
    let d = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
            .current_dir(&root)
            .arg("report")
            .args(args)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let (code, err) = run(&["--only", "nope"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("no section `nope`") && err.contains("headline"),
        "{err}"
    );
    let bare = d.path().join("bare.md");
    std::fs::write(&bare, "# Results\n").unwrap();
    let (code, err) = run(&["--only", "ways", "--out", bare.to_str().unwrap()]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("bare.md") && err.contains("no section `ways`"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&bare).unwrap(), "# Results\n");
}
