//! `morphosys reference`, `compile` and `compare` from the command line.

mod common;
use common::morphosys;
use std::path::PathBuf;
use std::process::Command;

fn shared(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/spd")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn reference_default_scene_png_and_json() {
    let dir = tempfile::tempdir().unwrap();
    // No scene argument: scenes/default.toml (found beside the sources).
    let (ok, out, err) = morphosys(
        dir.path(),
        &[
            "reference",
            "--size",
            "40x30",
            "--depth",
            "2",
            "--out",
            "a.png",
            "--json",
            "a.json",
            "--hits",
            "a.hits",
        ],
    );
    assert!(ok, "{out}{err}");
    assert!(out.contains("default.toml: 40x30, depth 2"), "{out}");
    let img = image::open(dir.path().join("a.png")).unwrap();
    assert_eq!((img.width(), img.height()), (40, 30));
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("a.json")).unwrap()).unwrap();
    assert_eq!(j["eye_rays"], 1200);
    // Only temporary files renamed into place: nothing else left behind.
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into())
        .collect();
    names.sort();
    assert_eq!(names, ["a.hits", "a.json", "a.png"]);
    // The same image compares as identical, hit maps agree.
    let (ok, out, err) = morphosys(
        dir.path(),
        &["compare", "a.png", "a.png", "--hits", "a.hits", "a.hits"],
    );
    assert!(ok, "{err}");
    assert!(
        out.contains("PSNR inf") && out.contains("hit agreement 100.000%"),
        "{out}"
    );
}

#[test]
fn spd_stats_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = morphosys(
        dir.path(),
        &[
            "reference",
            &shared("tetra-1.nff"),
            "--spd-stats",
            "--json",
            "s.json",
        ],
    );
    assert!(ok, "{out}{err}");
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap();
    for k in [
        "eye_hit_rays",
        "reflect_rays",
        "refract_rays",
        "shadow_rays",
    ] {
        assert!(j[k].is_u64(), "{k} missing: {j}");
    }
    assert_eq!(j["eye_rays"], 513 * 513);
    assert_eq!(j["reflect_rays"], 0);
    let (ok, _, err) = morphosys(
        dir.path(),
        &[
            "reference",
            &shared("tetra-1.nff"),
            "--spd-stats",
            "--depth",
            "3",
        ],
    );
    assert!(!ok && err.contains("--spd-stats"), "{err}");
}

#[test]
fn compile_reports_and_bad_scenes_fail_with_file_line() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = morphosys(
        dir.path(),
        &[
            "compile",
            &shared("jacks-1.nff"),
            "--json",
            "r.json",
            "--out",
            "img.bin",
        ],
    );
    assert!(ok, "{err}");
    assert!(out.contains("format: Q"), "{out}");
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    let words = j["total_words"].as_u64().unwrap();
    assert_eq!(
        std::fs::metadata(dir.path().join("img.bin")).unwrap().len(),
        2 * words
    );
    std::fs::write(
        dir.path().join("bad.nff"),
        "v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 4 4\ns 0 0 0 -0\n",
    )
    .unwrap();
    for cmd in ["compile", "reference"] {
        let (ok, out, err) = morphosys(dir.path(), &[cmd, "bad.nff", "--out", "x"]);
        assert!(!ok, "{out}");
        assert_eq!(
            err.trim(),
            "morphosys: error: bad.nff:8:1: sphere has radius 0",
            "{cmd}"
        );
    }
    assert!(!dir.path().join("x").exists());
    // An output in a missing directory: an error, no file.
    let (ok, _, err) = morphosys(
        dir.path(),
        &["reference", "--size", "8x8", "--out", "nodir/a.png"],
    );
    assert!(!ok && err.contains("nodir/a.png"), "{err}");
}

