//! The scene subcommands: `morphosys reference`, `morphosys compile` and
//! `morphosys compare`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use firmware::bsp::{BspParams, SplitRule};
use firmware::scene::Scene;
use firmware::scene_image::{compile, CompileOptions, NodeFormat};
use serde_json::json;

use crate::metrics;
use crate::reference::{render, Image, Options};

/// The default scene: `scenes/default.toml` under the current directory,
/// else beside this crate in the source tree.
pub fn default_scene() -> PathBuf {
    PathBuf::from("scenes/default.toml")
}

/// The default scene, built into the binary: `morphosys render` works from
/// any folder (a `scenes/default.toml` in the current folder is used
/// instead, so an edited copy wins).
pub(crate) const DEFAULT_SCENE: &str = include_str!("../../scenes/default.toml");

/// Load a scene (or the default one), errors as `file:line:col: ...`.
pub fn load_scene(path: Option<&Path>) -> Result<Scene> {
    let scene = match path {
        Some(p) => Scene::load(p)?,
        None if default_scene().is_file() => Scene::load(&default_scene())?,
        None => firmware::scene::native::parse(DEFAULT_SCENE, "scenes/default.toml")?,
    };
    for w in &scene.warnings {
        eprintln!("{w}");
    }
    Ok(scene)
}

/// Encode 8-bit RGB as PNG.
pub(crate) fn png_bytes(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(rgb, width, height, image::ExtendedColorType::Rgb8)
        .context("cannot encode PNG")?;
    Ok(out)
}

/// Read a PNG (any colour type) as 8-bit RGB.
pub(crate) fn read_png(path: &Path) -> Result<(u32, u32, Vec<u8>)> {
    let img = image::ImageReader::open(path)
        .with_context(|| format!("cannot open {}", path.display()))?
        .with_guessed_format()
        .with_context(|| format!("cannot read {}", path.display()))?
        .decode()
        .with_context(|| format!("{}: not a readable image", path.display()))?
        .to_rgb8();
    Ok((img.width(), img.height(), img.into_raw()))
}

/// Hit map file: `MSHITS1\n<w> <h>\n` then one little-endian u32 per
/// pixel (object index, 0xFFFFFFFF for none).
pub(crate) fn hits_bytes(img: &Image) -> Vec<u8> {
    hit_map_bytes(img.width, img.height, &img.hits)
}

/// A hit map: `MSHITS1`, the size, then the object hit by each pixel's eye
/// ray (u32, little-endian, row by row; `u32::MAX` for none).
pub(crate) fn hit_map_bytes(width: u32, height: u32, hits: &[u32]) -> Vec<u8> {
    let mut out = format!("MSHITS1\n{width} {height}\n").into_bytes();
    for h in hits {
        out.extend_from_slice(&h.to_le_bytes());
    }
    out
}

pub(crate) fn read_hits(path: &Path) -> Result<(u32, u32, Vec<u32>)> {
    let bytes =
        firmware::input::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    let bad = || {
        anyhow::anyhow!(
            "{}: not a hit map (expected 'MSHITS1', size, u32 per pixel)",
            path.display()
        )
    };
    let mut lines = bytes.splitn(3, |&b| b == b'\n');
    if lines.next() != Some(b"MSHITS1") {
        return Err(bad());
    }
    let size = std::str::from_utf8(lines.next().ok_or_else(bad)?).map_err(|_| bad())?;
    let (w, h) = size.split_once(' ').ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    let data = lines.next().ok_or_else(bad)?;
    if data.len() != w as usize * h as usize * 4 {
        return Err(bad());
    }
    Ok((
        w,
        h,
        data.chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
    ))
}

/// Arguments of `morphosys reference`.
#[derive(clap::Args, Debug)]
pub struct ReferenceArgs {
    /// Scene file (.nff or .toml); default scenes/default.toml.
    pub scene: Option<PathBuf>,
    /// Image size WIDTHxHEIGHT, each side 1..=4096 (default: the scene's resolution).
    #[arg(long, value_name = "WxH", value_parser = crate::cli::parse_size)]
    pub size: Option<(u32, u32)>,
    /// Maximum ray depth 1..=8; the eye ray is depth 1 (default 2, the
    /// paper's recursion level, as `render` and `sweep`, so their images
    /// compare as they are; `--spd-stats`: 5, the SPD's).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=firmware::tracer::MAX_RAY_DEPTH as i64))]
    pub depth: Option<u32>,
    /// Write the image here (default: <scene>-reference.png).
    #[arg(long, value_name = "PNG")]
    pub out: Option<PathBuf>,
    /// Write ray counts and timing as JSON here.
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Write the per-pixel hit map (which object each eye ray hit) here.
    #[arg(long, value_name = "PATH")]
    pub hits: Option<PathBuf>,
    /// Count rays as the SPD prescribes: 512x512, rays through pixel
    /// corners (513x513 eye rays), depth 5.
    #[arg(long)]
    pub spd_stats: bool,
}

