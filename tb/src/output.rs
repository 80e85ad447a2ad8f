//! Output files, the one way every command writes them:
//!
//! * a regular file (or a new one) is written to a temporary file beside it
//!   and renamed into place, so a failed or killed run never leaves half a
//!   file under the asked name;
//! * a symbolic link is followed: its target is replaced (atomically, as
//!   above), the link stays;
//! * a character device, FIFO or socket (`/dev/null`, `/dev/stdout`, a
//!   named pipe) is written through, never replaced;
//! * `-` (or `/dev/stdout`) is standard output, and the command's report
//!   then goes to standard error.
//!
//! [`Files`] checks a command's outputs before any work: each can be
//! written, none is one of the command's inputs, no two are the same file.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context as _, Result};

/// Where the bytes for an output path go.
#[derive(Debug, PartialEq, Eq)]
enum Target {
    Stdout,
    /// A regular file (existing or not), after following symbolic links.
    File(PathBuf),
    /// A device, FIFO or socket: opened and written through.
    Stream(PathBuf),
}

/// `-` and the names of this process's standard output.
fn is_stdout(path: &Path) -> bool {
    ["-", "/dev/stdout", "/dev/fd/1", "/proc/self/fd/1"]
        .iter()
        .any(|s| path.as_os_str() == *s)
}

/// A path naming an open descriptor: `/dev/fd/N`, `/dev/stdout`,
/// `/dev/stderr`, `/proc/self/fd/N`, `/proc/PID/fd/N`.
fn is_descriptor(path: &Path) -> bool {
    let s = path.to_string_lossy();
    if s.starts_with("/dev/fd/") || ["/dev/stdout", "/dev/stderr"].contains(&s.as_ref()) {
        return true;
    }
    let parts: Vec<&str> = s.split('/').collect();
    // "", "proc", self|PID, "fd", N
    parts.len() == 5
        && parts[1] == "proc"
        && (parts[2] == "self" || parts[2].chars().all(|c| c.is_ascii_digit()))
        && parts[3] == "fd"
}

fn target(path: &Path) -> Result<Target> {
    if is_stdout(path) {
        return Ok(Target::Stdout);
    }
    // `/dev/stdout`, `/dev/fd/3`, `/proc/self/fd/1`: a descriptor's file,
    // written through even when it is a regular file (replacing it would
    // leave the descriptor on the old, unlinked file). Any other regular
    // file, under /dev or not (`/dev/shm/r.json`), is replaced.
    if is_descriptor(path) && path.exists() {
        return Ok(Target::Stream(path.to_path_buf()));
    }
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => anyhow::bail!("{} is a folder", path.display()),
        Ok(m) if m.is_file() => Ok(Target::File(
            std::fs::canonicalize(path).with_context(|| format!("{}", path.display()))?,
        )),
        Ok(_) => Ok(Target::Stream(path.to_path_buf())),
        Err(_) => {
            // A dangling symbolic link: the file it names is created.
            let mut p = path.to_path_buf();
            for _ in 0..40 {
                match std::fs::read_link(&p) {
                    Ok(to) => {
                        p = match p.parent() {
                            Some(d) if to.is_relative() => d.join(to),
                            _ => to,
                        }
                    }
                    Err(_) => return Ok(Target::File(p)),
                }
            }
            anyhow::bail!("{}: too many levels of symbolic links", path.display())
        }
    }
}

/// Temporary files and folders of this process: what an interrupted run
/// removes ([`remove_temporaries`]).
static TEMPS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Note a temporary file or folder to remove if the run is interrupted.
pub(crate) fn register_temporary(p: &Path) {
    if let Ok(mut v) = TEMPS.lock() {
        v.push(p.to_path_buf());
    }
}

/// It is gone (renamed into place or removed): forget it.
pub(crate) fn forget_temporary(p: &Path) {
    if let Ok(mut v) = TEMPS.lock() {
        v.retain(|q| q != p);
    }
}

/// Remove every temporary file and folder of the run, partial waveforms
/// included: called on SIGINT, SIGTERM and SIGHUP before exiting.
pub fn remove_temporaries() {
    let mut all = Vec::new();
    if let Ok(v) = TEMPS.lock() {
        all.extend(v.iter().cloned());
    }
    for p in all {
        if p.is_dir() {
            let _ = std::fs::remove_dir_all(&p);
        } else {
            let _ = std::fs::remove_file(&p);
        }
    }
}

