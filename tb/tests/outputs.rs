//! Output files under hostile or careless use: devices
//! and FIFOs are written through, never replaced; symbolic links are
//! followed and kept; standard output is `-`; an output that is an input or
//! another output is refused before any work.

mod common;
use common::morphosys;

use std::path::Path;

fn scene() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/default.toml")
        .display()
        .to_string()
}

#[test]
fn devices_are_written_through_not_replaced() {
    let null = Path::new("/dev/null");
    if !null.exists() {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let s = scene();
    for args in [
        vec![
            "render",
            &s,
            "--size",
            "8x8",
            "--out",
            "/dev/null",
            "--json",
            "/dev/null",
        ],
        vec![
            "reference",
            &s,
            "--size",
            "8x8",
            "--out",
            "/dev/null",
            "--hits",
            "/dev/null",
        ],
        vec!["compile", &s, "--out", "/dev/null"],
        vec!["spd", "tetra", "--size", "1", "--out", "/dev/null"],
    ] {
        let (ok, _, err) = morphosys(d.path(), &args);
        assert!(ok, "{args:?}: {err}");
        let m = std::fs::metadata(null).unwrap();
        assert!(!m.is_file(), "{args:?} replaced /dev/null with a file");
    }
    // nothing was left beside the device either
    assert!(std::fs::read_dir("/dev").unwrap().all(|e| !e
        .unwrap()
        .file_name()
        .to_string_lossy()
        .starts_with(".tmp")));
}

#[test]
fn a_fifo_takes_a_waveform_and_no_partial_file_is_left() {
    let d = tempfile::tempdir().unwrap();
    let fifo = d.path().join("wave.vcd");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo(3) with a NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    let s = scene();
    let (ok, _, err) = morphosys(
        d.path(),
        &[
            "render",
            &s,
            "--size",
            "8x8",
            "--out",
            "o.png",
            "--vcd",
            "wave.vcd",
            "--trace-cycles",
            "200",
        ],
    );
    assert!(ok, "{err}");
    let vcd = reader.join().unwrap();
    assert!(String::from_utf8_lossy(&vcd).contains("$enddefinitions"));
    let names: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.ends_with(".partial")), "{names:?}");
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
}

use std::os::unix::fs::FileTypeExt;

