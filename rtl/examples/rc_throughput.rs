//! Quick throughput probe of the lane-wise RC datapath (64 lanes, tracing
//! off): `cargo run --release -p morphosys-rtl --example rc_throughput`.
//! The benchmark proper arrives with `morphosys bench`.

use rtl::kernel::Clocked;
use rtl::rc::context::{Context, Op};
use rtl::rc::{LaneNames, RcArray};

fn main() {
    let mut rc: Box<RcArray<64>> = Box::new(RcArray::new(LaneNames::Grid));
    let prog: Vec<Context> = vec![
        Context::rri(Op::Add, 1, 1, 3),
        Context::rrr(Op::Mul, 2, 1, 1),
        Context {
            shift: 8,
            ..Context::rrr(Op::Mac, 3, 2, 1)
        },
        Context::rrr(Op::Sub, 4, 3, 2),
        Context {
            rd: 2,
            ..Context::rrr(Op::Cmp, 0, 4, 1)
        },
        Context {
            guard: rtl::rc::context::Guard::IfF,
            ..Context::rrr(Op::Min, 5, 4, 3)
        },
        Context::rri(Op::Sra, 6, 5, 2),
        Context::rrr(Op::Absd, 7, 6, 1),
    ];
    let words: Vec<u32> = prog.iter().map(|c| c.encode()).collect();
    let n = 20_000_000u64;
    let t = std::time::Instant::now();
    for i in 0..n {
        let k = (i % prog.len() as u64) as usize;
        rc.set_context(words[k], prog[k]);
        rc.eval().unwrap();
        rc.commit();
    }
    let s = t.elapsed().as_secs_f64();
    println!(
        "{n} array cycles in {s:.2} s: {:.1} M array cycles per host second (r7 lane 0 = {})",
        n as f64 / s / 1e6,
        rc.regs.read(7)[0]
    );
}