/// What the tracer does with a waveform's temporary file
/// ([`rtl::trace::TraceConfig::partial_files`], set by the command line's
/// trace window, `cli.rs`): listed with the
/// run's other temporaries, and those a killed run left removed.
pub const PARTIAL_FILES: rtl::trace::PartialFiles = rtl::trace::PartialFiles {
    clean_stale: remove_stale_partials,
    created: register_temporary,
    done: forget_temporary,
};

/// A waveform's temporary file is `.<name>.<pid>.<random>.partial` beside
/// it (the tracer makes it). Those of `name` in `dir` left by a process
/// that no longer runs (killed outright, with no chance to clean up) are
/// removed.
pub(crate) fn remove_stale_partials(dir: &Path, name: &str) {
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

/// `--quiet`: no progress bars and no "wrote FILE" lines (warnings and
/// errors still print).
static QUIET: AtomicBool = AtomicBool::new(false);

pub fn set_quiet(q: bool) {
    QUIET.store(q, Ordering::Relaxed);
}

pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// A progress bar of `len` steps, hidden under `--quiet`.
pub(crate) fn progress_bar(len: u64) -> indicatif::ProgressBar {
    if quiet() {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(len)
    }
}

/// `eprintln!` unless `--quiet`: what a command wrote, and where.
#[macro_export]
macro_rules! note {
    ($($t:tt)*) => {
        if !$crate::output::quiet() {
            eprintln!($($t)*)
        }
    };
}

/// Set when an output is standard output: reports go to standard error.
static STDOUT_TAKEN: AtomicBool = AtomicBool::new(false);

/// Whether an output of this command is standard output (`-`), so its
/// report must go to standard error.
pub(crate) fn stdout_taken() -> bool {
    STDOUT_TAKEN.load(Ordering::Relaxed)
}

/// `println!`, or `eprintln!` when standard output carries an output file.
#[macro_export]
macro_rules! report {
    ($($t:tt)*) => {
        if $crate::output::stdout_taken() {
            eprintln!($($t)*)
        } else {
            println!($($t)*)
        }
    };
}

/// Write `bytes` to `path` by the rules of this module.
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    let what = || format!("cannot write {}", path.display());
    match target(path).with_context(what)? {
        Target::Stdout => {
            let mut o = std::io::stdout().lock();
            o.write_all(bytes)
                .and_then(|_| o.flush())
                .with_context(what)
        }
        Target::Stream(p) => {
            // A descriptor's regular file is written from its start, as the
            // shell's `>` would (a device or FIFO has nothing to truncate).
            let regular = std::fs::metadata(&p).is_ok_and(|m| m.is_file());
            let mut f = std::fs::OpenOptions::new()
                .write(true)
                .truncate(regular)
                .open(&p)
                .with_context(what)?;
            f.write_all(bytes)
                .and_then(|_| f.flush())
                .with_context(what)
        }
        Target::File(p) => {
            let dir = match p.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            let tmp = new_output_file(dir, &p).with_context(what)?;
            let tmp_path = tmp.path().to_path_buf();
            register_temporary(&tmp_path);
            let done = finish_file(tmp, bytes, &p).with_context(what);
            forget_temporary(&tmp_path);
            done
        }
    }
}

/// The temporary file in `dir` that becomes the output `p`: with the mode
/// `p` has when it exists (an overwritten output keeps its permissions),
/// else as any new file (0666 less the umask), not tempfile's private 0600.
fn new_output_file(dir: &Path, p: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mut b = tempfile::Builder::new();
        b.permissions(std::fs::Permissions::from_mode(0o666));
        let tmp = b.tempfile_in(dir)?;
        if let Ok(m) = std::fs::metadata(p) {
            tmp.as_file().set_permissions(m.permissions())?;
        }
        Ok(tmp)
    }
    #[cfg(not(unix))]
    {
        let _ = p;
        tempfile::NamedTempFile::new_in(dir)
    }
}

/// Fill the temporary file and rename it onto `p`.
fn finish_file(mut tmp: tempfile::NamedTempFile, bytes: &[u8], p: &Path) -> std::io::Result<()> {
    tmp.write_all(bytes)?;
    tmp.persist(p).map_err(|e| e.error)?;
    Ok(())
}

/// Identity of a file for the "same file" checks: device and inode when it
/// exists, else its absolute path (folder canonicalised).
#[derive(Debug, PartialEq, Eq)]
enum Id {
    Inode(u64, u64),
    Path(PathBuf),
    Stdout,
}