/// `render --datapath auto` (the default) keeps the paper's 16-bit chip for
/// the default scene and, with local positions, for SPD balls-2 (whose
/// global positions fall under the bar: with them the 32-bit chip), moves
/// a scene the 16-bit format cannot hold (shells-1) to the 32-bit chip,
/// says so in the JSON, and `--datapath 16` on shells-1 is refused with
/// the scene's own error.
#[test]
fn render_datapath_auto_picks_the_chip_and_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let bits = |args: &[&str]| {
        let mut a = vec![
            "render", "--size", "8x8", "--out", "x.png", "--json", "x.json",
        ];
        a.extend_from_slice(args);
        let (ok, _, err) = morphosys(dir.path(), &a);
        assert!(ok, "{err}");
        let j: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("x.json")).unwrap()).unwrap();
        (
            j["datapath_bits"].as_u64().unwrap(),
            j["datapath_choice"].as_str().unwrap().to_string(),
        )
    };
    let (b, why) = bits(&[]);
    assert_eq!(b, 16, "{why}");
    assert!(
        why.starts_with("auto: the 16-bit chip (Q5.10) renders the probe"),
        "{why}"
    );
    // SPD balls size 2 at 24x24: the 16-bit chip's probe (the middle tile)
    // with global positions measures 28.6 dB against the reference, under
    // the 30 dB bar; with local ones 64.9 dB.
    let (ok, _, err) = morphosys(
        dir.path(),
        &["spd", "balls", "--size", "2", "--out", "b2.nff"],
    );
    assert!(ok, "{err}");
    let (ok, _, err) = morphosys(
        dir.path(),
        &[
            "render", "b2.nff", "--size", "24x24", "--out", "x.png", "--json", "x.json",
        ],
    );
    assert!(ok, "{err}");
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("x.json")).unwrap()).unwrap();
    let why = j["datapath_choice"].as_str().unwrap();
    assert_eq!(j["datapath_bits"], 16, "{why}");
    assert!(why.contains("local positions"), "{why}");
    assert!(j["psnr_db"].as_f64().unwrap() >= 40.0, "{j}");
    let (ok, _, err) = morphosys(
        dir.path(),
        &[
            "render",
            "b2.nff",
            "--size",
            "24x24",
            "--positions",
            "global",
            "--out",
            "x.png",
            "--json",
            "x.json",
        ],
    );
    assert!(ok, "{err}");
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("x.json")).unwrap()).unwrap();
    let why = j["datapath_choice"].as_str().unwrap();
    assert_eq!(j["datapath_bits"], 32, "{why}");
    assert!(why.contains("under the 30 dB / 99% bar"), "{why}");
    assert!(j["psnr_db"].as_f64().unwrap() >= 30.0, "{j}");
    // SPD shells: spheres of 0.2 LSB in the scene's format, which the
    // 16-bit chip holds only with local positions.
    let shells = shared("shells-1.nff");
    let (b, why) = bits(&[&shells, "--positions", "global"]);
    assert_eq!(b, 32, "{why}");
    assert!(why.contains("16-bit chip cannot hold"), "{why}");
    let (b, why) = bits(&[&shells]);
    assert_eq!(b, 16, "{why}");
    assert!(
        why.contains("local positions: global ones cannot hold the scene"),
        "{why}"
    );
    let (b, _) = bits(&["--datapath", "32"]);
    assert_eq!(b, 32);
    let (ok, _, err) = morphosys(
        dir.path(),
        &[
            "render",
            &shells,
            "--size",
            "8x8",
            "--datapath",
            "16",
            "--positions",
            "global",
        ],
    );
    assert!(
        !ok && err.contains("shells-1.nff:11: cannot represent the scene in 16-bit"),
        "{err}"
    );
    let (b, why) = bits(&[&shells, "--datapath", "16"]);
    assert_eq!(b, 16, "{why}");
    assert!(why.starts_with("--datapath 16 (local positions"), "{why}");
    let (ok, _, err) = morphosys(dir.path(), &["render", "--datapath", "24"]);
    assert!(
        !ok && err.contains("--datapath") && err.lines().count() == 1,
        "{err}"
    );
}

/// Standard output that cannot be written ends with one error line and exit
/// code 1, never a panic: a reader that goes away (`| head -c 10`) and a
/// full device (`> /dev/full`).
#[test]
fn closed_stdout_ends_quietly_and_a_full_one_is_an_error() {
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    // A reader that closes at once: 300 KB of NFF (more than a pipe holds,
    // so the write fails whenever the reader closes) into a closed pipe.
    let mut child = Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .current_dir(dir.path())
        .args(["spd", "balls", "--size", "4"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    // A reader that went away ends the command quietly.
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.is_empty(), "{err}");
    if let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") {
        let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
            .current_dir(dir.path())
            .args(["timing"])
            .stdout(full)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(
            err.contains("No space left on device") && !err.contains("panicked"),
            "{err}"
        );
    }
}

