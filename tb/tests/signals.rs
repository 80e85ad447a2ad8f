//! Interrupted runs leave nothing behind: SIGINT or
//! SIGTERM removes the partial waveform and the temporary folders; a
//! partial file left by a run killed outright (SIGKILL) is removed by the
//! next run writing the same waveform.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn spawn(dir: &Path, args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .current_dir(dir)
        .env("TMPDIR", dir.join("tmp"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn partials(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".partial"))
        .collect()
}

fn signal(child: &Child, sig: i32) {
    // SAFETY: kill(2) on our own child's pid.
    assert_eq!(unsafe { libc::kill(child.id() as i32, sig) }, 0);
}

fn loop_program(dir: &Path) {
    std::fs::create_dir_all(dir.join("tmp")).unwrap();
    std::fs::write(
        dir.join("loop.s"),
        ".text\nstart:\n  addi r1, r1, 1\n  j start\n",
    )
    .unwrap();
}

#[test]
fn sigint_during_a_trace_removes_the_partial_waveform() {
    let d = tempfile::tempdir().unwrap();
    loop_program(d.path());
    let child = spawn(
        d.path(),
        &[
            "run",
            "loop.s",
            "--vcd",
            "w.vcd",
            "--max-cycles",
            "1000000000",
            "--trace-scope",
            "tinyrisc",
        ],
    );
    let t0 = Instant::now();
    while partials(d.path()).is_empty() {
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "no partial waveform appeared"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    signal(&child, libc::SIGINT);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted"), "{err}");
    assert!(partials(d.path()).is_empty(), "{:?}", partials(d.path()));
    assert!(!d.path().join("w.vcd").exists());
}

#[test]
fn sigterm_during_bench_removes_its_temporary_folder() {
    let d = tempfile::tempdir().unwrap();
    loop_program(d.path());
    let child = spawn(d.path(), &["bench", "--size", "64x64", "--repeat", "20"]);
    // bench makes its temporary folder (under TMPDIR) at once
    let t0 = Instant::now();
    while std::fs::read_dir(d.path().join("tmp")).unwrap().count() == 0 {
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "bench made no temporary folder"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    signal(&child, libc::SIGTERM);
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let left: Vec<_> = std::fs::read_dir(d.path().join("tmp")).unwrap().collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn a_partial_left_by_a_killed_run_goes_with_the_next_run() {
    let d = tempfile::tempdir().unwrap();
    loop_program(d.path());
    // A partial of w.vcd from a process that no longer exists (SIGKILL
    // leaves no chance to clean up), and one of another waveform.
    let dead = d.path().join(".w.vcd.4194000.AbCdEf.partial");
    let other = d.path().join(".x.vcd.4194000.AbCdEf.partial");
    std::fs::write(&dead, "junk").unwrap();
    std::fs::write(&other, "junk").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .current_dir(d.path())
        .args(["run", "loop.s", "--vcd", "w.vcd", "--max-cycles", "100"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1)); // no halt within 100 cycles
    assert!(d.path().join("w.vcd").exists());
    assert!(!dead.exists(), "the stale partial of w.vcd is still there");
    assert!(other.exists(), "another waveform's partial was removed");
}
