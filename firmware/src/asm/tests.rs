use super::*;
use rtl::rc::context::{ASrc, BSrc, Context, Guard, Op, ALL_CONDS, ALL_OPS};
use rtl::tinyrisc::decode::{Format, Instr, Opcode, ALL_OPCODES};

fn words(img: &Image, sec: Section) -> Vec<u32> {
    img.segments
        .iter()
        .filter(|s| s.section == sec)
        .flat_map(|s| {
            s.data
                .chunks(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect::<Vec<_>>()
        })
        .collect()
}

fn one_text(line: &str) -> u32 {
    let img =
        assemble(&format!(".text\n{line}\n"), "t.s").unwrap_or_else(|e| panic!("{line}: {e}"));
    let w = words(&img, Section::Text);
    assert_eq!(w.len(), 1, "{line}");
    w[0]
}

fn one_ctx(line: &str) -> u32 {
    let img = assemble(&format!(".ctx\n{line}\n"), "t.s").unwrap_or_else(|e| panic!("{line}: {e}"));
    let w = words(&img, Section::Ctx);
    assert_eq!(w.len(), 1, "{line}");
    w[0]
}

#[test]
fn every_tinyrisc_instruction_disassembles_and_reassembles_to_itself() {
    for &op in ALL_OPCODES {
        let samples: Vec<Instr> = match op.format() {
            Format::None => vec![Instr::new(op, 0, 0, 0, 0)],
            Format::R3 => vec![Instr::new(op, 1, 2, 15, 0)],
            Format::RIs => vec![Instr::new(op, 3, 4, 0, -7), Instr::new(op, 3, 4, 0, 131071)],
            Format::RIu => vec![Instr::new(
                op,
                3,
                4,
                0,
                if matches!(op, Opcode::Slli | Opcode::Srli | Opcode::Srai) {
                    31
                } else {
                    262143
                },
            )],
            Format::LUi => vec![Instr::new(op, 5, 0, 0, 0x2ABCD)],
            Format::Mem => vec![Instr::new(op, 3, 4, 0, -8), Instr::new(op, 3, 4, 0, 0)],
            Format::Br => vec![Instr::new(op, 3, 4, 0, 5), Instr::new(op, 3, 4, 0, -1)],
            Format::J => vec![Instr::new(op, 0, 0, 0, 0x100)],
            Format::R1 | Format::Rd => vec![Instr::new(op, 9, 0, 0, 0)],
            Format::R2 => vec![Instr::new(op, 9, 10, 0, 0)],
            Format::M2 => vec![
                Instr::new(op, 1, 2, 3, 17),
                Instr::new(op, 1, 2, 0, 64),
                Instr::new(op, 1, 2, 5, 0),
            ],
            Format::M1 => vec![Instr::new(op, 1, 0, 3, 17), Instr::new(op, 7, 0, 0, 12)],
            Format::M3 => vec![
                Instr::new(op, 1, 2, 3, 40),
                Instr::new(op, 1, 2, 3, 1 << 12 | 7),
                Instr::new(op, 1, 2, 3, 2 << 12 | 4095),
            ],
            Format::MI => vec![Instr::new(op, 6, 0, 0, 64)],
            Format::MRI => vec![Instr::new(op, 6, 7, 0, 63)],
        };
        for i in samples {
            let text = i.to_string();
            // branches are relative to the line's address: the line is at 0x100
            let src = format!(".text\n.org 0x100\n{text}\n");
            let img = assemble(&src, "t.s").unwrap_or_else(|e| panic!("{text}: {e}"));
            let w = words(&img, Section::Text);
            assert_eq!(w, vec![i.encode().unwrap()], "{text}");
            assert_eq!(Instr::decode(w[0]).unwrap().to_string(), text);
        }
    }
}

#[test]
fn every_context_disassembles_and_reassembles_to_itself() {
    let mut n = 0;
    for &op in ALL_OPS {
        for guard in [Guard::Always, Guard::IfF, Guard::IfNotF] {
            for (asrc, ra) in [
                (ASrc::Reg, 3),
                (ASrc::Out, 0),
                (ASrc::Nbr, 2),
                (ASrc::QRow, 1),
                (ASrc::QCol, 3),
                (ASrc::XRow, 7),
                (ASrc::XCol, 0),
                (ASrc::Fb, 1),
            ] {
                for (b, shift, trunc) in [
                    (BSrc::Reg(7), 0, false),
                    (BSrc::Reg(2), 13, true),
                    (BSrc::Imm(-1024), 0, false),
                    (BSrc::Imm(1023), 0, false),
                ] {
                    for we in [false, true] {
                        let mut c = Context {
                            op,
                            guard,
                            we,
                            rd: 9,
                            asrc,
                            ra,
                            b,
                            shift,
                            trunc,
                        };
                        // canonical forms only: fields the syntax cannot show are 0
                        if !op.uses_shift() {
                            c.shift = 0;
                            c.trunc = false;
                        }
                        if matches!(op, Op::Acc | Op::Ldacc) && shift != 0 {
                            // acc/ldacc: B unused, shift shown
                        }
                        if op == Op::Cmp {
                            c.we = false;
                            c.rd = 5;
                        }
                        if !op.has_result() {
                            c.we = false;
                            if op != Op::Cmp {
                                c.rd = 0;
                            }
                        }
                        if !c.we && op != Op::Cmp {
                            c.rd = 0;
                        }
                        if matches!(
                            op,
                            Op::Nop
                                | Op::Sleep
                                | Op::Wake
                                | Op::Movb
                                | Op::Acc
                                | Op::Acch
                                | Op::Accl
                        ) {
                            c.asrc = ASrc::Reg;
                            c.ra = 0;
                        }
                        if matches!(
                            op,
                            Op::Nop
                                | Op::Sleep
                                | Op::Wake
                                | Op::Not
                                | Op::Mov
                                | Op::Abs
                                | Op::Neg
                                | Op::Clz
                                | Op::Acc
                                | Op::Acch
                                | Op::Accl
                                | Op::Ldacc
                        ) {
                            c.b = BSrc::Reg(0);
                            if !matches!(op, Op::Acc | Op::Ldacc) {
                                c.shift = 0;
                                c.trunc = false;
                            }
                        }
                        if op == Op::Nop || op == Op::Sleep || op == Op::Wake {
                            c.shift = 0;
                            c.trunc = false;
                        }
                        if matches!(c.b, BSrc::Imm(_)) {
                            c.shift = 0;
                            c.trunc = false;
                        }
                        let text = c.to_string();
                        let w = one_ctx(&text);
                        assert_eq!(Context::decode(w), Ok(c), "{text}");
                        assert_eq!(Context::decode(w).unwrap().to_string(), text);
                        n += 1;
                    }
                }
            }
        }
    }
    assert!(n > 1000);
    for c in ALL_CONDS {
        let t = format!("cmp.{} r1, #3", c.mnemonic());
        assert_eq!(Context::decode(one_ctx(&t)).unwrap().to_string(), t);
    }
}

#[test]
fn labels_constants_expressions_and_sections() {
    let src = r#"
; comment
N = 4 * (3 + 2)          // 20
.equ M, N << 1 | 1       ; 41
        .text
_start: addi r1, r0, N
        addi r2, r0, M - 1
loop:   addi r1, r1, -1
        bne r1, r0, loop
        li r3, later
        halt
        .data
later:  .word 0x12345678, -1
        .half 7
        .byte 'A', 2
        .align 4
tbl:    .space 3, 0xFF
        .ctx
k0:     add r1, r2, #N
k1:     (f) mov out, e
"#;
    let img = assemble(src, "t.s").unwrap();
    assert_eq!(img.entry, 0);
    let t = words(&img, Section::Text);
    assert_eq!(
        t[0],
        Instr::new(Opcode::Addi, 1, 0, 0, 20).encode().unwrap()
    );
    assert_eq!(
        t[1],
        Instr::new(Opcode::Addi, 2, 0, 0, 40).encode().unwrap()
    );
    assert_eq!(t[3], Instr::new(Opcode::Bne, 1, 0, 0, -2).encode().unwrap());
    // li of a forward label: lui + ori
    assert_eq!(
        t[4],
        Instr::new(Opcode::Lui, 3, 0, 0, 0x10000 >> 14)
            .encode()
            .unwrap()
    );
    assert_eq!(t[5], Instr::new(Opcode::Ori, 3, 3, 0, 0).encode().unwrap());
    assert_eq!(img.symbol("later"), Some(0x10000));
    assert_eq!(img.symbol("tbl"), Some(0x10000 + 8 + 2 + 2));
    let d = &img
        .segments
        .iter()
        .find(|s| s.section == Section::Data)
        .unwrap()
        .data;
    assert_eq!(&d[0..4], &0x12345678u32.to_le_bytes());
    assert_eq!(&d[4..8], &[0xFF; 4]);
    assert_eq!(&d[8..12], &[7, 0, b'A', 2]);
    assert_eq!(&d[12..15], &[0xFF; 3]);
    let c = words(&img, Section::Ctx);
    assert_eq!(
        Context::decode(c[0]).unwrap(),
        Context::rri(Op::Add, 1, 2, 20)
    );
    assert_eq!(img.symbol("k1"), Some(0x20004));
    assert_eq!(Context::decode(c[1]).unwrap().to_string(), "(f) mov out, e");
    // image file round trip
    let b = img.to_bytes();
    let back = Image::from_bytes(&b).unwrap();
    assert_eq!(back.segments, img.segments);
    assert_eq!(back.entry, img.entry);
    assert!(disassemble_image(&img).contains("bne r1, r0, .-4"));
}

#[test]
fn pseudo_instructions() {
    assert_eq!(
        one_text("mv r1, r2"),
        Instr::new(Opcode::Add, 1, 2, 0, 0).encode().unwrap()
    );
    assert_eq!(
        one_text("ret"),
        Instr::new(Opcode::Jr, 15, 0, 0, 0).encode().unwrap()
    );
    assert_eq!(
        one_text("li r4, -5"),
        Instr::new(Opcode::Addi, 4, 0, 0, -5).encode().unwrap()
    );
    let img = assemble(".text\nli r4, 0x12345678\n", "t.s").unwrap();
    let w = words(&img, Section::Text);
    // reference: value rebuilt from lui/ori fields
    let hi = Instr::decode(w[0]).unwrap().imm as u32;
    let lo = Instr::decode(w[1]).unwrap().imm as u32;
    assert_eq!(hi << 14 | lo, 0x12345678);
    assert_eq!(
        one_text("bgt r1, r2, .+8"),
        Instr::new(Opcode::Blt, 2, 1, 0, 1).encode().unwrap()
    );
}

fn err(src: &str) -> AsmError {
    match assemble(src, "bad.s") {
        Ok(_) => panic!("expected an error for {src:?}"),
        Err(e) => e.0[0].clone(),
    }
}

#[test]
fn errors_name_file_line_and_column_and_show_the_text() {
    let e = err(".text\n  addi r1, r0, 1\n  frob r1, r2\n");
    assert_eq!((e.line, e.col), (3, 3));
    assert!(
        e.message.contains("unknown instruction `frob`"),
        "{}",
        e.message
    );
    let shown = e.to_string();
    assert!(shown.starts_with("bad.s:3:3: error:"), "{shown}");
    assert!(shown.contains("frob r1, r2"));
    let e = err(".text\naddi r1, r0, 1 << 20\n");
    assert_eq!((e.line, e.col), (2, 14));
    assert!(e.message.contains("out of range"));
    let e = err(".text\nbeq r1, r2, nowhere\n");
    assert!(e.message.contains("undefined symbol `nowhere`"));
    assert_eq!(e.col, 13);
    let e = err(".ctx\nadd r1, r2, #5000\n");
    assert_eq!(e.col, 14);
    let e = err(".ctx\nmul r1, r2, #5, >>3\n");
    assert!(e.message.contains("register"), "{}", e.message);
    let e = err(".text\nadd r1, r2, r16\n");
    assert_eq!(e.col, 13);
    let e = err("x:\nx:\n");
    assert!(e.message.contains("defined twice"));
    let e = err(".text\naddi r1, r0, 5 / 0\n");
    assert!(e.message.contains("division by zero"));
    let e = err(".data\nadd r1, r2, r3\n");
    assert!(e.message.contains("only data directives"));
    let e = err(".text\n.org 0x10000\n.word 1\n.data\n.word 2\n");
    assert!(e.message.contains("overlap"), "{}", e.message);
}

#[test]
fn never_panics_on_garbage() {
    // A deterministic fuzz: mutations of valid lines and random bytes.
    let seeds = [
        "add r1, r2, r3",
        "lw r1, -4(r2)",
        "(!f) mac.t r1, fb0, r2, >>7",
        "ld r3, [out + #4]",
        "st xrow3, [r1]",
        ".word 1, 2",
        "x = (1 + 2) * 3",
        "li r1, x",
        "dbcb r1, r2, r3, 4",
        "ldfb r1, r2, r3+4",
        ".ascii \"hi\"",
        "cmp.lt n, #3",
    ];
    let alphabet: Vec<char> = "r0123456789abcdefx()[],.+-*/%<>&|^~#!=:;'\" \tfqwensoutlmc"
        .chars()
        .collect();
    let mut state = 0x1234_5678_9abc_def0u64;
    let mut rnd = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..20_000 {
        let base = seeds[(rnd() % seeds.len() as u64) as usize];
        let mut line: Vec<char> = base.chars().collect();
        for _ in 0..(rnd() % 4) {
            let pos = (rnd() % (line.len() as u64 + 1)) as usize;
            match rnd() % 3 {
                0 if pos < line.len() => {
                    line.remove(pos);
                }
                1 => line.insert(pos, alphabet[(rnd() % alphabet.len() as u64) as usize]),
                _ if pos < line.len() => {
                    line[pos] = alphabet[(rnd() % alphabet.len() as u64) as usize]
                }
                _ => {}
            }
        }
        let l: String = line.into_iter().collect();
        for sec in [".text", ".ctx", ".data"] {
            let _ = assemble(&format!("{sec}\n{l}\n"), "fuzz.s");
        }
    }
}

#[test]
fn wide_multiplier_shifts_need_the_32_bit_datapath() {
    // 16-bit (default): 0..=31, and the error names the directive.
    let e = assemble(".ctx\nmul r1, r2, r3, >>40\n", "t.s").unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("t.s:2:") && msg.contains("0..=31"), "{msg}");
    assert!(msg.contains(".datapath 32"), "{msg}");
    // 32-bit: 0..=63, with bit 5 of the shift in f[10].
    let img = assemble(
        ".datapath 32\n.ctx\nmac.t r1, r2, r3, >>45\nldacc r4, <<63\n",
        "t.s",
    )
    .unwrap();
    let w = words(&img, Section::Ctx);
    let c = Context::decode_wide(w[0]).unwrap();
    assert_eq!((c.op, c.shift, c.trunc), (Op::Mac, 45, true));
    assert_eq!(w[0] >> 10 & 1, 1);
    assert_eq!(Context::decode_wide(w[1]).unwrap().shift, 63);
    // the disassembly reads back
    assert_eq!(c.to_string(), "mac.t r1, r2, r3, >>45");
    assert!(assemble(".datapath 32\n.ctx\nmul r1, r2, r3, >>64\n", "t.s").is_err());
    assert!(assemble(".datapath 24\n", "t.s").is_err());
}

