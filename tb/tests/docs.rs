//! Every command README.md and docs/*.md show runs as written.
//!
//! The commands are read out of the Markdown itself: each line of a ```sh
//! block (its `# comment` removed) and each inline code span that begins
//! with `morphosys `. Each one is then
//!
//! - **run** as written, in document order, with `bash` in a scratch folder
//!   holding copies of `scenes/` and `firmware/` and `morphosys` (the binary
//!   under test) first on PATH; it must exit 0. Files an earlier command
//!   writes (`chip.hits`, `fw.s`, a sweep plan) are there for later ones,
//!   as they are for a reader typing them in turn;
//! - or, where it is a **synopsis** (a placeholder such as `SCENE`, `WxH`,
//!   `FILE.nff`, brackets, `a|b` alternatives or `...`), **checked against
//!   `morphosys SUB --help`**: the subcommand exists, every option it names
//!   is one the subcommand takes, and each alternative value is one the
//!   option's help lists;
//! - or, for the few listed in [`SPECIAL`], run shrunk (a million fuzz
//!   inputs take most of an hour), or not run with the reason given
//!   (installing packages, a real cluster), or run by the named test.
//!
//! An inline mention of a bare subcommand (`morphosys sweep`) is checked
//! to exist. A command line the test cannot classify fails it, and so does
//! an entry of [`SPECIAL`] that no document shows any more.

mod common;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One command a document shows.
#[derive(Debug)]
struct DocCommand {
    line: usize,
    text: String,
    /// From an inline code span (prose), not a ```sh block.
    inline: bool,
}

