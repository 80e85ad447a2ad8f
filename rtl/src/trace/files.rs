//! The files around a waveform: partial files removed on interruption,
//! the GTKWave save file, translate filters and Surfer decoders beside it,
//! and the scope patterns of `--trace-scope`.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use super::tracer::*;
use super::*;

/// The waveforms being written right now (their temporary files), for a
/// signal handler to remove: [`partial_files`].
pub(super) static PARTIALS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// The temporary files of the waveforms being written now: what an
/// interrupted run must remove (the `morphosys` command does so on SIGINT,
/// SIGTERM and SIGHUP).
pub fn partial_files() -> Vec<PathBuf> {
    PARTIALS.lock().map(|v| v.clone()).unwrap_or_default()
}

pub(super) fn forget_partial(p: &Path) {
    if let Ok(mut v) = PARTIALS.lock() {
        v.retain(|q| q != p);
    }
}

/// A waveform's temporary file is `.<name>.<pid>.<random>.partial` beside
/// it. Those of `target` left by a process that no longer runs (killed
/// outright, with no chance to clean up) are removed.
pub(super) fn remove_stale_partials(dir: &Path, name: &str) {
    let proc_fs = Path::new("/proc/self").exists();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let prefix = format!(".{name}.");
    for e in entries.flatten() {
        let f = e.file_name().to_string_lossy().into_owned();
        let Some(rest) = f
            .strip_prefix(&prefix)
            .and_then(|r| r.strip_suffix(".partial"))
        else {
            continue;
        };
        let Some(pid) = rest.split('.').next().and_then(|p| p.parse::<u32>().ok()) else {
            continue;
        };
        if proc_fs && pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// Write a small text file through a temporary file and a rename.
/// `text` in a temporary file beside `path`, to be renamed onto it.
pub(super) fn stage(path: &Path, text: &str) -> io::Result<tempfile::NamedTempFile> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = output_tempfile(&mut tempfile::Builder::new(), dir, path)?;
    tmp.write_all(text.as_bytes())?;
    Ok(tmp)
}

/// A waveform's GTKWave save file: `<stem>.gtkw`.
pub(super) fn save_file_path(wave: &Path) -> PathBuf {
    wave.with_extension("gtkw")
}

/// A waveform's translate filter `name`: `<stem>.<name>.txt`.
pub(super) fn filter_path(wave: &Path, name: &str) -> PathBuf {
    PathBuf::from(format!("{}.{name}.txt", wave.with_extension("").display()))
}

/// A waveform's Surfer decoder of the labels `name`:
/// `.surfer/decoders/<stem>.<name>/<name>.toml` in its folder.
pub(super) fn decoder_path(wave: &Path, name: &str) -> PathBuf {
    let stem = wave.with_extension("");
    let stem_name = stem.file_name().unwrap_or_default().to_string_lossy();
    wave.parent()
        .unwrap_or(Path::new("."))
        .join(".surfer/decoders")
        .join(format!("{stem_name}.{name}"))
        .join(format!("{name}.toml"))
}

/// Every file that may be written beside a waveform at `wave` whose
/// signals use the translate filters `filters` (names) and, with labels,
/// the label kinds: its save file, filter files and Surfer decoders, each
/// with what it is. Commands check these against their inputs and other
/// outputs before the work ([`Tracer::finish`] writes those the traced
/// signals need).
pub(crate) fn side_files(wave: &Path, filters: &[&str]) -> Vec<(PathBuf, String)> {
    let wave = std::path::absolute(wave).unwrap_or_else(|_| wave.to_path_buf());
    let mut v = vec![(save_file_path(&wave), "save file".to_string())];
    for name in filters {
        v.push((filter_path(&wave, name), format!("filter file `{name}`")));
    }
    for k in [LabelKind::Code, LabelKind::Context] {
        let name = k.filter_name();
        v.push((filter_path(&wave, name), format!("filter file `{name}`")));
        v.push((
            decoder_path(&wave, name),
            format!("Surfer decoder `{name}`"),
        ));
    }
    v
}

/// The files written beside a waveform ([`Tracer::side_files`]).
pub(super) struct SideFiles {
    pub(super) vcd_abs: PathBuf,
    pub(super) gtkw: PathBuf,
    /// Per translate filter its name and file.
    pub(super) filters: Vec<(&'static str, PathBuf)>,
    /// Per label kind shown, Surfer's decoder of it: the kind, the
    /// signal's width and the file (`.surfer/decoders/<stem>.<name>/`
    /// beside the waveform, where Surfer started there finds it).
    pub(super) decoders: Vec<(LabelKind, u32, PathBuf)>,
}

pub(super) fn glob(p: &str, s: &str) -> bool {
    let (p, s) = (p.as_bytes(), s.as_bytes());
    let (mut pi, mut si, mut star, mut mark) = (0, 0, None, 0);
    while si < s.len() {
        if pi < p.len() && (p[pi] == b'?' || p[pi] == s[si]) {
            pi += 1;
            si += 1;
        } else if pi < p.len() && p[pi] == b'*' {
            star = Some(pi);
            mark = si;
            pi += 1;
        } else if let Some(st) = star {
            pi = st + 1;
            mark += 1;
            si = mark;
        } else {
            return false;
        }
    }
    while pi < p.len() && p[pi] == b'*' {
        pi += 1;
    }
    pi == p.len()
}

/// Check a scope pattern list for the command line: components of letters,
/// digits, `_`, `*`, `?`, separated by dots.
pub fn check_scope_patterns(s: &str) -> Result<(), String> {
    for pat in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        for comp in pat.split('.') {
            if comp.is_empty()
                || !comp
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '*' | '?'))
            {
                return Err(format!(
                    "bad scope pattern `{pat}`: use dot-separated names with `*` and `?` globs, e.g. `rc.alu` or `array.rc_r*_c0`"
                ));
            }
        }
    }
    Ok(())
}