/// A usage error names the argument on one line and exits 2, whether clap
/// or a value range catches it (missing arguments were cut from
/// the message, and --ways / --depth errors exited 1).
#[test]
fn usage_errors_name_the_argument_and_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    for (args, want) in [
        (
            &["sweep"][..],
            "required arguments were not provided: --out-dir <DIR>",
        ),
        (
            &["compare"][..],
            "required arguments were not provided: <A>, <B>",
        ),
        (
            &["render", "--ways", "3"][..],
            "'--ways <N>': expected 4, 8, 16, 32 or 64",
        ),
        (
            &["render", "--depth", "0"][..],
            "'--depth <N>': 0 is not in 1..=8",
        ),
        (
            &["render", "--newton-steps", "4"][..],
            "'--newton-steps <N>': 4 is not in 0..=3",
        ),
        (
            &["reference", "--depth", "9"][..],
            "'--depth <N>': 9 is not in 1..=8",
        ),
        (
            &["render", "--table-entries", "5"][..],
            "'--table-entries <N>': expected 16, 32, 64 or 128",
        ),
        (
            &["render", "--max-leaf", "0"][..],
            "'--max-leaf <N>': expected a whole number of at least 1",
        ),
        (
            &["render", "--leaf-pieces", "300,100"][..],
            "'--leaf-pieces <auto|FIRST,[SECOND,]REST>': leaf pieces '300,100': expected auto, FIRST,REST or FIRST,SECOND,REST",
        ),
        (
            &["render", "--leaf-pieces", "0,64"][..],
            "word counts 1..=16384 with FIRST <= SECOND <= REST",
        ),
        (
            &["render", "--leaf-pieces", "64,256,128"][..],
            "leaf pieces '64,256,128': expected auto, FIRST,REST or FIRST,SECOND,REST",
        ),
        (
            &["render", "--leaf-pieces", "64,128,256,512"][..],
            "leaf pieces '64,128,256,512': expected",
        ),
        (
            &["render", "--leaf-pieces", "64,auto"][..],
            "leaf pieces '64,auto': expected",
        ),
        (
            &["render", "--shadow-packets", "some"][..],
            "'--shadow-packets <auto|light|merged>': shadow packets 'some': expected auto, light or merged",
        ),
        (
            &["render", "--test-cuts", "maybe"][..],
            "'--test-cuts <auto|on|tinyrisc|off>': test cuts 'maybe': expected auto, on, tinyrisc or off",
        ),
        (
            &["regroup", "--size", "12"][..],
            "'--size <N>': '12': expected a multiple of 8, 8..=1024",
        ),
        (
            &["compile", "--max-leaf", "0"][..],
            "'--max-leaf <N>': expected a whole number of at least 1",
        ),
        (
            &["sweep", "--families", "nope", "--out-dir", "x"][..],
            "'--families <NAMES>'",
        ),
        (
            &["bench", "--repeat", "0"][..],
            "'--repeat <N>': expected a whole number of at least 1",
        ),
        (
            &["fuzz", "--count", "0"][..],
            "'--count <N>': expected a whole number of at least 1",
        ),
        (
            &["spd", "balls", "--size", "99"][..],
            "'--size <N>': size 99 for balls: expected 1 to 6",
        ),
        (
            &["render", "--vcd", "x.vcd", "--trace-cycles", "0"][..],
            "'--trace-cycles <CYCLES>': expected a whole number of at least 1",
        ),
        (
            &["sweep", "--out-dir", "x", "--size-seconds=-1"][..],
            "'--size-seconds <SECONDS>': expected a number of seconds above 0",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
            .current_dir(dir.path())
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        // The hint points to the help of the subcommand at fault.
        assert!(
            err.contains(&format!("(see `morphosys {} --help`)", args[0])),
            "{args:?}: {err}"
        );
    }
}

