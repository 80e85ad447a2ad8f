//! `morphosys asm FILE [-o OUT]`: assemble TinyRISC code and RC contexts.
//! With `-o`, writes the image (`morphosys run` loads it); without, prints
//! the listing (the disassembly of what was assembled).

use std::path::PathBuf;

use firmware::asm;

pub fn command(file: PathBuf, out: Option<PathBuf>) -> anyhow::Result<()> {
    if let Some(o) = &out {
        crate::output::Files::new()
            .input(&file, "FILE")
            .output(o, "-o")
            .check()?;
    }
    let img = asm::assemble_file(&file).map_err(|e| anyhow::anyhow!("{e}"))?;
    match out {
        Some(o) => {
            crate::output::write(&o, &img.to_bytes())?;
            let bytes: usize = img.segments.iter().map(|s| s.data.len()).sum();
            crate::report!(
                "wrote {} ({} segments, {bytes} bytes, entry 0x{:08x})",
                o.display(),
                img.segments.len(),
                img.entry
            );
        }
        None => print!("{}", asm::disassemble_image(&img)),
    }
    Ok(())
}

/// `morphosys asm` arguments.
#[derive(clap::Args, Debug)]
pub struct AsmArgs {
    pub file: PathBuf,
    /// Write the assembled image here.
    #[arg(short, long, value_name = "FILE.img")]
    pub out: Option<PathBuf>,
}

/// `morphosys asm`.
pub fn run(a: AsmArgs) -> anyhow::Result<()> {
    command(a.file, a.out)
}
