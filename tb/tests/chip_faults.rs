//! Faults stop the simulation with one message naming the cycle, the PC and
//! the block; the waveform up to the fault is still written.

use rtl::Timing;
use tb::cmd_run::run_image;

fn run_src(src: &str, max: u64) -> (String, tb::cmd_run::Outcome) {
    let img = firmware::asm::assemble(src, "t.s").unwrap_or_else(|e| panic!("{e}"));
    let out = run_image(&img, Timing::default(), max, None).unwrap();
    let msg = match &out.result {
        Ok(c) => panic!("expected a fault, halted after {c} cycles"),
        Err(e) => e.to_string(),
    };
    (msg, out)
}

#[test]
fn illegal_instruction() {
    let (m, _) = run_src(".text\nnop\nnop\n.word 0xFFFFFFFF\n", 100);
    assert!(
        m.starts_with("cycle 2: tinyrisc: illegal instruction 0xffffffff"),
        "{m}"
    );
    assert!(m.contains("pc 0x00000008"), "{m}");
}

#[test]
fn address_out_of_range() {
    let (m, _) = run_src(".text\nli r1, 0x7FFFFFF0\nlw r2, 0(r1)\nhalt\n", 100);
    assert!(
        m.contains("memory: address 0x7ffffff0 outside main memory"),
        "{m}"
    );
    assert!(m.contains("`lw r2, 0(r1)`"), "{m}");
    let (m, _) = run_src(".text\nli r1, 2\nlw r2, 0(r1)\nhalt\n", 100);
    assert!(m.contains("misaligned"), "{m}");
    let (m, _) = run_src(
        ".text\nli r1, 0\nli r2, 0xFFF0\nldfb r1, r2, 32\nhalt\n",
        100,
    );
    assert!(
        m.contains("dma: ldfb: frame buffer address 0xfff0+32 words outside"),
        "{m}"
    );
    let (m, _) = run_src(".text\nli r1, 64\nrcrisc r2, r1, 0\nhalt\n", 100);
    assert!(m.contains("RC index 64"), "{m}");
}

#[test]
fn array_reading_a_bank_dma_is_filling_is_a_dma_conflict() {
    let src = "
        .ctx
k:      add r1, fb0, r1
        .text
        li r1, k
        ldctxt r1, r0, 1
        dwait
        li r2, 0x1000
        ldfb r0, r2, 64        ; bank 0 of set 0
        sbcb r0, r2, 1         ; the array reads the same bank
        halt
";
    let (m, _) = run_src(src, 1000);
    assert!(
        m.contains("broadcast: DMA conflict: the array reads FB bank 0"),
        "{m}"
    );
    assert!(m.contains("issued at pc"), "{m}");
    // the other bank is fine
    let ok = src.replace(
        "li r2, 0x1000\n        ldfb r0, r2, 64",
        "li r3, 0x4000\n        li r2, 0x1000\n        ldfb r0, r3, 64",
    );
    let img = firmware::asm::assemble(&ok, "t.s").unwrap();
    let out = run_image(&img, Timing::default(), 1000, None).unwrap();
    assert!(
        out.result.is_ok(),
        "{:?}",
        out.result.err().map(|e| e.to_string())
    );
}

#[test]
fn tinyrisc_and_context_conflicts() {
    let (m, _) = run_src(
        ".text\nli r2, 0x4010\nldfb r0, r2, 8\nlfb r3, 0(r2)\nhalt\n",
        1000,
    );
    assert!(
        m.contains("fb: DMA conflict: TinyRISC reads FB bank 1 while `ldfb`"),
        "{m}"
    );
    let (m, _) = run_src(".text\nldctxt r0, r0, 8\ncbcast r0, 1\nhalt\n", 1000);
    assert!(
        m.contains("DMA conflict: the array reads context bank 0 while DMA loads it"),
        "{m}"
    );
    let (m, _) = run_src(
        ".text\nli r2, 0x8000\nstfb r0, r2, 8\nwfb r2, 0\nhalt\n",
        1000,
    );
    assert!(m.contains("DMA conflict: a write to FB bank 2"), "{m}");
}

