//! The chip's conformance suite: the programs under `firmware/conformance/`
//! run on the model and check their own results (halt with r1 = 1; on a
//! failure r1 = 0xBAD and r2 = the number of the failed check).

use std::path::PathBuf;

use rtl::Timing;
use tb::cmd_run::{load_program, run_image, run_image_on, Outcome};

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../firmware/conformance")
}

pub fn run(name: &str) -> Outcome {
    let path = dir().join(name);
    let img = load_program(&path).unwrap_or_else(|e| panic!("{e:#}"));
    let out = run_image(&img, Timing::default(), 2_000_000, None).unwrap();
    if let Err(e) = &out.result {
        panic!("{name}: {e}");
    }
    let (r1, r2) = (out.reg(1), out.reg(2));
    assert_eq!(
        r1,
        1,
        "{name}: failed check {r2} (r1 = {r1:#x}); stats {:?}",
        out.stats()
    );
    out
}

macro_rules! conformance {
    ($($test:ident => $file:expr,)*) => {
        $(
            #[test]
            fn $test() {
                run($file);
            }
        )*
        const LISTED: &[&str] = &[$($file,)*];
    };
}

conformance! {
    ldctxt => "ldctxt.s",
    ldfb_and_dwait => "ldfb.s",
    stfb => "stfb.s",
    cbcast => "cbcast.s",
    sbcb => "sbcb.s",
    dbcb => "dbcb.s",
    cbcr_row_mode => "cbcr.s",
    cbcc_column_mode => "cbcc.s",
    wfb => "wfb.s",
    rcrisc => "rcrisc.s",
    status_rcany_rcall_masks => "status.s",
    cut_ends_a_run_where_no_awake_rc_has_f => "cut.s",
    lfb_sfb => "lfb_sfb.s",
    guarded_if_then_else => "ifelse.s",
    tinyrisc_scalar => "tinyrisc.s",
    transpose_8x8 => "transpose.s",
}

const REPORTED: &[&str] = &["double_buffer.s", "dct.s"];

#[test]
fn double_buffering_overlaps_transfer_and_computation() {
    let out = run("double_buffer.s");
    let (t_seq, t_ovl, t_dma, t_comp) = (out.reg(3), out.reg(4), out.reg(5), out.reg(6));
    eprintln!("double buffering: T_dma {t_dma}, T_comp {t_comp}, 4 blocks sequential {t_seq}, overlapped {t_ovl} cycles");
    // Independent of the program's own checks: three of the four transfers
    // are hidden behind computation, less at most 16 cycles of loop
    // overhead per block.
    assert!(t_ovl < t_seq);
    assert!(
        t_ovl + 3 * t_dma <= t_seq + 4 * 16,
        "only {} cycles saved",
        t_seq - t_ovl
    );
    assert!(t_ovl < t_dma + 4 * (t_comp + 16));
    assert!(out.stats().dma_busy_cycles > 0);
}

#[test]
fn dct_8x8_matches_a_float_dct() {
    let out = run("dct.s");
    eprintln!(
        "8x8 2D DCT: {} cycles (issue to status; 34 array cycles), load {} cycles, total with wfb and stfb {} cycles",
        out.reg(3),
        out.reg(4),
        out.reg(5)
    );
    // Independent reference: the f64 DCT of the same block.
    let img = load_program(&dir().join("dct.s")).unwrap();
    let result = img.symbol("result").unwrap() as u32;
    let x = |r: usize, c: usize| (((r * 37 + c * 23 + (r * c) % 5 * 11) % 256) as f64) - 128.0;
    let a = |k: usize| if k == 0 { (1.0f64 / 8.0).sqrt() } else { 0.5 };
    let pi = std::f64::consts::PI;
    for l in 0..8 {
        for k in 0..8 {
            let mut z = 0.0;
            for r in 0..8 {
                for c in 0..8 {
                    z += a(l)
                        * a(k)
                        * ((2 * r + 1) as f64 * l as f64 * pi / 16.0).cos()
                        * ((2 * c + 1) as f64 * k as f64 * pi / 16.0).cos()
                        * x(r, c);
                }
            }
            let addr = result + 2 * (l * 8 + k) as u32;
            let got = out.sim.top.mem.read(addr, 2) as u16 as i16 as f64;
            assert!((got - z).abs() <= 2.5, "Z[{l}][{k}] = {got}, float {z:.2}");
        }
    }
}