/// `morphosys reference`: render a scene with the float reference.
pub fn reference(a: ReferenceArgs) -> Result<()> {
    let scene = load_scene(a.scene.as_deref())?;
    let (width, height, max_depth, corners) = if a.spd_stats {
        if a.size.is_some_and(|s| s != (512, 512)) || a.depth.is_some_and(|d| d != 5) {
            bail!("--spd-stats renders as the SPD prescribes (512x512, depth 5): drop --size and --depth");
        }
        (512, 512, 5, true)
    } else {
        let (w, h) = match a.size {
            Some(s) => s,
            None => {
                let (w, h) = scene.camera.resolution;
                crate::cli::check_size(w.into(), h.into()).map_err(|e| {
                    anyhow::anyhow!("{}: the scene's resolution {e}; give --size", scene.source)
                })?
            }
        };
        (w, h, a.depth.unwrap_or(2), false)
    };
    let cap = firmware::tracer::MAX_RAY_DEPTH;
    if max_depth == 0 || max_depth > cap {
        bail!("--depth {max_depth}: must be 1..={cap} (the eye ray is depth 1; the chip's limit, so reference and chip images always compare)");
    }
    let out = a.out.clone().or_else(|| {
        (!a.spd_stats).then(|| {
            let stem = Path::new(&scene.source)
                .file_stem()
                .map_or("scene".into(), |s| s.to_string_lossy().to_string());
            PathBuf::from(format!("{stem}-reference.png"))
        })
    });
    // Every output checked before the image is rendered.
    let mut files = crate::output::Files::new();
    files.input(&a.scene.clone().unwrap_or_else(default_scene), "SCENE");
    for (p, what) in [(&out, "--out"), (&a.json, "--json"), (&a.hits, "--hits")] {
        if let Some(p) = p {
            files.output(p, what);
        }
    }
    files.check()?;
    let t0 = Instant::now();
    let img = render(
        &scene,
        &Options {
            width,
            height,
            max_depth,
            corners,
            progress: true,
        },
    );
    let secs = t0.elapsed().as_secs_f64();
    let s = img.stats;
    crate::report!(
        "{}: {width}x{height}, depth {max_depth}{}, {:.2} s: {} eye rays ({} hit), {} reflection, {} refraction, {} shadow",
        scene.source,
        if corners { ", rays through pixel corners" } else { "" },
        secs,
        s.eye_rays,
        s.eye_hit_rays,
        s.reflect_rays,
        s.refract_rays,
        s.shadow_rays
    );
    if let Some(out) = &out {
        crate::output::write(out, &png_bytes(img.width, img.height, &img.to_rgb8())?)?;
        crate::note!("wrote {}", out.display());
    }
    if let Some(path) = &a.hits {
        crate::output::write(path, &hits_bytes(&img))?;
        crate::note!("wrote {}", path.display());
    }
    if let Some(path) = &a.json {
        let v = json!({
            "scene": scene.source,
            "width": width,
            "height": height,
            "depth": max_depth,
            "corners": corners,
            "seconds": secs,
            "eye_rays": s.eye_rays,
            "eye_hit_rays": s.eye_hit_rays,
            "reflect_rays": s.reflect_rays,
            "refract_rays": s.refract_rays,
            "shadow_rays": s.shadow_rays,
            "image": out.as_ref().map(|p| p.display().to_string()),
        });
        crate::output::write(path, (serde_json::to_string_pretty(&v)? + "\n").as_bytes())?;
    }
    Ok(())
}

/// Arguments of `morphosys compile`.
#[derive(clap::Args, Debug)]
pub struct CompileArgs {
    /// Scene file (.nff or .toml); default scenes/default.toml.
    pub scene: Option<PathBuf>,
    /// Write the report as JSON here.
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Write the memory image (16-bit little-endian words) here.
    #[arg(long, value_name = "FILE.img")]
    pub out: Option<PathBuf>,
    /// BSP split rule: median (the paper's spatial median, axes in turn)
    /// or sah (surface area heuristic); `--sah` is short for `--split sah`.
    #[arg(long, value_name = "median|sah", default_value = "median", value_parser = ["median", "sah"])]
    pub split: String,
    #[arg(long, hide = true)]
    pub sah: bool,
    /// Maximum BSP depth (1..=32).
    #[arg(long, value_name = "N", default_value_t = 15, value_parser = clap::value_parser!(u32).range(1..=firmware::scene_image::MAX_BSP_DEPTH as i64))]
    pub max_depth: u32,
    /// Maximum objects per BSP leaf.
    #[arg(long, value_name = "N", default_value_t = 5, value_parser = crate::cli::parse_count::<usize>)]
    pub max_leaf: usize,
    /// How BSP nodes name their objects: fig5 (the paper's bit
    /// vectors) or compact (index lists), as `render --layout`
    /// (default: the smaller).
    #[arg(long, value_name = "fig5|compact")]
    pub layout: Option<firmware::tracer::NodeLayout>,
}