#[test]
fn deep_expressions_are_refused_at_their_column_not_overflowing_the_stack() {
    // Within the limit: evaluated (the independent value: nested negations
    // of 5 cancel in pairs, parentheses change nothing).
    let n = expr::MAX_NESTING as usize - 1;
    let ok = format!("li r1, {}(5)", "-".repeat((n - 1) & !1));
    assert_eq!(one_text(&ok), one_text("li r1, 5"));
    // 20,000 parentheses and 50,000 minus signs: one located error each.
    for text in [
        format!("li r1, {}1{}", "(".repeat(20_000), ")".repeat(20_000)),
        format!("li r1, {}1", "-".repeat(50_000)),
    ] {
        let e = assemble(&format!(".text\n{text}\n"), "deep.s").unwrap_err();
        let s = e.to_string();
        assert!(
            s.contains("deep.s:2:") && s.contains("nested more than"),
            "{}",
            &s[..200.min(s.len())]
        );
    }
}

/// `.rept N, VAR`: the body N times, VAR the iteration.
#[test]
fn rept_with_a_counter_numbers_its_copies() {
    let img = assemble(
        ".ctx\nBASE = 10\n.rept 4, i\nst fb0, [#BASE+i]\n.endr\n.rept 2\nnop\n.endr\n",
        "t.s",
    )
    .unwrap();
    let got = words(&img, Section::Ctx);
    let want: Vec<u32> = [10, 11, 12, 13]
        .iter()
        .map(|a| one_ctx(&format!("st fb0, [#{a}]")))
        .chain([one_ctx("nop"), one_ctx("nop")])
        .collect();
    assert_eq!(got, want);
    let e = err(".ctx\n.rept 2, r3\nnop\n.endr\n");
    assert!(e.message.contains("VAR must be a name"), "{}", e.message);
    let e = err(".ctx\n.rept 2 3\nnop\n.endr\n");
    assert!(e.message.contains("`.rept N, VAR`"), "{}", e.message);
}