/// Output paths are checked before the work (a render into a
/// missing folder ran the whole frame, then failed): one line naming the
/// argument, no output, at once.
#[test]
fn output_paths_are_checked_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    for (args, want) in [
        (
            &["render", "--out", "missing/x.png"][..],
            "--out missing/x.png: the folder missing does not exist",
        ),
        (
            &["render", "--size", "8x8", "--json", "missing/x.json"][..],
            "--json missing/x.json: the folder missing does not exist",
        ),
        (
            &["reference", "--hits", "missing/h.hits"][..],
            "--hits missing/h.hits: the folder missing does not exist",
        ),
    ] {
        let (ok, out, err) = morphosys(dir.path(), args);
        assert!(!ok, "{args:?}");
        assert!(
            err.contains(want) && err.lines().count() == 1,
            "{args:?}: {err}"
        );
        // Nothing rendered: no figures, no files.
        assert!(!out.contains("fps") && !out.contains("eye rays"), "{out}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}

/// `bench` traces into temporary files it deletes: it does not announce
/// them (a dozen "wrote /tmp/.tmpXXX/bench0.vcd" lines).
#[test]
fn bench_does_not_announce_its_temporary_waveforms() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = morphosys(dir.path(), &["bench", "--size", "16x16", "--repeat", "1"]);
    assert!(ok, "{out}{err}");
    assert!(out.contains("tracing on, 1 thread"), "{out}");
    assert!(
        !err.contains("wrote") && !out.contains("wrote"),
        "{out}{err}"
    );
    // Honest figures: the host, the statistic
    // and the traced slowdown.
    let (ok, out, err) = morphosys(
        dir.path(),
        &[
            "bench", "--size", "16x16", "--repeat", "2", "--json", "b.json", "-q",
        ],
    );
    assert!(ok, "{out}{err}");
    assert!(out.contains("fastest of 2 runs"), "{out}");
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("b.json")).unwrap()).unwrap();
    assert_eq!(j["repeat"], 2);
    assert!(!j["host_cpu"].as_str().unwrap().is_empty());
    assert!(j["traced_slowdown"].as_f64().unwrap() > 1.0, "{j}");
    // The same for the chip alone (the frame's setup aside), and
    // the two frames' times it comes from.
    assert!(j["traced_slowdown_chip"].as_f64().unwrap() > 0.0, "{j}");
    assert!(j["host_seconds_traced"].as_f64().unwrap() > 0.0, "{j}");
    assert!(
        j["host_seconds_untraced_small"].as_f64().unwrap() > 0.0,
        "{j}"
    );
}

/// `bench`'s schedule model: the frame's work items, and with `--sweep`
/// one record per render the sweep makes (counted against the sweep's own
/// points), its predictions between 1 and the thread count.
#[test]
fn bench_predicts_a_frame_and_a_sweep_from_their_work_items() {
    let dir = tempfile::tempdir().unwrap();
    let tetra = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/spd/tetra-1.nff")
        .display()
        .to_string();
    let small = ["--sweep-size", "16x16", "--sweep-max-size", "1"];
    let mut args = vec![
        "bench", "--size", "16x16", "--repeat", "1", "--json", "b.json", "-q",
    ];
    args.extend(["--sweep", &tetra]);
    args.extend(small);
    let (ok, out, err) = morphosys(dir.path(), &args);
    assert!(ok, "{out}{err}");
    assert!(
        out.contains("schedule model") && out.contains("sweep "),
        "{out}"
    );
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("b.json")).unwrap()).unwrap();
    let s = &j["schedule"];
    // 256x256: 1024 tiles of 8x8 pixels.
    assert_eq!(s["tile_seconds"].as_array().unwrap().len(), 1024, "{s}");
    let sw = &j["sweep"];
    for (sched, most) in [(s, 64.0), (sw, 64.0)] {
        for n in ["16", "64"] {
            let p = sched["predicted_speedup"][n].as_f64().unwrap();
            assert!((1.0..=most).contains(&p), "{n}: {p}");
        }
    }
    // The same sweep run by `sweep` writes one JSON per render.
    let (ok, out, err) = morphosys(
        dir.path(),
        &[
            "sweep",
            &tetra,
            "--out-dir",
            "sw",
            "-q",
            "--size",
            "16x16",
            "--max-size",
            "1",
        ],
    );
    assert!(ok, "{out}{err}");
    let renders = std::fs::read_dir(dir.path().join("sw/points"))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "json")
        })
        .count();
    assert_eq!(sw["renders"], renders, "{sw}");
    // Its work and serial part add up to its time on one thread.
    let work: f64 = sw["renders_work"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| {
            // On one thread a render is one work item: its own work and
            // its tiles.
            w["prep_seconds"].as_f64().unwrap()
                + w["item_own_seconds"].as_f64().unwrap()
                + w["tile_seconds"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|t| t.as_f64().unwrap())
                    .sum::<f64>()
        })
        .sum();
    let one = sw["host_seconds_1_thread"].as_f64().unwrap();
    assert!(
        (work + sw["serial_seconds"].as_f64().unwrap() - one).abs() < 1e-6 * one.max(1.0) + 1e-9
    );
    // A bad scene stops it before any work.
    let (ok, _, err) = morphosys(dir.path(), &["bench", "--sweep", "nothere.nff"]);
    assert!(!ok && err.contains("nothere.nff"), "{err}");
}