#[test]
fn illegal_context_word_and_lane_conflict() {
    let (m, _) = run_src(
        ".ctx\nw: .word 0xFC000000\n.text\nli r1, w\nldctxt r1, r0, 1\ndwait\ncbcast r0, 1\nhalt\n",
        1000,
    );
    assert!(m.contains("broadcast: illegal RC opcode 0x3f"), "{m}");
    let mut src = String::from(".ctx\ng:\n");
    for r in 0..8 {
        src += &format!("mov r1, xcol{}\n", r % 2);
    }
    src += ".text\nli r1, g\nldctxt r1, r0, 8\ndwait\ncbcr r0, r0, 1\nhalt\n";
    let (m, _) = run_src(&src, 1000);
    assert!(m.contains("array: lane conflict in row mode"), "{m}");
}

#[test]
fn rc_ram_fault_names_the_rc() {
    let (m, _) = run_src(".ctx\nk: ld r1, [r0 + #600]\n.text\nli r1, k\nldctxt r1, r0, 1\ndwait\ncbcast r0, 1\nhalt\n", 1000);
    assert!(m.contains("rc_r0_c0"), "{m}");
    assert!(m.contains("[pc 0x"), "{m}");
}

#[test]
fn running_past_max_cycles_is_reported() {
    let (m, out) = run_src(".text\nloop: b loop\n", 500);
    assert!(m.contains("no halt within 500 cycles"), "{m}");
    assert!(m.contains("`beq r0, r0, .+0`"), "{m}");
    assert_eq!(out.stats().cycles, 500);
}

#[test]
fn the_waveform_up_to_a_fault_is_written_and_shows_mnemonics() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fault.vcd");
    let src = ".ctx\nk: add r1, r1, #1\n.text\nli r1, k\nldctxt r1, r0, 1\ndwait\ncbcast r0, 1\nrcall r3\n.word 0xFFFFFFFF\n";
    let img = firmware::asm::assemble(src, "t.s").unwrap();
    let mut cfg = rtl::trace::TraceConfig::new(&path);
    cfg.scope = "tinyrisc,broadcast,dma,array.active,array.ctx_g0,array.rc_r0_c0".into();
    let out = run_image(&img, Timing::default(), 1000, Some(cfg)).unwrap();
    let e = out
        .result
        .as_ref()
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("illegal instruction"), "{e}");
    let vcd = std::fs::read_to_string(&path).unwrap();
    assert!(vcd.contains("stopped by a fault"), "no note of the fault");
    let filters: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    let instr = filters
        .iter()
        .find(|f| f.ends_with(".tinyrisc_instr.txt"))
        .expect("TinyRISC filter written");
    let text = std::fs::read_to_string(dir.path().join(instr)).unwrap();
    assert!(text.contains("cbcast r0, 1"), "{text}");
    let ctx = filters
        .iter()
        .find(|f| f.ends_with(".rc_ctx.txt"))
        .expect("context filter written");
    assert!(std::fs::read_to_string(dir.path().join(ctx))
        .unwrap()
        .contains("add r1, r1, #1"));
    // vcd2fst, when installed, accepts it
    if let Ok(st) = std::process::Command::new("vcd2fst")
        .arg(&path)
        .arg(dir.path().join("fault.fst"))
        .output()
    {
        assert!(
            st.status.success(),
            "vcd2fst: {}",
            String::from_utf8_lossy(&st.stderr)
        );
    }
}

#[test]
fn assembly_errors_name_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.s");
    std::fs::write(&p, ".text\n  nop\n  addi r1, r2\n").unwrap();
    let e = format!("{:#}", tb::cmd_run::load_program(&p).err().unwrap());
    assert!(
        e.starts_with(&format!(
            "{}:3:3: error: expected 3 operand(s)",
            p.display()
        )),
        "{e}"
    );
    assert!(e.contains("addi r1, r2"), "{e}");
}

#[test]
fn an_empty_program_is_refused_with_its_name_not_run() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("empty.s");
    std::fs::write(&p, "; only a comment\n\n").unwrap();
    let e = format!("{:#}", tb::cmd_run::load_program(&p).err().unwrap());
    assert_eq!(
        e,
        format!(
            "{}: empty program: no instructions or data to run",
            p.display()
        )
    );
}

