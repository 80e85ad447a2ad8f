//! FST waveforms: a `--vcd` path ending in `.fst` writes
//! FST (GTKWave's and Surfer's compressed format) through the `fst-writer`
//! crate. Each test writes the same window as VCD and as FST and reads both
//! back with the `wellen` crate (the reader Surfer uses): the same signals
//! under the same names, changing at the same times to the same values.
//! GTKWave's `fst2vcd` must convert the FST too, to a VCD that reads back
//! the same (the ignored tests: `.ci/run` installs GTKWave and runs them).

mod common;
use common::morphosys;
use std::collections::BTreeMap;
use std::path::Path;

/// Every signal of a waveform: full name -> its changes (time, bits).
type Changes = BTreeMap<String, Vec<(u64, String)>>;

fn read_back(path: &Path) -> Changes {
    let mut w = wellen::simple::read(path)
        .unwrap_or_else(|e| panic!("{} does not read back: {e:?}", path.display()));
    let h = w.hierarchy();
    let vars: Vec<(String, wellen::SignalRef)> = h
        .all_vars()
        .map(|v| (h[v].full_name(h), h[v].signal_ref()))
        .collect();
    let refs: Vec<wellen::SignalRef> = vars.iter().map(|(_, r)| *r).collect();
    w.load_signals(&refs);
    let times = w.time_table().to_vec();
    let mut out = Changes::new();
    for (name, r) in vars {
        let signal = w.get_signal(r).expect("loaded");
        // Undefined (x) before the first value: FST says so explicitly
        // from time 0 (its first frame) where a VCD that starts later
        // says nothing; both mean the same.
        let changes: Vec<(u64, String)> = signal
            .iter_changes()
            .skip_while(|(_, v)| v.to_bit_string().is_some_and(|b| b.contains('x')))
            .map(|(t, v)| {
                // Leading zeros are not part of a value (VCD drops them).
                let bits = v.to_bit_string().expect("a bit vector");
                let bits = bits.trim_start_matches('0');
                (
                    times[t as usize],
                    if bits.is_empty() { "0" } else { bits }.to_string(),
                )
            })
            .collect();
        assert!(out.insert(name.clone(), changes).is_none(), "{name} twice");
    }
    out
}

fn assert_same(vcd: &Changes, fst: &Changes, what: &str) {
    assert_eq!(
        vcd.keys().collect::<Vec<_>>(),
        fst.keys().collect::<Vec<_>>(),
        "{what}: the signals differ"
    );
    let mut changes = 0;
    for (name, a) in vcd {
        let b = &fst[name];
        assert_eq!(a, b, "{what}: {name} differs");
        changes += a.len();
    }
    assert!(vcd.len() > 10 && changes > 100, "{what}: too little traced");
}

