//! `morphosys tb cosim --bench`: the Verilated array's speed and the Rust
//! array's on the same stream.

use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

use anyhow::{bail, Context as _};
use rtl::array::Array;
use rtl::rc::{Datapath, Word};

use super::array::{array_cycle, array_input, decode_step};
use super::ArrayStep;

/// The speed of the Verilated array and of the Rust array on the same
/// stream, in array cycles per second.
#[derive(Clone, Copy, Debug)]
pub struct Speeds {
    pub cycles: u64,
    pub verilator: f64,
    pub rust: f64,
}

/// Run `steps` `repeat` times through the Verilated array (`program`, its
/// `--bench` mode: the stream in memory, nothing compared) and through the
/// Rust array of width `dp`, each timed alone on one thread.
pub fn bench_array(
    dp: Datapath,
    program: &Path,
    steps: &[ArrayStep],
    repeat: u32,
) -> anyhow::Result<Speeds> {
    let mut child = Command::new(program)
        .arg("--bench")
        .arg(repeat.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .with_context(|| format!("cannot run {}", program.display()))?;
    child
        .stdin
        .take()
        .expect("piped")
        .write_all(&array_input(steps))
        .context("writing the stream to the Verilog harness")?;
    let out = child.wait_with_output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let mut it = text.split_whitespace();
    let (Some(n), Some(secs)) = (
        it.next().and_then(|x| x.parse::<u64>().ok()),
        it.next().and_then(|x| x.parse::<f64>().ok()),
    ) else {
        bail!("the Verilog harness's bench printed `{}`", text.trim());
    };
    let rust = match dp {
        Datapath::W16 => time_rust::<i16>(steps, repeat)?,
        Datapath::W32 => time_rust::<i32>(steps, repeat)?,
    };
    Ok(Speeds {
        cycles: n,
        verilator: n as f64 / secs,
        rust: n as f64 / rust,
    })
}

fn time_rust<W: Word>(steps: &[ArrayStep], repeat: u32) -> anyhow::Result<f64> {
    let decoded = steps
        .iter()
        .map(|s| decode_step(s, W::BITS == 32))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut a: Array<W> = Array::new();
    let t = Instant::now();
    for _ in 0..repeat {
        for (s, c) in steps.iter().zip(&decoded) {
            array_cycle(&mut a, s, c)?;
        }
    }
    let secs = t.elapsed().as_secs_f64();
    std::hint::black_box(&a.rc.out);
    Ok(secs)
}