#[test]
fn symlinks_are_followed_and_stdout_is_a_dash() {
    let d = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink("real.png", d.path().join("link.png")).unwrap();
    let s = scene();
    let (ok, _, err) = morphosys(
        d.path(),
        &["render", &s, "--size", "8x8", "--out", "link.png"],
    );
    assert!(ok, "{err}");
    let link = d.path().join("link.png");
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    let png = std::fs::read(d.path().join("real.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");

    // `--out -`: the PNG on standard output, the report on standard error.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .current_dir(d.path())
        .args(["render", &s, "--size", "8x8", "--out", "-"])
        .output()
        .unwrap();
    assert!(out.status.success());
    assert_eq!(&out.stdout[1..4], b"PNG");
    assert!(String::from_utf8_lossy(&out.stderr).contains("psnr"));

    // `/dev/stdout` redirected to a regular file: written through the
    // descriptor, the report on standard error, the file not replaced.
    let file = d.path().join("so.nff");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .current_dir(d.path())
        .args(["spd", "tetra", "--size", "1", "--out", "/dev/stdout"])
        .stdout(std::fs::File::create(&file).unwrap())
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.starts_with("b ") && text.contains("\nv\n"), "{text}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("tetra size 1"));
}

#[test]
fn an_output_over_an_input_or_another_output_is_refused_before_the_work() {
    let d = tempfile::tempdir().unwrap();
    let nff = d.path().join("s.nff");
    let (ok, _, err) = morphosys(d.path(), &["spd", "tetra", "--size", "1", "--out", "s.nff"]);
    assert!(ok, "{err}");
    let before = std::fs::read(&nff).unwrap();
    std::fs::write(d.path().join("d.s"), "halt\n").unwrap();
    for (args, says) in [
        (
            vec!["render", "s.nff", "--size", "8x8", "--out", "s.nff"],
            "input SCENE",
        ),
        (
            vec!["render", "s.nff", "--size", "8x8", "--out", "./s.nff"],
            "input SCENE",
        ),
        (
            vec![
                "render", "s.nff", "--size", "8x8", "--out", "o.png", "--json", "o.png",
            ],
            "same file",
        ),
        (
            vec!["reference", "s.nff", "--size", "8x8", "--json", "s.nff"],
            "input SCENE",
        ),
        (vec!["compile", "s.nff", "--out", "s.nff"], "input SCENE"),
        (vec!["asm", "d.s", "-o", "d.s"], "input FILE"),
    ] {
        let (ok, out, err) = morphosys(d.path(), &args);
        assert!(!ok, "{args:?} succeeded");
        assert!(err.contains(says), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(
            !out.contains("cycles"),
            "{args:?} worked before refusing: {out}"
        );
    }
    assert_eq!(
        std::fs::read(&nff).unwrap(),
        before,
        "the scene was overwritten"
    );
    assert_eq!(
        std::fs::read_to_string(d.path().join("d.s")).unwrap(),
        "halt\n"
    );
    assert!(!d.path().join("o.png").exists());
}

/// A waveform's side files (its `.gtkw` save file, translate-filter files
/// and Surfer label decoders) are outputs too: one that would overwrite an
/// input, or another output, is refused before the work, and both files
/// are left as they were.
#[test]
fn a_waveforms_side_files_cannot_overwrite_an_input_or_an_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = scene();
    // The program to render with, named like the waveform's rc_op filter.
    let (ok, _, err) = morphosys(
        d,
        &["render", &s, "--size", "16x16", "--emit-asm", "w.rc_op.txt"],
    );
    assert!(ok, "{err}");
    let program = std::fs::read(d.join("w.rc_op.txt")).unwrap();
    let (ok, _, err) = morphosys(
        d,
        &[
            "render",
            &s,
            "--size",
            "16x16",
            "--firmware",
            "w.rc_op.txt",
            "--vcd",
            "w.vcd",
        ],
    );
    assert!(!ok);
    assert!(err.contains("rc_op") && err.contains("--firmware"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert_eq!(std::fs::read(d.join("w.rc_op.txt")).unwrap(), program);
    assert!(!d.join("w.vcd").exists());
    // The JSON named like the save file.
    std::fs::write(d.join("w.gtkw"), "keep").unwrap();
    let (ok, _, err) = morphosys(
        d,
        &[
            "render", &s, "--size", "16x16", "--vcd", "w.vcd", "--json", "w.gtkw",
        ],
    );
    assert!(!ok);
    assert!(err.contains("save file") && err.contains("--json"), "{err}");
    assert_eq!(std::fs::read_to_string(d.join("w.gtkw")).unwrap(), "keep");
    // `run` checks the same: a program named like a label filter.
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/conformance/cbcast.s"),
        d.join("p.code_labels.txt"),
    )
    .unwrap();
    let (ok, _, err) = morphosys(d, &["run", "p.code_labels.txt", "--vcd", "p.vcd"]);
    assert!(!ok);
    assert!(err.contains("code_labels") && err.contains("FILE"), "{err}");
}

/// An output keeps the permissions of the file it replaces, and a new one
/// gets the umask's (every output was made 0644).
#[test]
fn outputs_keep_their_mode_and_new_ones_follow_the_umask() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mode = |f: &str| std::fs::metadata(d.join(f)).unwrap().permissions().mode() & 0o777;
    let bin = env!("CARGO_BIN_EXE_morphosys");
    let sh = |cmd: &str| {
        let st = std::process::Command::new("bash")
            .current_dir(d)
            .args(["-c", &format!("umask 077 && '{bin}' {cmd}")])
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{cmd}: {}",
            String::from_utf8_lossy(&st.stderr)
        );
    };
    // New files, umask 077: private.
    sh("spd tetra --size 1 --out t.nff");
    assert_eq!(mode("t.nff"), 0o600);
    sh("render t.nff --size 8x8 --out t.png --vcd w.vcd --trace-cycles 50 -q");
    for f in ["t.png", "w.vcd", "w.gtkw", "w.code_labels.txt"] {
        assert_eq!(mode(f), 0o600, "{f}");
    }
    // Existing files keep their mode, whatever the umask.
    for f in ["t.nff", "t.png", "w.vcd", "w.gtkw"] {
        std::fs::set_permissions(d.join(f), std::fs::Permissions::from_mode(0o640)).unwrap();
    }
    sh("spd tetra --size 1 --out t.nff");
    sh("render t.nff --size 8x8 --out t.png --vcd w.vcd --trace-cycles 50 -q");
    for f in ["t.nff", "t.png", "w.vcd", "w.gtkw"] {
        assert_eq!(mode(f), 0o640, "{f}");
    }
}