#[test]
fn every_program_in_the_directory_is_in_the_suite() {
    let mut found: Vec<String> = std::fs::read_dir(dir())
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".s"))
        .collect();
    found.sort();
    let mut listed: Vec<String> = LISTED
        .iter()
        .chain(REPORTED)
        .chain(WIDE)
        .map(|s| s.to_string())
        .collect();
    listed.sort();
    assert_eq!(found, listed);
}

#[test]
fn guarded_if_then_else_runs_the_then_and_else_parts_on_their_lanes_only() {
    let out = run("ifelse.s");
    let s = out.stats();
    // the 4 guarded contexts: 20 + 44 + 44 lanes... checked by the active count
    assert!(s.active_rc_fraction() < 1.0);
}

/// The 32-bit datapath: 32-bit FB words through DMA, `lfb`/`sfb`, the FB
/// stream, a multiplier shift of 40, `acch`/`accl` of the 64-bit
/// accumulator, `rcrisc`, `wfb` (expected values computed outside the chip).
/// Programs for the 32-bit chip (`.datapath 32`).
const WIDE: &[&str] = &["wide.s"];

#[test]
fn wide_datapath_on_the_32_bit_chip() {
    let img = load_program(&dir().join("wide.s")).unwrap();
    let out = run_image_on::<i32>(&img, Timing::default(), 100_000, None, false).unwrap();
    out.result.as_ref().unwrap();
    assert_eq!(out.reg(1), 1, "failed check {}", out.reg(2));
    // The same program on the 16-bit chip fails its first check: `ldfb`
    // moves 16-bit words there.
    let out16 = run_image(&img, Timing::default(), 100_000, None).unwrap();
    out16.result.as_ref().unwrap();
    assert_eq!((out16.reg(1), out16.reg(2)), (0xBAD, 1));
}

/// `run_to_halt` runs the cycles in which TinyRISC waits for the array or
/// the DMA through a fast path (`Chip::run_stalled`). Every program of the
/// suite, run that way and one cycle at a time through `Sim::step` (the
/// plain two-phase kernel), must end in the same state: statistics (stall
/// counters included), TinyRISC registers, RC outputs, registers, flags and
/// RAM, the frame buffer and main memory.
#[test]
fn the_stall_fast_path_is_cycle_exact() {
    let mut stalled = 0;
    for name in LISTED.iter().chain(REPORTED) {
        let img = load_program(&dir().join(name)).unwrap();
        let fast = run_image(&img, Timing::default(), 2_000_000, None).unwrap();
        assert!(fast.result.is_ok(), "{name}");
        let mut chip = rtl::Chip::new(Timing::default(), tb::cmd_run::DEFAULT_MEMORY);
        img.load(&mut chip).unwrap();
        let mut slow = rtl::Sim::new(chip);
        while !slow.top.halted() {
            slow.step().unwrap();
        }
        let (f, s) = (&fast.sim.top, &slow.top);
        assert_eq!(f.stats(), s.stats(), "{name}: statistics");
        if f.stats().array_stall_cycles + f.stats().dma_stall_cycles > 0 {
            stalled += 1;
        }
        assert_eq!(fast.sim.cycle(), slow.cycle(), "{name}: cycles");
        for k in 0..16 {
            assert_eq!(
                f.risc.regs.read(k),
                s.risc.regs.read(k),
                "{name}: TinyRISC r{k}"
            );
        }
        let (fr, sr) = (&f.array.rc, &s.array.rc);
        assert_eq!(fr.out, sr.out, "{name}: RC outputs");
        assert_eq!(fr.acc, sr.acc, "{name}: accumulators");
        assert_eq!(
            (fr.flags.f, fr.flags.c, fr.flags.v, fr.flags.sleep),
            (sr.flags.f, sr.flags.c, sr.flags.v, sr.flags.sleep),
            "{name}: flags"
        );
        for k in 0..16 {
            assert_eq!(fr.regs.read(k), sr.regs.read(k), "{name}: RC r{k}");
        }
        for a in 0..512 {
            for lane in 0..64 {
                assert_eq!(fr.ram.read(lane, a), sr.ram.read(lane, a), "{name}: RAM");
            }
        }
        for a in 0..=0xFFFFu16 {
            assert_eq!(f.fb.read(a), s.fb.read(a), "{name}: FB word {a:#x}");
        }
        let n = f.mem.size();
        assert!(
            f.mem.bytes(0, n) == s.mem.bytes(0, n),
            "{name}: main memory"
        );
    }
    // The comparison means something only where the fast path ran.
    assert!(stalled >= 10, "only {stalled} programs stall");
}