fn id(path: &Path) -> Id {
    if is_stdout(path) {
        return Id::Stdout;
    }
    #[cfg(unix)]
    if let Ok(m) = std::fs::metadata(path) {
        use std::os::unix::fs::MetadataExt;
        return Id::Inode(m.dev(), m.ino());
    }
    let p = match target(path) {
        Ok(Target::File(p)) => p,
        _ => path.to_path_buf(),
    };
    let p = std::path::absolute(&p).unwrap_or(p);
    let p = match (p.parent(), p.file_name()) {
        (Some(d), Some(f)) => std::fs::canonicalize(d).map_or(p.clone(), |d| d.join(f)),
        _ => p,
    };
    Id::Path(p)
}

fn is_stream(path: &Path) -> bool {
    matches!(target(path), Ok(Target::Stream(_)))
}

/// A command's input and output files, checked together before any work.
#[derive(Default)]
pub struct Files {
    inputs: Vec<(PathBuf, String)>,
    outputs: Vec<(PathBuf, String)>,
    /// Files written beside an output (a waveform's save and filter
    /// files): neither an input nor another output, but made by the
    /// writer itself (folders included), so not checked for writability.
    beside: Vec<(PathBuf, String)>,
    /// Waveform outputs: their GTKWave save file names them by their
    /// absolute path, one line each.
    waveforms: Vec<(PathBuf, String)>,
}

impl Files {
    pub fn new() -> Files {
        Files::default()
    }

    /// An input file (`what` names its argument in messages).
    pub fn input(&mut self, path: &Path, what: &str) -> &mut Files {
        self.inputs.push((path.to_path_buf(), what.into()));
        self
    }

    /// An output file (`what` names its argument).
    pub fn output(&mut self, path: &Path, what: &str) -> &mut Files {
        self.outputs.push((path.to_path_buf(), what.into()));
        self
    }

    /// A waveform output (`what` names its argument) and, unless it goes
    /// to a device, FIFO or standard output, every file the waveform may
    /// be written with beside it.
    pub fn waveform(&mut self, path: &Path, what: &str) -> &mut Files {
        self.output(path, what);
        if !is_stream(path) && path != Path::new("-") {
            self.waveforms.push((path.to_path_buf(), what.into()));
            for (p, kind) in rtl::chip::waveform_side_files(path) {
                self.beside.push((p, format!("{what}'s {kind}")));
            }
        }
        self
    }

    /// Every output can be written, none is an input, no two are the same
    /// (two outputs to one device, such as `/dev/null`, are fine; two to
    /// standard output are not). Marks standard output as taken when an
    /// output is `-`.
    pub fn check(&self) -> Result<()> {
        for (p, what) in &self.waveforms {
            let abs = std::path::absolute(p).unwrap_or_else(|_| p.clone());
            if let Some(c) = abs.to_string_lossy().chars().find(|c| c.is_control()) {
                let shown = escaped(&p.to_string_lossy());
                anyhow::bail!(
                    "{what} {shown}: its path {}holds the control character U+{:04X}, which the \
                     GTKWave save file written beside it (one line per path) cannot name: give \
                     a path without it",
                    if p.to_string_lossy().contains(c) {
                        ""
                    } else {
                        "(a folder above it) "
                    },
                    c as u32
                );
            }
        }
        for (i, (p, what)) in self.outputs.iter().enumerate() {
            check_writable(p, what)?;
            let me = id(p);
            for (q, qwhat) in &self.inputs {
                if id(q) == me && me != Id::Stdout {
                    anyhow::bail!(
                        "{what} {}: that is the input {qwhat} {}; refusing to overwrite it",
                        p.display(),
                        q.display()
                    );
                }
            }
            for (q, qwhat) in &self.outputs[..i] {
                if id(q) == me && !is_stream(p) {
                    anyhow::bail!(
                        "{what} {} and {qwhat} {} are the same file: give each output a path of its own",
                        p.display(),
                        q.display()
                    );
                }
            }
            if me == Id::Stdout {
                STDOUT_TAKEN.store(true, Ordering::Relaxed);
            }
        }
        for (p, what) in &self.beside {
            let me = id(p);
            for (q, qwhat) in &self.inputs {
                if id(q) == me {
                    anyhow::bail!(
                        "{what} would be {}: that is the input {qwhat}; refusing to overwrite it",
                        p.display()
                    );
                }
            }
            for (q, qwhat) in &self.outputs {
                if id(q) == me {
                    anyhow::bail!(
                        "{what} would be {}, which is also {qwhat} {}: give each output a path of its own",
                        p.display(),
                        q.display()
                    );
                }
            }
            // The writer makes the folders it lacks: one that is a file
            // (or the side file a folder) fails it only after the work.
            let mut at = p.parent();
            while let Some(dir) = at.filter(|d| !d.as_os_str().is_empty()) {
                if dir.exists() && !dir.is_dir() {
                    anyhow::bail!(
                        "{what} would be {}, but {} is not a folder: move it or give the waveform another folder",
                        p.display(),
                        dir.display()
                    );
                }
                at = dir.parent();
            }
            if p.is_dir() {
                anyhow::bail!(
                    "{what} would be {}, which is a folder: move it or give the waveform another folder",
                    p.display()
                );
            }
        }
        Ok(())
    }
}

