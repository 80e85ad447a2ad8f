//! TinyRISC against a double of the chip around it (the `Machine` trait):
//! semantics checked against i64 arithmetic, stalls, commands and cycle
//! costs, without the array, the FB or the DMA.

use std::cell::Cell;

use rtl::array::Mode;
use rtl::dma::{DmaKind, DmaRequest};
use rtl::kernel::Fault;
use rtl::tinyrisc::decode::{Instr, Opcode, Opcode::*};
use rtl::tinyrisc::{execute::cycles, Command, Machine, RiscTiming, State, TinyRisc};

/// A machine double: a program, a small data memory, and knobs.
struct Double {
    prog: Vec<u32>,
    data: Vec<u8>,
    array_idle: Cell<bool>,
    can_issue: Cell<bool>,
    dma_idle: Cell<bool>,
    f: u64,
    sleep: u64,
}

impl Double {
    fn new(prog: &[Instr]) -> Double {
        Double {
            // a halt after the program, so a run can drain
            prog: prog
                .iter()
                .chain(&[Instr::new(Halt, 0, 0, 0, 0)])
                .map(|i| i.encode().unwrap())
                .collect(),
            data: vec![0; 256],
            array_idle: Cell::new(true),
            can_issue: Cell::new(true),
            dma_idle: Cell::new(true),
            f: 0,
            sleep: 0,
        }
    }
}

impl Machine for Double {
    fn fetch(&self, pc: u32) -> Result<u32, Fault> {
        self.prog
            .get(pc as usize / 4)
            .copied()
            .ok_or_else(|| Fault::new("double", "fetch"))
    }
    fn load(&self, addr: u32, size: u32) -> Result<u32, Fault> {
        let a = addr as usize;
        let b = self
            .data
            .get(a..a + size as usize)
            .ok_or_else(|| Fault::new("double", "load"))?;
        Ok(b.iter().rev().fold(0u32, |v, x| v << 8 | *x as u32))
    }
    fn check_store(&self, addr: u32, size: u32) -> Result<(), Fault> {
        self.load(addr, size).map(|_| ())
    }
    fn fb_read(&self, addr: u16) -> Result<i32, Fault> {
        Ok((addr as i16 ^ 0x5555) as i32)
    }
    fn check_fb_write(&self, _: u16, _: u32) -> Result<(), Fault> {
        Ok(())
    }
    fn rc_out(&self, lane: usize) -> i32 {
        (-(lane as i16) * 100) as i32
    }
    fn rc_flags(&self) -> (u64, u64) {
        (self.f, self.sleep)
    }
    fn array_can_issue(&self) -> bool {
        self.can_issue.get()
    }
    fn array_idle(&self) -> bool {
        self.array_idle.get()
    }
    fn dma_idle(&self) -> bool {
        self.dma_idle.get()
    }
    fn mem_size(&self) -> usize {
        1 << 20
    }
    fn cycle(&self) -> u64 {
        1234
    }
}

/// Run until `n` instructions issued; returns the cycles taken.
fn run(t: &mut TinyRisc, m: &Double, n: usize) -> (u64, Vec<Command>) {
    let mut cycles = 0;
    let mut cmds = Vec::new();
    let mut issued = 0;
    while issued < n {
        t.eval(m).unwrap();
        if t.state == State::Issue {
            issued += 1;
            if t.cmd != Command::None {
                cmds.push(t.cmd);
            }
        }
        t.commit();
        cycles += 1;
        assert!(cycles < 10_000);
    }
    // drain the busy cycles of the last instruction
    loop {
        t.eval(m).unwrap();
        if t.state != State::Busy {
            break;
        }
        t.commit();
        cycles += 1;
    }
    (cycles, cmds)
}

#[test]
fn alu_ops_match_i64_arithmetic() {
    let vals: [i64; 6] = [0, 1, -1, 0x7FFF_FFFF, -0x8000_0000, 0x1234_5678];
    let ops: &[(Opcode, fn(i64, i64) -> i64)] = &[
        (Add, |a, b| a + b),
        (Sub, |a, b| a - b),
        (And, |a, b| a & b),
        (Or, |a, b| a | b),
        (Xor, |a, b| a ^ b),
        (Nor, |a, b| !(a | b)),
        (Sll, |a, b| a << (b & 31)),
        (Srl, |a, b| (a as u32 as i64) >> (b & 31)),
        (Sra, |a, b| a >> (b & 31)),
        (Slt, |a, b| (a < b) as i64),
        (Sltu, |a, b| ((a as u32) < (b as u32)) as i64),
        (Mul, |a, b| a * b),
    ];
    for &(op, f) in ops {
        for &a in &vals {
            for &b in &vals {
                // r1 = a, r2 = b through lui/ori, then the op
                let prog = [
                    Instr::new(Lui, 1, 0, 0, ((a as u32) >> 14) as i32),
                    Instr::new(Ori, 1, 1, 0, (a as u32 & 0x3FFF) as i32),
                    Instr::new(Lui, 2, 0, 0, ((b as u32) >> 14) as i32),
                    Instr::new(Ori, 2, 2, 0, (b as u32 & 0x3FFF) as i32),
                    Instr::new(op, 3, 1, 2, 0),
                ];
                let m = Double::new(&prog);
                let mut t = TinyRisc::new(0, RiscTiming::default());
                run(&mut t, &m, 5);
                assert_eq!(t.regs.read(3), f(a, b) as u32, "{op:?} {a} {b}");
            }
        }
    }
}

