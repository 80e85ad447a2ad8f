//! Charts as SVG and PNG (plotters), with a bundled font (DejaVu Sans, in
//! `tb/assets/`) so PNG text renders without system font libraries.
//! Every file is written through a temporary file and a rename.

use std::path::{Path, PathBuf};
use std::sync::Once;

use anyhow::{anyhow, Context as _};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

fn font() {
    REGISTER.call_once(|| {
        // The bundled font is valid; registration only fails on a bad file.
        let _ = register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// A named series of (x, y) points.
#[derive(Clone, Debug, Default)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub style: SeriesStyle,
}

/// How a series is drawn; the default is a solid line (or scatter) of
/// filled circles in the series' own colour.
#[derive(Clone, Debug, Default)]
pub struct SeriesStyle {
    /// Colour index into the palette (default: the series' position).
    pub color: Option<usize>,
    /// A dashed line (charts with `lines`).
    pub dashed: bool,
    /// Per point, whether its marker is hollow (missing: filled).
    pub hollow: Vec<bool>,
    /// Per point, a label drawn beside it in the series' colour (missing or
    /// empty: none).
    pub labels: Vec<String>,
}

/// A labelled point drawn on top of a chart (e.g. a published figure).
#[derive(Clone, Debug)]
pub struct Mark {
    pub label: String,
    pub x: f64,
    pub y: f64,
}

/// What to draw.
#[derive(Clone, Debug)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub marks: Vec<Mark>,
    /// Join the points of each series with lines (else scatter).
    pub lines: bool,
    /// Logarithmic x axis (base 2 ticks look best for 4..64 ways).
    pub log_x: bool,
    /// Draw the Pareto front (max x, max y) of all points.
    pub pareto: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
}

const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// Points not dominated in both coordinates (larger is better in both),
/// sorted by x.
pub(crate) fn pareto_front(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut f: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|&(x, y)| {
            !points
                .iter()
                .any(|&(a, b)| a >= x && b >= y && (a > x || b > y))
        })
        .collect();
    f.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    f.dedup();
    f
}

/// Axis tick text: integers without a fraction, large numbers with SI
/// suffixes.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a >= 1e6 {
        let t = format!("{:.2}", v / 1e6);
        format!("{}M", t.trim_end_matches('0').trim_end_matches('.'))
    } else if a >= 1e4 {
        format!("{:.0}k", v / 1e3)
    } else if (v - v.round()).abs() < 1e-9 {
        format!("{v:.0}")
    } else if a >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// The ticks of a logarithmic axis over `lo..hi`: powers of two over up
/// to eight octaves (4, 8, .. 64 ways), 1-2-5 steps over up to three
/// decades, powers of ten beyond.
pub(crate) fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if !(lo > 0.0 && hi > lo) {
        return vec![];
    }
    let within = |v: f64| v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9);
    if hi / lo <= 256.0 {
        let (a, b) = (lo.log2().ceil() as i32, hi.log2().floor() as i32);
        let v: Vec<f64> = (a..=b).map(|k| 2f64.powi(k)).collect();
        if v.len() >= 2 {
            return v;
        }
    }
    let (a, b) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let steps: &[f64] = if hi / lo <= 1000.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    (a..=b)
        .flat_map(|e| steps.iter().map(move |m| m * 10f64.powi(e)))
        .filter(|v| within(*v))
        .collect()
}

fn range(v: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite()) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if log {
        (lo / 1.3, hi * 1.3)
    } else {
        let pad = ((hi - lo) * 0.08).max(1e-9).max(hi.abs() * 0.02);
        (
            if lo >= 0.0 {
                (lo - pad).max(0.0)
            } else {
                lo - pad
            },
            hi + pad,
        )
    }
}

