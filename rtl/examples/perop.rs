//! Per-operation throughput of the 64-lane RC datapath (tracing off):
//! `cargo run --release -p morphosys-rtl --example perop [OP]`.
use rtl::kernel::Clocked;
use rtl::rc::context::{Context, Guard, Op};
use rtl::rc::{LaneNames, RcArray};
fn main() {
    let only = std::env::args().nth(1);
    let mut rc: Box<RcArray<64>> = Box::new(RcArray::new(LaneNames::Grid));
    for (name, c) in [
        ("nop", Context::NOP),
        ("and", Context::rrr(Op::And, 1, 1, 2)),
        ("add", Context::rrr(Op::Add, 1, 1, 2)),
        ("adds", Context::rrr(Op::Adds, 1, 1, 2)),
        (
            "mul",
            Context {
                shift: 8,
                ..Context::rrr(Op::Mul, 1, 1, 2)
            },
        ),
        (
            "mac",
            Context {
                shift: 8,
                ..Context::rrr(Op::Mac, 1, 1, 2)
            },
        ),
        (
            "cmp",
            Context {
                rd: 2,
                ..Context::rrr(Op::Cmp, 0, 1, 2)
            },
        ),
        ("min", Context::rrr(Op::Min, 1, 1, 2)),
        ("sra", Context::rri(Op::Sra, 1, 1, 2)),
        ("ld", Context::rri(Op::Ld, 1, 0, 2)),
        ("st", Context::rri(Op::St, 0, 1, 2)),
        ("sub", Context::rrr(Op::Sub, 1, 1, 2)),
        ("ldacc", Context::rri(Op::Ldacc, 0, 1, 14)),
    ]
    .into_iter()
    .flat_map(|(name, c)| {
        // Each also guarded by F, set in every other lane: the partial
        // masks of the tracer's sleeping rays.
        let guarded = Context {
            guard: Guard::IfF,
            ..c
        };
        [(name.to_string(), c), (format!("{name}(f)"), guarded)]
    }) {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        // The guarded cases run in every other lane (F set in the odd ones).
        rc.flags.f = 0xAAAA_AAAA_AAAA_AAAA;
        let n = 5_000_000u64;
        let w = c.encode();
        let t = std::time::Instant::now();
        for _ in 0..n {
            rc.set_context(w, c);
            rc.eval().unwrap();
            rc.commit();
        }
        let s = t.elapsed().as_secs_f64();
        println!("{name:8} {:6.1} M/s", n as f64 / s / 1e6);
    }
}