/// fst2vcd (GTKWave's) converts our FST, and its VCD reads back the same.
fn check_with_fst2vcd(fst: &Path, want: &Changes) {
    let out = std::process::Command::new("fst2vcd")
        .arg(fst)
        .output()
        .unwrap_or_else(|e| panic!("fst2vcd (Debian package gtkwave) is not installed: {e}"));
    assert!(
        out.status.success(),
        "fst2vcd {}: {}",
        fst.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let back = fst.with_extension("fst2vcd.vcd");
    std::fs::write(&back, &out.stdout).unwrap();
    assert_same(want, &read_back(&back), "fst2vcd's VCD");
}

/// `dct.vcd` and `dct.fst` in `dir`: the same run of the DCT conformance
/// program, traced in both formats.
fn trace_program(dir: &Path) {
    let program = Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/conformance/dct.s");
    let program = program.to_str().unwrap();
    for name in ["dct.vcd", "dct.fst"] {
        let (ok, _, err) = morphosys(dir, &["run", program, "--vcd", name]);
        assert!(ok, "{name}: {err}");
    }
}

/// `r.vcd` and `r.fst` in `dir`: the same window (cycles 2000 to 5000) of a
/// 16x16 render of the default scene.
fn trace_render_window(dir: &Path) {
    for name in ["r.vcd", "r.fst"] {
        let (ok, _, err) = morphosys(
            dir,
            &[
                "render",
                "--size",
                "16x16",
                "--vcd",
                name,
                "--trace-from",
                "2000",
                "--trace-cycles",
                "3000",
            ],
        );
        assert!(ok, "{name}: {err}");
    }
}

#[test]
fn a_program_traced_as_fst_reads_back_as_its_vcd() {
    let dir = tempfile::tempdir().unwrap();
    trace_program(dir.path());
    let vcd = read_back(&dir.path().join("dct.vcd"));
    let fst = read_back(&dir.path().join("dct.fst"));
    assert_same(&vcd, &fst, "run dct.s");
    // The GTKWave save file names the FST.
    let gtkw = std::fs::read_to_string(dir.path().join("dct.gtkw")).unwrap();
    assert!(gtkw.contains("dct.fst"), "{gtkw}");
}

/// GTKWave's own converter reads our FST of a program and of a render
/// window back to the VCD we wrote of the same window.
#[test]
#[ignore = "needs GTKWave's fst2vcd (Debian package gtkwave); .ci/run installs it and runs the ignored tests"]
fn gtkwaves_fst2vcd_converts_our_fst_to_our_vcd() {
    let dir = tempfile::tempdir().unwrap();
    trace_program(dir.path());
    let vcd = read_back(&dir.path().join("dct.vcd"));
    check_with_fst2vcd(&dir.path().join("dct.fst"), &vcd);
    trace_render_window(dir.path());
    let vcd = read_back(&dir.path().join("r.vcd"));
    check_with_fst2vcd(&dir.path().join("r.fst"), &vcd);
}

#[test]
fn a_render_window_traced_as_fst_reads_back_as_its_vcd_and_is_smaller() {
    let dir = tempfile::tempdir().unwrap();
    trace_render_window(dir.path());
    let vcd_path = dir.path().join("r.vcd");
    let fst_path = dir.path().join("r.fst");
    let vcd = read_back(&vcd_path);
    let fst = read_back(&fst_path);
    assert_same(&vcd, &fst, "render window");
    let (a, b) = (
        std::fs::metadata(&vcd_path).unwrap().len(),
        std::fs::metadata(&fst_path).unwrap().len(),
    );
    assert!(
        b * 4 < a,
        "FST {b} bytes is not much smaller than VCD {a} bytes"
    );
}

#[test]
fn an_fst_waveform_into_a_pipe_is_refused_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("w.fst");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("mkfifo unavailable; test skipped");
        return;
    }
    let program = Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/conformance/dct.s");
    let (ok, _, err) = morphosys(
        dir.path(),
        &["run", program.to_str().unwrap(), "--vcd", "w.fst"],
    );
    assert!(!ok);
    assert!(
        err.contains("an FST waveform needs a regular file"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}

/// A render's waveform reads well by default: the
/// control path, the array's masks and one RC, every group open in the
/// save file; `--trace-scope all` records every signal.
#[test]
fn a_render_traces_what_an_architect_looks_at_first() {
    let dir = tempfile::tempdir().unwrap();
    let render = |name: &str, extra: &[&str]| {
        let mut args = vec![
            "render",
            "--size",
            "16x16",
            "--vcd",
            name,
            "--trace-cycles",
            "500",
        ];
        args.extend(extra);
        let (ok, _, err) = morphosys(dir.path(), &args);
        assert!(ok, "{err}");
        read_back(&dir.path().join(name))
    };
    let default = render("d.vcd", &[]);
    for want in [
        "morphosys.tinyrisc.pc",
        "morphosys.tinyrisc.ir",
        "morphosys.tinyrisc.state",
        "morphosys.broadcast.run_ctx",
        "morphosys.dma.remaining",
        "morphosys.array.ctx",
        "morphosys.array.awake",
        "morphosys.array.flag_f",
        "morphosys.array.rc_r0_c0.regfile.r1",
        "morphosys.array.rc_r0_c0.flags.f",
    ] {
        assert!(
            default.contains_key(want),
            "{want} not traced: {:?}",
            default.keys()
        );
    }
    assert!(default.len() < 100, "{} signals by default", default.len());
    assert!(!default.keys().any(|k| k.contains("rc_r0_c1")));
    // All 64 RCs awake at the start of a frame: the mask is all ones.
    let awake = &default["morphosys.array.awake"];
    assert_eq!(awake[0].1, "1".repeat(64), "{awake:?}");
    let gtkw = std::fs::read_to_string(dir.path().join("d.gtkw")).unwrap();
    assert!(gtkw.contains("@800200\n-tinyrisc"), "{gtkw}");
    let all = render("a.vcd", &["--trace-scope", "all"]);
    assert!(
        all.len() > 1800,
        "{} signals with --trace-scope all",
        all.len()
    );
    let gtkw = std::fs::read_to_string(dir.path().join("a.gtkw")).unwrap();
    assert!(!gtkw.contains("@c00200"), "a group saved closed"); // An empty list of scopes is no list (it once meant every signal).
    for empty in ["", ",", " , "] {
        let (ok, _, err) = common::morphosys(
            dir.path(),
            &[
                "render",
                "--size",
                "8x8",
                "--vcd",
                "e.vcd",
                "--trace-scope",
                empty,
            ],
        );
        assert!(
            !ok && err.contains("--trace-scope") && err.contains("names no scope"),
            "{err}"
        );
        assert!(!dir.path().join("e.vcd").exists());
    }
}

/// An FST trace longer than one in-memory section (the writer
/// thread once flushed a section in the middle of a time step, which the
/// FST writer refuses with a panic): with sections of 256 bytes, a run of
/// dct.s is written in many sections and still reads back as its VCD.
#[test]
fn an_fst_of_many_sections_reads_back_as_its_vcd() {
    let dir = tempfile::tempdir().unwrap();
    let program = Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/conformance/dct.s");
    let img = tb::cmd_run::load_program(&program).unwrap();
    let mut fst = rtl::trace::TraceConfig::new(dir.path().join("s.fst"));
    fst.fst_section_bytes = 256;
    let vcd = rtl::trace::TraceConfig::new(dir.path().join("s.vcd"));
    for cfg in [fst, vcd] {
        let out =
            tb::cmd_run::run_image(&img, rtl::Timing::default(), 2_000_000, Some(cfg)).unwrap();
        assert!(out.result.is_ok());
    }
    let vcd = read_back(&dir.path().join("s.vcd"));
    let fst = read_back(&dir.path().join("s.fst"));
    assert_same(&vcd, &fst, "dct.s in 256-byte FST sections");
}

/// A render's waveform names the PC and the broadcast unit's context
/// address by the firmware's labels: the GTKWave save file shows them
/// through filter files written beside it, and every value the PC took in
/// the window is there as the label at or before it plus the offset, which
/// the assembler's own symbol table of the emitted program confirms.
#[test]
fn a_render_waveform_names_the_pc_and_the_context_by_the_firmware_labels() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (ok, _, err) = morphosys(
        d,
        &[
            "render",
            "--size",
            "16x16",
            "--vcd",
            "w.vcd",
            "--trace-cycles",
            "3000",
            "--emit-asm",
            "fw.s",
        ],
    );
    assert!(ok, "{err}");
    let gtkw = std::fs::read_to_string(d.join("w.gtkw")).unwrap();
    for (filter, signal) in [
        ("w.code_labels.txt", "morphosys.tinyrisc.pc[31:0]"),
        ("w.context_labels.txt", "morphosys.broadcast.run_ctx[12:0]"),
    ] {
        let at = gtkw
            .find(signal)
            .unwrap_or_else(|| panic!("{signal} not in the save file"));
        assert!(
            gtkw[..at].rsplit("^").next().unwrap().contains(filter),
            "{signal} is not shown through {filter}: {gtkw}"
        );
    }
    let img =
        firmware::asm::assemble(&std::fs::read_to_string(d.join("fw.s")).unwrap(), "fw.s").unwrap();
    let code = std::fs::read_to_string(d.join("w.code_labels.txt")).unwrap();
    let pcs = &read_back(&d.join("w.vcd"))["morphosys.tinyrisc.pc"];
    let mut named = 0;
    for line in code.lines().filter(|l| !l.starts_with('#')) {
        let (value, text) = line.split_once(' ').unwrap();
        let pc = u32::from_str_radix(value, 16).unwrap();
        let (label, offset) = text.split_once('+').unwrap_or((text, "0"));
        let at = img
            .symbol(label)
            .unwrap_or_else(|| panic!("{label} is no symbol")) as u32;
        assert_eq!(at + offset.parse::<u32>().unwrap(), pc, "{line}");
        named += 1;
    }
    // Every PC of the window is named (distinct values).
    let distinct: std::collections::BTreeSet<&String> = pcs.iter().map(|(_, v)| v).collect();
    assert_eq!(named, distinct.len(), "{code}");
    assert!(
        code.contains(" tile\n") || code.contains(" tile+"),
        "{code}"
    );
    let ctx = std::fs::read_to_string(d.join("w.context_labels.txt")).unwrap();
    assert!(ctx.contains(" k_eye\n"), "{ctx}");
    let base = img.symbol("CTXBASE").unwrap() as u32;
    for line in ctx.lines().filter(|l| !l.starts_with('#')) {
        let (value, text) = line.split_once(' ').unwrap();
        if text == "idle" {
            assert_eq!(value, "1FFF", "the broadcast unit idle: all ones");
            continue;
        }
        let (label, offset) = text.split_once('+').unwrap_or((text, "0"));
        let at = (img.symbol(label).unwrap() as u32 - base) / 4;
        assert_eq!(
            at + offset.parse::<u32>().unwrap(),
            u32::from_str_radix(value, 16).unwrap(),
            "{line}"
        );
    }
}

/// The size limit counts an FST as what it is, compressed
/// (not by the VCD estimate): a window of all signals over 1.5M
/// cycles is refused as VCD (about 5.5 GB) and taken as FST (about a tenth).
#[test]
fn the_size_limit_counts_an_fst_compressed() {
    let dir = tempfile::tempdir().unwrap();
    let window = [
        "render",
        "--size",
        "8x8",
        "--trace-scope",
        "all",
        "--trace-cycles",
        "1500000",
        "--vcd",
    ];
    let (ok, _, err) = common::morphosys(dir.path(), &[&window[..], &["big.vcd"]].concat());
    assert!(!ok && err.contains("of VCD, over the"), "{err}");
    assert!(!dir.path().join("big.vcd").exists());
    let (ok, _, err) = common::morphosys(dir.path(), &[&window[..], &["big.fst"]].concat());
    assert!(ok, "{err}");
    assert!(dir.path().join("big.fst").is_file());
}
