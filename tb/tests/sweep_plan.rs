//! Sweeps past one process: `sweep --plan` writes one
//! `morphosys render` per distinct render, GNU parallel runs them, `sweep
//! --merge` writes the table and charts, byte for byte those of the same
//! sweep run in one process; reruns skip what is done, and a killed job
//! leaves nothing that looks complete.

mod common;
use common::morphosys;
use std::path::Path;
use std::process::{Command, Stdio};

/// GNU parallel on `jobs` with 2 job slots: its output. The tests that
/// call it are ignored by default (`cargo test -- --ignored` runs them;
/// `.ci/run` does, after installing GNU parallel) and fail without it.
fn parallel(jobs: &Path) -> String {
    let out = Command::new("parallel")
        .args(["--jobs", "2"])
        .stdin(std::fs::File::open(jobs).unwrap())
        .output()
        .unwrap_or_else(|e| {
            panic!("GNU parallel is not installed (apt-get install parallel): {e}")
        });
    assert!(
        out.status.success(),
        "parallel: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[ignore = "needs GNU parallel (Debian package parallel); .ci/run installs it and runs the ignored tests"]
#[test]
fn planned_sweep_on_gnu_parallel_merges_to_the_in_process_sweep() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    // A timing file of our own, so the plan carries one (and its knob).
    std::fs::write(d.join("slowload.toml"), "[risc]\nload = 4\n").unwrap();
    let sweep = [
        "sweep",
        "--size",
        "16x16",
        "--families",
        "balls,tetra",
        "--max-size",
        "1",
        "--family-size",
        "16x16",
        "--timing",
        "slowload.toml",
    ];
    let mut planned = sweep.to_vec();
    planned.extend(["--plan", "plan"]);
    let (ok, out, err) = morphosys(d, &planned);
    assert!(ok, "plan: {err}");
    assert!(
        out.contains("parallel") && out.contains("jobs.txt"),
        "{out}{err}"
    );
    let plan = d.join("plan");
    let jobs = std::fs::read_to_string(plan.join("jobs.txt")).unwrap();
    let lines: Vec<&str> = jobs.lines().collect();
    // Every line a self-contained render writing its own JSON; equal
    // configurations (the paper's and newton_steps=2, ...) share a line.
    assert!(lines.len() > 20, "{jobs}");
    for l in &lines {
        assert!(l.contains(" render ") && l.contains("/points/") && l.ends_with("--skip-done"));
    }
    assert!(jobs.contains("--timing") && jobs.contains("slowload.toml"));
    parallel(&plan.join("jobs.txt"));
    let (ok, out, err) = morphosys(d, &["sweep", "--merge", "plan"]);
    assert!(ok, "merge: {err}");
    assert!(err.is_empty() || !err.contains("missing"), "{err}");
    assert!(out.contains("merged"), "{out}");

    // The same sweep in one process: the same table, the same charts.
    let mut here = sweep.to_vec();
    here.extend(["--out-dir", "here"]);
    let (ok, _, err) = morphosys(d, &here);
    assert!(ok, "sweep: {err}");
    let csv = std::fs::read(d.join("here/results.csv")).unwrap();
    assert_eq!(
        String::from_utf8_lossy(&std::fs::read(plan.join("results.csv")).unwrap()),
        String::from_utf8_lossy(&csv),
        "the merged table differs from the in-process sweep's"
    );
    assert!(csv.len() > 1000);
    for chart in [
        "fig8.svg",
        "pareto.svg",
        "scaling.svg",
        "broadcast.svg",
        "timing.svg",
    ] {
        assert_eq!(
            std::fs::read(plan.join(chart)).unwrap(),
            std::fs::read(d.join("here").join(chart)).unwrap(),
            "{chart}"
        );
    }

    // A rerun of the plan renders nothing.
    let out = parallel(&plan.join("jobs.txt"));
    assert_eq!(
        out.matches("already rendered with these arguments").count(),
        lines.len(),
        "{out}"
    );

    // A missing render is named; the rest are merged.
    std::fs::remove_file(plan.join("points/default-ways-8.json")).unwrap();
    let (ok, out, err) = morphosys(d, &["sweep", "--merge", "plan", "--out-dir", "part"]);
    assert!(ok, "{err}");
    assert!(err.contains("default-ways-8"), "{err}");
    let rows = std::fs::read_to_string(d.join("part/results.csv")).unwrap();
    assert_eq!(
        rows.lines().count() + 1,
        String::from_utf8_lossy(&csv).lines().count()
    );
    assert!(!rows.contains(",ways,8,"));
    assert!(out.contains("merged"), "{out}");
}

#[test]
fn killed_render_leaves_no_complete_json_and_merge_names_it() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let (ok, _, err) = morphosys(
        d,
        &[
            "sweep",
            "--only",
            "broadcast",
            "--size",
            "1024x1024",
            "--plan",
            "plan",
        ],
    );
    assert!(ok, "{err}");
    let plan = d.join("plan");
    let jobs = std::fs::read_to_string(plan.join("jobs.txt")).unwrap();
    let first = jobs.lines().next().unwrap();
    // Kill the first render inside its frame: once it has used 0.1 s of
    // CPU time (a 1024x1024 frame takes seconds of it on any machine),
    // whatever the wall clock says.
    let mut child = Command::new("sh")
        .args(["-c", &format!("exec {first}")])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let cpu_ticks = |pid: u32| -> u64 {
        let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
        // Fields after the command's closing parenthesis: utime and stime
        // are the 12th and 13th.
        let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
        let f: Vec<u64> = rest
            .split_whitespace()
            .map(|x| x.parse().unwrap_or(0))
            .collect();
        f.get(11).copied().unwrap_or(0) + f.get(12).copied().unwrap_or(0)
    };
    let tick = unsafe { libc::sysconf(libc::_SC_CLK_TCK) }.max(1) as u64;
    while cpu_ticks(child.id()) < tick / 10 {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the render ended before it used 0.1 s of CPU time"
        );
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert!(child.try_wait().unwrap().is_none(), "the render ended");
    child.kill().unwrap();
    child.wait().unwrap();
    // Nothing under points/ parses as a render's report.
    for e in std::fs::read_dir(plan.join("points")).unwrap() {
        let p = e.unwrap().path();
        let text = std::fs::read_to_string(&p).unwrap_or_default();
        assert!(
            serde_json::from_str::<serde_json::Value>(&text).is_err(),
            "{} looks complete",
            p.display()
        );
    }
    // The merge names every render it lacks and fails: nothing is done.
    let (ok, _, err) = morphosys(d, &["sweep", "--merge", "plan"]);
    assert!(!ok);
    assert!(err.contains("default-paper ("), "{err}");
    assert!(err.contains("no render of the plan is complete"), "{err}");
    assert!(!plan.join("results.csv").exists());
}

