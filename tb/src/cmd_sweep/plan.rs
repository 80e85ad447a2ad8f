//! `sweep --plan` (one `morphosys render` job line per render, and
//! `sweep.toml`, what was asked) and `sweep --merge` (the table and charts
//! from the plan's renders).

use anyhow::{Context as _, Result};
use rtl::Timing;
use std::path::{Path, PathBuf};

use super::*;

/// `sweep.toml`: what a plan asked, enough for `--merge` to rebuild its
/// points.
#[derive(serde::Serialize, serde::Deserialize)]
pub(super) struct Plan {
    /// The morphosys that wrote the plan (its jobs run it), and the plan's
    /// folder when written (its jobs' paths; the folder may move before
    /// the merge).
    program: PathBuf,
    dir: PathBuf,
    /// Image size of the knob sweep and of the size sweep.
    size: String,
    family_size: String,
    /// The knob sweep (`false`: `--only sizes`) and `--only broadcast`.
    knobs: bool,
    broadcast_only: bool,
    /// Timing files, copied into the plan's folder (paths relative to it),
    /// and their series' names (a plan without them: the copies' stems).
    timing: Vec<PathBuf>,
    #[serde(default)]
    timing_names: Vec<String>,
    /// Every scene, copied or generated into the plan's `scenes/`.
    scene: Vec<SceneRef>,
}

pub(super) const PLAN_FILE: &str = "sweep.toml";
pub(super) const JOBS_FILE: &str = "jobs.txt";
/// The M1 chip's timing (instruction issue), the broadcast knob's.
pub(super) const M1_TIMING_FILE: &str = "m1-issue.toml";