/// A jump out of main memory, or to a misaligned address, stops at the
/// fetch with the fetch's message (through the fast path of the cycle
/// loop, which reads the instruction word it waits on, as through plain
/// stepping).
#[test]
fn fetch_outside_memory_or_misaligned() {
    let (m, out) = run_src(".text\nli r1, 0x7FFFFFF0\njr r1\n", 100);
    assert!(
        m.contains("tinyrisc: instruction fetch: address 0x7ffffff0 outside main memory"),
        "{m}"
    );
    assert!(m.contains("pc 0x7ffffff0"), "{m}");
    assert!(out.sim.cycle() < 10, "{m}");
    // The jump lands while a transfer runs and the transfer ends before the
    // fetch: the cycle loop's fast path starts again at a pc outside
    // memory (some of these spacings give that).
    for k in 0..24 {
        let nops = "nop\n".repeat(k);
        let src = format!(".text\nli r1, 0x7FFFFFF0\nli r2, 0x1000\nldfb r0, r2, 4\n{nops}jr r1\n");
        let (m, _) = run_src(&src, 200);
        assert!(
            m.contains("instruction fetch: address 0x7ffffff0 outside main memory"),
            "{k} nops: {m}"
        );
    }
    let (m, _) = run_src(".text\nli r1, 6\njr r1\n", 100);
    assert!(
        m.contains("instruction fetch: misaligned 4-byte access at 0x00000006"),
        "{m}"
    );
}

/// A fault met in the fast loops (the untraced streaming loop of SIMD runs
/// among them) stops at the cycle plain stepping through `Sim::step`
/// stops at, with the same message, and leaves the same statistics.
#[test]
fn faults_in_the_fast_loops_stop_where_plain_stepping_does() {
    let programs = [
        // RC RAM address out of range, in the third context of a run
        // TinyRISC waits on
        ".ctx\nk: add r1, r1, #1\nadd r1, r1, #2\nld r2, [r0 + #600]\n.text\nli r1, k\nldctxt r1, r0, 3\ndwait\ncbcast r0, 3\nhalt\n",
        // an address per RC (a row-mode run gives each row its own base),
        // out of range in the last row only
        ".ctx\ng: add r1, r1, #0\nadd r1, r1, #70\nadd r1, r1, #140\nadd r1, r1, #210\nadd r1, r1, #280\nadd r1, r1, #350\nadd r1, r1, #420\nadd r1, r1, #490\nld r2, [r1 + #40]\n.text\nli r1, g\nldctxt r1, r0, 9\ndwait\ncbcr r0, r0, 1\nli r3, 8\ncbcast r3, 1\nrcany r4\nhalt\n",
        // an FB stream that runs past the end of its set on its third datum
        ".ctx\nk: mov r1, fb0\nmov r1, fb0\nmov r1, fb0\nmov r1, fb0\n.text\nli r1, k\nldctxt r1, r0, 4\ndwait\nli r2, 0x7FFE\nsbcb r0, r2, 4\nhalt\n",
        // a context word that does not decode, after two good runs
        ".ctx\nk: add r1, r1, #1\nw: .word 0xFC000000\n.text\nli r1, k\nldctxt r1, r0, 2\ndwait\ncbcast r0, 1\ncbcast r0, 1\nli r3, 1\ncbcast r3, 1\nhalt\n",
    ];
    let expect = [
        "RAM address 600 outside",
        "RAM address 530 outside",
        "ran past the end of the set",
        "illegal RC opcode",
    ];
    for (src, want) in programs.into_iter().zip(expect) {
        let (m, fast) = run_src(src, 1000);
        assert!(m.contains(want), "{m}");
        let img = firmware::asm::assemble(src, "t.s").unwrap();
        let mut chip = rtl::Chip::new(Timing::default(), tb::cmd_run::DEFAULT_MEMORY);
        img.load(&mut chip).unwrap();
        let mut slow = rtl::Sim::new(chip);
        let e = loop {
            if let Err(e) = slow.step() {
                break e.to_string();
            }
            assert!(!slow.top.halted(), "plain stepping halted: {src}");
        };
        assert_eq!(m, e, "{src}");
        assert_eq!(fast.sim.top.stats(), slow.top.stats(), "{src}");
    }
}
