//! The sweep's charts: the Pareto chart of PSNR against frames/s, the
//! paper's Fig. 8, the what-if charts of timing and issue model, and the
//! scene-size chart with its fitted log-log slopes.

use crate::charts::{self, Chart, Mark, Series, SeriesStyle};
use crate::render_options as ro;
use anyhow::Result;
use firmware::tracer::Traversal;
use std::path::{Path, PathBuf};

use super::*;

pub(super) fn short(scene: &str) -> String {
    Path::new(scene)
        .file_stem()
        .map_or(scene.to_string(), |s| s.to_string_lossy().into_owned())
}

pub(super) fn charts_for(all_rows: &[Row], dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let sizes: Vec<&Row> = all_rows.iter().filter(|r| r.knob == SCENE_SIZE).collect();
    if !sizes.is_empty() {
        out.extend(scaling_chart(&sizes, dir)?);
    }
    if all_rows.iter().any(|r| r.knob == "broadcast") {
        out.extend(what_if_chart(all_rows, dir, "broadcast")?);
    }
    if all_rows.iter().any(|r| r.knob == "timing") {
        out.extend(what_if_chart(all_rows, dir, "timing")?);
    }
    // The chip what-ifs have charts of their own.
    let rows: Vec<Row> = all_rows
        .iter()
        .filter(|r| !matches!(r.knob.as_str(), SCENE_SIZE | "broadcast" | "timing"))
        .cloned()
        .collect();
    if !rows.iter().any(|r| r.knob == ro::WAYS.name) {
        return Ok(out);
    }
    let rows = &rows[..];
    let mut scenes: Vec<&str> = rows.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    let size = rows.first().map_or((256, 256), |r| (r.width, r.height));
    out.extend(fig8_charts(rows, &scenes, size, dir)?);
    out.extend(pareto_charts(rows, &scenes, dir)?);
    out.extend(normals_chart(rows, &scenes, size, dir)?);
    if sizes.is_empty() {
        out.extend(knob_scenes_chart(rows, size, dir)?);
    }
    Ok(out)
}

/// The paper's Fig. 8 (frame rate against rays in parallel) and the ray
/// lanes' use.
fn fig8_charts(
    rows: &[Row],
    scenes: &[&str],
    size: (u32, u32),
    dir: &Path,
) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let per = |knob: &str, y: &dyn Fn(&Row) -> f64| -> Vec<Series> {
        scenes
            .iter()
            .map(|s| Series {
                name: short(s),
                points: rows
                    .iter()
                    .filter(|r| r.scene == *s && r.knob == knob)
                    .map(|r| (r.ways as f64, y(r)))
                    .collect(),
                style: SeriesStyle::default(),
            })
            .collect()
    };
    out.extend(charts::write(
        &dir.join("fig8"),
        &Chart {
            title: format!(
                "Frame rate against rays in parallel ({}x{}, recursion level 2)",
                size.0, size.1
            ),
            x_label: "rays traced in parallel (ways)".into(),
            y_label: "frames/s at 300 MHz".into(),
            series: per(ro::WAYS.name, &|r| r.fps_at_300mhz),
            marks: vec![Mark {
                label: "paper: 13.3 frames/s".into(),
                x: 64.0,
                y: 13.3,
            }],
            lines: true,
            log_x: true,
            pareto: false,
            log_y: true,
        },
    )?);
    out.extend(charts::write(
        &dir.join("fig8_active"),
        &Chart {
            title: "Utilisation of the ray lanes against rays in parallel".into(),
            x_label: "rays traced in parallel (ways)".into(),
            y_label: "active RCs / ways (while the array runs)".into(),
            series: per(ro::WAYS.name, &|r| {
                r.active_rc_fraction * 64.0 / r.ways as f64
            }),
            marks: vec![],
            lines: true,
            log_x: true,
            pareto: false,
            log_y: false,
        },
    )?);
    Ok(out)
}

