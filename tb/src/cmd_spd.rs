//! `morphosys spd NAME [--size N] [--out FILE.nff]`: run one of the ported
//! Standard Procedural Databases generators (firmware::scene::spd) and print
//! or write its NFF text.

use std::path::PathBuf;

use anyhow::{anyhow, Result};
use firmware::scene::{spd, PrimType};

/// Generate `name` at `size` (default: the SPD program's default size) and
/// write it to `out`, or to stdout without `out`.
pub fn command(name: &str, size: Option<u32>, out: Option<PathBuf>) -> Result<()> {
    let size = match size {
        Some(s) => s,
        None => spd::default_size(name).map_err(|e| anyhow!(e))?,
    };
    // The size's limits depend on the generator: a usage error (exit 2).
    if let Err(message) = spd::check_size(name, size) {
        return Err(crate::cli::UsageError {
            command: "spd",
            message: format!("invalid value '{size}' for '--size <N>': {message}"),
        }
        .into());
    }
    if let Some(o) = &out {
        crate::output::Files::new().output(o, "--out").check()?;
    }
    let text = spd::generate(name, size).map_err(|e| anyhow!(e))?;
    match out {
        Some(path) => {
            crate::output::write(&path, text.as_bytes())?;
            let scene = firmware::scene::nff::parse(&text, &path.display().to_string())?;
            let c = scene.type_counts();
            let parts: Vec<String> = PrimType::ALL
                .iter()
                .filter(|t| c[t.index()] > 0)
                .map(|t| format!("{} {}", c[t.index()], t.name()))
                .collect();
            crate::report!(
                "{}: {name} size {size}: {} objects ({}), {} light{}",
                path.display(),
                scene.objects.len(),
                parts.join(", "),
                scene.lights.len(),
                if scene.lights.len() == 1 { "" } else { "s" }
            );
        }
        None => print!("{text}"),
    }
    Ok(())
}

/// `morphosys spd` arguments.
#[derive(clap::Args, Debug)]
pub struct SpdArgs {
    #[arg(value_parser = clap::builder::PossibleValuesParser::new(firmware::scene::spd::names()))]
    pub name: String,
    /// SPD size factor (default: the SPD program's default).
    #[arg(long, value_name = "N", value_parser = crate::cli::parse_count::<u32>)]
    pub size: Option<u32>,
    /// Write the NFF here (default: stdout).
    #[arg(long, value_name = "FILE.nff")]
    pub out: Option<PathBuf>,
}

/// `morphosys spd`.
pub fn run(a: SpdArgs) -> Result<()> {
    command(&a.name, a.size, a.out)
}