#[test]
fn branches_calls_and_their_cycle_costs() {
    let tm = RiscTiming::default();
    // beq taken over one instruction, then jal to 0x20, jr back.
    let prog = [
        Instr::new(Beq, 0, 0, 0, 1),    // 0x00 taken -> 0x08
        Instr::new(Addi, 5, 0, 0, 99),  // 0x04 skipped
        Instr::new(Bne, 0, 0, 0, 5),    // 0x08 not taken
        Instr::new(Jal, 0, 0, 0, 0x20), // 0x0c
        Instr::new(Halt, 0, 0, 0, 0),   // 0x10
        Instr::new(Nop, 0, 0, 0, 0),
        Instr::new(Nop, 0, 0, 0, 0),
        Instr::new(Nop, 0, 0, 0, 0),
        Instr::new(Addi, 6, 6, 0, 7), // 0x20
        Instr::new(Jr, 15, 0, 0, 0),  // 0x24
    ];
    let m = Double::new(&prog);
    let mut t = TinyRisc::new(0, tm);
    let (c, _) = run(&mut t, &m, 6);
    assert_eq!(t.regs.read(5), 0);
    assert_eq!(t.regs.read(6), 7);
    assert_eq!(t.regs.read(15), 0x10);
    assert_eq!(t.pc, 0x10);
    let want = cycles(&tm, Beq, true)
        + cycles(&tm, Bne, false)
        + cycles(&tm, Jal, true)
        + cycles(&tm, Addi, false)
        + cycles(&tm, Jr, true)
        + 1;
    assert_eq!(c as u32, want);
    assert_eq!(want, 2 + 1 + 2 + 1 + 2 + 1);
}

#[test]
fn loads_stores_and_status_reads() {
    let mut m = Double::new(&[
        Instr::new(Addi, 1, 0, 0, -3),
        Instr::new(Sh, 1, 0, 0, 6), // store command
        Instr::new(Lh, 2, 0, 0, 8), // reads the double's memory
        Instr::new(Rcany, 3, 0, 0, 0),
        Instr::new(Rcall, 4, 0, 0, 0),
        Instr::new(Rcfh, 5, 0, 0, 0),
        Instr::new(Rcrisc, 7, 0, 0, 3),
        Instr::new(Lfb, 8, 0, 0, 0x10),
        Instr::new(Rdcyc, 9, 0, 0, 0),
    ]);
    m.data[8] = 0xFE;
    m.data[9] = 0xFF;
    m.f = 0xF0 << 32 | 1;
    m.sleep = !(0xF0 << 32 | 1 | 2); // awake: lanes 0, 1, 36..39
    let mut t = TinyRisc::new(0, RiscTiming::default());
    let (_, cmds) = run(&mut t, &m, 9);
    assert_eq!(
        cmds,
        vec![Command::Store {
            addr: 6,
            size: 2,
            value: -3i32 as u32
        }]
    );
    assert_eq!(t.regs.read(2), -2i32 as u32);
    assert_eq!(t.regs.read(3), 1); // lane 0 awake with F
    assert_eq!(t.regs.read(4), 0); // lane 1 awake without F
    assert_eq!(t.regs.read(5), 0xF0);
    assert_eq!(t.regs.read(7), -300i32 as u32);
    assert_eq!(t.regs.read(8), (0x10 ^ 0x5555) as u32);
    assert_eq!(t.regs.read(9), 1234);
}