/// A single-node Slurm inside `dir` (docs/cluster/local-slurm.sh), stopped
/// when dropped.
struct LocalSlurm {
    dir: std::path::PathBuf,
}

impl Drop for LocalSlurm {
    fn drop(&mut self) {
        let _ = Command::new("bash")
            .arg(cluster_script("local-slurm.sh"))
            .arg("stop")
            .arg(&self.dir)
            .output();
    }
}

fn cluster_script(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../docs/cluster")
        .join(name)
}

/// Checks that this machine can run a Slurm of its own: root, and the
/// Debian packages slurm-wlm and munge (`.ci/run` installs them and runs
/// the ignored tests).
fn require_slurm() {
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    let missing: Vec<&str> = ["munged", "slurmctld", "slurmd", "sbatch"]
        .into_iter()
        .filter(|t| {
            !Command::new("sh")
                .args(["-c", &format!("command -v {t}")])
                .output()
                .is_ok_and(|o| o.status.success())
        })
        .collect();
    assert!(
        root,
        "the Slurm test needs root (it starts slurmctld and munged)"
    );
    assert!(
        missing.is_empty(),
        "the Slurm test needs slurm-wlm and munge: {} not found",
        missing.join(", ")
    );
}

#[test]
#[ignore = "needs root, slurm-wlm and munge; .ci/run installs them and runs the ignored tests"]
fn planned_sweep_on_a_slurm_job_array_merges_to_the_in_process_sweep() {
    require_slurm();
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let sweep = ["sweep", "--only", "broadcast", "--size", "16x16"];
    let mut planned = sweep.to_vec();
    planned.extend(["--plan", "plan"]);
    let (ok, _, err) = morphosys(d, &planned);
    assert!(ok, "plan: {err}");

    let slurm = LocalSlurm {
        dir: d.join("slurm"),
    };
    let up = Command::new("bash")
        .arg(cluster_script("local-slurm.sh"))
        .arg("start")
        .arg(&slurm.dir)
        .output()
        .unwrap();
    assert!(
        up.status.success(),
        "local Slurm: {}{}",
        String::from_utf8_lossy(&up.stdout),
        String::from_utf8_lossy(&up.stderr)
    );
    let conf = slurm.dir.join("slurm.conf");
    let submit = Command::new("bash")
        .arg(cluster_script("submit.sh"))
        .arg(d.join("plan"))
        .env("SLURM_CONF", &conf)
        .output()
        .unwrap();
    assert!(
        submit.status.success(),
        "submit.sh: {}",
        String::from_utf8_lossy(&submit.stderr)
    );
    // Wait for the array and the merge (a minute at most).
    let t0 = std::time::Instant::now();
    loop {
        let q = Command::new("squeue")
            .arg("-h")
            .env("SLURM_CONF", &conf)
            .output()
            .unwrap();
        assert!(q.status.success(), "{}", String::from_utf8_lossy(&q.stderr));
        if q.stdout.is_empty() {
            break;
        }
        assert!(
            t0.elapsed().as_secs() < 120,
            "Slurm jobs still queued: {}",
            String::from_utf8_lossy(&q.stdout)
        );
        std::thread::sleep(std::time::Duration::from_millis(500));
    }
    let merged = std::fs::read(d.join("plan/results.csv")).unwrap_or_else(|e| {
        let logs: Vec<String> = std::fs::read_dir(d.join("plan/slurm"))
            .map(|r| {
                r.filter_map(|e| e.ok())
                    .map(|e| std::fs::read_to_string(e.path()).unwrap_or_default())
                    .collect()
            })
            .unwrap_or_default();
        panic!(
            "no merged results.csv ({e}); Slurm logs:\n{}",
            logs.join("\n")
        )
    });
    let mut here = sweep.to_vec();
    here.extend(["--out-dir", "here"]);
    let (ok, _, err) = morphosys(d, &here);
    assert!(ok, "sweep: {err}");
    assert_eq!(
        String::from_utf8_lossy(&merged),
        String::from_utf8_lossy(&std::fs::read(d.join("here/results.csv")).unwrap())
    );
}