/// `morphosys compile`: the fixed-point scene image and its report.
pub fn compile_cmd(a: CompileArgs) -> Result<()> {
    let sah = a.sah || a.split == "sah";
    let layout = a.layout.map(|l| match l {
        firmware::tracer::NodeLayout::Compact => NodeFormat::IndexLists,
        firmware::tracer::NodeLayout::Fig5 => NodeFormat::BitVectors,
    });
    let mut files = crate::output::Files::new();
    files.input(&a.scene.clone().unwrap_or_else(default_scene), "SCENE");
    for (p, what) in [(&a.out, "--out"), (&a.json, "--json")] {
        if let Some(p) = p {
            files.output(p, what);
        }
    }
    files.check()?;
    let scene = load_scene(a.scene.as_deref())?;
    let opt = CompileOptions {
        bsp: BspParams {
            max_depth: a.max_depth,
            max_leaf: a.max_leaf,
            rule: if sah {
                SplitRule::Sah
            } else {
                SplitRule::Median
            },
            snap: 0.0,
        },
        layout,
        ..CompileOptions::default()
    };
    let img = compile(&scene, &opt)?;
    crate::report!("{}", img.report.text().trim_end());
    if let Some(path) = &a.out {
        crate::output::write(path, &img.to_le_bytes())?;
        crate::report!(
            "wrote {} ({} words, little-endian)",
            path.display(),
            img.words.len()
        );
    }
    if let Some(path) = &a.json {
        crate::output::write(
            path,
            (serde_json::to_string_pretty(&img.report)? + "\n").as_bytes(),
        )?;
    }
    Ok(())
}

/// `morphosys compare`: PSNR, share of pixels off, and hit agreement.
pub fn compare(
    a: &Path,
    b: &Path,
    threshold: u8,
    hits: Option<(PathBuf, PathBuf)>,
    json_out: Option<PathBuf>,
) -> Result<()> {
    if let Some(j) = &json_out {
        let mut files = crate::output::Files::new();
        files.input(a, "A").input(b, "B");
        if let Some((ha, hb)) = &hits {
            files.input(ha, "HITS_A").input(hb, "HITS_B");
        }
        files.output(j, "--json").check()?;
    }
    let (wa, ha, pa) = read_png(a)?;
    let (wb, hb, pb) = read_png(b)?;
    if (wa, ha) != (wb, hb) {
        bail!(
            "{} is {wa}x{ha} but {} is {wb}x{hb}",
            a.display(),
            b.display()
        );
    }
    let psnr = metrics::psnr(&pa, &pb);
    let off = metrics::share_off(&pa, &pb, threshold);
    println!(
        "PSNR {} dB; {:.3}% of pixels off by more than {threshold}/255",
        if psnr.is_infinite() {
            "inf (identical)".to_string()
        } else {
            format!("{psnr:.2}")
        },
        off * 100.0
    );
    let mut agreement = None;
    if let Some((x, y)) = hits {
        let (w1, h1, m1) = read_hits(&x)?;
        let (w2, h2, m2) = read_hits(&y)?;
        if (w1, h1) != (w2, h2) || (w1, h1) != (wa, ha) {
            bail!(
                "hit maps {} ({w1}x{h1}) and {} ({w2}x{h2}) must match the images ({wa}x{ha})",
                x.display(),
                y.display()
            );
        }
        let h = metrics::hit_agreement(&m1, &m2);
        println!("hit agreement {:.3}%", h * 100.0);
        agreement = Some(h);
    }
    if let Some(path) = json_out {
        let v = json!({
            "a": a.display().to_string(),
            "b": b.display().to_string(),
            "width": wa,
            "height": ha,
            "psnr_db": if psnr.is_infinite() { None } else { Some(psnr) },
            "threshold": threshold,
            "share_off": off,
            "hit_agreement": agreement,
        });
        crate::output::write(&path, (serde_json::to_string_pretty(&v)? + "\n").as_bytes())?;
    }
    Ok(())
}

/// `morphosys compare` arguments.
#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    pub a: PathBuf,
    pub b: PathBuf,
    /// A pixel is "off" when a channel differs by more than this.
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub threshold: u8,
    /// Hit maps of A and B (from `reference --hits`).
    #[arg(long, num_args = 2, value_names = ["HITS_A", "HITS_B"])]
    pub hits: Option<Vec<PathBuf>>,
    /// Write the figures as JSON here.
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
}

/// `morphosys compare`.
pub fn compare_cmd(a: CompareArgs) -> Result<()> {
    let hits = a.hits.map(|h| (h[0].clone(), h[1].clone()));
    compare(&a.a, &a.b, a.threshold, hits, a.json)
}
