//! The architect's workbench end to end: render an emitted (and edited)
//! firmware with `--firmware`, the chip's timing from a file, the M1 issue
//! model, and the sweep's timing and broadcast knobs.

mod common;
use common::morphosys;
use std::path::{Path, PathBuf};

fn scene(name: &str) -> String {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let p = [
        root.join("scenes").join(name),
        root.join("scenes/spd").join(name),
    ]
    .into_iter()
    .find(|p| p.is_file())
    .unwrap();
    p.display().to_string()
}

/// `render ARGS --json NAME.json`: the report.
fn render(dir: &Path, name: &str, args: &[&str]) -> serde_json::Value {
    let json = format!("{name}.json");
    let png = format!("{name}.png");
    let mut a = vec!["render", "--size", "32x32", "--out", &png, "--json", &json];
    a.extend_from_slice(args);
    let (ok, _, err) = morphosys(dir, &a);
    assert!(ok, "render {args:?}: {err}");
    serde_json::from_slice(&std::fs::read(dir.join(json)).unwrap()).unwrap()
}

fn cycles(j: &serde_json::Value) -> u64 {
    j["cycles"].as_u64().unwrap()
}

#[test]
fn an_emitted_firmware_renders_the_same_and_an_edited_one_differs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = scene("default.toml");
    let a = render(d, "a", &[&s, "--emit-asm", "fw.s"]);
    let b = render(d, "b", &[&s, "--firmware", "fw.s"]);
    assert_eq!(cycles(&a), cycles(&b));
    assert_eq!(b["firmware"], "fw.s");
    assert_eq!(
        std::fs::read(d.join("a.png")).unwrap(),
        std::fs::read(d.join("b.png")).unwrap()
    );
    let fw = std::fs::read_to_string(d.join("fw.s")).unwrap();
    // Drop the first Newton-Raphson step of the sphere kernel's square
    // root: five contexts fewer per sphere test.
    let at =
        fw.find("k_sphere:").unwrap() + fw[fw.find("k_sphere:").unwrap()..].find("; sqrt").unwrap();
    let step = "        mul r8, r13, r13, >>Q14         ; Newton: y += y (1 - X y^2) / 2\n        mul r8, r8, r10, >>Q11\n        sub r8, r8, r14\n        ldacc r13, <<Q15\n        msu r13, r13, r8, >>Q15\n";
    let k = at + fw[at..].find(step).unwrap();
    let edited = format!("{}{}", &fw[..k], &fw[k + step.len()..]);
    std::fs::write(d.join("nr1.s"), edited).unwrap();
    let c = render(d, "c", &[&s, "--firmware", "nr1.s"]);
    assert!(cycles(&c) < cycles(&a), "{} !< {}", cycles(&c), cycles(&a));
    let len = |j: &serde_json::Value| {
        j["kernels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|k| k["name"] == "k_sphere")
            .unwrap()["contexts"]
            .as_u64()
            .unwrap()
    };
    assert_eq!(len(&c) + 5, len(&a));
    // Output green as red: the same cycles, another image.
    let swapped = fw.replacen(
        "k_out_red:\n        ld out, [r0 + #COL]",
        "k_out_red:\n        ld out, [r0 + #COL+1]",
        1,
    );
    assert_ne!(swapped, fw, "k_out_red reads COL");
    std::fs::write(d.join("swap.s"), swapped).unwrap();
    let e = render(d, "e", &[&s, "--firmware", "swap.s"]);
    assert_eq!(cycles(&e), cycles(&a));
    assert!(e["psnr_db"].as_f64().unwrap() < a["psnr_db"].as_f64().unwrap() - 3.0);
    // Errors name the file: a bad line, and options the file was not
    // emitted for.
    std::fs::write(
        d.join("bad.s"),
        fw.replacen("sub r8, fb0, r1", "sub r8, fb0, r99", 1),
    )
    .unwrap();
    let (ok, _, err) = morphosys(d, &["render", &s, "--size", "32x32", "--firmware", "bad.s"]);
    assert!(
        !ok && err.contains("bad.s:") && err.contains("expected operand B"),
        "{err}"
    );
    let (ok, _, err) = morphosys(d, &["render", &s, "--size", "16x16", "--firmware", "fw.s"]);
    assert!(
        !ok && err.contains("fw.s:2: the firmware was generated for `32x32"),
        "{err}"
    );
    // The fine normals' records and kernels are not the coarse ones'.
    let (ok, _, err) = morphosys(
        d,
        &[
            "render",
            &s,
            "--size",
            "32x32",
            "--normals",
            "coarse",
            "--firmware",
            "fw.s",
        ],
    );
    assert!(
        !ok && err.contains("fine normals`; these options give") && err.contains("coarse normals`"),
        "{err}"
    );
    // A fault stops with the cycle and the PC, and no image is written.
    let fault = fw.replacen("ld r13, [r13 + #RSQ]", "ld r13, [r13 + #RSQ+600]", 1);
    assert_ne!(fault, fw, "the sphere kernel reads RSQ by r13");
    std::fs::write(d.join("fault.s"), fault).unwrap();
    let (ok, _, err) = morphosys(
        d,
        &[
            "render",
            &s,
            "--size",
            "32x32",
            "--firmware",
            "fault.s",
            "--out",
            "f.png",
        ],
    );
    assert!(
        !ok && err.contains("cycle ") && err.contains("[pc 0x"),
        "{err}"
    );
    // The address named is RSQ's index plus 600 (an index 0..127 of the
    // first RC to fault), outside the RAM.
    let addr: u32 = err
        .split("RAM address ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|a| a.parse().ok())
        .unwrap_or_else(|| panic!("no RAM address named: {err}"));
    assert!(
        (600..728).contains(&addr) && err.contains("outside 0..=511"),
        "{err}"
    );
    assert!(!d.join("f.png").exists());
}

#[test]
fn timing_files_change_the_chip_and_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = scene("jacks-1.nff");
    // `morphosys timing` read back: the default cycles, echoed in the JSON.
    let (ok, text, err) = morphosys(d, &["timing"]);
    assert!(ok, "{err}");
    assert!(text.contains("status = 2") && text.contains("issue = \"run\""));
    std::fs::write(d.join("t.toml"), &text).unwrap();
    let a = render(d, "a", &[&s]);
    let b = render(d, "b", &[&s, "--timing", "t.toml"]);
    assert_eq!(cycles(&a), cycles(&b));
    assert_eq!(b["timing"]["risc"]["status"], 2);
    // Twice the status read latency: more cycles.
    std::fs::write(d.join("slow.toml"), "[risc]\nstatus = 4\n").unwrap();
    let c = render(d, "c", &[&s, "--timing", "slow.toml"]);
    assert!(cycles(&c) > cycles(&a));
    assert_eq!(c["timing"]["risc"]["status"], 4);
    // A twice as wide external bus: no more cycles.
    std::fs::write(d.join("wide.toml"), "[dma]\nbytes_per_cycle = 8\n").unwrap();
    assert!(cycles(&render(d, "w", &[&s, "--timing", "wide.toml"])) <= cycles(&a));
    // The M1 chip's issue model: TinyRISC busy for every context.
    std::fs::write(d.join("m1.toml"), "issue = \"instruction\"\n").unwrap();
    let m = render(d, "m", &[&s, "--timing", "m1.toml"]);
    assert!(cycles(&m) > cycles(&a));
    assert_eq!(m["timing"]["issue"], "instruction");
    // Unknown keys and bad values: one line naming the file and line.
    std::fs::write(d.join("bad.toml"), "[risc]\nalu = 1\nstats = 4\n").unwrap();
    let (ok, _, err) = morphosys(d, &["render", &s, "--size", "8x8", "--timing", "bad.toml"]);
    assert!(
        !ok && err.contains("bad.toml:3:") && err.contains("stats"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    std::fs::write(d.join("zero.toml"), "[dma]\nbytes_per_cycle = 0\n").unwrap();
    let (ok, _, err) = morphosys(d, &["render", &s, "--size", "8x8", "--timing", "zero.toml"]);
    assert!(!ok && err.contains("zero.toml:2"), "{err}");
    // `run` takes the same file: a program's cycles follow its ALU cost.
    let dct = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../firmware/conformance/dct.s");
    let dct = dct.to_str().unwrap();
    std::fs::write(d.join("alu2.toml"), "[risc]\nalu = 2\n").unwrap();
    let halted = |out: &str| -> u64 {
        out.lines()
            .find_map(|l| l.strip_prefix("halted after "))
            .and_then(|l| l.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap()
    };
    let (ok1, o1, e1) = morphosys(d, &["run", dct]);
    let (ok2, o2, e2) = morphosys(d, &["run", dct, "--timing", "alu2.toml"]);
    assert!(ok1 && ok2, "{e1}{e2}");
    assert!(halted(&o2) > halted(&o1), "{o1}\n{o2}");
}

#[test]
fn the_sweep_charts_the_issue_models_and_timing_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = scene("tetra-1.nff");
    std::fs::write(d.join("dma8.toml"), "[dma]\nbytes_per_cycle = 8\n").unwrap();
    let (ok, out, err) = morphosys(
        d,
        &[
            "sweep",
            &s,
            "--only",
            "broadcast",
            "--size",
            "16x16",
            "--out-dir",
            "sw",
            "--timing",
            "dma8.toml",
        ],
    );
    assert!(ok, "{out}\n{err}");
    let mut rd = csv::Reader::from_path(d.join("sw/results.csv")).unwrap();
    let head = rd.headers().unwrap().clone();
    let col = |n: &str| head.iter().position(|h| h == n).unwrap();
    let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    let find = |knob: &str, traversal: &str| {
        rows.iter()
            .find(|r| &r[col("knob")] == knob && &r[col("traversal")] == traversal)
            .unwrap_or_else(|| panic!("no {knob} row for {traversal}"))
    };
    let cyc = |r: &csv::StringRecord| r[col("cycles")].parse::<u64>().unwrap();
    for t in ["paper", "packet"] {
        let base = if t == "paper" {
            find("paper", t)
        } else {
            find("traversal", t)
        };
        let m1 = find("broadcast", t);
        assert_eq!(&m1[col("issue")], "instruction");
        assert!(cyc(m1) > cyc(base), "{t}: {} !> {}", cyc(m1), cyc(base));
        let f = find("timing", t);
        assert_eq!(&f[col("timing")], "dma8");
    }
    assert!(d.join("sw/broadcast.png").is_file());
    assert!(d.join("sw/timing.png").is_file());
}

/// A knob sweep of one scene draws no one-point scaling chart (`sweep
/// --only knobs` once wrote a `scaling.png` of a single point); with two
/// scenes it draws one with both.
#[test]
fn a_one_scene_knob_sweep_writes_no_scaling_chart() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = scene("tetra-1.nff");
    let (ok, out, err) = morphosys(
        d,
        &[
            "sweep",
            &s,
            "--only",
            "knobs",
            "--size",
            "8x8",
            "--out-dir",
            "one",
        ],
    );
    assert!(ok, "{out}\n{err}");
    assert!(d.join("one/fig8.svg").is_file());
    assert!(!d.join("one/scaling.svg").exists());
    assert!(!d.join("one/scaling.png").exists());
    let t = scene("jacks-1.nff");
    let (ok, out, err) = morphosys(
        d,
        &[
            "sweep",
            &s,
            &t,
            "--only",
            "knobs",
            "--size",
            "8x8",
            "--out-dir",
            "two",
        ],
    );
    assert!(ok, "{out}\n{err}");
    let svg = std::fs::read_to_string(d.join("two/scaling.svg")).unwrap();
    assert!(svg.contains("paper configuration"), "{svg}");
    // Coarse beside fine normals: a row of its own, and a chart of the
    // pairs. jacks-1's spheres and cylinders take the fine kernels' extra
    // contexts (tetra-1 has neither: the same kernels).
    let svg = std::fs::read_to_string(d.join("two/normals.svg")).unwrap();
    assert!(svg.contains("jacks-1") && svg.contains("tetra-1"), "{svg}");
    let csv = std::fs::read_to_string(d.join("two/results.csv")).unwrap();
    let head: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let cycles = |knob: &str, normals: &str| -> u64 {
        csv.lines()
            .map(|l| l.split(',').collect::<Vec<_>>())
            .find(|f| {
                f[0].contains("jacks-1") && f[col("knob")] == knob && f[col("normals")] == normals
            })
            .unwrap_or_else(|| panic!("no jacks-1 row {knob}, {normals}:\n{csv}"))[col("cycles")]
        .parse()
        .unwrap()
    };
    assert!(cycles("normals", "coarse") < cycles("paper", "fine"));
}

/// A frame's cycles are the simulator's count, whatever the program
/// writes into `T_START` and `T_END`: a program that writes
/// `T_END = T_START + 100` reports the cycles the chip ran, and one that
/// halts before its tile loop reports the start-up it ran; both warn
/// that the firmware's own count disagrees, on the terminal and in the
/// JSON. The honest program's own count (the counter read by `rdcyc`)
/// stays within a few cycles of the simulator's.
#[test]
fn the_cycles_are_the_simulators_not_the_firmwares() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = scene("tetra-1.nff");
    let a = render(d, "a", &[&s, "--emit-asm", "fw.s"]);
    let honest = cycles(&a);
    let own = a["firmware_cycles"].as_u64().unwrap();
    assert!(honest.abs_diff(own) <= 16, "{honest} vs {own}");
    let warned = |j: &serde_json::Value| {
        j["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w["feature"] == "cycle-count")
    };
    assert!(!warned(&a));
    let fw = std::fs::read_to_string(d.join("fw.s")).unwrap();
    let end = "        rdcyc r1\n        sw r1, T_END(r0)\n";
    assert!(fw.contains(end), "the tracer stores its counter in T_END");
    let faked = fw.replacen(
        end,
        "        lw r1, T_START(r0)\n        addi r1, r1, 100\n        sw r1, T_END(r0)\n",
        1,
    );
    std::fs::write(d.join("fake.s"), faked).unwrap();
    let (ok, _, err) = morphosys(
        d,
        &[
            "render",
            &s,
            "--size",
            "32x32",
            "--firmware",
            "fake.s",
            "--out",
            "f.png",
            "--json",
            "f.json",
        ],
    );
    assert!(ok, "{err}");
    let f: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("f.json")).unwrap()).unwrap();
    // One instruction more than the honest program, no fewer cycles.
    assert!(
        cycles(&f) >= honest && cycles(&f) <= honest + 8,
        "{} against {honest}",
        cycles(&f)
    );
    assert!(f["firmware_cycles"].as_u64().unwrap() < honest / 4);
    assert!(warned(&f), "{f}");
    assert!(
        err.contains("fake.s: warning:") && err.contains("the simulator counted"),
        "{err}"
    );
    // Halting before the tile loop: the start-up's cycles, not 0.
    let start = "        rdcyc r1\n        sw r1, T_START(r0)\n";
    assert!(fw.contains(start));
    std::fs::write(d.join("halt.s"), fw.replacen(start, "        halt\n", 1)).unwrap();
    let h = render(d, "h", &[&s, "--firmware", "halt.s"]);
    assert_eq!(h["firmware_cycles"], 0);
    assert!(cycles(&h) > 0 && cycles(&h) < honest, "{}", cycles(&h));
    assert!(h["fps_at_300mhz"].as_f64().unwrap() > 0.0);
    assert!(warned(&h));
}