/// The corner of the plot where the legend hides the fewest points (a
/// box of 40% of the width and 25% of the height, on the axes' scales);
/// upper left on a tie.
fn legend_corner(
    points: &[(f64, f64)],
    (x0, x1, log_x): (f64, f64, bool),
    (y0, y1, log_y): (f64, f64, bool),
) -> SeriesLabelPosition {
    let unit = |v: f64, a: f64, b: f64, log: bool| {
        if log {
            (v.max(1e-300).ln() - a.max(1e-300).ln()) / (b.max(1e-300).ln() - a.max(1e-300).ln())
        } else {
            (v - a) / (b - a)
        }
    };
    let corners = [
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::LowerLeft, false, false),
    ];
    let hidden = |right: bool, upper: bool| {
        points
            .iter()
            .filter(|p| {
                let (u, v) = (unit(p.0, x0, x1, log_x), unit(p.1, y0, y1, log_y));
                let inx = if right { u >= 0.6 } else { u <= 0.4 };
                let iny = if upper { v >= 0.75 } else { v <= 0.25 };
                inx && iny
            })
            .count()
    };
    corners
        .into_iter()
        .min_by_key(|&(_, r, u)| hidden(r, u))
        .map(|c| c.0)
        .unwrap_or(SeriesLabelPosition::UpperLeft)
}

