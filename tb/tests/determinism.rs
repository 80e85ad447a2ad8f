//! Same scene and options, same bits: images, figures (all but host
//! timing) and waveforms are identical with 1 and 2 host threads.

use firmware::tracer::Options;
use rtl::trace::TraceConfig;
use tb::cmd_scene::load_scene;
use tb::render::render;

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn renders_are_bit_identical_for_1_and_2_threads() {
    let scene = load_scene(None).unwrap();
    // 64x64: 64 tiles, several work items on two threads.
    let opt = Options {
        width: 64,
        height: 64,
        ..Options::default()
    };
    let dir = tempfile::tempdir().unwrap();
    let mut outs = Vec::new();
    for threads in [1, 2] {
        let mut cfg = TraceConfig::new(dir.path().join(format!("t{threads}.vcd")));
        cfg.first = 1000;
        cfg.count = Some(2000);
        let (chip, rep) = in_pool(threads, || {
            render(
                &scene,
                &opt,
                &tb::render::RenderSettings {
                    trace: Some(cfg),
                    ..Default::default()
                },
            )
            .unwrap()
        });
        let mut j = rep.json.clone();
        let o = j.as_object_mut().unwrap();
        o.remove("host_seconds");
        o.remove("host_chip_seconds");
        o.remove("array_cycles_per_host_second");
        let vcd = std::fs::read(dir.path().join(format!("t{threads}.vcd"))).unwrap();
        outs.push((chip.rgb8, chip.hits, j, vcd));
    }
    let (a, b) = (&outs[0], &outs[1]);
    assert!(a.0 == b.0, "images differ");
    assert!(a.1 == b.1, "hit maps differ");
    assert_eq!(a.2, b.2, "figures differ");
    assert!(a.3.len() > 10_000, "the waveform has content");
    assert!(a.3 == b.3, "waveforms differ");
}

/// The in-process sweep renders its knob points concurrently: on 1 and on
/// 2 threads its table and charts are byte for byte the same.
#[test]
fn a_sweep_is_bit_identical_for_1_and_2_threads() {
    let d = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let tetra = root.join("scenes/spd/tetra-1.nff");
    let jacks = root.join("scenes/spd/jacks-1.nff");
    for threads in ["1", "2"] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_morphosys"))
            .current_dir(d.path())
            .env("RAYON_NUM_THREADS", threads)
            .args(["--quiet", "sweep"])
            .arg(&tetra)
            .arg(&jacks)
            .args(["--size", "16x16", "--family-size", "8x8", "--max-size", "1"])
            .args(["--families", "tetra", "--out-dir", threads])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let mut compared = 0;
    for e in std::fs::read_dir(d.path().join("1")).unwrap() {
        let name = e.unwrap().file_name();
        let a = d.path().join("1").join(&name);
        if a.is_dir() {
            continue;
        }
        let b = d.path().join("2").join(&name);
        assert!(
            std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
            "{name:?} differs between 1 and 2 threads"
        );
        compared += 1;
    }
    assert!(compared >= 5, "only {compared} files");
}
