//! The per-cycle path's instruction sets (`rtl::simd`): every path this
//! CPU can run gives the same bits. Each conformance program (its
//! waveform, registers and statistics) and renders on both datapaths and
//! both traversals (image, hit map, figures but host timing, waveform) are
//! run by the `morphosys` binary with `MORPHOSYS_SIMD` forcing each path,
//! and compared with the portable path's. A path this CPU lacks is left
//! out, with a note; on an x86-64 CPU with AVX-512 all three run.

use std::path::{Path, PathBuf};
use std::process::Command;

use rtl::simd::Simd;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `morphosys ARGS` on the path `simd`, in `dir`; panics with its error.
fn morphosys(simd: Simd, dir: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .current_dir(dir)
        .env("MORPHOSYS_SIMD", simd.name())
        .arg("--quiet")
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "MORPHOSYS_SIMD={} morphosys {}: {}",
        simd.name(),
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A JSON file without the host's timing (the only figures that differ
/// from run to run).
fn figures(path: &Path) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    let o = v.as_object_mut().unwrap();
    o.retain(|k, _| !k.starts_with("host_") && !k.contains("per_host"));
    v
}

/// Every output of the runs on one path: (file name, bytes or figures).
fn outputs(simd: Simd, dir: &Path) -> Vec<(String, Vec<u8>)> {
    let conformance = root().join("firmware/conformance");
    let mut programs: Vec<PathBuf> = std::fs::read_dir(&conformance)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "s"))
        .collect();
    programs.sort();
    assert!(programs.len() >= 18, "{} programs", programs.len());
    for p in &programs {
        let stem = p.file_stem().unwrap().to_str().unwrap();
        let (vcd, json) = (format!("{stem}.vcd"), format!("{stem}.json"));
        morphosys(
            simd,
            dir,
            &["run", p.to_str().unwrap(), "--vcd", &vcd, "--json", &json],
        );
    }
    let scene = root().join("scenes/default.toml");
    for (datapath, traversal) in [("16", "packet"), ("16", "paper"), ("32", "packet")] {
        let stem = format!("render-{datapath}-{traversal}");
        let (png, json, hits, fst) = (
            format!("{stem}.png"),
            format!("{stem}.json"),
            format!("{stem}.hits"),
            format!("{stem}.fst"),
        );
        morphosys(
            simd,
            dir,
            &[
                "render",
                scene.to_str().unwrap(),
                "--size",
                "32x32",
                "--datapath",
                datapath,
                "--traversal",
                traversal,
                "--out",
                &png,
                "--json",
                &json,
                "--hits",
                &hits,
                "--vcd",
                &format!("{stem}.vcd"),
                "--trace-cycles",
                "30000",
                "--trace-scope",
                "all",
            ],
        );
        // The FST writer too, on a window of its own.
        morphosys(
            simd,
            dir,
            &[
                "render",
                scene.to_str().unwrap(),
                "--size",
                "16x16",
                "--datapath",
                datapath,
                "--traversal",
                traversal,
                "--out",
                &format!("{stem}-fst.png"),
                "--vcd",
                &fst,
                "--trace-from",
                "5000",
                "--trace-cycles",
                "5000",
            ],
        );
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            let bytes = if name.ends_with(".json") {
                serde_json::to_vec(&figures(&p)).unwrap()
            } else if name.ends_with(".gtkw") {
                // A save file names its waveform by its whole path.
                let text = std::fs::read_to_string(&p).unwrap();
                text.replace(dir.to_str().unwrap(), "DIR").into_bytes()
            } else {
                std::fs::read(&p).unwrap()
            };
            (name, bytes)
        })
        .collect()
}

#[test]
fn every_simd_path_gives_the_same_cycles_images_and_waveforms() {
    let portable_dir = tempfile::tempdir().unwrap();
    let want = outputs(Simd::Portable, portable_dir.path());
    // 18 programs x (VCD, JSON, side files) and 3 renders' outputs.
    assert!(want.len() >= 60, "{} outputs", want.len());
    assert!(
        want.iter()
            .any(|(n, b)| n == "render-16-packet.vcd" && b.len() > 100_000),
        "the render's waveform has content"
    );
    let mut compared = 0;
    for simd in [Simd::Avx2, Simd::Avx512] {
        if !simd.supported() {
            eprintln!(
                "note: this CPU cannot run the {} path; not compared",
                simd.name()
            );
            continue;
        }
        let dir = tempfile::tempdir().unwrap();
        let got = outputs(simd, dir.path());
        let names = |o: &[(String, Vec<u8>)]| o.iter().map(|f| f.0.clone()).collect::<Vec<_>>();
        assert_eq!(names(&got), names(&want), "{}: other files", simd.name());
        for ((name, a), (_, b)) in want.iter().zip(&got) {
            assert!(
                a == b,
                "{name} differs between the portable and the {} path",
                simd.name()
            );
        }
        compared += 1;
    }
    // On an x86-64 CPU with AVX-512 (the CI machines) both wide paths ran.
    if Simd::Avx512.supported() {
        assert_eq!(compared, 2);
    }
}

#[test]
fn an_unknown_or_unsupported_path_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let run = |v: &str| {
        Command::new(env!("CARGO_BIN_EXE_morphosys"))
            .current_dir(dir.path())
            .env("MORPHOSYS_SIMD", v)
            .args(["spd", "tetra", "--size", "1"])
            .output()
            .unwrap()
    };
    let out = run("avx1024");
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty(), "no work done");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("MORPHOSYS_SIMD=\"avx1024\"") && err.contains("portable, avx2 or avx512"),
        "{err}"
    );
    for simd in Simd::ALL {
        let out = run(simd.name());
        assert_eq!(out.status.success(), simd.supported(), "{}", simd.name());
        if !simd.supported() {
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(err.contains("this CPU cannot run"), "{err}");
        }
    }
}