/// Speed against accuracy over every configuration, and the same with the
/// silicon's price on the speed axis.
fn pareto_charts(rows: &[Row], scenes: &[&str], dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let pareto: Vec<Series> = scenes
        .iter()
        .map(|s| Series {
            name: short(s),
            points: rows
                .iter()
                .filter(|r| r.scene == *s)
                .map(|r| (r.fps_at_estimated_clock, r.psnr_db))
                .collect(),
            style: SeriesStyle {
                hollow: rows
                    .iter()
                    .filter(|r| r.scene == *s)
                    .map(|r| r.datapath_bits == 32)
                    .collect(),
                ..SeriesStyle::default()
            },
        })
        .collect();
    // The table-size knob as a series of its own per scene.
    let tables = scenes.iter().map(|s| Series {
        name: format!("{} table sizes", short(s)),
        points: rows
            .iter()
            .filter(|r| r.scene == *s && r.knob == "table_entries")
            .map(|r| (r.fps_at_estimated_clock, r.psnr_db))
            .collect(),
        style: Default::default(),
    });
    // Coarse normals, then the paper configuration's fine ones: the same
    // kernels' cost and gain.
    let normals = scenes.iter().map(|s| Series {
        name: format!("{} normals coarse, fine", short(s)),
        points: [ro::NORMALS.name, "paper"]
            .iter()
            .filter_map(|k| rows.iter().find(|r| r.scene == *s && r.knob == *k))
            .map(|r| (r.fps_at_estimated_clock, r.psnr_db))
            .collect(),
        style: Default::default(),
    });
    let pareto: Vec<Series> = pareto.into_iter().chain(tables).chain(normals).collect();
    let paper: Vec<Mark> = rows
        .iter()
        .filter(|r| r.knob == "paper")
        .map(|r| Mark {
            label: format!("paper config ({})", short(&r.scene)),
            x: r.fps_at_estimated_clock,
            y: r.psnr_db,
        })
        .collect();
    out.extend(charts::write(
        &dir.join("pareto"),
        &Chart {
            title: "Speed against accuracy over every configuration (hollow: 32-bit datapath)"
                .into(),
            x_label:
                "frames/s at each chip's clock (16-bit: 300 MHz; 32-bit: lower, `morphosys cost`)"
                    .into(),
            y_label: "PSNR against the f64 reference (dB)".into(),
            series: pareto,
            marks: paper,
            lines: false,
            log_x: true,
            pareto: true,
            log_y: false,
        },
    )?);
    // The same points with the silicon's price on the speed axis.
    let cost = crate::cost::Synthesis::committed();
    let (w16, w32) = (
        firmware::tracer::Datapath::W16,
        firmware::tracer::Datapath::W32,
    );
    let priced: Vec<Series> = scenes
        .iter()
        .map(|s| {
            let mine: Vec<&Row> = rows.iter().filter(|r| r.scene == *s).collect();
            Series {
                name: short(s),
                points: mine
                    .iter()
                    .map(|r| (r.fps_per_m_transistors, r.psnr_db))
                    .collect(),
                style: SeriesStyle {
                    hollow: mine.iter().map(|r| r.datapath_bits == 32).collect(),
                    ..SeriesStyle::default()
                },
            }
        })
        .collect();
    out.extend(charts::write(
        &dir.join("pareto_cost"),
        &Chart {
            title: format!(
                "Speed for the silicon against accuracy (hollow: 32-bit, {:.1}x area, {:.0} MHz est.)",
                cost.array_transistors(w32) as f64 / cost.array_transistors(w16) as f64,
                cost.clock_mhz(w32)
            ),
            x_label: "frames/s at the estimated clock per million array transistors".into(),
            y_label: "PSNR against the f64 reference (dB)".into(),
            series: priced,
            marks: vec![],
            lines: false,
            log_x: true,
            pareto: true,
            log_y: false,
        },
    )?);
    Ok(out)
}