/// What to do with a command other than running it as written.
enum Special {
    /// Run this instead, for the reason given.
    RunAs(&'static str, &'static str),
    /// Not run, for the reason given.
    Skip(&'static str),
    /// Run by this test (file, function), which must exist.
    CoveredBy(&'static str, &'static str),
}

/// (document, command as written, what to do).
const SPECIAL: &[(&str, &str, Special)] = &[
    (
        "docs/tracer.md",
        "morphosys regroup rings.nff",
        Special::RunAs(
            "morphosys regroup rings.nff --size 32",
            "the same estimate on a smaller frame (seconds, not a minute, in a debug build)",
        ),
    ),
    (
        "README.md",
        "morphosys tb cosim",
        Special::CoveredBy("cosim.rs", "the_verilog_rc_is_the_rust_rc_cycle_for_cycle"),
    ),
    (
        "docs/silicon.md",
        "morphosys tb cosim",
        Special::CoveredBy("cosim.rs", "the_verilog_rc_is_the_rust_rc_cycle_for_cycle"),
    ),
    (
        "docs/silicon.md",
        "morphosys tb cosim --bench",
        Special::Skip("a measurement of Verilator against this model (minutes of Verilator builds); the co-simulation it builds runs in cosim.rs"),
    ),
    (
        "docs/performance.md",
        "morphosys tb cosim --random 0 --array 0 --bench",
        Special::Skip("a measurement of Verilator against this model (minutes of Verilator builds); the co-simulation it builds runs in cosim.rs"),
    ),
    (
        "docs/performance.md",
        "morphosys bench --repeat 3",
        Special::RunAs("morphosys bench --repeat 1", "a measurement, not a check: run once"),
    ),
    (
        "docs/silicon.md",
        "morphosys cost --synthesize",
        Special::CoveredBy("cost.rs", "the_committed_synthesis_is_what_yosys_gives"),
    ),
    (
        "docs/testing.md",
        "cargo test --workspace -- --ignored",
        Special::Skip("the tests .ci/run runs after this one, where their tools are installed"),
    ),
    (
        "docs/usage.md",
        "cargo install --path tb",
        Special::Skip("installs into ~/.cargo/bin; the test puts the built binary on PATH instead"),
    ),
    (
        "docs/testing.md",
        "cargo test --workspace",
        Special::Skip("this is the command running this test (.ci/run runs it)"),
    ),
    (
        "README.md",
        "morphosys report --only headline",
        Special::CoveredBy("report.rs", "the_checked_sections_are_what_report_writes"),
    ),
    (
        "docs/results.md",
        "morphosys sweep scenes/default.toml scenes/spd/jacks-1.nff scenes/spd/tetra-1.nff --out-dir out",
        Special::RunAs(
            "morphosys sweep scenes/default.toml scenes/spd/jacks-1.nff scenes/spd/tetra-1.nff --out-dir out --size 16x16 --family-size 16x16 --max-size 2",
            "the charted sweep takes minutes; the same sweep at 16x16 and sizes 1-2",
        ),
    ),
    (
        "docs/performance.md",
        "morphosys bench --repeat 1 --sweep scenes/default.toml,scenes/spd/jacks-1.nff,scenes/spd/tetra-1.nff",
        Special::RunAs(
            "morphosys bench --repeat 1 --size 16x16 --sweep scenes/default.toml,scenes/spd/jacks-1.nff,scenes/spd/tetra-1.nff --sweep-size 16x16 --sweep-max-size 1",
            "the measured sweep takes minutes; the same sweep at 16x16 and size 1",
        ),
    ),
    (
        "README.md",
        "cargo run --release --bin morphosys -- render",
        Special::RunAs(
            "morphosys render",
            "the same binary and arguments; a release build inside the test run would take minutes",
        ),
    ),
    (
        "README.md",
        "cargo test --workspace",
        Special::Skip("this is the command running this test (.ci/run runs it)"),
    ),
    (
        "README.md",
        "cargo install --path tb",
        Special::Skip("installs into ~/.cargo/bin; the test puts the built binary on PATH instead"),
    ),
    (
        "docs/testing.md",
        "cargo test -p morphosys-tb --test stability -- --nocapture",
        Special::Skip("one of the test files `cargo test --workspace` runs (tb/tests/stability.rs)"),
    ),
    (
        "docs/performance.md",
        "cargo bench -p morphosys-tb",
        Special::Skip("a benchmark: speed is measured, never run as a test"),
    ),
    (
        "docs/testing.md",
        "morphosys fuzz --count 1000000 --seed 7",
        Special::RunAs(
            "morphosys fuzz --count 200 --seed 7",
            "a million inputs take most of an hour; the same seed, fewer inputs",
        ),
    ),
    (
        "docs/scenes.md",
        "morphosys fuzz --count 30000 --seed 7",
        Special::RunAs(
            "morphosys fuzz --count 200 --seed 7",
            "30,000 inputs take minutes; the same seed, fewer inputs",
        ),
    ),
    (
        "docs/cluster.md",
        "parallel --jobs 2 < PLAN/jobs.txt",
        Special::Skip("a synopsis (PLAN a plan's folder); the example below runs it on a real plan"),
    ),
    (
        "docs/cluster.md",
        "morphosys sweep scenes/default.toml scenes/spd/jacks-1.nff scenes/spd/tetra-1.nff --out-dir m1",
        Special::RunAs(
            "morphosys sweep scenes/default.toml scenes/spd/jacks-1.nff scenes/spd/tetra-1.nff --out-dir m1 --size 16x16 --family-size 16x16 --max-size 2",
            "the measured sweep takes minutes; the same sweep at 16x16 and sizes 1-2",
        ),
    ),
    (
        "docs/cluster.md",
        "docs/cluster/submit.sh PLAN --partition=short --time=30:00",
        Special::CoveredBy(
            "sweep_plan.rs",
            "planned_sweep_on_a_slurm_job_array_merges_to_the_in_process_sweep",
        ),
    ),
    (
        "docs/cluster.md",
        "sbatch --dependency=afterany:JOBID --wrap \"morphosys sweep --merge plan\"",
        Special::CoveredBy(
            "sweep_plan.rs",
            "planned_sweep_on_a_slurm_job_array_merges_to_the_in_process_sweep",
        ),
    ),
    (
        "docs/cluster.md",
        "cargo test",
        Special::Skip("the command running this test (.ci/run runs it)"),
    ),
    (
        "docs/performance.md",
        "morphosys bench --repeat 7 --json docs/results/bench.json",
        Special::RunAs(
            "morphosys bench --repeat 1 --json bench.json",
            "a measurement, not a check: run once, into the scratch folder rather than over the committed results",
        ),
    ),
    (
        "docs/cluster.md",
        "apt-get install parallel",
        Special::Skip("installs a Debian package; .ci/run installs it"),
    ),
    (
        "docs/cluster.md",
        "sbatch --array=1-$(wc -l < plan/jobs.txt) docs/cluster/sweep-array.sbatch plan",
        Special::CoveredBy(
            "sweep_plan.rs",
            "planned_sweep_on_a_slurm_job_array_merges_to_the_in_process_sweep",
        ),
    ),
    (
        "docs/cluster.md",
        "docs/cluster/local-slurm.sh start /tmp/slurm && export SLURM_CONF=/tmp/slurm/slurm.conf",
        Special::CoveredBy(
            "sweep_plan.rs",
            "planned_sweep_on_a_slurm_job_array_merges_to_the_in_process_sweep",
        ),
    ),
    (
        "docs/cluster.md",
        "sinfo",
        Special::CoveredBy(
            "sweep_plan.rs",
            "planned_sweep_on_a_slurm_job_array_merges_to_the_in_process_sweep",
        ),
    ),
    (
        "docs/cluster.md",
        "docs/cluster/submit.sh plan",
        Special::CoveredBy(
            "sweep_plan.rs",
            "planned_sweep_on_a_slurm_job_array_merges_to_the_in_process_sweep",
        ),
    ),
    (
        "docs/cluster.md",
        "docs/cluster/local-slurm.sh stop /tmp/slurm",
        Special::CoveredBy(
            "sweep_plan.rs",
            "planned_sweep_on_a_slurm_job_array_merges_to_the_in_process_sweep",
        ),
    ),
];

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The commands of one Markdown document, in order.
fn commands(markdown: &str) -> Vec<DocCommand> {
    let mut out = Vec::new();
    let mut fence: Option<String> = None;
    // Prose outside code blocks, with the line each byte came from, so
    // that a code span broken over two lines is still one span.
    let mut prose = String::new();
    let mut prose_lines = Vec::new();
    for (i, line) in markdown.lines().enumerate() {
        let n = i + 1;
        let trimmed = line.trim_start();
        if let Some(lang) = trimmed.strip_prefix("```") {
            fence = match fence {
                Some(_) => None,
                None => Some(lang.trim().to_string()),
            };
            prose.push('\n');
            prose_lines.push(n);
            continue;
        }
        match fence.as_deref() {
            Some("sh") => {
                let text = strip_comment(line).trim().to_string();
                if !text.is_empty() {
                    out.push(DocCommand {
                        line: n,
                        text,
                        inline: false,
                    });
                }
            }
            Some(_) => {}
            None => {
                for _ in 0..line.len() + 1 {
                    prose_lines.push(n);
                }
                prose.push_str(line);
                prose.push('\n');
            }
        }
    }
    // Inline code spans (single backticks) of the prose.
    let bytes = prose.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] != b'`' {
            i += 1;
            continue;
        }
        let Some(len) = prose[i + 1..].find('`') else {
            break;
        };
        let span = &prose[i + 1..i + 1 + len];
        let text = span.replace('\n', " ").replace("\\|", "|");
        if text.starts_with("morphosys ") || text.starts_with("cargo ") {
            out.push(DocCommand {
                line: prose_lines[i],
                text: text.trim().to_string(),
                inline: true,
            });
        }
        i += len + 2;
    }
    out.sort_by_key(|c| c.line);
    out
}

