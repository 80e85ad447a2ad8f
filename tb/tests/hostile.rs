//! The smaller findings of the adversarial pass, one
//! regression test each: every bad input gets one located line and a
//! non-zero exit, and valid input written oddly is read.

mod common;
use common::morphosys;

use std::path::Path;

fn default_toml() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/default.toml"))
        .unwrap()
}

const NFF_HEAD: &str = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 8 8\n\
                        b 0 0 0\nl 1 1 1\nf 1 0 0 0.5 0.5 3 0 1\n";

fn fails_with(dir: &Path, args: &[&str], says: &[&str]) {
    let (ok, _, err) = morphosys(dir, args);
    assert!(!ok, "{args:?} succeeded");
    assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
    for s in says {
        assert!(err.contains(s), "{args:?}: `{s}` not in: {err}");
    }
}

#[test]
fn toml_vectors_take_exactly_three_numbers() {
    let d = tempfile::tempdir().unwrap();
    let text = default_toml();
    let line = text
        .lines()
        .position(|l| l.starts_with("center = "))
        .unwrap()
        + 1;
    let bad = text.replacen(
        "center = [0.0, 0.0, 1.2]",
        "center = [0.0, 0.0, 1.2, 5, 6, 7]",
        1,
    );
    assert_ne!(bad, text);
    std::fs::write(d.path().join("x.toml"), bad).unwrap();
    fails_with(
        d.path(),
        &["reference", "x.toml", "--out", "x.png"],
        &[&format!("x.toml:{line}:"), "expected 3 numbers", "found 6"],
    );
}

#[test]
fn camera_light_and_material_errors_name_their_line() {
    let d = tempfile::tempdir().unwrap();
    let text = default_toml();
    let cam = text.lines().position(|l| l == "[camera]").unwrap() + 1;
    std::fs::write(
        d.path().join("a.toml"),
        text.replacen("angle = 40.0", "angle = 200.0", 1),
    )
    .unwrap();
    fails_with(
        d.path(),
        &["reference", "a.toml", "--out", "x.png"],
        &[&format!("a.toml:{cam}:"), "angle 200"],
    );
    // NFF: the viewpoint's line, and a material's
    std::fs::write(
        d.path().join("b.nff"),
        "b 0 0 0\nv\nfrom 0 0 5\nat 0 0 5\nup 0 1 0\nangle 45\nhither 1\nresolution 8 8\nl 1 1 1\nf 1 0 0 0.5 0.5 3 0 1\ns 0 0 0 1\n",
    )
    .unwrap();
    fails_with(
        d.path(),
        &["reference", "b.nff", "--out", "x.png"],
        &["b.nff:2:", "coincide"],
    );
}

#[test]
fn a_whole_nff_scene_on_one_line_reads_as_the_same_scene() {
    let d = tempfile::tempdir().unwrap();
    let text =
        format!("{NFF_HEAD}l -1 2 3 0.5 0.5 0.5\ns 0 0 0 1\np 3\n-2 -2 -1\n2 -2 -1\n0 2 -1\n");
    std::fs::write(d.path().join("many.nff"), &text).unwrap();
    std::fs::write(d.path().join("one.nff"), text.replace('\n', " ")).unwrap();
    for f in ["many", "one"] {
        let (ok, _, err) = morphosys(
            d.path(),
            &[
                "reference",
                &format!("{f}.nff"),
                "--out",
                &format!("{f}.png"),
            ],
        );
        assert!(ok, "{f}: {err}");
    }
    assert_eq!(
        std::fs::read(d.path().join("many.png")).unwrap(),
        std::fs::read(d.path().join("one.png")).unwrap()
    );
}

#[test]
fn a_polygon_starting_with_three_collinear_vertices_is_read() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(
        d.path().join("p.nff"),
        format!("{NFF_HEAD}p 4\n0 0 0\n1 0 0\n2 0 0\n0 1 0\n"),
    )
    .unwrap();
    let (ok, _, err) = morphosys(d.path(), &["reference", "p.nff", "--out", "p.png"]);
    assert!(ok, "{err}");
}

#[test]
fn a_thin_image_is_blamed_on_its_aspect_ratio() {
    let d = tempfile::tempdir().unwrap();
    fails_with(
        d.path(),
        &["render", "--size", "16x256", "--out", "x.png"],
        &["16x256", "16.0:1", "shorter side"],
    );
}

