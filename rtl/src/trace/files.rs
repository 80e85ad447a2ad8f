//! The files around a waveform: the hooks through which the program
//! tracks its temporary file, the GTKWave save file, translate filters and
//! Surfer decoders beside it, and the scope patterns of `--trace-scope`.

use super::{is_fst, LabelKind, TraceConfig};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// What the program around the tracer does with a waveform's temporary
/// file (`.<name>.<pid>.<random>.partial` beside the waveform, renamed onto
/// it when finished): the `morphosys` command keeps the list its signal
/// handler empties and removes what a killed run left
/// (`tb::output::PARTIAL_FILES`), given in
/// [`TraceConfig::partial_files`]. Without it (as in a library's tests)
/// the tracer only makes and renames the file.
#[derive(Clone, Copy, Debug)]
pub struct PartialFiles {
    /// Before a waveform named `name` is begun in `dir`: remove the
    /// temporary files of it that a run killed outright left.
    pub clean_stale: fn(dir: &Path, name: &str),
    /// The tracer made this temporary file: remove it if the run is
    /// interrupted.
    pub created: fn(&Path),
    /// Renamed into place or removed: nothing is left to clean.
    pub done: fn(&Path),
}

pub(super) fn clean_stale_partials(p: Option<PartialFiles>, dir: &Path, name: &str) {
    if let Some(p) = p {
        (p.clean_stale)(dir, name);
    }
}

pub(super) fn partial_created(p: Option<PartialFiles>, path: &Path) {
    if let Some(p) = p {
        (p.created)(path);
    }
}

pub(super) fn forget_partial(p: Option<PartialFiles>, path: &Path) {
    if let Some(p) = p {
        (p.done)(path);
    }
}

/// Temporary files are created 0600; outputs are ordinary files (0644).
/// A temporary file in `dir` (named by `b`) that becomes `target`: with
/// the mode `target` has when it exists, else as any new file (0666 less
/// the umask), not tempfile's private 0600.
pub(super) fn output_tempfile(
    b: &mut tempfile::Builder,
    dir: &Path,
    target: &Path,
) -> io::Result<tempfile::NamedTempFile> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let tmp = b.tempfile_in(dir)?;
    if let Ok(m) = std::fs::metadata(target) {
        tmp.as_file().set_permissions(m.permissions())?;
    }
    Ok(tmp)
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

/// The file a waveform is written to: a regular file goes to a temporary
/// file beside it, renamed into place by finish(), so an interrupted run
/// never leaves a truncated waveform under the requested name; a symbolic
/// link is followed (its target replaced, the link kept); a device or FIFO
/// (`/dev/null`, a named pipe) is written through. Returns the file, the
/// temporary's path and the target.
pub(super) fn open_output(
    cfg: &TraceConfig,
) -> io::Result<(std::fs::File, Option<tempfile::TempPath>, PathBuf)> {
    let through = matches!(std::fs::metadata(&cfg.path), Ok(m) if !m.is_file() && !m.is_dir());
    if through && is_fst(&cfg.path) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{}: an FST waveform needs a regular file (it is written out of order); \
                 give a path ending in .vcd to write through a device or pipe",
                cfg.path.display()
            ),
        ));
    }
    Ok(match std::fs::metadata(&cfg.path) {
        Ok(m) if !m.is_file() && !m.is_dir() => (
            std::fs::OpenOptions::new().write(true).open(&cfg.path)?,
            None,
            cfg.path.clone(),
        ),
        _ => {
            let target = std::fs::canonicalize(&cfg.path).unwrap_or_else(|_| cfg.path.clone());
            let dir = match target.parent() {
                Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                _ => PathBuf::from("."),
            };
            let name = target
                .file_name()
                .map_or_else(|| "waveform".into(), |n| n.to_string_lossy().into_owned());
            clean_stale_partials(cfg.partial_files, &dir, &name);
            let tmp = output_tempfile(
                tempfile::Builder::new()
                    .prefix(&format!(".{name}.{}.", std::process::id()))
                    .suffix(".partial"),
                &dir,
                &target,
            )?;
            let (file, tmp_path) = tmp.into_parts();
            partial_created(cfg.partial_files, &tmp_path);
            (file, Some(tmp_path), target)
        }
    })
}