#[test]
fn plan_and_merge_refuse_bad_input_with_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
            .current_dir(d)
            .args(args)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    // Usage errors: exit 2, naming the arguments.
    let (code, err) = run(&["sweep", "--plan", "p", "--size-seconds", "5"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("--size-seconds") && err.contains("--plan"),
        "{err}"
    );
    let (code, err) = run(&["sweep", "--merge", "p", "scenes/default.toml"]);
    assert_eq!(code, Some(2), "{err}");
    let (code, err) = run(&["sweep"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--out-dir"), "{err}");
    // No plan, or a broken one: exit 1, one line naming the file.
    let (code, err) = run(&["sweep", "--merge", "nothing"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("nothing") && err.contains("sweep.toml"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    std::fs::create_dir(d.join("bad")).unwrap();
    std::fs::write(d.join("bad/sweep.toml"), "program = \"x\"\nsize = [\n").unwrap();
    let (code, err) = run(&["sweep", "--merge", "bad"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("bad/sweep.toml:2:"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
}

/// An interrupted in-process sweep resumes: every
/// render's JSON is kept under OUT/points as it finishes, and a rerun takes
/// those made with the same arguments instead of rendering them again.
#[test]
fn an_in_process_sweep_resumes_from_its_finished_points() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let sweep = [
        "sweep",
        "--only",
        "broadcast",
        "--size",
        "16x16",
        "--out-dir",
        "out",
    ];
    let (ok, _, err) = morphosys(d, &sweep);
    assert!(ok, "{err}");
    assert!(!err.contains("taken from an earlier run"), "{err}");
    let first = std::fs::read(d.join("out/results.csv")).unwrap();
    let points: Vec<_> = std::fs::read_dir(d.join("out/points")).unwrap().collect();
    assert_eq!(points.len(), 4);
    // A point whose JSON was made with other arguments renders again.
    let p = d.join("out/points/default-paper.json");
    let text = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, text.replacen("\"--ways\"", "\"--WAYS\"", 1)).unwrap();
    let (ok, _, err) = morphosys(d, &sweep);
    assert!(ok, "{err}");
    assert!(err.contains("3 renders taken from an earlier run"), "{err}");
    assert_eq!(std::fs::read(d.join("out/results.csv")).unwrap(), first);
}

/// In `d`: tetra-1 copied to `scene` and the default timing to `timing`
/// (names that may hold newlines and commands), planned as a broadcast
/// sweep into `d/plan`; the sweep's standard output.
fn hostile_plan(d: &Path, scene: &str, timing: &str) -> String {
    std::fs::copy(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/spd/tetra-1.nff"),
        d.join(scene),
    )
    .unwrap();
    let (ok, out, err) = morphosys(d, &["timing"]);
    assert!(ok, "{err}");
    std::fs::write(d.join(timing), out).unwrap();
    let (ok, out, err) = morphosys(
        d,
        &[
            "sweep",
            scene,
            "--timing",
            timing,
            "--only",
            "broadcast",
            "--size",
            "16x16",
            "--plan",
            "plan",
        ],
    );
    assert!(ok, "{err}");
    out
}

/// A scene or timing file whose name holds a newline cannot split a job
/// line (which GNU parallel and the Slurm script run as a shell command):
/// the plan's copies get plain names, and a `--plan` folder whose path
/// holds a control character is refused before anything is made.
#[test]
fn file_names_cannot_inject_commands_into_a_plan() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let scene = "x\ntouch INJECTED #.nff";
    let timing = "t\ntouch INJECTED_T #.toml";
    let out = hostile_plan(d, scene, timing);
    let renders: usize = out
        .split_once("jobs.txt (")
        .and_then(|(_, r)| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{out}"));
    let jobs = std::fs::read_to_string(d.join("plan/jobs.txt")).unwrap();
    assert_eq!(
        jobs.lines().count(),
        renders,
        "one line per render:\n{jobs}"
    );
    let program = std::fs::canonicalize(env!("CARGO_BIN_EXE_morphosys")).unwrap();
    for line in jobs.lines() {
        assert!(
            line.starts_with(&format!("{} render ", program.display())),
            "{line}"
        );
    }
    // The first two jobs run as written: nothing but renders.
    std::fs::write(
        d.join("first.txt"),
        jobs.lines().take(2).collect::<Vec<_>>().join("\n") + "\n",
    )
    .unwrap();
    // As the Slurm script runs a line (`bash -c "$line"`); GNU parallel's
    // own reading of them: hostile_names_run_as_renders_under_gnu_parallel.
    for line in jobs.lines().take(2) {
        let st = Command::new("bash")
            .args(["-c", line])
            .current_dir(d)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .unwrap();
        assert!(st.success(), "{line}");
    }
    assert!(!d.join("INJECTED").exists() && !d.join("plan/INJECTED").exists());
    assert!(!d.join("INJECTED_T").exists());
    // A plan folder with a newline: refused, nothing made.
    let (ok, _, err) = morphosys(
        d,
        &[
            "sweep",
            scene,
            "--only",
            "broadcast",
            "--size",
            "16x16",
            "--plan",
            "p\nq",
        ],
    );
    assert!(!ok);
    assert!(err.contains("--plan") && err.contains("U+000A"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!d.join("p\nq").exists());
    // Nor a folder whose name is not UTF-8.
    use std::os::unix::ffi::OsStrExt;
    let bad = std::ffi::OsStr::from_bytes(b"p\xff");
    let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .current_dir(d)
        .args([
            "sweep",
            scene,
            "--only",
            "broadcast",
            "--size",
            "16x16",
            "--plan",
        ])
        .arg(bad)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("--plan") && err.contains("not UTF-8"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!d.join(bad).exists());
}

/// A point's JSON holding a value no render gives (edited or corrupted:
/// a hit agreement of 1e308, a PSNR of -1e308, cycles of u64::MAX) is left
/// out of the merge and named with the value, never written into
/// results.csv.
#[test]
fn merge_leaves_out_impossible_values_and_names_them() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/spd/tetra-1.nff")
        .display()
        .to_string();
    let (ok, _, err) = morphosys(
        d,
        &[
            "sweep",
            &scene,
            "--only",
            "broadcast",
            "--size",
            "16x16",
            "--plan",
            "plan",
        ],
    );
    assert!(ok, "{err}");
    let jobs = std::fs::read_to_string(d.join("plan/jobs.txt")).unwrap();
    for line in jobs.lines() {
        let st = Command::new("bash")
            .args(["-c", line])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .unwrap();
        assert!(st.success(), "{line}");
    }
    let (ok, _, err) = morphosys(d, &["sweep", "--merge", "plan", "--out-dir", "good"]);
    assert!(ok, "{err}");
    let good = std::fs::read_to_string(d.join("good/results.csv")).unwrap();
    let mut points: Vec<_> = std::fs::read_dir(d.join("plan/points"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    points.sort();
    assert!(points.len() >= 3, "{points:?}");
    let edits: [(&str, serde_json::Value, &str); 3] = [
        ("hit_agreement", serde_json::json!(1e308), "hit_agreement"),
        ("psnr_db", serde_json::json!(-1e308), "psnr_db"),
        ("cycles", serde_json::json!(u64::MAX), "cycles"),
    ];
    let mut names = Vec::new();
    for ((key, value, says), p) in edits.iter().zip(&points) {
        let mut j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        j[*key] = value.clone();
        std::fs::write(p, serde_json::to_string(&j).unwrap()).unwrap();
        names.push((p.file_stem().unwrap().to_string_lossy().into_owned(), *says));
    }
    let (ok, _, err) = morphosys(d, &["sweep", "--merge", "plan", "--out-dir", "bad"]);
    assert!(ok, "{err}");
    for (name, says) in &names {
        assert!(err.contains(&format!("{name} ({says}")), "{name}: {err}");
    }
    let bad = std::fs::read_to_string(d.join("bad/results.csv")).unwrap();
    assert_eq!(
        bad.lines().count() + names.len(),
        good.lines().count(),
        "{bad}"
    );
    assert!(
        !bad.contains("1e308") && !bad.contains("18446744073709551615"),
        "{bad}"
    );
}

/// A finished render is taken again only when its inputs are unchanged
/// (the key was the arguments alone): a sweep resumed
/// after its scene file was replaced renders every point again and says
/// why; `render --skip-done` does the same; `sweep --merge` leaves out a
/// point whose scene copy changed since its render.
#[test]
fn a_changed_scene_is_rendered_again_not_taken_from_before() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/spd");
    std::fs::copy(scenes.join("tetra-1.nff"), d.join("s.nff")).unwrap();
    let sweep = [
        "sweep",
        "s.nff",
        "--only",
        "broadcast",
        "--size",
        "16x16",
        "--out-dir",
        "o",
    ];
    let (ok, _, err) = morphosys(d, &sweep);
    assert!(ok, "{err}");
    let (ok, _, err) = morphosys(d, &sweep);
    assert!(ok && err.contains("taken from an earlier run"), "{err}");
    std::fs::copy(scenes.join("jacks-1.nff"), d.join("s.nff")).unwrap();
    let (ok, _, err) = morphosys(d, &sweep);
    assert!(ok, "{err}");
    assert!(
        err.contains("made before the scene changed: rendering again"),
        "{err}"
    );
    assert!(!err.contains("taken from an earlier run"), "{err}");
    let csv = std::fs::read_to_string(d.join("o/results.csv")).unwrap();
    let row = csv.lines().nth(1).unwrap();
    assert!(
        row.starts_with("s.nff,9,"),
        "jacks-1 has 9 primitives: {row}"
    );
    // render --skip-done.
    let render = [
        "render",
        "s.nff",
        "--size",
        "8x8",
        "--json",
        "r.json",
        "--skip-done",
    ];
    let (ok, _, err) = morphosys(d, &render);
    assert!(ok, "{err}");
    let (ok, out, err) = morphosys(d, &render);
    assert!(ok && (out + &err).contains("already rendered"), "{err}");
    std::fs::copy(scenes.join("tetra-1.nff"), d.join("s.nff")).unwrap();
    let (ok, _, err) = morphosys(d, &render);
    assert!(ok && err.contains("made before the scene changed"), "{err}");
    // A plan whose scene copy changes after its renders.
    let (ok, _, err) = morphosys(
        d,
        &[
            "sweep",
            "s.nff",
            "--only",
            "broadcast",
            "--size",
            "16x16",
            "--plan",
            "plan",
        ],
    );
    assert!(ok, "{err}");
    for line in std::fs::read_to_string(d.join("plan/jobs.txt"))
        .unwrap()
        .lines()
    {
        let st = Command::new("bash")
            .args(["-c", line])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .unwrap();
        assert!(st.success(), "{line}");
    }
    let (ok, _, err) = morphosys(d, &["sweep", "--merge", "plan", "--out-dir", "m1"]);
    assert!(ok && !err.contains("left out"), "{err}");
    let copy = std::fs::read_dir(d.join("plan/scenes"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    std::fs::copy(scenes.join("jacks-1.nff"), &copy).unwrap();
    let (ok, _, err) = morphosys(d, &["sweep", "--merge", "plan", "--out-dir", "m2"]);
    assert!(!ok, "nothing of the plan is valid any more: {err}");
    assert!(err.contains("made before the scene changed"), "{err}");
}

/// Timing files are told apart by more than their file names: two `t.toml` in different folders make two series with their
/// own figures, a file named `default.toml` is not the default chip, and a
/// plan of them merges to what the sweep gives in one process.
#[test]
fn timing_files_of_one_name_stay_apart() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let (ok, base, err) = morphosys(d, &["timing"]);
    assert!(ok, "{err}");
    std::fs::create_dir_all(d.join("a")).unwrap();
    std::fs::create_dir_all(d.join("b")).unwrap();
    std::fs::write(d.join("a/t.toml"), &base).unwrap();
    let slower = |n: &str| base.replace("\nstatus = 2\n", &format!("\nstatus = {n}\n"));
    std::fs::write(d.join("b/t.toml"), slower("40")).unwrap();
    std::fs::write(d.join("default.toml"), slower("80")).unwrap();
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/spd/tetra-1.nff")
        .display()
        .to_string();
    let args = |out: &[&'static str]| {
        let mut v: Vec<String> = [
            "sweep",
            &scene,
            "--timing",
            "a/t.toml",
            "b/t.toml",
            "default.toml",
            "--only",
            "broadcast",
            "--size",
            "16x16",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        v.extend(out.iter().map(|s| s.to_string()));
        v
    };
    let run = |v: Vec<String>| {
        let v: Vec<&str> = v.iter().map(String::as_str).collect();
        morphosys(d, &v)
    };
    let (ok, _, err) = run(args(&["--out-dir", "o"]));
    assert!(ok, "{err}");
    let csv = std::fs::read_to_string(d.join("o/results.csv")).unwrap();
    let cycles = |series: &str| -> Vec<u64> {
        let head: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
        let (kv, kc) = (
            head.iter().position(|h| *h == "value").unwrap(),
            head.iter().position(|h| *h == "cycles").unwrap(),
        );
        csv.lines()
            .skip(1)
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|f| f[kv] == series)
            .map(|f| f[kc].parse().unwrap())
            .collect()
    };
    let (a, b, def) = (
        cycles("a/t.toml"),
        cycles("b/t.toml"),
        cycles("default.toml"),
    );
    assert_eq!((a.len(), b.len(), def.len()), (2, 2, 2), "{csv}");
    assert!(
        b.iter().zip(&a).all(|(b, a)| b > a),
        "b is slower than a: {csv}"
    );
    assert!(
        def.iter().zip(&b).all(|(d, b)| d > b),
        "default.toml is slower still: {csv}"
    );
    // The same as a plan: its jobs run one by one, then merged.
    let (ok, _, err) = run(args(&["--plan", "plan"]));
    assert!(ok, "{err}");
    for line in std::fs::read_to_string(d.join("plan/jobs.txt"))
        .unwrap()
        .lines()
    {
        let st = Command::new("bash")
            .args(["-c", line])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .unwrap();
        assert!(st.success(), "{line}");
    }
    let (ok, _, err) = morphosys(d, &["sweep", "--merge", "plan", "--out-dir", "m"]);
    assert!(ok, "{err}");
    assert_eq!(
        std::fs::read_to_string(d.join("m/results.csv")).unwrap(),
        csv
    );
}

/// The plan's job lines for a scene and a timing file whose names hold a
/// newline and a command run under GNU parallel as renders and nothing
/// else (parallel reads lines and its own replacement strings).
#[test]
#[ignore = "needs GNU parallel (Debian package parallel); .ci/run installs it and runs the ignored tests"]
fn hostile_names_run_as_renders_under_gnu_parallel() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let scene = "x\ntouch INJECTED #{}.nff";
    let timing = "t\ntouch INJECTED_T #{1}.toml";
    hostile_plan(d, scene, timing);
    let jobs = std::fs::read_to_string(d.join("plan/jobs.txt")).unwrap();
    std::fs::write(
        d.join("first.txt"),
        jobs.lines().take(2).collect::<Vec<_>>().join("\n") + "\n",
    )
    .unwrap();
    parallel(&d.join("first.txt"));
    assert!(!d.join("INJECTED").exists() && !d.join("plan/INJECTED").exists());
    assert!(!d.join("INJECTED_T").exists());
    assert_eq!(
        std::fs::read_dir(d.join("plan/points"))
            .unwrap()
            .filter(|e| e
                .as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "json"))
            .count(),
        2,
        "the two lines made their two renders"
    );
}