#[test]
fn a_trace_scope_matching_nothing_is_refused_with_the_scopes() {
    let d = tempfile::tempdir().unwrap();
    let dct = Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/conformance/dct.s");
    let dct = dct.to_str().unwrap();
    fails_with(
        d.path(),
        &["run", dct, "--vcd", "w.vcd", "--trace-scope", "nothing"],
        &["matches no signal", "tinyrisc"],
    );
    assert_eq!(
        std::fs::read_dir(d.path()).unwrap().count(),
        0,
        "a file was left"
    );
}

#[test]
fn asm_names_an_image_and_control_characters() {
    let d = tempfile::tempdir().unwrap();
    let dct = Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/conformance/dct.s");
    let (ok, _, err) = morphosys(d.path(), &["asm", dct.to_str().unwrap(), "-o", "dct.img"]);
    assert!(ok, "{err}");
    fails_with(
        d.path(),
        &["asm", "dct.img"],
        &["assembled image", "morphosys run"],
    );
    std::fs::write(d.path().join("nul.s"), ".text\nli r1, 1\n\0halt\n").unwrap();
    let (ok, _, err) = morphosys(d.path(), &["asm", "nul.s"]);
    assert!(!ok);
    assert!(
        err.contains("nul.s:3:1") && err.contains("U+0000") && !err.contains('\0'),
        "{err:?}"
    );
}

#[test]
fn a_sweep_whose_every_point_fails_is_an_error() {
    let d = tempfile::tempdir().unwrap();
    // Too fine for the 16-bit chip: every point of the broadcast sweep fails.
    std::fs::write(
        d.path().join("tiny.nff"),
        "v\nfrom 0 0 -3000\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 8 8\nb 0 0 0\nl 1 1 -100\n\
         f 1 0 0 0.5 0.5 3 0 1\ns 1000 0 0 1\ns -1000 0 0 0.0001\n",
    )
    .unwrap();
    let (ok, _, err) = morphosys(
        d.path(),
        &[
            "sweep",
            "tiny.nff",
            "--only",
            "broadcast",
            "--size",
            "8x8",
            "--out-dir",
            "out",
        ],
    );
    assert!(!ok, "{err}");
    assert!(
        err.contains("no configuration of the sweep could be rendered"),
        "{err}"
    );
    assert!(!d.path().join("out/results.csv").exists());
}

/// A control character in an input reaches the terminal written out
/// (`U+001B`), never raw: an escape sequence in a scene cannot recolour or
/// clear the user's terminal, a NUL cannot cut the line.
#[test]
fn control_characters_in_errors_are_written_out() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(
        d.path().join("cc.nff"),
        "v\nfrom 0 0 5\x1b[31mRED\x00\x07\nat 0 0 0\n",
    )
    .unwrap();
    let (ok, _, err) = morphosys(d.path(), &["reference", "cc.nff"]);
    assert!(!ok);
    assert!(
        err.contains("cc.nff:2:") && err.contains("U+001B[31mREDU+0000U+0007"),
        "{err}"
    );
    assert!(
        !err.trim_end().chars().any(|c| c.is_control()),
        "raw control characters: {err:?}"
    );
    // The same in a TOML scene's error and an argument's.
    std::fs::write(
        d.path().join("cc.toml"),
        "[camera]\nfrom = \"\x1b]0;x\x07\"\n",
    )
    .unwrap();
    let (ok, _, err) = morphosys(d.path(), &["reference", "cc.toml"]);
    assert!(!ok);
    assert!(!err.trim_end().chars().any(|c| c.is_control()), "{err:?}");
    let (ok, _, err) = morphosys(d.path(), &["render", "--size", "8x\x1b8"]);
    assert!(!ok);
    assert!(!err.trim_end().chars().any(|c| c.is_control()), "{err:?}");
}