/// A shell line without its trailing `# comment` (a `#` that starts a word).
fn strip_comment(line: &str) -> &str {
    if line.trim_start().starts_with('#') {
        return "";
    }
    let b = line.as_bytes();
    for i in 1..b.len() {
        if b[i] == b'#' && b[i - 1].is_ascii_whitespace() {
            return &line[..i];
        }
    }
    line
}

/// Whether a command is a synopsis rather than a command to type: a
/// placeholder (`SCENE`, `NAME.nff`, `A.png`, `WxH`), brackets,
/// alternatives `a|b` or an ellipsis.
fn is_synopsis(text: &str) -> bool {
    if text.contains('[') || text.contains("...") {
        return true;
    }
    text.split_whitespace().any(|token| {
        token == "WxH" || (token.contains('|') && token != "|") || has_placeholder(token)
    })
}

/// A run of capitals not joined to lower-case letters: `SCENE`,
/// `scenes/spd/NAME-1.nff`, `FW.s`, `REG=VALUE`.
fn has_placeholder(token: &str) -> bool {
    let b = token.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_uppercase() {
            let start = i;
            while i < b.len() && (b[i].is_ascii_uppercase() || b[i] == b'_') {
                i += 1;
            }
            let before = start == 0 || !b[start - 1].is_ascii_alphabetic();
            let after = i == b.len() || !b[i].is_ascii_alphanumeric();
            if before && after {
                return true;
            }
        } else {
            i += 1;
        }
    }
    false
}