/// `render --hits` and `reference --hits` make the hit maps `compare --hits`
/// reads, and `render` and `reference` share their default depth, so their
/// default images compare as they are.
#[test]
fn chip_and_reference_hit_maps_and_depths_compare() {
    let d = tempfile::tempdir().unwrap();
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/default.toml")
        .display()
        .to_string();
    for args in [
        vec![
            "render",
            &scene,
            "--size",
            "32x32",
            "--out",
            "chip.png",
            "--hits",
            "chip.hits",
        ],
        vec![
            "reference",
            &scene,
            "--size",
            "32x32",
            "--out",
            "ref.png",
            "--hits",
            "ref.hits",
            "--json",
            "ref.json",
        ],
    ] {
        let (ok, _, err) = morphosys(d.path(), &args);
        assert!(ok, "{args:?}: {err}");
    }
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("ref.json")).unwrap()).unwrap();
    assert_eq!(j["depth"], 2, "reference's default depth is render's");
    let (ok, out, err) = morphosys(
        d.path(),
        &[
            "compare",
            "chip.png",
            "ref.png",
            "--hits",
            "chip.hits",
            "ref.hits",
        ],
    );
    assert!(ok, "{err}");
    let agree: f64 = out
        .split("hit agreement ")
        .nth(1)
        .and_then(|s| s.trim().trim_end_matches('%').parse().ok())
        .unwrap_or_else(|| panic!("{out}"));
    assert!(agree > 97.0 && agree <= 100.0, "{out}");
}

/// `run` honours `.datapath`, fails on the conformance failure code and on
/// an `--expect`ed register off, and writes the registers as JSON (issue
/// 17, item 4).
#[test]
fn run_reports_pass_and_failure_by_its_exit_status() {
    let d = tempfile::tempdir().unwrap();
    let conf = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/conformance");
    let wide = conf.join("wide.s").display().to_string();
    let dct = conf.join("dct.s").display().to_string();
    // wide.s says `.datapath 32`: it passes without --datapath.
    let (ok, out, err) = morphosys(d.path(), &["run", &wide]);
    assert!(ok, "{err}");
    assert!(out.contains("32-bit datapath"), "{out}");
    // ... and asking for 16 bits contradicts it.
    let (ok, _, err) = morphosys(d.path(), &["run", &wide, "--datapath", "16"]);
    assert!(!ok && err.contains(".datapath"), "{err}");
    // The DCT's own cycle count, checked from outside, and as JSON.
    let (ok, _, err) = morphosys(
        d.path(),
        &[
            "run", &dct, "--expect", "r1=1", "--expect", "r3=0x26", "--json", "dct.json",
        ],
    );
    assert!(ok, "{err}");
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("dct.json")).unwrap()).unwrap();
    assert_eq!(j["registers"][3]["value"], 38);
    assert_eq!(j["registers"][3]["hex"], "0x00000026");
    let (ok, _, err) = morphosys(d.path(), &["run", &dct, "--expect", "r3=37"]);
    assert!(
        !ok && err.contains("r3 = 0x26 (38), expected 0x25 (37)"),
        "{err}"
    );
    // A program that signals failure.
    std::fs::write(
        d.path().join("fail.s"),
        ".text\n li r1, 0xBAD\n li r2, 7\n halt\n",
    )
    .unwrap();
    let (ok, _, err) = morphosys(d.path(), &["run", "fail.s"]);
    assert!(!ok, "exit 0 on a failing program");
    assert!(err.contains("0xBAD") && err.contains("r2 = 7"), "{err}");
}