/// A file name made of `A-Z a-z 0-9 . _ + -` only (others become `_`):
/// the plan's own copies, named in its job lines.
pub(super) fn plain_file_name(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._+-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// A path that goes into a job line: refused when it is not UTF-8 or holds
/// a control character (a newline would end the job's line there and run
/// the rest as a command of its own).
pub(super) fn job_line_path(what: &str, p: &Path) -> Result<String> {
    let Some(text) = p.to_str() else {
        anyhow::bail!(
            "{what} {}: not UTF-8; a plan's job lines name it",
            p.display()
        );
    };
    if let Some(c) = text.chars().find(|c| c.is_control()) {
        anyhow::bail!(
            "{what} {}: holds the control character U+{:04X}; a plan's job lines name it",
            text.escape_debug(),
            c as u32
        );
    }
    Ok(text.to_string())
}

/// A word of a shell command line, quoted when it needs to be.
pub(super) fn shell_word(w: &str) -> String {
    if !w.is_empty()
        && w.chars()
            .all(|c| c.is_ascii_alphanumeric() || "_./=:,+-@%".contains(c))
    {
        w.to_string()
    } else {
        format!("'{}'", w.replace('\'', r"'\''"))
    }
}

/// The arguments of the `morphosys render` that measures `c` on `scene`,
/// writing `points/NAME.{png,json}` under `dir`.
pub(super) fn render_argv(dir: &Path, scene: &Path, c: &Config, name: &str) -> Vec<String> {
    let mut v: Vec<String> = vec!["render".into(), scene.display().to_string()];
    v.extend(crate::render_options::argv(&c.opt, &c.nm));
    let mut arg = |k: &str, val: String| {
        v.push(k.into());
        v.push(val);
    };
    match (c.timing_file, c.timing_name.as_str()) {
        (Some(i), t) => arg(
            "--timing",
            dir.join("timing")
                .join(timing_copy_name(i, t))
                .display()
                .to_string(),
        ),
        (None, "M1 issue") => arg("--timing", dir.join(M1_TIMING_FILE).display().to_string()),
        (None, _) => {}
    }
    let points = dir.join("points");
    arg(
        "--out",
        points.join(format!("{name}.png")).display().to_string(),
    );
    arg(
        "--json",
        points.join(format!("{name}.json")).display().to_string(),
    );
    v.push("--skip-done".into());
    v
}

pub(super) fn write_plan(
    dir: &Path,
    a: &SweepArgs,
    files: &[(String, Timing)],
    scenes: Vec<(SceneRef, firmware::scene::Scene)>,
    pts: &[Point],
    jobs: &[Job],
) -> Result<()> {
    if pts.is_empty() {
        anyhow::bail!("--plan {}: the sweep asked has no points", dir.display());
    }
    // Checked before anything is made: the folder and this program go into
    // every job line.
    let abs = std::path::absolute(dir).with_context(|| format!("--plan {}", dir.display()))?;
    job_line_path("--plan", &abs)?;
    let program = std::env::current_exe().context("the path of this morphosys")?;
    job_line_path("this morphosys at", &program)?;
    for sub in ["points", "scenes", "timing"] {
        std::fs::create_dir_all(dir.join(sub))
            .with_context(|| format!("--plan {}: cannot create {sub}/ in it", dir.display()))?;
    }
    let dir = &std::fs::canonicalize(dir).with_context(|| format!("--plan {}", dir.display()))?;
    job_line_path("--plan", dir)?;
    // The plan's own copies of the scenes and timing files: its jobs give
    // the same results whatever happens to the originals.
    let mut refs = Vec::new();
    for (i, (mut sc, scene)) in scenes.into_iter().enumerate() {
        let fname = sc
            .file
            .file_name()
            .map_or_else(|| "scene".into(), |f| plain_file_name(&f.to_string_lossy()));
        let to = dir.join("scenes").join(format!("{i:03}-{fname}"));
        let bytes = match &sc.family {
            Some(f) => firmware::scene::spd::generate(f, sc.size.unwrap_or(1))
                .map_err(|e| anyhow::anyhow!(e))?
                .into_bytes(),
            // The default scene, built in when there is no file of it here.
            None if sc.file == crate::cmd_scene::default_scene() && !sc.file.is_file() => {
                crate::cmd_scene::DEFAULT_SCENE.as_bytes().to_vec()
            }
            None => firmware::input::read(&sc.file)
                .with_context(|| format!("{}: cannot read the scene", sc.file.display()))?,
        };
        drop(scene);
        crate::output::write(&to, &bytes)?;
        sc.file = to;
        refs.push(sc);
    }
    let mut timing = Vec::new();
    for (i, ((name, _), from)) in files.iter().zip(&a.timing).enumerate() {
        let rel = Path::new("timing").join(timing_copy_name(i, name));
        let bytes = firmware::input::read(from)
            .with_context(|| format!("{}: cannot read the timing file", from.display()))?;
        crate::output::write(&dir.join(&rel), &bytes)?;
        timing.push(rel);
    }
    if pts.iter().any(|p| p.cfg.timing_name == "M1 issue") {
        let m1 = pts
            .iter()
            .find(|p| p.cfg.timing_name == "M1 issue")
            .map(|p| p.cfg.timing);
        let t = crate::timing::to_toml(&m1.unwrap_or_default());
        crate::output::write(&dir.join(M1_TIMING_FILE), t.as_bytes())?;
    }
    let mut text = String::new();
    for job in jobs {
        let p = &pts[job.point];
        let argv = render_argv(dir, &refs[p.scene].file, &p.cfg, &job.name);
        text.push_str(&shell_word(&program.display().to_string()));
        for w in &argv {
            text.push(' ');
            text.push_str(&shell_word(w));
        }
        text.push('\n');
    }
    let plan = Plan {
        program,
        dir: dir.clone(),
        size: format!("{}x{}", a.size.0, a.size.1),
        family_size: format!("{}x{}", a.family_size.0, a.family_size.1),
        knobs: a.knobs,
        broadcast_only: a.broadcast_only,
        timing,
        timing_names: files.iter().map(|(n, _)| n.clone()).collect(),
        scene: refs,
    };
    let toml_text = format!(
        "# A sweep plan written by `morphosys sweep --plan`: what was asked.\n\
         # Run the jobs ({JOBS_FILE}), then `morphosys sweep --merge {}`.\n{}",
        dir.display(),
        toml::to_string(&plan).context("sweep.toml")?
    );
    crate::output::write(&dir.join(PLAN_FILE), toml_text.as_bytes())?;
    crate::output::write(&dir.join(JOBS_FILE), text.as_bytes())?;
    println!(
        "wrote {} ({} renders for {} points) and {}",
        dir.join(JOBS_FILE).display(),
        jobs.len(),
        pts.len(),
        dir.join(PLAN_FILE).display()
    );
    println!(
        "run them, for example:  parallel --jobs 2 < {}",
        shell_word(&dir.join(JOBS_FILE).display().to_string())
    );
    println!(
        "then:                   morphosys sweep --merge {}",
        shell_word(&dir.display().to_string())
    );
    Ok(())
}

/// `sweep --merge DIR`: the table and charts of a plan from its renders'
/// JSON, into `out_dir`; points whose render is missing, failed or was made
/// with other arguments are named and left out.
pub fn merge(dir: &Path, out_dir: &Path) -> Result<()> {
    let plan_path = dir.join(PLAN_FILE);
    let text = firmware::input::read_to_string(&plan_path).with_context(|| {
        format!(
            "--merge {}: no plan there (cannot read {PLAN_FILE})",
            dir.display()
        )
    })?;
    let plan: Plan = toml::from_str(&text)
        .map_err(|e| crate::timing::toml_error(&e, &text, &plan_path.display().to_string()))?;
    let size = |s: &str| {
        crate::cli::parse_size(s)
            .map_err(|e| anyhow::anyhow!("{}: size {s}: {e}", plan_path.display()))
    };
    // The jobs' arguments name the plan's folder as it was when planned.
    let pdir = &plan.dir;
    let tfiles: Vec<PathBuf> = plan.timing.iter().map(|t| dir.join(t)).collect();
    let mut files = timing_files(&tfiles)?;
    if plan.timing_names.len() == files.len() {
        for ((name, _), n) in files.iter_mut().zip(&plan.timing_names) {
            name.clone_from(n);
        }
    }
    let cfgs = if plan.knobs {
        asked_configs(size(&plan.size)?, plan.broadcast_only, &files)
    } else {
        vec![]
    };
    let (pts, jobs) = points(&plan.scene, &cfgs, size(&plan.family_size)?);
    // The plan's copies of its scenes, read where the folder is now: what
    // its renders read (their content digests must agree).
    let mut scenes = Vec::new();
    for sc in &plan.scene {
        let name = sc.file.file_name().unwrap_or_default();
        let local = dir.join("scenes").join(name);
        let scene = firmware::scene::Scene::load(&local)
            .with_context(|| format!("--merge {}: the plan's scene copy", dir.display()))?;
        scenes.push(scene);
    }
    let mut measured: Vec<Option<serde_json::Value>> = Vec::new();
    let mut missing = Vec::new();
    for job in &jobs {
        let p = &pts[job.point];
        let argv = render_argv(pdir, &plan.scene[p.scene].file, &p.cfg, &job.name);
        let json = dir.join("points").join(format!("{}.json", job.name));
        let inputs = crate::inputs::inputs(&scenes[p.scene], &p.cfg.timing, None);
        let j = match crate::render::render_json(&json, &argv, &inputs) {
            Ok(j) => Some(j),
            Err(why) => {
                missing.push(format!("{} ({why})", job.name));
                None
            }
        };
        measured.push(j);
    }
    let rows: Vec<Row> = pts
        .iter()
        .filter_map(|p| {
            measured[p.job]
                .as_ref()
                .map(|j| point_row(&plan.scene, p, j))
        })
        .collect();
    if !missing.is_empty() {
        eprintln!(
            "{} of {} renders left out (no complete {}/points/NAME.json made with the plan's arguments): {}",
            missing.len(),
            jobs.len(),
            dir.display(),
            missing.join(", ")
        );
    }
    if rows.is_empty() {
        anyhow::bail!(
            "--merge {}: no render of the plan is complete",
            dir.display()
        );
    }
    std::fs::create_dir_all(out_dir)
        .with_context(|| format!("cannot create {}", out_dir.display()))?;
    println!(
        "merged {} of {} points ({} of {} renders)",
        rows.len(),
        pts.len(),
        jobs.len() - missing.len(),
        jobs.len()
    );
    write_results(&rows, out_dir)
}
