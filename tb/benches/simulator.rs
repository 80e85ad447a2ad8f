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

/// A 64x32 frame of the default scene (32 tiles, one work item on the
/// bench's one thread), tracing off.
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
        tb::render::render_chip(&scene, &opt, &Default::default())
            .unwrap()
            .cycles
    });
    b.counter(ItemsCount::new(cycles)).bench(|| {
        pool.install(|| tb::render::render_chip(&scene, &opt, &Default::default()).unwrap())
    });
}

/// The RC datapath alone: one context of each kind on 64 lanes (eval and
/// clock edge in one `RcArray::step`, as the untraced loop runs them),
/// with varied register contents: what each operation costs
/// per cycle, against the mix of a render (`render_one_chip_instance`).
#[divan::bench(args = [
    "add", "sub", "mov", "min", "cmp", "sel", "mul", "mul_trunc", "mac", "msu",
    "ldacc", "ld_uniform", "ld_lanes", "st_uniform", "nop_guarded", "add_guarded",
])]
fn rc_array_op(b: Bencher, kind: &str) {
    use rtl::rc::context::{Context, Guard, Op};
    let mut rc: Box<rtl::rc::RcArray<64>> =
        Box::new(rtl::rc::RcArray::new(rtl::rc::LaneNames::Grid));
    for lane in 0..64 {
        for k in 0..16u8 {
            let v = (lane as i32 * 97 + k as i32 * 1031) % 4001 - 2000;
            rc.regs.poke(lane, k, v as i16);
        }
        // r3: a RAM address per lane; r4: one address in every lane
        rc.regs.poke(lane, 3, (lane * 7 % 500) as i16);
        rc.regs.poke(lane, 4, 100);
    }
    rc.flags.f = 0x5555_aaaa_0f0f_f0f0;
    let c = match kind {
        "add" => Context::rrr(Op::Add, 5, 1, 2),
        "sub" => Context::rrr(Op::Sub, 5, 1, 2),
        "mov" => Context::rrr(Op::Mov, 5, 1, 2),
        "min" => Context::rrr(Op::Min, 5, 1, 2),
        "cmp" => Context {
            rd: 2, // the condition (lt)
            ..Context::rrr(Op::Cmp, 0, 1, 2)
        },
        "sel" => Context::rrr(Op::Sel, 5, 1, 2),
        "mul" => Context {
            shift: 8,
            ..Context::rrr(Op::Mul, 5, 1, 2)
        },
        "mul_trunc" => Context {
            shift: 8,
            trunc: true,
            ..Context::rrr(Op::Mul, 5, 1, 2)
        },
        "mac" => Context {
            shift: 8,
            ..Context::rrr(Op::Mac, 5, 1, 2)
        },
        "msu" => Context {
            shift: 8,
            ..Context::rrr(Op::Msu, 5, 1, 2)
        },
        "ldacc" => Context {
            shift: 14,
            ..Context::rrr(Op::Ldacc, 0, 1, 2)
        },
        "ld_uniform" => Context::rri(Op::Ld, 5, 4, 3),
        "ld_lanes" => Context::rri(Op::Ld, 5, 3, 1),
        "st_uniform" => Context::rri(Op::St, 0, 1, 40),
        "nop_guarded" => Context {
            guard: Guard::IfF,
            ..Context::NOP
        },
        "add_guarded" => Context {
            guard: Guard::IfF,
            ..Context::rrr(Op::Add, 5, 1, 2)
        },
        _ => unreachable!("{kind}"),
    };
    let w = c.encode();
    b.counter(ItemsCount::new(1000u32)).bench_local(|| {
        for _ in 0..1000 {
            rc.set_context(w, c);
            rc.step().unwrap();
        }
    });
}