/// Shell completions and `--quiet`.
#[test]
fn completions_parse_and_quiet_is_quiet() {
    let d = tempfile::tempdir().unwrap();
    let (ok, script, err) = morphosys(d.path(), &["completions", "bash"]);
    assert!(ok, "{err}");
    assert!(
        script.contains("render") && script.contains("--traversal"),
        "no subcommands"
    );
    std::fs::write(d.path().join("c.bash"), &script).unwrap();
    let syntax = Command::new("bash")
        .arg("-n")
        .arg(d.path().join("c.bash"))
        .output();
    if let Ok(o) = syntax {
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let (ok, out, err) = morphosys(
        d.path(),
        &["reference", "--size", "8x8", "--out", "r.png", "--quiet"],
    );
    assert!(ok, "{err}");
    assert!(
        !err.contains("wrote") && !out.contains("wrote"),
        "{out}{err}"
    );
    assert!(d.path().join("r.png").exists());
    let (_, _, err) = morphosys(d.path(), &["reference", "--size", "8x8", "--out", "r.png"]);
    assert!(err.contains("wrote"), "{err}");
}

/// The default scene is built into the binary: `render` and `reference`
/// work from any folder.
#[test]
fn the_default_scene_is_built_in() {
    let d = tempfile::tempdir().unwrap();
    for cmd in ["render", "reference"] {
        let (ok, _, err) = morphosys(d.path(), &[cmd, "--size", "8x8"]);
        assert!(ok, "{cmd}: {err}");
    }
    assert!(d.path().join("default-chip.png").exists());
    assert!(d.path().join("default-reference.png").exists());
}

/// The same value names for the same concept:
/// `compile` takes render's `--layout fig5|compact` and `--split
/// median|sah`, says so in words, and refuses the old names with the valid
/// ones.
#[test]
fn compile_speaks_renders_names() {
    let d = tempfile::tempdir().unwrap();
    let (ok, out, err) = morphosys(
        d.path(),
        &["compile", "--layout", "compact", "--split", "sah"],
    );
    assert!(ok, "{err}");
    assert!(
        out.contains("SAH split") && out.contains("compact (index lists)"),
        "{out}"
    );
    assert!(
        !out.contains("IndexLists") && !out.contains("Sah,") && !out.contains("(0 KiB)"),
        "{out}"
    );
    let (ok, _, err) = morphosys(d.path(), &["compile", "--layout", "bit-vectors"]);
    assert!(
        !ok && err.contains("fig5") && err.contains("compact"),
        "{err}"
    );
    let (ok, out, err) = morphosys(d.path(), &["spd", "tetra", "--size", "1", "--out", "t.nff"]);
    assert!(
        ok && out.contains("1 light") && !out.contains("1 lights"),
        "{out}{err}"
    );
}

/// JSON from every command that measures: `tb rc` and
/// `fuzz` too.
#[test]
fn testbench_and_fuzz_write_json() {
    let d = tempfile::tempdir().unwrap();
    let (ok, _, err) = morphosys(
        d.path(),
        &[
            "tb", "rc", "--vcd", "rc.vcd", "--json", "rc.json", "--quiet",
        ],
    );
    assert!(ok, "{err}");
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("rc.json")).unwrap()).unwrap();
    assert_eq!(j["pass"], true);
    assert!(j["values_checked"].as_u64().unwrap() > 1000, "{j}");
    let (ok, _, err) = morphosys(
        d.path(),
        &["fuzz", "asm", "--count", "50", "--json", "f.json"],
    );
    assert!(ok, "{err}");
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.path().join("f.json")).unwrap()).unwrap();
    assert_eq!(j["targets"][0]["target"], "asm");
    assert_eq!(j["targets"][0]["inputs"], 50);
    assert!(j["targets"][0]["findings"].as_array().unwrap().is_empty());
}
