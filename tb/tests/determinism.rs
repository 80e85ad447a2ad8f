//! Same scene and options, same bits: images, figures (all but host
//! timing) and waveforms are identical with 1 and 2 host threads.

use firmware::tracer::Options;
use rtl::trace::TraceConfig;
use tb::cmd_render::render;
use tb::cmd_scene::load_scene;

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
    // 64x64: 64 tiles, two chip instances, so two threads really split it.
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
