//! The report's `span` section: where one number format per scene fails.
//! Five spheres of radius 0.5 down to 0.04 on a square floor whose half
//! width `W` sets the scene's span, `W` = 0.04 x 2^k for k = 6..=14, so
//! the span is 2^k times the smallest sphere's radius; each scene on the
//! 16-bit chip with global and with local positions and on the 32-bit
//! chip, and two charts: PSNR and hit disagreement (eye rays on another
//! object than the reference's) against `log2(W / r)`.

use anyhow::Result;

use super::*;
use crate::charts::{Chart, Series};

/// The smallest sphere's radius (scene units).
const SMALLEST: f64 = 0.04;

/// The exponents `k` of the span ratio `2^k`.
const RATIOS: std::ops::RangeInclusive<i32> = 6..=14;

/// The chips, as `render` arguments, and their names in the table and
/// the charts.
const CHIPS: [(&str, [&str; 4]); 3] = [
    (
        "16-bit, global",
        ["--datapath", "16", "--positions", "global"],
    ),
    (
        "16-bit, local",
        ["--datapath", "16", "--positions", "local"],
    ),
    ("32-bit", ["--datapath", "32", "--positions", "global"]),
];

/// The scene of span ratio `2^k`, as a native scene file (also the
/// stability suite's, `tb/tests/stability.rs`).
pub fn scene(k: i32) -> String {
    let w = SMALLEST * (k as f64).exp2();
    let mut s = format!(
        "# morphosys report, section span: five spheres of radius 0.5 to {SMALLEST} on a floor \
         {} units wide, its half width 2^{k} times the smallest radius.\n\
         background = [0.1, 0.1, 0.2]\n\
         [camera]\nfrom = [0.0, -6.0, 2.0]\nat = [0.0, 0.0, 0.3]\nup = [0.0, 0.0, 1.0]\n\
         angle = 30.0\nhither = 0.01\nresolution = [128, 128]\n\
         [[light]]\nposition = [3.0, -5.0, 6.0]\ncolor = [1.0, 1.0, 1.0]\n\
         [material.floor]\ncolor = [0.8, 0.8, 0.8]\nkd = 0.8\nks = 0.0\nshine = 1\n\
         [material.red]\ncolor = [0.9, 0.2, 0.1]\nkd = 0.7\nks = 0.3\nshine = 30\n\
         [[object]]\ntype = \"rectangle\"\nmaterial = \"floor\"\n\
         corner = [{:?}, {:?}, 0.0]\nedge1 = [{:?}, 0.0, 0.0]\nedge2 = [0.0, {:?}, 0.0]\n",
        2.0 * w,
        -w,
        -w,
        2.0 * w,
        2.0 * w
    );
    for (c, r) in [
        ([0.0, 0.0], 0.5),
        ([1.0, 0.2], 0.3),
        ([-0.8, -0.4], 0.15),
        ([0.5, -0.9], 0.08),
        ([-0.3, -1.1], SMALLEST),
    ] {
        s.push_str(&format!(
            "[[object]]\ntype = \"sphere\"\nmaterial = \"red\"\ncenter = [{:?}, {:?}, {r:?}]\nradius = {r:?}\n",
            c[0], c[1]
        ));
    }
    s
}

pub(super) fn span(r: &mut Runner) -> Result<String> {
    let dir = std::path::Path::new("scenes/span");
    std::fs::create_dir_all(dir)?;
    let mut rows = Vec::new();
    let mut psnr_series: Vec<Series> = CHIPS
        .iter()
        .map(|(name, _)| Series {
            name: name.to_string(),
            ..Default::default()
        })
        .collect();
    let mut hit_series = psnr_series.clone();
    for k in RATIOS {
        let file = dir.join(format!("span-{k}.toml"));
        crate::output::write(&file, scene(k).as_bytes())?;
        let path = file.display().to_string();
        let mut row = vec![format!("2^{k}")];
        for (i, (_, args)) in CHIPS.iter().enumerate() {
            let mut a = vec!["--size", "128x128", "--depth", "2"];
            a.extend_from_slice(args);
            match r.render(&path, &a) {
                Ok(j) => {
                    let (p, h) = (f(&j, "psnr_db"), f(&j, "hit_agreement"));
                    row.push(format!("{} dB, {}", psnr(&j), hits(&j)));
                    psnr_series[i].points.push((k as f64, p.min(99.0)));
                    hit_series[i].points.push((k as f64, 10_000.0 * (1.0 - h)));
                }
                Err(_) => row.push("refused".into()),
            }
        }
        rows.push(row);
    }
    let img = r.docs.join("img/span");
    std::fs::create_dir_all(&img)?;
    for (stem, y, series) in [
        ("psnr", "PSNR (dB) against the f64 reference", psnr_series),
        (
            "hits",
            "eye rays on another object than the reference's, per 10,000",
            hit_series,
        ),
    ] {
        let chart = Chart {
            title: "Five spheres on a floor: the span against the smallest sphere".into(),
            x_label: "log2(floor's half width / smallest radius)".into(),
            y_label: y.into(),
            series,
            marks: Vec::new(),
            lines: true,
            log_x: false,
            pareto: false,
            log_y: false,
        };
        let [svg, png] = crate::charts::write(&r.dir.path().join(stem), &chart)?;
        std::fs::remove_file(svg)?;
        crate::output::write(&img.join(format!("{stem}.png")), &std::fs::read(&png)?)?;
    }
    body(
        "One row: `morphosys render scenes/span/span-10.toml --size 128x128 --depth 2 \
         --datapath 16 --positions local --json out.json` (the scenes are written by the \
         report; no point where the format refuses the scene).\n\n\
         ![PSNR against the span](img/span/psnr.png)\n\n\
         ![hit disagreement against the span](img/span/hits.png)\n\n"
            .to_string(),
        &[
            "span / smallest radius",
            "16-bit, global: PSNR, hits",
            "16-bit, local",
            "32-bit",
        ],
        &rows,
    )
}