/// `text` on one line: its control characters (line breaks included)
/// written as `U+000A`.
pub(crate) fn escaped(text: &str) -> String {
    text.chars()
        .map(|c| match c.is_control() {
            true => format!("U+{:04X}", c as u32),
            false => c.to_string(),
        })
        .collect()
}

/// Check before the work that `path` can be written: a regular file's
/// folder exists and takes a new file (a temporary one, removed at once); a
/// device or FIFO is writable by us. `what` names the argument.
pub(crate) fn check_writable(path: &Path, what: &str) -> Result<()> {
    match target(path).with_context(|| format!("{what} {}", path.display()))? {
        Target::Stdout => Ok(()),
        Target::Stream(p) => {
            #[cfg(unix)]
            {
                use std::os::unix::ffi::OsStrExt;
                let c = std::ffi::CString::new(p.as_os_str().as_bytes())
                    .with_context(|| format!("{what} {}", path.display()))?;
                // SAFETY: access(2) reads a NUL-terminated path and nothing else.
                if unsafe { libc::access(c.as_ptr(), libc::W_OK) } != 0 {
                    anyhow::bail!(
                        "{what} {}: cannot write it: {}",
                        path.display(),
                        std::io::Error::last_os_error()
                    );
                }
            }
            let _ = p;
            Ok(())
        }
        Target::File(p) => {
            let dir = match p.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            if !dir.is_dir() {
                anyhow::bail!(
                    "{what} {}: the folder {} does not exist",
                    path.display(),
                    dir.display()
                );
            }
            tempfile::NamedTempFile::new_in(dir)
                .map(drop)
                .with_context(|| {
                    format!(
                        "{what} {}: cannot write in {}",
                        path.display(),
                        dir.display()
                    )
                })
        }
    }
}

/// 12,345,678
pub(crate) fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symlinks_are_followed_and_kept() {
        let d = tempfile::tempdir().unwrap();
        let real = d.path().join("real.txt");
        std::fs::write(&real, "old").unwrap();
        let link = d.path().join("link.txt");
        std::os::unix::fs::symlink("real.txt", &link).unwrap();
        write(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        // a dangling link creates its target
        let dang = d.path().join("dang.txt");
        std::os::unix::fs::symlink("made.txt", &dang).unwrap();
        write(&dang, b"x").unwrap();
        assert_eq!(
            std::fs::read_to_string(d.path().join("made.txt")).unwrap(),
            "x"
        );
        assert!(std::fs::symlink_metadata(&dang)
            .unwrap()
            .file_type()
            .is_symlink());
    }

    #[test]
    fn devices_are_written_through() {
        let null = Path::new("/dev/null");
        if !null.exists() {
            return;
        }
        write(null, b"bytes").unwrap();
        let m = std::fs::metadata(null).unwrap();
        assert!(!m.is_file(), "/dev/null was replaced by a file");
        // two outputs to /dev/null are fine, an output over an input is not
        let d = tempfile::tempdir().unwrap();
        let input = d.path().join("in.nff");
        std::fs::write(&input, "x").unwrap();
        let mut f = Files::new();
        f.input(&input, "SCENE")
            .output(null, "--out")
            .output(null, "--json");
        f.check().unwrap();
        let mut f = Files::new();
        f.input(&input, "SCENE").output(&input, "--out");
        let e = f.check().unwrap_err().to_string();
        assert!(e.contains("--out") && e.contains("input SCENE"), "{e}");
        let out = d.path().join("o.png");
        let mut f = Files::new();
        f.output(&out, "--out")
            .output(&d.path().join(".").join("o.png"), "--json");
        let e = f.check().unwrap_err().to_string();
        assert!(e.contains("same file"), "{e}");
    }
}