/// Macros expand to the same words as their bodies written out, with
/// parameters, `\()` and unique `\@` labels.
#[test]
fn macros_expand_to_their_bodies() {
    let src = "\
.macro BCAST k, n
        li r1, \\k
        cbcast r1, \\n
.endm
.macro LOOP p, reg
\\p\\()_top\\@:
        addi \\reg, \\reg, -1
        bnez \\reg, \\p\\()_top\\@
.endm
        .text
start:  BCAST 5, 2          ; a comment
        LOOP wait, r3
        LOOP wait, r4
";
    let plain = "\
        .text
start:  li r1, 5
        cbcast r1, 2
wait_top2:
        addi r3, r3, -1
        bnez r3, wait_top2
wait_top3:
        addi r4, r4, -1
        bnez r4, wait_top3
";
    let a = assemble(src, "m.s").unwrap_or_else(|e| panic!("{e}"));
    let b = assemble(plain, "p.s").unwrap();
    assert_eq!(words(&a, Section::Text), words(&b, Section::Text));
    // `\@` numbers every use: BCAST was the first.
    assert_eq!(a.symbol("wait_top3"), b.symbol("wait_top3"));
}

/// Errors in macros name the line of the body, show it expanded and say
/// where the macro was used; a bad definition or use names its own line.
#[test]
fn macro_errors_are_located() {
    let src = ".macro M a\n        addi r1, r0, \\a\n.endm\n.text\n        M 1 << 20\n";
    let e = err(src);
    assert_eq!(e.line, 2, "{e}");
    assert!(e.message.contains("out of range"), "{}", e.message);
    assert!(
        e.message.contains("in macro `M`, used at line 5"),
        "{}",
        e.message
    );
    assert!(e.text.contains("addi r1, r0, 1 << 20"), "{}", e.text);
    let e = err(".macro M a\nnop\n.endm\n.text\nM 1, 2\n");
    assert_eq!(e.line, 5);
    assert!(e.message.contains("takes 1 argument"), "{}", e.message);
    let e = err(".macro M a\nnop\n");
    assert!(e.message.contains("without `.endm`"), "{}", e.message);
    let e = err(".endm\n");
    assert!(e.message.contains("without `.macro`"), "{}", e.message);
    let e = err(".macro addi a\nnop\n.endm\n");
    assert!(e.message.contains("not a macro name"), "{}", e.message);
    let e = err(".macro M a\n  addi r1, r0, \\b\n.endm\n.text\nM 1\n");
    assert_eq!(e.line, 2);
    assert!(
        e.message.contains("`\\b` is not a parameter"),
        "{}",
        e.message
    );
    let e = err(".macro M\n  M\n.endm\n.text\nM\n");
    assert!(e.message.contains("use itself"), "{}", e.message);
    // Macros doubling each other's lines: refused, not run out of memory.
    let mut src = String::from(".macro M0\nnop\n.endm\n");
    for i in 1..30 {
        src += &format!(".macro M{i}\nM{}\nM{}\n.endm\n", i - 1, i - 1);
    }
    src += ".ctx\nM29\n";
    let e = err(&src);
    assert!(e.message.contains("expand to over"), "{}", e.message);
    let e = err(".macro M\nnop\n.endm\n.macro M\nnop\n.endm\n");
    assert!(e.message.contains("defined twice"), "{}", e.message);
}
