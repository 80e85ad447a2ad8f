//! Simulator throughput benchmarks (divan): `cargo bench -p morphosys-tb`.
//! Counters report simulated chip cycles per second alongside the time.
//! `morphosys bench` measures the same with tracing on and the multi-core
//! speed-up.

use divan::counter::ItemsCount;
use divan::Bencher;
use firmware::tracer::Options;

fn main() {
    divan::main();
}

/// One 64x32 tile group of the default scene on one chip instance (the
/// unit of work the renderer hands to a host thread), tracing off.
#[divan::bench(sample_count = 10)]
fn render_one_chip_instance(b: Bencher) {
    let scene = tb::cmd_scene::load_scene(None).unwrap();
    let opt = Options {
        width: 64,
        height: 32,
        ..Options::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let cycles = pool.install(|| {
        tb::render::render_chip(&scene, &opt, false, None)
            .unwrap()
            .cycles
    });
    b.counter(ItemsCount::new(cycles))
        .bench(|| pool.install(|| tb::render::render_chip(&scene, &opt, false, None).unwrap()));
}

/// The RC datapath alone: 64 lanes, one multiply-accumulate context.
#[divan::bench]
fn rc_array_mac(b: Bencher) {
    use rtl::kernel::Clocked;
    use rtl::rc::context::{Context, Op};
    let mut rc: Box<rtl::rc::RcArray<64>> =
        Box::new(rtl::rc::RcArray::new(rtl::rc::LaneNames::Grid));
    let c = Context {
        shift: 8,
        ..Context::rrr(Op::Mac, 1, 1, 2)
    };
    let w = c.encode();
    b.counter(ItemsCount::new(1000u32)).bench_local(|| {
        for _ in 0..1000 {
            rc.set_context(w, c);
            rc.eval().unwrap();
            rc.commit();
        }
    });
}