/// Coarse against fine normals per scene.
fn normals_chart(
    rows: &[Row],
    scenes: &[&str],
    size: (u32, u32),
    dir: &Path,
) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    // Coarse against fine normals: PSNR against cycles per scene, the
    // arrow's tail the kernels as first written.
    let normals: Vec<Series> = scenes
        .iter()
        .filter_map(|s| {
            let pick = |k: &str| rows.iter().find(|r| r.scene == *s && r.knob == k);
            let (coarse, fine) = (pick(ro::NORMALS.name)?, pick("paper")?);
            Some(Series {
                name: format!("{} ({}-bit)", short(s), fine.datapath_bits),
                points: [coarse, fine]
                    .iter()
                    .map(|r| (r.cycles as f64, r.psnr_db))
                    .collect(),
                style: SeriesStyle::default(),
            })
        })
        .collect();
    if !normals.is_empty() {
        out.extend(charts::write(
            &dir.join("normals"),
            &Chart {
                title: format!(
                    "Normals: each line from coarse to fine, paper configuration ({}x{})",
                    size.0, size.1
                ),
                x_label: "chip cycles per frame".into(),
                y_label: "PSNR against the f64 reference (dB)".into(),
                series: normals,
                marks: vec![],
                lines: true,
                log_x: true,
                pareto: false,
                log_y: false,
            },
        )?);
    }
    Ok(out)
}

/// Without a size sweep: cycles against the primitives of the knob
/// sweep's scenes (two at least).
fn knob_scenes_chart(rows: &[Row], size: (u32, u32), dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let knob_scenes = rows
        .iter()
        .filter(|r| r.knob == "paper")
        .map(|r| r.scene.as_str())
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    if knob_scenes >= 2 {
        // No size sweep: the scenes of the knob sweep, paper configuration
        // (a line needs two scenes at least; one is no chart).
        let scaling = vec![Series {
            name: "paper configuration".into(),
            points: rows
                .iter()
                .filter(|r| r.knob == "paper")
                .map(|r| (r.primitives as f64, r.cycles as f64))
                .collect(),
            style: SeriesStyle::default(),
        }];
        out.extend(charts::write(
            &dir.join("scaling"),
            &Chart {
                title: format!(
                    "Cycles per frame against primitive count ({}x{})",
                    size.0, size.1
                ),
                x_label: "primitives in the scene".into(),
                y_label: "chip cycles per frame".into(),
                series: scaling,
                marks: vec![],
                lines: false,
                log_x: rows.iter().any(|r| r.primitives > 100),
                pareto: false,
                log_y: true,
            },
        )?);
    }
    Ok(out)
}

/// A chip what-if against the default timing (`knob` "broadcast": the M1
/// chip's issue model; "timing": each timing file): per scene and
/// traversal, its frame rate on the default chip (x) and the ratio of the
/// what-if's frame rate to it (y); one series per what-if and traversal
/// (hollow: the paper's traversal), the scenes labelled.
pub(super) fn what_if_chart(rows: &[Row], dir: &Path, knob: &str) -> Result<[PathBuf; 2]> {
    let base = |r: &Row| {
        rows.iter().find(|b| {
            b.scene == r.scene
                && b.timing == "default"
                && b.traversal == r.traversal
                && match r.traversal.as_str() {
                    "paper" => b.knob == "paper",
                    _ => b.knob == ro::TRAVERSAL.name,
                }
        })
    };
    let mut names: Vec<String> = Vec::new();
    for r in rows.iter().filter(|r| r.knob == knob) {
        if !names.contains(&r.timing) {
            names.push(r.timing.clone());
        }
    }
    let mut series = Vec::new();
    for (k, name) in names.iter().enumerate() {
        for traversal in Traversal::ALL {
            let pts: Vec<(f64, f64, String)> = rows
                .iter()
                .filter(|r| r.knob == knob && &r.timing == name && r.traversal == traversal.name())
                .filter_map(|r| {
                    let b = base(r)?;
                    Some((
                        b.fps_at_300mhz,
                        r.fps_at_300mhz / b.fps_at_300mhz,
                        short(&r.scene),
                    ))
                })
                .collect();
            if pts.is_empty() {
                continue;
            }
            let paper = traversal == Traversal::Paper;
            series.push(Series {
                name: format!("{name}, {traversal} traversal"),
                points: pts.iter().map(|p| (p.0, p.1)).collect(),
                style: SeriesStyle {
                    color: Some(2 * k + paper as usize),
                    dashed: false,
                    hollow: vec![paper; pts.len()],
                    labels: pts.iter().map(|p| format!(" {}", p.2)).collect(),
                },
            });
        }
    }
    let size = rows.first().map_or((256, 256), |r| (r.width, r.height));
    let title = match knob {
        "broadcast" => format!(
            "Frame rate with the M1 chip's issue model against the run broadcast ({}x{})",
            size.0, size.1
        ),
        _ => format!(
            "Frame rate with each timing file against the default timing ({}x{})",
            size.0, size.1
        ),
    };
    charts::write(
        &dir.join(knob),
        &Chart {
            title,
            x_label: "frames/s at 300 MHz, default timing".into(),
            y_label: "frame rate relative to the default timing".into(),
            series,
            marks: vec![],
            lines: false,
            log_x: true,
            pareto: false,
            log_y: false,
        },
    )
}

