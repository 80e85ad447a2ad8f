//! `morphosys fuzz`: run the input fuzzers (see [`crate::fuzz`]).

use std::path::PathBuf;

use anyhow::bail;

use crate::fuzz::{self, Target};

pub fn command(
    targets: Vec<Target>,
    count: u64,
    seed: u64,
    save: Option<PathBuf>,
    json: Option<PathBuf>,
) -> anyhow::Result<()> {
    if let Some(j) = &json {
        crate::output::Files::new().output(j, "--json").check()?;
    }
    let mut figures = Vec::new();
    // The folder for findings is made (or refused) before any input runs.
    if let Some(dir) = &save {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("--save {}: {e}", dir.display()))?;
        crate::output::check_writable(&dir.join("finding"), "--save")?;
    }
    let targets = if targets.is_empty() {
        fuzz::ALL.to_vec()
    } else {
        targets
    };
    let mut total_findings = 0;
    for t in targets {
        let bar = crate::output::progress_bar(count);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{prefix:>6} [{bar:40}] {pos}/{len} inputs ({per_sec}, eta {eta})",
            )
            .unwrap()
            .progress_chars("=> "),
        );
        bar.set_prefix(t.name());
        let rep = fuzz::run(t, count, seed, |k| {
            if k % 256 == 0 {
                bar.set_position(k);
            }
        });
        let secs = bar.elapsed().as_secs_f64();
        bar.finish_and_clear();
        println!(
            "{:>6}: {} inputs ({} structured, largest {} KB), {} accepted, {} rejected with a located error, {} findings; {:.0} inputs/s, slowest input {:.3} s",
            t.name(),
            rep.inputs,
            rep.structured,
            rep.largest_input / 1024,
            rep.accepted,
            rep.rejected,
            rep.findings.len(),
            rep.inputs as f64 / secs.max(1e-9),
            rep.slowest_s
        );
        for (i, f) in rep.findings.iter().enumerate().take(10) {
            println!("        finding {i}: {}", f.what);
            if let Some(dir) = &save {
                let d = dir.join(t.name());
                std::fs::create_dir_all(&d)?;
                let p = d.join(format!("finding-{seed}-{i}"));
                std::fs::write(&p, &f.input)?;
                println!("          input saved to {}", p.display());
            }
        }
        total_findings += rep.findings.len();
        figures.push(serde_json::json!({
            "target": t.name(),
            "inputs": rep.inputs,
            "structured": rep.structured,
            "largest_input_bytes": rep.largest_input,
            "accepted": rep.accepted,
            "rejected": rep.rejected,
            "findings": rep.findings.iter().map(|f| f.what.clone()).collect::<Vec<_>>(),
            "inputs_per_second": rep.inputs as f64 / secs.max(1e-9),
            "slowest_input_seconds": rep.slowest_s,
        }));
    }
    if let Some(j) = &json {
        let v = serde_json::json!({"seed": seed, "count": count, "targets": figures});
        crate::output::write(j, (serde_json::to_string_pretty(&v)? + "\n").as_bytes())?;
        crate::note!("wrote {}", j.display());
    }
    if total_findings > 0 {
        bail!("{total_findings} findings");
    }
    Ok(())
}

/// `morphosys fuzz` arguments.
#[derive(clap::Args, Debug)]
pub struct FuzzArgs {
    /// Targets (default: all).
    #[arg(value_enum)]
    pub targets: Vec<crate::fuzz::Target>,
    /// Inputs per target.
    #[arg(long, value_name = "N", default_value_t = 100_000, value_parser = crate::cli::parse_count::<u64>)]
    pub count: u64,
    /// Random seed (runs are reproducible).
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub seed: u64,
    /// Save the inputs of findings under DIR/<target>/.
    #[arg(long, value_name = "DIR")]
    pub save: Option<PathBuf>,
    /// Write the figures per target (inputs, accepted, rejected,
    /// findings, inputs per second, slowest input) as JSON here.
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
}

/// `morphosys fuzz`.
pub fn run(a: FuzzArgs) -> anyhow::Result<()> {
    command(a.targets, a.count, a.seed, a.save, a.json)
}