#[test]
fn morphosys_instructions_issue_commands_and_stall_on_busy_units() {
    let prog = [
        Instr::new(Addi, 1, 0, 0, 100),
        Instr::new(Lui, 2, 0, 0, 2), // r2 = 0x8000
        Instr::new(Ldfb, 1, 2, 0, 64),
        Instr::new(Sbcb, 1, 2, 0, 5),
        Instr::new(Dbcb, 1, 0, 2, 3),
        Instr::new(Cbcr, 0, 2, 0, 2),
        Instr::new(Rcall, 3, 0, 0, 0),
    ];
    let m = Double::new(&prog);
    m.dma_idle.set(false);
    let mut t = TinyRisc::new(0, RiscTiming::default());
    // two issues, then ldfb stalls on the DMA
    for _ in 0..2 {
        t.eval(&m).unwrap();
        t.commit();
    }
    t.eval(&m).unwrap();
    assert_eq!(t.state, State::StallDma);
    t.commit();
    assert_eq!(t.pc, 8);
    assert_eq!(t.stall_dma, 1);
    m.dma_idle.set(true);
    t.eval(&m).unwrap();
    assert_eq!(
        t.cmd,
        Command::Dma(DmaRequest {
            kind: DmaKind::MemToFb,
            mem: 100,
            local: 0x8000,
            words: 64
        })
    );
    t.commit();
    t.eval(&m).unwrap();
    match t.cmd {
        Command::Run(r) => {
            assert_eq!(
                (r.mode, r.ctx, r.count, r.fb),
                (Mode::Simd, 100, 5, [None, Some(0x8000)])
            );
            assert_eq!(r.pc, 12);
        }
        c => panic!("{c:?}"),
    }
    t.commit();
    m.can_issue.set(false);
    t.eval(&m).unwrap();
    assert_eq!(t.state, State::StallArray);
    t.commit();
    m.can_issue.set(true);
    t.eval(&m).unwrap();
    match t.cmd {
        Command::Run(r) => assert_eq!((r.count, r.fb), (3, [Some(0), Some(0x8000)])),
        c => panic!("{c:?}"),
    }
    t.commit();
    t.eval(&m).unwrap();
    match t.cmd {
        Command::Run(r) => assert_eq!(
            (r.mode, r.count, r.fb),
            (Mode::Row, 2, [None, Some(0x8000)])
        ),
        c => panic!("{c:?}"),
    }
    t.commit();
    m.array_idle.set(false);
    t.eval(&m).unwrap();
    assert_eq!(t.state, State::StallArray);
}

#[test]
fn illegal_and_out_of_range_operands_fault() {
    let m = Double {
        prog: vec![0],
        ..Double::new(&[])
    };
    let mut t = TinyRisc::new(0, RiscTiming::default());
    let e = t.eval(&m).unwrap_err();
    assert_eq!(e.block, "tinyrisc");
    let m = Double::new(&[
        Instr::new(Addi, 1, 0, 0, 70),
        Instr::new(Rcrisc, 2, 1, 0, 0),
    ]);
    let mut t = TinyRisc::new(0, RiscTiming::default());
    t.eval(&m).unwrap();
    t.commit();
    assert!(t.eval(&m).unwrap_err().message.contains("RC index 70"));
    let m = Double::new(&[Instr::new(Cbcr, 0, 0, 0, 1), Instr::new(Addi, 1, 0, 0, 3)]);
    let mut t = TinyRisc::new(0, RiscTiming::default());
    t.eval(&m).unwrap(); // row mode at 0: fine
    t.commit();
    t.eval(&m).unwrap();
    t.commit();
    let m2 = Double::new(&[Instr::new(Addi, 1, 0, 0, 3), Instr::new(Cbcr, 1, 0, 0, 1)]);
    let mut t = TinyRisc::new(0, RiscTiming::default());
    t.eval(&m2).unwrap();
    t.commit();
    assert!(t.eval(&m2).unwrap_err().message.contains("not 8-aligned"));
}

#[test]
fn watched_addresses_count_issues_not_stalls() {
    // r1 = 5; loop: r1 -= 1 (watched) while r1 != 0; r2 = 1; rcany
    // (watched, stalled three cycles on a busy array first).
    let mut m = Double::new(&[
        Instr::new(Addi, 1, 0, 0, 5),  // 0x00
        Instr::new(Addi, 1, 1, 0, -1), // 0x04, five times
        Instr::new(Bne, 1, 0, 0, -2),  // 0x08 -> 0x04
        Instr::new(Addi, 2, 0, 0, 1),  // 0x0c
        Instr::new(Rcany, 3, 0, 0, 0), // 0x10
    ]);
    let mut t = TinyRisc::new(0, RiscTiming::default());
    t.issue_watch = [Some(0x04), Some(0x10)];
    run(&mut t, &m, 1 + 2 * 5 + 1);
    assert_eq!(t.regs.read(1), 0);
    assert_eq!(t.issues_watched, [5, 0]);
    m.array_idle = Cell::new(false);
    for _ in 0..3 {
        t.eval(&m).unwrap();
        assert_eq!(t.state, State::StallArray);
        t.commit();
    }
    assert_eq!(t.issues_watched, [5, 0]);
    m.array_idle = Cell::new(true);
    run(&mut t, &m, 1);
    assert_eq!(t.issues_watched, [5, 1]);
    assert_eq!(t.stall_array, 3);
}