/// Least-squares slope of `log y` against `log x` (the exponent of a power
/// law `y ~ x^k`), or `None` with fewer than two points.
pub fn loglog_slope(points: &[(f64, f64)]) -> Option<f64> {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if p.len() < 2 {
        return None;
    }
    let n = p.len() as f64;
    let (mx, my) = (
        p.iter().map(|q| q.0).sum::<f64>() / n,
        p.iter().map(|q| q.1).sum::<f64>() / n,
    );
    let sxx: f64 = p.iter().map(|q| (q.0 - mx).powi(2)).sum();
    if sxx == 0.0 {
        return None;
    }
    Some(p.iter().map(|q| (q.0 - mx) * (q.1 - my)).sum::<f64>() / sxx)
}

/// Cycles per frame against primitive count over the families of the size
/// sweep, log-log: one colour per family, solid the packet traversal,
/// dashed the paper's, hollow markers for scenes streamed from main memory;
/// the legend gives each series' fitted slope (cycles ~ objects^slope).
pub(super) fn scaling_chart(rows: &[&Row], dir: &Path) -> Result<[PathBuf; 2]> {
    let mut families: Vec<String> = Vec::new();
    for r in rows {
        let f = family(&r.scene);
        if !families.contains(&f) {
            families.push(f);
        }
    }
    let mut series = Vec::new();
    for (k, f) in families.iter().enumerate() {
        for traversal in Traversal::ALL {
            let mut pts: Vec<&Row> = rows
                .iter()
                .copied()
                .filter(|r| family(&r.scene) == *f && r.traversal == traversal.name())
                .collect();
            if pts.is_empty() {
                continue;
            }
            pts.sort_by_key(|r| r.primitives);
            let points: Vec<(f64, f64)> = pts
                .iter()
                .map(|r| (r.primitives as f64, r.cycles as f64))
                .collect();
            let slope = loglog_slope(&points).map_or(String::new(), |k| format!(", slope {k:.2}"));
            series.push(Series {
                name: format!("{f}, {traversal}{slope}"),
                points,
                style: SeriesStyle {
                    color: Some(k),
                    dashed: traversal == Traversal::Paper,
                    hollow: pts.iter().map(|r| r.fb_layout == "streamed").collect(),
                    labels: vec![],
                },
            });
        }
    }
    let size = rows.first().map_or((64, 64), |r| (r.width, r.height));
    charts::write(
        &dir.join("scaling"),
        &Chart {
            title: format!(
                "Cycles per frame against objects ({}x{}; solid: packet, dashed: paper; hollow: streamed)",
                size.0, size.1
            ),
            x_label: "objects in the scene (SPD sizes 1, 2, ...)".into(),
            y_label: "chip cycles per frame".into(),
            series,
            marks: vec![],
            lines: true,
            log_x: true,
            pareto: false,
            log_y: true,
        },
    )
}

/// The SPD family of a generated scene's source name (`balls-3.nff`).
pub(super) fn family(scene: &str) -> String {
    let s = short(scene);
    match s.rsplit_once('-') {
        Some((f, n)) if n.chars().all(|c| c.is_ascii_digit()) => f.to_string(),
        _ => s,
    }
}
