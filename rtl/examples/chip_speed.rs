//! Whole-chip simulation speed (tracing off): TinyRISC streams runs of 1024
//! mixed contexts (ALU, multiplier, compare/guard, interconnect, FB stream)
//! back to back while DMA moves data, for 20 million cycles.
//! `cargo run --release -p morphosys-rtl --example chip_speed [CYCLES]`
//! (CARGO_TARGET_DIR as you use it).

use rtl::chip::run_to_halt;
use rtl::context_memory;
use rtl::rc::context::{ASrc, BSrc, Context, Guard, Op};
use rtl::tinyrisc::{Instr, Opcode::*};
use rtl::{Chip, Sim, Timing};

fn main() {
    let cycles: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000_000);
    // `nop` as second argument: every context a nop (the chip's own overhead)
    let nop = std::env::args().nth(2).is_some_and(|a| a == "nop");
    // `add`: every context `add r1, r1, #3` (compare with the bare datapath)
    let add = std::env::args().nth(2).is_some_and(|a| a == "add");
    let mut chip = Chip::new(Timing::default(), 1 << 20);
    // 1024 contexts in context memory bank 0.
    let mix = [
        Context::rri(Op::Add, 1, 1, 3),
        Context {
            shift: 8,
            ..Context::rrr(Op::Mac, 2, 1, 2)
        },
        Context {
            asrc: ASrc::Nbr,
            ra: 3,
            ..Context::rrr(Op::Add, 3, 0, 2)
        },
        Context {
            rd: 2,
            ..Context::rrr(Op::Cmp, 0, 3, 1)
        },
        Context {
            guard: Guard::IfF,
            ..Context::rrr(Op::Min, 4, 3, 1)
        },
        Context {
            asrc: ASrc::XRow,
            ra: 5,
            ..Context::rrr(Op::Sub, 5, 0, 4)
        },
        Context {
            asrc: ASrc::Fb,
            ra: 0,
            b: BSrc::Reg(5),
            ..Context::rrr(Op::Add, 6, 0, 5)
        },
        Context::rri(Op::Sra, 7, 6, 2),
    ];
    for a in 0..1024u16 {
        let c = if nop {
            Context::NOP
        } else if add {
            Context::rri(Op::Add, 1, 1, 3)
        } else {
            mix[a as usize % mix.len()]
        };
        chip.ctx_mem.write(a, c.encode());
    }
    assert!(context_memory::WORDS >= 1024);
    // TinyRISC: loop { ldfb (bank 2 of set 1, not streamed); sbcb 1024 from set 0; } forever
    let prog = [
        Instr::new(Addi, 1, 0, 0, 0),           // r1 = ctx 0
        Instr::new(Addi, 2, 0, 0, 0),           // r2 = FB 0x0000 (set 0)
        Instr::new(Lui, 3, 0, 0, 0x8000 >> 14), // r3 = FB 0x8000 (set 1)
        Instr::new(Addi, 4, 0, 0, 0x1000),      // r4 = main memory source
        // loop:
        Instr::new(Ldfb, 4, 3, 0, 256),
        Instr::new(Sbcb, 1, 2, 0, 1024),
        Instr::new(Dwait, 0, 0, 0, 0),
        Instr::new(Beq, 0, 0, 0, -4),
    ];
    for (k, i) in prog.iter().enumerate() {
        chip.mem.write(4 * k as u32, 4, i.encode().unwrap());
    }
    let mut sim = Sim::new(chip);
    let t0 = std::time::Instant::now();
    let r = run_to_halt(&mut sim, cycles);
    let secs = t0.elapsed().as_secs_f64();
    assert!(r.is_err(), "the loop never halts");
    let s = sim.top.stats();
    println!(
        "{} cycles in {secs:.3} s: {:.1} M cycles/s; array busy {:.1}%, {:.1} M array cycles/s",
        s.cycles,
        s.cycles as f64 / secs / 1e6,
        100.0 * s.array_busy_cycles as f64 / s.cycles as f64,
        s.array_busy_cycles as f64 / secs / 1e6
    );
}