/// A regular file under /dev (`/dev/shm/...`) is an ordinary output,
/// replaced whole; a descriptor's regular file (`/dev/fd/N` opened
/// read-write over a longer file) is written from its start and cut to the
/// new length. Either way the JSON is exactly the render's, with
/// no old tail after the new JSON.
#[test]
fn regular_files_under_dev_and_descriptors_are_written_whole() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = scene();
    let long = "x".repeat(20_000);
    let shm = Path::new("/dev/shm");
    if shm.is_dir() {
        let f = shm.join(format!("morphosys-test-{}.json", std::process::id()));
        std::fs::write(&f, &long).unwrap();
        let (ok, _, err) = morphosys(
            d,
            &[
                "render",
                &s,
                "--size",
                "8x8",
                "--out",
                "/dev/null",
                "--json",
                f.to_str().unwrap(),
            ],
        );
        let text = std::fs::read_to_string(&f).unwrap();
        let _ = std::fs::remove_file(&f);
        assert!(ok, "{err}");
        serde_json::from_str::<serde_json::Value>(&text).expect("whole JSON");
    }
    std::fs::write(d.join("fd.json"), &long).unwrap();
    let bin = env!("CARGO_BIN_EXE_morphosys");
    let st = std::process::Command::new("bash")
        .current_dir(d)
        .args([
            "-c",
            &format!(
                "'{bin}' render '{s}' --size 8x8 --out /dev/null --json /dev/fd/4 4<> fd.json"
            ),
        ])
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let text = std::fs::read_to_string(d.join("fd.json")).unwrap();
    serde_json::from_str::<serde_json::Value>(&text).expect("whole JSON through the descriptor");
}

/// `render --json FIFO --skip-done` renders into the FIFO instead of
/// blocking on reading it, and `sweep --merge` with a FIFO among its points
/// names it instead of hanging. Bounded by `timeout`.
#[test]
fn a_fifo_where_a_finished_render_is_looked_for_does_not_hang() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = scene();
    let bin = env!("CARGO_BIN_EXE_morphosys");
    let run = |cmd: &str| {
        std::process::Command::new("bash")
            .current_dir(d)
            .args(["-c", cmd])
            .output()
            .unwrap()
    };
    assert!(run("mkfifo f.json").status.success());
    let out = run(&format!(
        "timeout 20 '{bin}' render '{s}' --size 8x8 --out /dev/null --json f.json --skip-done & \
         timeout 20 cat f.json > got.json; wait $!"
    ));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let got = std::fs::read_to_string(d.join("got.json")).unwrap();
    serde_json::from_str::<serde_json::Value>(&got).expect("the render's JSON through the FIFO");
    // A plan whose points folder holds a FIFO for one render.
    let (ok, _, err) = morphosys(
        d,
        &[
            "sweep",
            &s,
            "--only",
            "broadcast",
            "--size",
            "8x8",
            "--plan",
            "plan",
        ],
    );
    assert!(ok, "{err}");
    let jobs = std::fs::read_to_string(d.join("plan/jobs.txt")).unwrap();
    let first = jobs.lines().next().unwrap();
    let name = first
        .split(" --json ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .unwrap();
    assert!(run(&format!("mkfifo '{name}'")).status.success());
    let out = run(&format!(
        "timeout 20 '{bin}' sweep --merge plan --out-dir m"
    ));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_ne!(out.status.code(), Some(124), "the merge hung");
    assert!(err.contains("not a regular file"), "{err}");
}