/// `morphosys [SUB] --help`, cached per subcommand.
fn help(cache: &mut std::collections::HashMap<String, String>, sub: &str) -> String {
    cache
        .entry(sub.to_string())
        .or_insert_with(|| {
            let mut args: Vec<&str> = sub.split_whitespace().collect();
            args.push("--help");
            let (ok, stdout, stderr) = common::morphosys(&repo(), &args);
            assert!(ok, "morphosys {sub} --help failed: {stderr}");
            stdout
        })
        .clone()
}

/// Checks a synopsis against the subcommand's help: the subcommand exists,
/// every option is one it takes, every listed alternative value is in that
/// option's help.
fn check_synopsis(
    doc: &str,
    c: &DocCommand,
    cache: &mut std::collections::HashMap<String, String>,
) -> Result<(), String> {
    let tokens: Vec<String> = c
        .text
        .split_whitespace()
        .map(|t| t.trim_matches(|ch| ch == '[' || ch == ']').to_string())
        .collect();
    if tokens.len() < 2 {
        return Ok(());
    }
    let lists = |help: &str, name: &str| {
        help.lines()
            .any(|l| l.split_whitespace().next() == Some(name) && l.starts_with("  "))
    };
    let mut sub = tokens[1].clone();
    if !lists(&help(cache, ""), &sub) {
        return Err(format!(
            "{doc}:{}: no subcommand {sub:?}: {}",
            c.line, c.text
        ));
    }
    // A subcommand of the subcommand (`tb rc`).
    let mut first = 2;
    if let Some(next) = tokens.get(2) {
        let parent = help(cache, &sub);
        if parent.contains("Commands:") && lists(&parent, next) {
            sub = format!("{sub} {next}");
            first = 3;
        }
    }
    let text = help(cache, &sub);
    for (k, token) in tokens.iter().enumerate().skip(first) {
        if !token.starts_with('-') || token == "-" {
            continue;
        }
        let flag = token.split('=').next().unwrap();
        let paragraph = option_help(&text, flag).ok_or_else(|| {
            format!(
                "{doc}:{}: `morphosys {sub}` takes no option {flag} (`{}`)",
                c.line, c.text
            )
        })?;
        // `--json PATH`: the value is named as the help names it.
        if let Some(value) = tokens.get(k + 1) {
            let value = value.trim_end_matches("...");
            let named = paragraph
                .lines()
                .next()
                .and_then(|l| Some(&l[l.find('<')? + 1..l.find('>')?]));
            // A placeholder (`PATH`, `auto|N`) is the help's own; an
            // example path (`scenes/spd/NAME-1.nff`) has the help's
            // extension where the help names one (`FILE.nff`).
            let example_path = value.contains('.') || value.contains('/');
            let agrees = match named {
                Some(named) if example_path && !value.contains('|') => {
                    !named.contains('.') || named.rsplit('.').next() == value.rsplit('.').next()
                }
                named => named == Some(value),
            };
            let placeholder = is_synopsis(value) || value.contains('|');
            if !value.starts_with('-') && placeholder && !agrees {
                return Err(format!(
                    "{doc}:{}: {flag} {value}: `morphosys {sub} --help` names the value <{}>",
                    c.line,
                    named.unwrap_or("(none: a switch)")
                ));
            }
        }
        // `--traversal packet|paper`: each alternative is a value the help lists.
        if let Some(value) = tokens.get(k + 1) {
            if value.contains('|') && !value.starts_with('-') {
                for alt in value.split('|') {
                    if alt.chars().any(|ch| ch.is_ascii_uppercase()) {
                        continue; // a placeholder among the values (`auto|N`)
                    }
                    if !paragraph.contains(alt) {
                        return Err(format!(
                            "{doc}:{}: {flag} {alt}: not a value `morphosys {sub} --help` lists for {flag}:\n{paragraph}",
                            c.line
                        ));
                    }
                }
            }
        }
    }
    Ok(())
}

