//! `morphosys asm FILE [-o OUT]`: assemble TinyRISC code and RC contexts.
//! With `-o`, writes the image (`morphosys run` loads it); without, prints
//! the listing (the disassembly of what was assembled).

use std::path::PathBuf;

use anyhow::Context as _;
use firmware::asm;

pub fn command(file: PathBuf, out: Option<PathBuf>) -> anyhow::Result<()> {
    let img = asm::assemble_file(&file).map_err(|e| anyhow::anyhow!("{e}"))?;
    match out {
        Some(o) => {
            std::fs::write(&o, img.to_bytes())
                .with_context(|| format!("writing {}", o.display()))?;
            let bytes: usize = img.segments.iter().map(|s| s.data.len()).sum();
            println!(
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