/// The render counts the runs that start at watched context addresses
/// (`Watch`, the object tests' kernels), and the untraced streaming loop
/// (`Broadcast::stream_simd`) counts them itself. Every program of the
/// suite with every context address watched (two classes, tags every
/// fifth address), through the fast paths and through `Sim::step`: the
/// same counts, run for run.
#[test]
fn the_fast_paths_count_watched_runs_as_plain_stepping() {
    let watched = |img: &firmware::asm::Image| {
        let mut chip = rtl::Chip::new(Timing::default(), tb::cmd_run::DEFAULT_MEMORY);
        img.load(&mut chip).unwrap();
        for a in 0..rtl::context_memory::WORDS as u16 {
            chip.watch.add(a, usize::from(a % 3 == 0));
            if a % 5 == 0 {
                chip.watch
                    .tag(a, usize::from(a / 5) % rtl::chip::WATCH_TAGS);
            }
        }
        rtl::Sim::new(chip)
    };
    let mut counted = 0;
    for name in LISTED.iter().chain(REPORTED) {
        let img = load_program(&dir().join(name)).unwrap();
        let mut fast = watched(&img);
        rtl::chip::run_to_halt(&mut fast, 2_000_000).unwrap();
        let mut slow = watched(&img);
        while !slow.top.halted() {
            slow.step().unwrap();
        }
        let (f, s) = (fast.top.stats(), slow.top.stats());
        assert_eq!(f, s, "{name}: statistics");
        counted += usize::from(f.watched_runs.iter().sum::<u64>() > 0);
    }
    assert!(counted >= 10, "only {counted} programs start a watched run");
}

/// With a waveform, the cycles go through the same fast paths, sampled
/// cycle by cycle (`Chip::run_fast_sampled`: while the DMA is idle the
/// loops of `Chip::run_local`, otherwise `Chip::run_stalled_sampled`).
/// Every program's full waveform (`--trace-scope all`), run that way, must
/// be byte for byte the waveform of plain stepping through `Sim::step`.
#[test]
fn the_stall_fast_path_traces_the_same_waveform() {
    let tmp = tempfile::tempdir().unwrap();
    let mut stalled = 0;
    for name in LISTED.iter().chain(REPORTED) {
        let img = load_program(&dir().join(name)).unwrap();
        let fast_vcd = tmp.path().join("fast.vcd");
        let fast = run_image(
            &img,
            Timing::default(),
            2_000_000,
            Some(rtl::trace::TraceConfig::new(&fast_vcd)),
        )
        .unwrap();
        assert!(fast.result.is_ok(), "{name}");
        if fast.stats().array_stall_cycles + fast.stats().dma_stall_cycles > 0 {
            stalled += 1;
        }
        let slow_vcd = tmp.path().join("slow.vcd");
        let mut chip = rtl::Chip::new(Timing::default(), tb::cmd_run::DEFAULT_MEMORY);
        img.load(&mut chip).unwrap();
        let mut slow = rtl::Sim::new(chip);
        slow.trace(rtl::trace::TraceConfig::new(&slow_vcd), "morphosys")
            .unwrap();
        while !slow.top.halted() {
            slow.step().unwrap();
        }
        slow.finish_trace().unwrap();
        let (f, s) = (
            std::fs::read(&fast_vcd).unwrap(),
            std::fs::read(&slow_vcd).unwrap(),
        );
        assert!(f.len() > 1000, "{name}: a waveform of {} bytes", f.len());
        assert!(f == s, "{name}: the waveforms differ");
    }
    assert!(stalled >= 10, "only {stalled} programs stall");
}

