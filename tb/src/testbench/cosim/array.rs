//! The Verilated 8x8 array against the Rust array, cycle for cycle.

use std::path::Path;
use std::time::Instant;

use anyhow::Context as _;
use rtl::array::{Array, Mode};
use rtl::rc::context::Context;
use rtl::rc::{Datapath, LaneNames, Word};

use super::{mask, ArrayStep, Harness, Report};

/// Run `steps` through the array harness `program` (from [`super::build`] with
/// [`super::Top::Array`]) and the Rust array of width `dp`, comparing every RC's
/// `out`, the flag masks and the RCs executed after every cycle, and every
/// register, accumulator and RAM word at the end.
pub fn run_array(dp: Datapath, program: &Path, steps: &[ArrayStep]) -> anyhow::Result<Report> {
    match dp {
        Datapath::W16 => run_array_w::<i16>(program, steps),
        Datapath::W32 => run_array_w::<i32>(program, steps),
    }
}

pub(super) fn array_input(steps: &[ArrayStep]) -> Vec<u8> {
    let mut input = Vec::with_capacity(steps.len() * 56);
    for s in steps {
        let control = s.active as u32 | (s.mode as u32) << 1;
        input.extend_from_slice(&control.to_le_bytes());
        for w in s.words {
            input.extend_from_slice(&w.to_le_bytes());
        }
        input.extend_from_slice(&0u32.to_le_bytes());
        input.extend_from_slice(&(s.fb[0] as u64).to_le_bytes());
        input.extend_from_slice(&(s.fb[1] as u64).to_le_bytes());
    }
    input
}

/// A cycle's contexts, decoded (as the chip's context memory holds them).
pub(super) fn decode_step(s: &ArrayStep, wide: bool) -> anyhow::Result<[Context; 8]> {
    let mut ctx = [Context::NOP; 8];
    for (c, &w) in ctx.iter_mut().zip(&s.words) {
        *c = Context::decode_for(w, wide).map_err(|e| anyhow::anyhow!("word 0x{w:08x}: {e}"))?;
    }
    Ok(ctx)
}

/// One cycle of the Rust array, its contexts decoded.
#[inline]
pub(super) fn array_cycle<W: Word>(
    a: &mut Array<W>,
    s: &ArrayStep,
    ctx: &[Context; 8],
) -> anyhow::Result<()> {
    let fb = [W::wrap(s.fb[0]), W::wrap(s.fb[1])];
    if !s.active {
        a.idle();
        return Ok(());
    }
    if s.mode == Mode::Simd {
        a.drive_simd(s.words[0], &ctx[0], fb);
    } else {
        a.drive_group(s.mode, s.words, *ctx, fb);
    }
    a.step()
        .map_err(|e| anyhow::anyhow!("the Rust array faulted: {e}"))
}

fn run_array_w<W: Word>(program: &Path, steps: &[ArrayStep]) -> anyhow::Result<Report> {
    let t0 = Instant::now();
    let mut from = Harness::start(program, array_input(steps))?;
    let word = |x: W| x.to_i64() as u64 & mask(W::BITS);
    let mut a: Array<W> = Array::new();
    let mut report = Report::default();
    let mut rec = [0u8; 70 * 8];
    for (i, s) in steps.iter().enumerate() {
        let ctx = decode_step(s, W::BITS == 32)?;
        array_cycle(&mut a, s, &ctx).with_context(|| format!("cycle {i}"))?;
        from.read_exact(&mut rec)
            .with_context(|| format!("the Verilog harness stopped before cycle {i}"))?;
        let v = |k: usize| u64::from_le_bytes(rec[8 * k..8 * k + 8].try_into().unwrap());
        report.cycles += 1;
        report.values += 64 + 6;
        let executed = if s.active { a.active_now as u64 } else { 0 };
        report.executed += executed;
        let mut d = Vec::new();
        for k in 0..64 {
            let r = word(a.rc.out[k]);
            if v(k) != r {
                d.push(format!(
                    "{}: out Verilog 0x{:x}, Rust 0x{r:x}",
                    LaneNames::Grid.name(k),
                    v(k)
                ));
            }
        }
        let f = &a.rc.flags;
        for (name, k, r) in [
            ("F", 64, f.f),
            ("C", 65, f.c),
            ("V", 66, f.v),
            ("sleep", 67, f.sleep),
        ] {
            if v(k) != r {
                d.push(format!("{name} mask: Verilog {:016x}, Rust {r:016x}", v(k)));
            }
        }
        if v(68).count_ones() as u64 != executed {
            d.push(format!(
                "RCs executed: Verilog {}, Rust {executed}",
                v(68).count_ones()
            ));
        }
        if v(69) != 0 {
            d.push(format!("Verilog faults {:016x}", v(69)));
        }
        if !d.is_empty() {
            let words: Vec<String> = match s.mode {
                Mode::Simd => vec![describe(s.words[0], W::BITS == 32)],
                _ => s
                    .words
                    .iter()
                    .map(|&w| describe(w, W::BITS == 32))
                    .collect(),
            };
            report.mismatch = Some(format!(
                "first difference at cycle {i}: {:?} mode, {}, fb {:?}{}\n  {}",
                s.mode,
                words.join(" | "),
                s.fb,
                if s.active { "" } else { " (idle)" },
                d.join("\n  ")
            ));
            from.stop();
            report.seconds = t0.elapsed().as_secs_f64();
            return Ok(report);
        }
    }
    // The whole state: registers, accumulators, RAM.
    let mut rest = vec![0u8; (64 * 16 + 64 + 512 * 64) * 8];
    from.read_exact(&mut rest)
        .context("the Verilog harness stopped before its final state")?;
    let v = |k: usize| u64::from_le_bytes(rest[8 * k..8 * k + 8].try_into().unwrap());
    let mut diff = None;
    for i in 0..64 {
        for r in 0..16u8 {
            let got = word(a.rc.regs.read(r)[i]);
            let k = i * 16 + r as usize;
            if v(k) != got && diff.is_none() {
                diff = Some(format!(
                    "{} r{r} at the end: Verilog 0x{:x}, Rust 0x{got:x}",
                    LaneNames::Grid.name(i),
                    v(k)
                ));
            }
        }
        let acc = W::acc_i128(a.rc.acc[i]) as u64 & mask(2 * W::BITS);
        if v(64 * 16 + i) != acc && diff.is_none() {
            diff = Some(format!(
                "{} acc at the end: Verilog 0x{:x}, Rust 0x{acc:x}",
                LaneNames::Grid.name(i),
                v(64 * 16 + i)
            ));
        }
    }
    for addr in 0..512 {
        for i in 0..64 {
            let got = word(a.rc.ram.read(i, addr));
            let k = 64 * 17 + addr * 64 + i;
            if v(k) != got && diff.is_none() {
                diff = Some(format!(
                    "{} RAM word {addr} at the end: Verilog 0x{:x}, Rust 0x{got:x}",
                    LaneNames::Grid.name(i),
                    v(k)
                ));
            }
        }
    }
    report.values += (64 * 17 + 512 * 64) as u64;
    report.mismatch = diff;
    from.finish()?;
    report.seconds = t0.elapsed().as_secs_f64();
    Ok(report)
}

/// A context word in disassembly, or what is wrong with it.
fn describe(w: u32, wide: bool) -> String {
    match Context::decode_for(w, wide) {
        Ok(c) => format!("`{c}`"),
        Err(e) => format!("0x{w:08x} ({e})"),
    }
}
