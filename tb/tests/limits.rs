//! Absurd requests are refused up front, with an estimate of what they
//! would need, one line on stderr, a non-zero exit and no file left behind.

use std::process::Command;

fn morphosys(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("NO_COLOR", "1")
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn huge_images_are_refused_with_an_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    for cmd in ["render", "reference"] {
        let (code, err) = morphosys(&[
            cmd,
            "--size",
            "100000x100000",
            "--out",
            png.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{err}");
        assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
        assert!(err.contains("400 GB") && err.contains("hours"), "{err}");
        assert!(!err.contains("panicked"));
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn a_full_frame_trace_of_every_signal_is_refused_with_an_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let vcd = dir.path().join("frame.vcd");
    let png = dir.path().join("frame.png");
    let (code, err) = morphosys(&[
        "render",
        "--size",
        "16x16",
        "--vcd",
        vcd.to_str().unwrap(),
        "--trace-cycles",
        "50000000",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("would write about") && err.contains("GB"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "no VCD, PNG or temporary file"
    );
}

#[test]
fn runaway_firmware_stops_at_the_cycle_budget_with_cycle_and_pc() {
    let dir = tempfile::tempdir().unwrap();
    let prog = dir.path().join("loop.s");
    std::fs::write(&prog, ".text\nstart:\n  addi r1, r1, 1\n  j start\n").unwrap();
    let (code, err) = morphosys(&["run", prog.to_str().unwrap(), "--max-cycles", "5000"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("cycle 5000") && err.contains("pc 0x"), "{err}");
}