/// The help paragraph of one option (`--ways`, `-o`): its line and the
/// indented lines under it, up to the next option.
fn option_help(help: &str, flag: &str) -> Option<String> {
    let lines: Vec<&str> = help.lines().collect();
    let is_option_line = |l: &str| l.trim_start().starts_with('-');
    let names = |l: &str| -> Vec<String> {
        l.trim_start()
            .split([',', ' ', '='])
            .take_while(|w| w.is_empty() || w.starts_with('-') || w.starts_with('<'))
            .filter(|w| w.starts_with('-'))
            .map(str::to_string)
            .collect()
    };
    let start = lines
        .iter()
        .position(|l| is_option_line(l) && names(l).iter().any(|n| n == flag))?;
    let mut out = lines[start].to_string();
    for l in &lines[start + 1..] {
        if is_option_line(l) {
            break;
        }
        out.push('\n');
        out.push_str(l);
    }
    Some(out)
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

/// `bash -c TEXT` in `dir` with the binary under test first on PATH.
fn run_shell(dir: &Path, text: &str) -> (bool, String) {
    let bin = Path::new(env!("CARGO_BIN_EXE_morphosys")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let out = Command::new("bash")
        .args(["-c", &format!("set -eo pipefail\n{text}")])
        .current_dir(dir)
        .env("PATH", path)
        .output()
        .unwrap();
    (
        out.status.success(),
        format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ),
    )
}

/// The edit docs/tracer.md's worked example asks of a reader: in `fw.s`,
/// under `k_sphere:` after `; sqrt`, delete the first (`drop` = 1) or both
/// (2) five-line Newton-Raphson steps (mul, mul, sub, ldacc, msu).
fn drop_newton_steps(fw: &str, drop: usize) -> String {
    let lines: Vec<&str> = fw.lines().collect();
    let mnemonic = |l: &str| l.split_whitespace().next().unwrap_or("").to_string();
    let kernel = lines
        .iter()
        .position(|l| l.trim() == "k_sphere:")
        .expect("fw.s has no k_sphere: label");
    let sqrt = kernel
        + lines[kernel..]
            .iter()
            .position(|l| l.trim() == "; sqrt")
            .expect("k_sphere has no `; sqrt` comment");
    let step = ["mul", "mul", "sub", "ldacc", "msu"];
    let is_step =
        |at: usize| at + 5 <= lines.len() && (0..5).all(|k| mnemonic(lines[at + k]) == step[k]);
    let first = (sqrt..lines.len())
        .take_while(|&i| !lines[i].trim_end().ends_with(':') || i == sqrt)
        .find(|&i| is_step(i))
        .expect("no five-line Newton-Raphson step after `; sqrt`");
    assert!(
        is_step(first + 5),
        "the sqrt of k_sphere has one Newton-Raphson step, the document says two"
    );
    let mut out: Vec<&str> = Vec::new();
    out.extend(&lines[..first]);
    out.extend(&lines[first + 5 * drop..]);
    out.join("\n") + "\n"
}

/// Runs or checks every command of one document.
fn check_document(doc: &str) {
    let markdown = std::fs::read_to_string(repo().join(doc)).unwrap();
    let found = commands(&markdown);
    assert!(!found.is_empty(), "{doc}: no commands found");
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    copy_dir(&repo().join("scenes"), &dir.join("scenes"));
    copy_dir(&repo().join("firmware"), &dir.join("firmware"));
    let mut failures = Vec::new();
    let mut ran = 0;
    for c in &found {
        let special = SPECIAL
            .iter()
            .find(|(d, text, _)| *d == doc && *text == c.text);
        let text = match special {
            Some((_, _, Special::RunAs(instead, why))) => {
                eprintln!("{doc}:{}: `{}` run as `{instead}`: {why}", c.line, c.text);
                instead.to_string()
            }
            Some((_, _, Special::Skip(why))) => {
                eprintln!("{doc}:{}: `{}` not run: {why}", c.line, c.text);
                continue;
            }
            Some((_, _, Special::CoveredBy(file, function))) => {
                let source = std::fs::read_to_string(repo().join("tb/tests").join(file)).unwrap();
                assert!(
                    source.contains(&format!("fn {function}()")),
                    "{doc}:{}: `{}` is said to be run by {file}::{function}, which does not exist",
                    c.line,
                    c.text
                );
                continue;
            }
            None => c.text.clone(),
        };
        if !text.starts_with("morphosys") {
            // A tool the reader runs beside ours (GNU parallel): run it if
            // it is installed (CI installs it).
            let tool = text.split_whitespace().next().unwrap();
            if tool == "parallel" && which(tool).is_none() {
                failures.push(format!(
                    "{doc}:{}: GNU parallel is not installed (apt-get install parallel): \
                     the rest of the document cannot run",
                    c.line
                ));
                break;
            }
            if tool != "parallel" {
                failures.push(format!(
                    "{doc}:{}: `{}` is not a morphosys command: run it here or list it in SPECIAL",
                    c.line, c.text
                ));
                continue;
            }
        } else if is_synopsis(&text) || (c.inline && text.split_whitespace().count() == 2) {
            continue; // checked by synopses_name_what_the_help_names
        }
        if text == "morphosys render --firmware nr1.s --json nr1.json" {
            let fw = std::fs::read_to_string(dir.join("fw.s")).expect("fw.s written earlier");
            std::fs::write(dir.join("nr1.s"), drop_newton_steps(&fw, 1)).unwrap();
            std::fs::write(dir.join("nr0.s"), drop_newton_steps(&fw, 2)).unwrap();
        }
        let start = std::time::Instant::now();
        let (ok, output) = run_shell(dir, &text);
        ran += 1;
        eprintln!(
            "{doc}:{}: {:.1} s: {text}",
            c.line,
            start.elapsed().as_secs_f64()
        );
        if !ok {
            failures.push(format!("{doc}:{}: `{text}` failed:\n{output}", c.line));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of the commands of {doc} fail as written:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
    eprintln!("{doc}: {} commands found, {ran} run", found.len());
}

fn which(tool: &str) -> Option<PathBuf> {
    std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|p| p.join(tool))
            .find(|p| p.is_file())
    })
}