/// What every chart draws on its axes (one body for each pair of linear
/// and logarithmic axes, whose coordinate types differ): the mesh, the
/// series with their markers and labels, the Pareto fronts, the marks,
/// the legend.
macro_rules! body {
    ($chart:expr, $c:expr, $corner:expr) => {{
        let (mut chart, c, corner) = ($chart, $c, $corner);
        chart
            .configure_mesh()
            .x_desc(&c.x_label)
            .y_desc(&c.y_label)
            .x_label_formatter(&|x| tick(*x))
            .y_label_formatter(&|y| tick(*y))
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(|e| anyhow!("{e:?}"))?;
        for (k, s) in c.series.iter().enumerate() {
            let col = COLORS[s.style.color.unwrap_or(k) % COLORS.len()];
            let marker = |(i, &p): (usize, &(f64, f64))| {
                if s.style.hollow.get(i).copied().unwrap_or(false) {
                    Circle::new(p, 4, col.stroke_width(2))
                } else {
                    Circle::new(p, 4, col.filled())
                }
            };
            if c.lines && s.style.dashed {
                chart
                    .draw_series(DashedLineSeries::new(
                        s.points.iter().copied(),
                        8,
                        5,
                        col.stroke_width(2),
                    ))
                    .map_err(|e| anyhow!("{e:?}"))?
                    .label(s.name.clone())
                    .legend(move |(x, y)| {
                        plotters::element::DashedPathElement::new(
                            vec![(x, y), (x + 18, y)],
                            5,
                            3,
                            col.stroke_width(2),
                        )
                    });
                chart
                    .draw_series(s.points.iter().enumerate().map(marker))
                    .map_err(|e| anyhow!("{e:?}"))?;
            } else if c.lines {
                chart
                    .draw_series(LineSeries::new(
                        s.points.iter().copied(),
                        col.stroke_width(2),
                    ))
                    .map_err(|e| anyhow!("{e:?}"))?
                    .label(s.name.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], col.stroke_width(2))
                    });
                chart
                    .draw_series(s.points.iter().enumerate().map(marker))
                    .map_err(|e| anyhow!("{e:?}"))?;
            } else {
                chart
                    .draw_series(s.points.iter().enumerate().map(marker))
                    .map_err(|e| anyhow!("{e:?}"))?
                    .label(s.name.clone())
                    .legend(move |(x, y)| Circle::new((x + 9, y), 4, col.filled()));
            }
        }
        for (k, s) in c.series.iter().enumerate() {
            let col = COLORS[s.style.color.unwrap_or(k) % COLORS.len()];
            for (p, l) in s.points.iter().zip(&s.style.labels) {
                if l.is_empty() {
                    continue;
                }
                chart
                    .draw_series(std::iter::once(Text::new(
                        l.clone(),
                        *p,
                        ("sans-serif", 13)
                            .into_font()
                            .color(&col)
                            .pos(Pos::new(HPos::Left, VPos::Bottom)),
                    )))
                    .map_err(|e| anyhow!("{e:?}"))?;
            }
        }
        if c.pareto {
            // One front per series: configurations of one scene compete.
            for (k, s) in c.series.iter().enumerate() {
                let col = COLORS[k % COLORS.len()];
                let front = pareto_front(&s.points);
                let e = chart
                    .draw_series(LineSeries::new(front.into_iter(), col.stroke_width(1)))
                    .map_err(|e| anyhow!("{e:?}"))?;
                if k == 0 {
                    e.label("Pareto front (per scene)").legend(|(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], BLACK.stroke_width(1))
                    });
                }
            }
        }
        for m in &c.marks {
            chart
                .draw_series(std::iter::once(TriangleMarker::new(
                    (m.x, m.y),
                    8,
                    RED.filled(),
                )))
                .map_err(|e| anyhow!("{e:?}"))?;
            chart
                .draw_series(std::iter::once(Text::new(
                    // beside the marker, not over it
                    format!("{}   ", m.label),
                    (m.x, m.y),
                    ("sans-serif", 14)
                        .into_font()
                        .color(&RED)
                        .pos(Pos::new(HPos::Right, VPos::Center)),
                )))
                .map_err(|e| anyhow!("{e:?}"))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .label_font(("sans-serif", 14))
            .position(corner)
            .draw()
            .map_err(|e| anyhow!("{e:?}"))?;
    }};
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    c: &Chart,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| anyhow!("{e:?}"))?;
    let all: Vec<(f64, f64)> = c
        .series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .chain(c.marks.iter().map(|m| (m.x, m.y)))
        .collect();
    let (x0, x1) = range(all.iter().map(|p| p.0), c.log_x);
    let (y0, y1) = range(all.iter().map(|p| p.1), c.log_y);
    let corner = legend_corner(&all, (x0, x1, c.log_x), (y0, y1, c.log_y));
    let mut b = ChartBuilder::on(&root);
    b.caption(&c.title, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(42)
        .y_label_area_size(62);
    let (y0, y1) = if c.log_y {
        (y0.max(1e-9), y1)
    } else {
        (y0, y1)
    };
    // Logarithmic axes tick where the data's scale does ([`log_ticks`]).
    let (xt, yt) = (log_ticks(x0, x1), log_ticks(y0, y1));
    match (c.log_x, c.log_y) {
        (true, true) => body!(
            b.build_cartesian_2d(
                (x0..x1).log_scale().with_key_points(xt),
                (y0..y1).log_scale().with_key_points(yt)
            )
            .map_err(|e| anyhow!("{e:?}"))?,
            c,
            corner
        ),
        (true, false) => body!(
            b.build_cartesian_2d((x0..x1).log_scale().with_key_points(xt), y0..y1)
                .map_err(|e| anyhow!("{e:?}"))?,
            c,
            corner
        ),
        (false, true) => body!(
            b.build_cartesian_2d(x0..x1, (y0..y1).log_scale().with_key_points(yt))
                .map_err(|e| anyhow!("{e:?}"))?,
            c,
            corner
        ),
        (false, false) => body!(
            b.build_cartesian_2d(x0..x1, y0..y1)
                .map_err(|e| anyhow!("{e:?}"))?,
            c,
            corner
        ),
    }
    root.present().map_err(|e| anyhow!("{e:?}"))?;
    Ok(())
}

