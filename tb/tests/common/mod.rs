//! What the end-to-end tests share: running the `morphosys` binary.

use std::path::Path;
use std::process::Command;

/// `morphosys ARGS` in `dir`: (succeeded, stdout, stderr).
pub fn morphosys(dir: &Path, args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