/// Every synopsis and every mention of a subcommand in every document,
/// against `--help` (fast: nothing is rendered).
#[test]
fn synopses_name_what_the_help_names() {
    let mut cache = std::collections::HashMap::new();
    let mut failures = Vec::new();
    let mut checked = 0;
    for doc in DOCUMENTS {
        let markdown = std::fs::read_to_string(repo().join(doc)).unwrap();
        for c in commands(&markdown) {
            if !c.text.starts_with("morphosys ") {
                continue;
            }
            if is_synopsis(&c.text) {
                checked += 1;
                if let Err(e) = check_synopsis(doc, &c, &mut cache) {
                    failures.push(e);
                }
            } else if c.inline && c.text.split_whitespace().count() == 2 {
                // A mention of a subcommand: it exists.
                checked += 1;
                let sub = c.text.split_whitespace().nth(1).unwrap();
                let (ok, _, stderr) = common::morphosys(&repo(), &[sub, "--help"]);
                if !ok {
                    failures.push(format!("{doc}:{}: `{}`: {stderr}", c.line, c.text));
                }
            }
        }
    }
    assert!(checked > 40, "only {checked} synopses found");
    assert!(
        failures.is_empty(),
        "{} synopses disagree with --help:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

const DOCUMENTS: &[&str] = &[
    "README.md",
    "docs/usage.md",
    "docs/results.md",
    "docs/isa.md",
    "docs/scenes.md",
    "docs/tracer.md",
    "docs/waveforms.md",
    "docs/testing.md",
    "docs/cluster.md",
    "docs/performance.md",
    "docs/silicon.md",
    "docs/adding-a-primitive.md",
];

#[test]
fn adding_a_primitive_commands_run_as_written() {
    check_document("docs/adding-a-primitive.md");
}

#[test]
fn readme_commands_run_as_written() {
    check_document("README.md");
}

#[test]
fn isa_commands_run_as_written() {
    check_document("docs/isa.md");
}

#[test]
fn scenes_commands_run_as_written() {
    check_document("docs/scenes.md");
}

#[test]
fn tracer_commands_run_as_written() {
    check_document("docs/tracer.md");
}

#[test]
#[ignore = "needs GNU parallel (Debian package parallel); .ci/run installs it and runs the ignored tests"]
fn cluster_commands_run_as_written() {
    check_document("docs/cluster.md");
}

#[test]
fn performance_commands_run_as_written() {
    check_document("docs/performance.md");
}

#[test]
fn usage_commands_run_as_written() {
    check_document("docs/usage.md");
}

#[test]
fn results_commands_run_as_written() {
    check_document("docs/results.md");
}

#[test]
fn waveforms_commands_run_as_written() {
    check_document("docs/waveforms.md");
}

#[test]
fn testing_commands_run_as_written() {
    check_document("docs/testing.md");
}

#[test]
fn silicon_commands_run_as_written() {
    check_document("docs/silicon.md");
}

/// Every document is checked, and every exception still names a command a
/// document shows.
#[test]
fn every_document_is_checked_and_every_exception_is_used() {
    let mut docs: Vec<String> = vec!["README.md".into()];
    for entry in std::fs::read_dir(repo().join("docs")).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name.ends_with(".md") {
            docs.push(format!("docs/{name}"));
        }
    }
    let checked: HashSet<&str> = DOCUMENTS.iter().copied().collect();
    for doc in &docs {
        assert!(checked.contains(doc.as_str()), "{doc} has no test here");
    }
    for (doc, text, _) in SPECIAL {
        let markdown = std::fs::read_to_string(repo().join(doc)).unwrap();
        assert!(
            commands(&markdown).iter().any(|c| c.text == *text),
            "SPECIAL lists `{text}` for {doc}, which no longer shows it"
        );
    }
}

/// The extractor and classifier themselves, on a document made up here.
#[test]
fn commands_are_read_out_of_markdown() {
    let md = "Run `morphosys render --size\n64x64` or `morphosys render SCENE [--ways N]`.\n\
              ```sh\nmorphosys spd balls | head   # first lines\n# a comment\n```\n\
              ```\nmorphosys not-a-command\n```\n| `morphosys render --traversal packet\\|paper` |\n";
    let found = commands(md);
    let texts: Vec<&str> = found.iter().map(|c| c.text.as_str()).collect();
    assert_eq!(
        texts,
        [
            "morphosys render --size 64x64",
            "morphosys render SCENE [--ways N]",
            "morphosys spd balls | head",
            "morphosys render --traversal packet|paper",
        ]
    );
    assert_eq!(found[0].line, 1);
    assert_eq!(found[2].line, 4);
    assert!(!found[2].inline);
    assert_eq!(
        found
            .iter()
            .map(|c| is_synopsis(&c.text))
            .collect::<Vec<_>>(),
        [false, true, false, true]
    );
    for (token, placeholder) in [
        ("SCENE", true),
        ("scenes/spd/NAME-1.nff", true),
        ("FW.s", true),
        ("REG=VALUE", true),
        ("default-chip.png", false),
        ("--size", false),
        ("256x256", false),
        ("Q5.10", false),
    ] {
        assert_eq!(has_placeholder(token), placeholder, "{token}");
    }
    let mut cache = std::collections::HashMap::new();
    let bad = DocCommand {
        line: 1,
        text: "morphosys render [--no-such-option N]".into(),
        inline: true,
    };
    assert!(check_synopsis("x.md", &bad, &mut cache).is_err());
    let bad_value = DocCommand {
        line: 1,
        text: "morphosys render [--traversal packet|nonsense]".into(),
        inline: true,
    };
    assert!(check_synopsis("x.md", &bad_value, &mut cache).is_err());
    let good = DocCommand {
        line: 1,
        text: "morphosys render [SCENE] [--traversal packet|paper]".into(),
        inline: true,
    };
    check_synopsis("x.md", &good, &mut cache).unwrap();
}