/// Every conformance program, `wide.s` included, on both datapaths: run
/// to its halt through the fast paths (`rtl::chip::run_to_halt`) and
/// through the plain model alone (`rtl::chip::run_to_halt_plain`, what
/// `--plain` runs), each with a waveform of every signal. The outcome (the
/// cycles, or the same error), the statistics, TinyRISC's and the RCs'
/// registers, outputs, flags, the FB and main memory, and the waveform
/// byte for byte must be the same.
#[test]
fn fast_paths_equal_the_plain_model_on_both_datapaths() {
    fn both<W: rtl::rc::Word>(name: &str, img: &firmware::asm::Image, dir: &std::path::Path) {
        let run = |plain: bool| {
            let vcd = dir.join(if plain { "plain.vcd" } else { "fast.vcd" });
            let mut chip = rtl::Chip::<W>::build(Timing::default(), tb::cmd_run::DEFAULT_MEMORY);
            img.load(&mut chip).unwrap();
            let mut sim = rtl::Sim::new(chip);
            // Every signal (an empty scope filter).
            sim.trace(rtl::trace::TraceConfig::new(&vcd), "morphosys")
                .unwrap();
            let r = if plain {
                rtl::chip::run_to_halt_plain(&mut sim, 300_000)
            } else {
                rtl::chip::run_to_halt(&mut sim, 300_000)
            };
            sim.finish_trace().unwrap();
            (
                sim,
                r.map_err(|e| e.to_string()),
                std::fs::read(&vcd).unwrap(),
            )
        };
        let (fast, fr, fw) = run(false);
        let (plain, pr, pw) = run(true);
        let bits = W::BITS;
        assert_eq!(fr, pr, "{name} ({bits}-bit): outcome");
        let (f, s) = (&fast.top, &plain.top);
        assert_eq!(f.stats(), s.stats(), "{name} ({bits}-bit): statistics");
        for k in 0..16 {
            assert_eq!(
                f.risc.regs.read(k),
                s.risc.regs.read(k),
                "{name}: TinyRISC r{k}"
            );
            assert_eq!(
                f.array.rc.regs.read(k),
                s.array.rc.regs.read(k),
                "{name}: RC r{k}"
            );
        }
        assert_eq!(
            f.array.rc.out, s.array.rc.out,
            "{name} ({bits}-bit): RC outputs"
        );
        assert_eq!(
            f.array.rc.acc, s.array.rc.acc,
            "{name} ({bits}-bit): accumulators"
        );
        for a in 0..=0xFFFFu16 {
            assert_eq!(
                f.fb.read(a),
                s.fb.read(a),
                "{name} ({bits}-bit): FB word {a:#x}"
            );
        }
        let n = f.mem.size();
        assert!(
            f.mem.bytes(0, n) == s.mem.bytes(0, n),
            "{name} ({bits}-bit): main memory"
        );
        assert!(fw.len() > 1000, "{name}: a waveform of {} bytes", fw.len());
        assert!(fw == pw, "{name} ({bits}-bit): the waveforms differ");
    }
    let tmp = tempfile::tempdir().unwrap();
    let mut names: Vec<String> = std::fs::read_dir(dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".s"))
        .collect();
    names.sort();
    assert!(
        names.iter().any(|n| n == "wide.s") && names.len() >= 18,
        "{names:?}"
    );
    for name in &names {
        let img = load_program(&dir().join(name)).unwrap();
        both::<i16>(name, &img, tmp.path());
        both::<i32>(name, &img, tmp.path());
    }
}