/// A render that runs out of its cycle budget says what the budget is and
/// what to change (it does not take `run`'s --max-cycles); `run` names its
/// own option.
#[test]
fn a_render_out_of_cycles_names_its_own_budget() {
    let d = tempfile::tempdir().unwrap();
    let (ok, timing, err) = morphosys(d.path(), &["timing"]);
    assert!(ok, "{err}");
    let slow = timing.replace("\nstatus = 2\n", "\nstatus = 1000000\n");
    assert_ne!(slow, timing, "the timing file has a status field");
    std::fs::write(d.path().join("slow.toml"), slow).unwrap();
    let (ok, _, err) = morphosys(
        d.path(),
        &["render", "--size", "64x64", "--timing", "slow.toml", "-q"],
    );
    assert!(!ok);
    assert!(
        err.contains("took more than 62500000 cycles")
            && err.contains("per tile")
            && !err.contains("--max-cycles"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    std::fs::write(d.path().join("loop.s"), ".text\nl: b l\n").unwrap();
    let (ok, _, err) = morphosys(d.path(), &["run", "loop.s", "--max-cycles", "500"]);
    assert!(!ok && err.contains("raise --max-cycles (now 500)"), "{err}");
}

/// Inputs that are endless streams (`/dev/zero`, a FIFO fed by `yes`) are
/// read up to the same 64 MB as files and refused there, by every command
/// that reads one (they were read until memory ran out).
/// Bounded by `timeout`.
#[test]
fn endless_inputs_stop_at_the_input_limit() {
    let d = tempfile::tempdir().unwrap();
    let bin = env!("CARGO_BIN_EXE_morphosys");
    let sh = |cmd: &str| {
        let out = std::process::Command::new("bash")
            .current_dir(d.path())
            .args(["-c", &format!("timeout 60 {cmd}")])
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    for args in [
        "reference /dev/zero",
        "run /dev/zero",
        "asm /dev/zero",
        "render --size 8x8 --firmware /dev/zero",
        "render --size 8x8 --timing /dev/zero",
    ] {
        let (code, err) = sh(&format!("'{bin}' {args}"));
        assert_eq!(code, Some(1), "{args}: {err}");
        assert!(
            err.contains("/dev/zero") && err.contains("more than 64 MB"),
            "{args}: {err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "{args}: {err}");
    }
    let (code, err) = sh(&format!(
        "bash -c 'mkfifo y.nff; (yes > y.nff 2>/dev/null &); '\"'{bin}'\"' reference y.nff'"
    ));
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("y.nff") && err.contains("more than 64 MB"),
        "{err}"
    );
}

/// Errors that had no location get one, and a file with many errors is
/// summed up: a TOML nesting past the parser's limit
/// names its line (scene and timing file), a camera angle too wide for
/// the chip names the viewpoint's line, and a program cut short shows
/// three errors and one line for the rest, not 150 lines.
#[test]
fn errors_are_located_and_summed_up() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path();
    let deep = format!(
        "# a scene\n\n[{}]\n",
        std::iter::repeat_n("a", 100).collect::<Vec<_>>().join(".")
    );
    std::fs::write(p.join("deep.toml"), &deep).unwrap();
    fails_with(p, &["reference", "deep.toml"], &["deep.toml:3:"]);
    fails_with(
        p,
        &["render", "--size", "8x8", "--timing", "deep.toml"],
        &["deep.toml:3:"],
    );
    let wide = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/spd/tetra-1.nff"),
    )
    .unwrap();
    let v = wide.lines().position(|l| l.starts_with('v')).unwrap() + 1;
    let wide: String = wide
        .lines()
        .map(|l| {
            if l.starts_with("angle") {
                "angle 179.9"
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(p.join("wide.nff"), wide).unwrap();
    fails_with(
        p,
        &["render", "wide.nff", "--size", "8x8"],
        &[&format!("wide.nff:{v}:"), "too wide"],
    );
    let golden = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/golden/default.s"),
    )
    .unwrap();
    // Whole lines (a line cut in two is one syntax error, which stops the
    // assembler before it looks up names).
    let cut = golden[..20_000].rfind('\n').unwrap();
    std::fs::write(p.join("cut.s"), &golden[..cut]).unwrap();
    let (ok, _, err) = morphosys(p, &["asm", "cut.s"]);
    assert!(!ok);
    assert!(
        err.lines().count() <= 12,
        "{} lines: {err}",
        err.lines().count()
    );
    assert!(
        err.contains("more errors") && err.contains("undefined:"),
        "{err}"
    );
}

/// A polygon of many short edges is not degenerate (a
/// 100,000-vertex circle was refused as 'collinear or coincident', its
/// corners being judged against the scene's size, while a 100,000-vertex
/// square passed): the reference renders it, and the chip refuses it only
/// for what its format cannot hold, saying so.
#[test]
fn a_polygon_of_many_short_edges_is_not_degenerate() {
    let d = tempfile::tempdir().unwrap();
    let n = 100_000;
    let mut nff = String::from(NFF_HEAD);
    nff.push_str(&format!("p {n}\n"));
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        nff.push_str(&format!("{:.9} {:.9} 0\n", a.cos(), a.sin()));
    }
    std::fs::write(d.path().join("circle.nff"), nff).unwrap();
    let (ok, out, err) = morphosys(
        d.path(),
        &[
            "reference",
            "circle.nff",
            "--size",
            "16x16",
            "--out",
            "c.png",
        ],
    );
    assert!(ok, "{err}");
    let hit: usize = out
        .split(" eye rays (")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|h| h.parse().ok())
        .unwrap_or_else(|| panic!("{out}"));
    assert!(
        hit > 30,
        "the disc covers about a fifth of the image: {out}"
    );
    let (ok, _, err) = morphosys(d.path(), &["render", "circle.nff", "--size", "16x16"]);
    assert!(!ok);
    assert!(
        !err.contains("degenerate") && err.contains("circle.nff:11:"),
        "{err}"
    );
}

/// A deep median tree over objects that overlap by the hundred (SPD shells
/// at `--max-depth 30` took the host's memory until the kernel killed it):
/// the build stops at the node budget and the render says why, naming the
/// options, without writing the image.
#[test]
fn a_tree_too_large_for_node_indices_is_refused_before_memory_runs_out() {
    let d = tempfile::tempdir().unwrap();
    let mut nff = NFF_HEAD.to_string();
    for i in 0..1500 {
        let x = -0.75 + i as f64 * 0.001;
        nff += &format!("s {x} {x} {x} 0.05\n");
    }
    std::fs::write(d.path().join("overlap.nff"), nff).unwrap();
    fails_with(
        d.path(),
        &[
            "render",
            "overlap.nff",
            "--split",
            "median",
            "--max-depth",
            "32",
            "--datapath",
            "32",
            "--size",
            "8x8",
            "--out",
            "x.png",
        ],
        &["overlap.nff", "grows past 65536 nodes", "--max-depth"],
    );
    assert!(!d.path().join("x.png").exists());
}

/// A scene's file name is written into the generated program's header
/// comment: its line breaks are written out, not lines of the program
/// (a name holding `\n.entry 0\nhalt` ran that program instead).
#[test]
fn a_scene_name_cannot_add_lines_to_the_program() {
    let d = tempfile::tempdir().unwrap();
    let tetra = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/spd/tetra-1.nff");
    let evil = "t\n.entry 0\nhalt ;.nff";
    std::fs::copy(&tetra, d.path().join(evil)).unwrap();
    std::fs::copy(&tetra, d.path().join("plain.nff")).unwrap();
    let run = |scene: &str, asm: &str| {
        let args = [
            "render",
            scene,
            "--size",
            "16x16",
            "--datapath",
            "16",
            "--out",
            "o.png",
            "--emit-asm",
            asm,
        ];
        let (ok, out, err) = morphosys(d.path(), &args);
        assert!(ok, "{err}");
        let cycles = out
            .lines()
            .find(|l| l.starts_with("cycles"))
            .unwrap()
            .to_string();
        (cycles, std::fs::read_to_string(d.path().join(asm)).unwrap())
    };
    let (evil_cycles, evil_asm) = run(evil, "evil.s");
    let (plain_cycles, plain_asm) = run("plain.nff", "plain.s");
    assert_eq!(evil_cycles, plain_cycles);
    assert!(
        evil_asm
            .lines()
            .next()
            .unwrap()
            .ends_with("tU+000A.entry 0U+000Ahalt ;.nff"),
        "{}",
        evil_asm.lines().next().unwrap()
    );
    assert!(!evil_asm
        .lines()
        .any(|l| l == ".entry 0" || l.starts_with("halt ;")));
    assert_eq!(evil_asm.lines().count(), plain_asm.lines().count());
}

/// `report --readme` naming the document `--out` writes is refused before
/// any render (the second write, built from the old text, replaced the
/// first).
#[test]
fn report_refuses_the_readme_and_the_document_as_one_file() {
    let d = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    std::fs::create_dir_all(d.path().join("scenes")).unwrap();
    std::fs::copy(
        root.join("scenes/default.toml"),
        d.path().join("scenes/default.toml"),
    )
    .unwrap();
    let doc = "# r\n<!-- report: headline -->\nold\n<!-- /report: headline -->\n";
    std::fs::write(d.path().join("r.md"), doc).unwrap();
    fails_with(
        d.path(),
        &[
            "report", "--only", "headline", "--out", "r.md", "--readme", "./r.md",
        ],
        &["--readme", "r.md", "same file"],
    );
    assert_eq!(std::fs::read_to_string(d.path().join("r.md")).unwrap(), doc);
}

/// A line break in a waveform's path (or a folder above it) would add
/// lines to the GTKWave save file written beside it, where `^>1 sh x` runs
/// a program: refused before the run, for `run`, `render` and `tb rc`,
/// and nothing is written.
#[test]
fn a_waveform_path_cannot_add_lines_to_the_save_file() {
    let d = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    std::fs::copy(
        root.join("firmware/conformance/dct.s"),
        d.path().join("dct.s"),
    )
    .unwrap();
    let evil = "w\n^>1 sh payload.sh\n[*]x.vcd";
    let runs: [&[&str]; 3] = [
        &["run", "dct.s", "--vcd", evil, "--trace-cycles", "200"],
        &[
            "render",
            "../scenes/spd/tetra-1.nff",
            "--size",
            "8x8",
            "--out",
            "o.png",
            "--vcd",
            evil,
        ],
        &["tb", "rc", "--vcd", evil],
    ];
    for args in runs {
        let args: Vec<String> = args
            .iter()
            .map(|a| a.replace("../scenes", &root.join("scenes").display().to_string()))
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        fails_with(d.path(), &args, &["--vcd", "U+000A", "save file"]);
    }
    // A folder above it: the save file holds the absolute path.
    let above = d.path().join("a\nb");
    std::fs::create_dir(&above).unwrap();
    std::fs::copy(root.join("firmware/conformance/dct.s"), above.join("dct.s")).unwrap();
    fails_with(
        &above,
        &["run", "dct.s", "--vcd", "w.vcd", "--trace-cycles", "200"],
        &["--vcd w.vcd", "a folder above it", "U+000A"],
    );
    assert!(!above.join("w.vcd").exists());
    let left: Vec<_> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".vcd") || n.contains(".gtkw"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// `tb cosim` hands its build folder to Verilator, which runs `make -C
/// <folder>` through the shell: a folder whose path holds `$(...)` (as
/// `--build-dir`, or a folder above it) is refused before Verilator runs,
/// and nothing is run.
#[test]
fn the_cosim_build_folder_cannot_run_shell_code() {
    let d = tempfile::tempdir().unwrap();
    let args = |dir: &str| {
        [
            "-q",
            "tb",
            "cosim",
            "--datapath",
            "16",
            "--random",
            "10",
            "--array",
            "0",
            "--build-dir",
            dir,
        ]
        .map(String::from)
    };
    let a = args("vb$(touch${IFS}PWN_VB)");
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    fails_with(d.path(), &a, &["--build-dir", "holds `$`", "make"]);
    let above = d.path().join("p$(touch${IFS}PWN_ABOVE)");
    std::fs::create_dir(&above).unwrap();
    let a = args("vb");
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    fails_with(&above, &a, &["--build-dir", "holds `$`"]);
    assert!(!d.path().join("PWN_VB").exists() && !above.join("PWN_ABOVE").exists());
    assert!(!d.path().join("vb$(touch${IFS}PWN_VB)").exists() && !above.join("vb").exists());
}

/// `tb cosim --random/--array` counts are range-checked before anything is
/// allocated (issue 62 reported 2^64 - 1 panicking on the stream's
/// capacity and 10^9 asking for 16 GB).
#[test]
fn cosim_counts_are_range_checked() {
    let d = tempfile::tempdir().unwrap();
    for (flag, n) in [
        ("--random", "18446744073709551615"),
        ("--random", "1000000000"),
        ("--array", "200000000"),
        ("--random", "many"),
    ] {
        let (ok, _, err) = morphosys(d.path(), &["tb", "cosim", flag, n]);
        assert!(!ok, "{flag} {n}");
        assert!(
            err.contains(flag) && !err.contains("panicked"),
            "{flag} {n}: {err}"
        );
    }
    let (ok, _, err) = morphosys(d.path(), &["tb", "cosim", "--random", "30000000"]);
    assert!(!ok && err.contains("at most 20000000"), "{err}");
}

/// `RAYON_NUM_THREADS` is checked as `MORPHOSYS_SIMD` is: nonsense is
/// refused, and a count far over the cores is capped and said (issue 62
/// reported 1,000 threads 60 times slower than 2, with the same image).
#[test]
fn host_thread_counts_are_checked_and_capped() {
    let d = tempfile::tempdir().unwrap();
    let run = |threads: &str| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_morphosys"))
            .current_dir(d.path())
            .env("RAYON_NUM_THREADS", threads)
            .args(["spd", "tetra", "--out", "t.nff"])
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    for bad in ["abc", "-1", "2.5", ""] {
        let (code, err) = run(bad);
        assert_eq!(code, Some(2), "{bad:?}: {err}");
        assert!(
            err.contains("RAYON_NUM_THREADS") && err.contains("not a number"),
            "{err}"
        );
    }
    let (code, err) = run("100000");
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("RAYON_NUM_THREADS=100000") && err.contains("per core"),
        "{err}"
    );
    let (code, err) = run("2");
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("RAYON_NUM_THREADS"), "{err}");
}

