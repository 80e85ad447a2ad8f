//! The build's identity: the SHA-256 of the sources a render's result
//! depends on (the chip, the firmware generator and assembler, the
//! testbench crate, the lock file), as `MORPHOSYS_SOURCE_DIGEST` for
//! `tb::inputs::build_digest`. Hashing the sources once here costs a
//! render nothing; hashing the 40 MB binary cost every render 0.1 s.

use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            files(&p, out);
        } else {
            out.push(p);
        }
    }
}

fn main() {
    let tb = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let root = tb.parent().unwrap().to_path_buf();
    let mut list = Vec::new();
    for dir in ["rtl/src", "firmware/src", "tb/src"] {
        let d = root.join(dir);
        println!("cargo:rerun-if-changed={}", d.display());
        files(&d, &mut list);
    }
    for f in [
        "Cargo.lock",
        "Cargo.toml",
        "rtl/Cargo.toml",
        "firmware/Cargo.toml",
        "tb/Cargo.toml",
    ] {
        let p = root.join(f);
        println!("cargo:rerun-if-changed={}", p.display());
        list.push(p);
    }
    list.sort();
    let mut h = Sha256::new();
    for p in &list {
        let rel = p.strip_prefix(&root).unwrap_or(p);
        h.update(rel.to_string_lossy().as_bytes());
        h.update([0]);
        h.update(std::fs::read(p).unwrap_or_default());
        h.update([0]);
    }
    let hex: String = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
    println!("cargo:rustc-env=MORPHOSYS_SOURCE_DIGEST={hex}");
}
