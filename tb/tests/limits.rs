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

/// One image-size limit everywhere:
/// `--size` on every command and a scene's own resolution.
#[test]
fn every_image_size_has_the_same_limit_and_an_estimate() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        vec!["render", "--size", "5000x5000"],
        vec!["bench", "--size", "16384x16384"],
        vec!["sweep", "--size", "16384x16384", "--out-dir", "x"],
    ] {
        let (code, err) = morphosys(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.contains("1..=4096") && err.contains("GB"),
            "{args:?}: {err}"
        );
    }
    let nff = dir.path().join("big.nff");
    std::fs::write(
        &nff,
        "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 16384 16384\n\
         b 0 0 0\nl 1 1 1\nf 1 0 0 0.5 0.5 3 0 1\ns 0 0 0 1\n",
    )
    .unwrap();
    let png = dir.path().join("x.png");
    let (code, err) = morphosys(&[
        "reference",
        nff.to_str().unwrap(),
        "--out",
        png.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("resolution 16384x16384") && err.contains("--size") && err.contains("11 GB"),
        "{err}"
    );
    assert!(!png.exists());
    // within the limit from --size, the scene's resolution aside
    let (code, err) = morphosys(&[
        "reference",
        nff.to_str().unwrap(),
        "--size",
        "8x8",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
}

/// Every 16-bit count of the scene image is checked, never wrapped (issue
/// 18, item 4: 70,000 spheres compiled with a count field of 65535).
#[test]
fn counts_past_the_image_fields_are_refused_at_the_first_object_past_them() {
    let dir = tempfile::tempdir().unwrap();
    let nff = dir.path().join("many.nff");
    let mut text = String::from(
        "v\nfrom 0 0 -30\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 64 64\n\
         b 0 0 0\nl 1 1 -10\nf 1 0 0 0.5 0.5 3 0 1\n",
    );
    for i in 0..70_000 {
        let (x, y, z) = (i % 41, (i / 41) % 41, i / (41 * 41));
        text.push_str(&format!(
            "s {} {} {} 0.05\n",
            x as f64 * 0.5 - 10.0,
            y as f64 * 0.5 - 10.0,
            z as f64 * 0.5 - 10.0
        ));
    }
    std::fs::write(&nff, text).unwrap();
    let img = dir.path().join("many.img");
    let (code, err) = morphosys(&[
        "compile",
        nff.to_str().unwrap(),
        "--out",
        img.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    // 10 header lines, then sphere number 65,536 (index 65,535)
    assert!(
        err.contains("many.nff:65546:") && err.contains("70000 spheres") && err.contains("65535"),
        "{err}"
    );
    assert!(!img.exists());
}

/// Scenes too large are refused while being read, before they can take the
/// machine's memory (1.89 M spheres aborted on a failed
/// 6 GB allocation): under a 2 GB address-space cap, one located line.
#[test]
fn huge_scenes_are_refused_while_read_within_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let head = "v\nfrom 0 0 -30\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 64 64\n\
                b 0 0 0\nl 1 1 -10\nf 1 0 0 0.5 0.5 3 0 1\n";
    let n = firmware::scene::MAX_OBJECTS + 1000;
    let mut text = String::with_capacity(n * 24);
    text.push_str(head);
    for i in 0..n {
        text.push_str(&format!("s {} {} 0 0.05\n", i % 1000, i / 1000));
    }
    let nff = dir.path().join("huge.nff");
    std::fs::write(&nff, &text).unwrap();
    let mut toml =
        String::from("[camera]\nfrom = [0, 0, 10]\nat = [0, 0, 0]\nup = [0, 1, 0]\nangle = 45\n");
    for _ in 0..n {
        toml.push_str("[[object]]\n");
    }
    let tml = dir.path().join("huge.toml");
    std::fs::write(&tml, &toml).unwrap();
    let big = dir.path().join("big.nff");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(firmware::scene::MAX_FILE_BYTES + 1)
        .unwrap();
    let bin = env!("CARGO_BIN_EXE_morphosys");
    for (file, says) in [
        (
            &nff,
            format!(
                "huge.nff:{}:1: more than",
                firmware::scene::MAX_OBJECTS + 11
            ),
        ),
        (
            &tml,
            format!(
                "huge.toml:{}:1: more than",
                firmware::scene::MAX_OBJECTS + 6
            ),
        ),
        (&big, "big.nff: the file is 67 MB".to_string()),
    ] {
        let out = Command::new("sh")
            .arg("-c")
            .arg(format!(
                "ulimit -v 2000000 && exec {bin} reference {} --out {}",
                file.display(),
                dir.path().join("x.png").display()
            ))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains(&says), "{says}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
}