/// An image with one side over the limit and few pixels is refused for
/// that side, not for a cost of "about 0 MB ... about 0 seconds".
#[test]
fn a_long_thin_size_is_refused_for_its_side() {
    let d = tempfile::tempdir().unwrap();
    fails_with(
        d.path(),
        &["render", "--size", "1x10000"],
        &["--size", "1x10000", "the height is over 4096"],
    );
    let (ok, _, err) = morphosys(d.path(), &["render", "--size", "10000x10000"]);
    assert!(!ok && err.contains("GB of memory"), "{err}");
}

/// A trace window that starts after the program halts says its waveform
/// is empty (it was written without a word).
#[test]
fn a_trace_window_past_the_halt_is_said() {
    let d = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    std::fs::copy(
        root.join("firmware/conformance/dct.s"),
        d.path().join("dct.s"),
    )
    .unwrap();
    let (ok, _, err) = morphosys(
        d.path(),
        &[
            "-q",
            "run",
            "dct.s",
            "--vcd",
            "z.vcd",
            "--trace-from",
            "99999999",
        ],
    );
    assert!(ok, "{err}");
    assert!(
        err.contains("warning: --trace-from 99999999 is past the program's halt"),
        "{err}"
    );
    let (ok, _, err) = morphosys(d.path(), &["-q", "run", "dct.s", "--vcd", "y.vcd"]);
    assert!(ok && !err.contains("warning"), "{err}");
}