/// Write `<stem>.svg` and `<stem>.png`; returns both paths.
pub fn write(stem: &Path, c: &Chart) -> anyhow::Result<[PathBuf; 2]> {
    font();
    let (w, h) = (900u32, 560u32);
    let mut svg = String::new();
    draw(
        SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area(),
        c,
    )?;
    let svg_path = stem.with_extension("svg");
    crate::output::write(&svg_path, svg.as_bytes())?;
    let mut buf = vec![0u8; (w * h * 3) as usize];
    draw(
        BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area(),
        c,
    )?;
    let img = image::RgbImage::from_raw(w, h, buf).context("chart buffer size")?;
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)?;
    let png_path = stem.with_extension("png");
    crate::output::write(&png_path, &png)?;
    Ok([svg_path, png_path])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_svg_and_png_with_text() {
        let dir = tempfile::tempdir().unwrap();
        let c = Chart {
            title: "Frame rate against parallel rays".into(),
            x_label: "ways".into(),
            y_label: "frames/s at 300 MHz".into(),
            series: vec![Series {
                name: "default scene".into(),
                points: vec![
                    (4.0, 1.0),
                    (8.0, 2.0),
                    (16.0, 3.5),
                    (32.0, 6.0),
                    (64.0, 9.0),
                ],
                style: SeriesStyle {
                    dashed: true,
                    hollow: vec![false, true],
                    ..Default::default()
                },
            }],
            marks: vec![Mark {
                label: "paper: 13.3".into(),
                x: 64.0,
                y: 13.3,
            }],
            lines: true,
            log_x: true,
            pareto: false,
            log_y: false,
        };
        let [svg, png] = write(&dir.path().join("fig8"), &c).unwrap();
        let s = std::fs::read_to_string(svg).unwrap();
        assert!(s.contains("Frame rate against parallel rays") && s.contains("paper: 13.3"));
        let img = image::open(png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (900, 560));
        // The title is drawn with the bundled font: dark pixels in its band.
        let dark = (300..600)
            .flat_map(|x| (8..34).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&v| v < 100))
            .count();
        assert!(dark > 200, "title text not rendered ({dark} dark pixels)");
        // What the chart promises, read back from the SVG: the x ticks at the measured ways, the hollow marker drawn
        // hollow and the others filled.
        // (y position, text) of every text element; the x axis's tick
        // labels are the ones on the row of the "64".
        let texts: Vec<(String, String)> = s
            .split("</text>")
            .filter_map(|t| {
                let open = t.rfind("<text")?;
                let el = &t[open..];
                let y = el.split(" y=\"").nth(1)?.split('"').next()?.to_string();
                Some((y, el.rsplit('>').next()?.trim().to_string()))
            })
            .collect();
        let row = &texts.iter().find(|(_, t)| t == "64").expect("a 64 tick").0;
        let x_ticks: Vec<&str> = texts
            .iter()
            .filter(|(y, _)| y == row)
            .map(|(_, t)| t.as_str())
            .collect();
        assert_eq!(x_ticks, ["4", "8", "16", "32", "64"], "{texts:?}");
        assert_eq!(
            s.matches("fill=\"none\" stroke=\"#1F77B4\"").count(),
            1,
            "one hollow marker"
        );
        assert!(
            s.matches("fill=\"#1F77B4\" stroke=\"none\"").count() >= 4,
            "filled markers"
        );
    }

    #[test]
    fn log_ticks_follow_the_data() {
        assert_eq!(log_ticks(3.0, 80.0), vec![4.0, 8.0, 16.0, 32.0, 64.0]);
        assert_eq!(
            log_ticks(3.0, 2000.0),
            vec![5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0]
        );
        assert_eq!(log_ticks(50_000.0, 3e9), vec![1e5, 1e6, 1e7, 1e8, 1e9]);
    }

    #[test]
    fn pareto_front_by_hand() {
        let p = [
            (1.0, 5.0),
            (2.0, 4.0),
            (2.0, 3.0),
            (3.0, 1.0),
            (0.5, 0.5),
            (3.0, 0.5),
        ];
        assert_eq!(pareto_front(&p), vec![(1.0, 5.0), (2.0, 4.0), (3.0, 1.0)]);
    }
}