/// `report --list` says what each section renders (it printed titles
/// only).
#[test]
fn report_list_says_what_each_section_renders() {
    let d = tempfile::tempdir().unwrap();
    let (ok, out, err) = morphosys(d.path(), &["report", "--list"]);
    assert!(ok, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    let heads: Vec<usize> = (0..lines.len())
        .filter(|&i| !lines[i].starts_with(' '))
        .collect();
    assert!(heads.len() >= 10, "{out}");
    for (k, &i) in heads.iter().enumerate() {
        let end = heads.get(k + 1).copied().unwrap_or(lines.len());
        let about = lines[i + 1..end].join(" ");
        assert!(
            about.split_whitespace().count() >= 8,
            "{}: {about:?}",
            lines[i]
        );
    }
    assert!(
        out.contains("whitted") && out.contains("ray depth 2"),
        "{out}"
    );
}

/// A file where a waveform's side folder goes (`.surfer`) is found before
/// the render, with the path named (the render failed at its end, "Not a
/// directory", and wrote nothing).
#[test]
fn an_obstructed_side_folder_is_found_before_the_work() {
    let d = tempfile::tempdir().unwrap();
    let tetra = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/spd/tetra-1.nff");
    std::fs::write(d.path().join(".surfer"), "x").unwrap();
    let t = tetra.display().to_string();
    fails_with(
        d.path(),
        &[
            "-q", "render", &t, "--size", "8x8", "--vcd", "w.vcd", "--out", "w.png",
        ],
        &[".surfer", "is not a folder"],
    );
    assert!(!d.path().join("w.png").exists() && !d.path().join("w.vcd").exists());
}

/// A program over TinyRISC's code space (SPD gears-1 at ray depth 8) is
/// said as such, not as an internal error with a caret under an empty
/// line.
#[test]
fn a_program_over_the_code_space_says_so() {
    let d = tempfile::tempdir().unwrap();
    let gears = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/spd/gears-1.nff");
    let g = gears.display().to_string();
    let args = [
        "render",
        &g,
        "--depth",
        "8",
        "--datapath",
        "16",
        "--size",
        "8x8",
        "--out",
        "o.png",
    ];
    fails_with(
        d.path(),
        &args,
        &["ray depth 8", "bytes of TinyRISC code", "lower --depth"],
    );
    let (_, _, err) = morphosys(d.path(), &args);
    assert!(!err.contains("internal"), "{err}");
}

/// `cost --json -` gives standard output to the JSON alone (the table goes
/// to standard error), and `--synthesize`'s outputs are checked before
/// the synthesis: one file twice, a missing folder.
#[test]
fn cost_outputs_are_checked_and_kept_apart() {
    let d = tempfile::tempdir().unwrap();
    let (ok, out, err) = morphosys(d.path(), &["cost", "--json", "-"]);
    assert!(ok, "{err}");
    let v: serde_json::Value =
        serde_json::from_str(&out).expect("standard output is the JSON alone");
    assert!(v["widths"].is_array());
    assert!(err.contains("What the RC costs in silicon"), "{err}");
    fails_with(
        d.path(),
        &[
            "cost",
            "--synthesize",
            "--out",
            "x.json",
            "--json",
            "x.json",
        ],
        &["same file"],
    );
    fails_with(
        d.path(),
        &["cost", "--synthesize", "--out", "no/such/x.json"],
        &["--out", "does not exist"],
    );
}

/// `--leaf-pieces 1,1` says the pieces hold whole records (at least one
/// each), not pieces "of up to 1 words".
#[test]
fn leaf_pieces_smaller_than_a_record_are_said_as_done() {
    let d = tempfile::tempdir().unwrap();
    let balls = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/spd/balls-4.nff");
    let b = balls.display().to_string();
    let (ok, out, err) = morphosys(
        d.path(),
        &[
            "-q",
            "render",
            &b,
            "--size",
            "8x8",
            "--leaf-pieces",
            "1,1",
            "--out",
            "o.png",
        ],
    );
    assert!(ok, "{err}");
    let line = out
        .lines()
        .find(|l| l.starts_with("scene streamed"))
        .expect(&out);
    assert!(
        line.contains("pieces of whole records (at least one each)"),
        "{line}"
    );
}

/// The packet traversal's knobs given with `--traversal paper` are said to
/// be ignored (they were ignored silently); their defaults are not.
#[test]
fn packet_knobs_under_the_paper_traversal_are_said() {
    let d = tempfile::tempdir().unwrap();
    let tetra = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/spd/tetra-1.nff");
    let t = tetra.display().to_string();
    let base = [
        "-q",
        "render",
        &t,
        "--size",
        "8x8",
        "--traversal",
        "paper",
        "--out",
        "o.png",
    ];
    let with = |extra: &[&str]| {
        let mut a: Vec<&str> = base.to_vec();
        a.extend_from_slice(extra);
        let (ok, _, err) = morphosys(d.path(), &a);
        assert!(ok, "{err}");
        err
    };
    let err = with(&[
        "--child-order",
        "majority",
        "--leaf-pieces",
        "64,256",
        "--collapse",
        "2",
    ]);
    for k in ["--child-order majority", "--leaf-pieces", "--collapse 2"] {
        assert!(err.contains(&format!("warning: {k}")), "{k}: {err}");
    }
    assert!(!with(&["--child-order", "auto"]).contains("warning"));
    assert!(!with(&[]).contains("warning"));
}
