//! Fitting the number format to a scene: the coordinates a record holds,
//! the largest of them, the smallest feature, and the shape as the chip
//! sees it once rounded.

use crate::scene::{Scene, SceneError, Shape};

use super::{CompileOptions, QFormat};

/// Triangles in the documented tessellation of a shape: spheres 16
/// segments x 8 rings (224), cylinders and cones 16 segments (32, plus 16
/// per cap), boxes 12, rectangles 2, polygons n - 2.
pub fn tessellated_triangles(s: &Shape) -> usize {
    s.surface().tessellated_triangles()
}

/// The smallest length that defines a shape.
pub fn smallest_feature(s: &Shape) -> f64 {
    s.surface().smallest_feature()
}

/// The fraction bits of the format [`compile`](super::compile) fits to `scene` with
/// `guard_bits`, if it can represent the scene (no BSP built).
pub fn fitted_frac(scene: &Scene, guard_bits: u32) -> Option<u32> {
    let opt = CompileOptions {
        guard_bits,
        ..CompileOptions::default()
    };
    fit(scene, &opt).ok().map(|(q, _)| q.frac)
}

/// Fit the format, or say why the scene cannot be represented.
pub(super) fn fit(scene: &Scene, opt: &CompileOptions) -> Result<(QFormat, f64), SceneError> {
    let err = |line: usize, message: String| SceneError {
        file: scene.source.clone(),
        line,
        col: 0,
        message,
    };
    let mut max_abs: f64 = 0.0;
    let mut max_line = 0;
    let mut see = |x: f64, line: usize| {
        if x.abs() > max_abs {
            max_abs = x.abs();
            max_line = line;
        }
    };
    for o in &scene.objects {
        o.shape
            .surface()
            .coordinates()
            .into_iter()
            .for_each(|x| see(x, o.line));
    }
    let c = &scene.camera;
    c.from
        .to_array()
        .into_iter()
        .chain(c.at.to_array())
        .for_each(|x| see(x, 0));
    for l in &scene.lights {
        l.position.to_array().into_iter().for_each(|x| see(x, 0));
    }
    // Largest n with max_abs * 2^guard < 2^(15 - n).
    let need = max_abs * (opt.guard_bits as f64).exp2();
    let frac = (0..=15u32).rev().find(|&n| need < ((15 - n) as f64).exp2());
    let Some(frac) = frac else {
        return Err(err(
            max_line,
            format!(
                "cannot represent the scene in 16-bit fixed point: a coordinate reaches {max_abs}, and with {} guard bit(s) \
                 the largest allowed is {}",
                opt.guard_bits,
                (15.0 - opt.guard_bits as f64).exp2()
            ),
        ));
    };
    let q = QFormat { frac };
    for o in &scene.objects {
        let edges = o.shape.surface().edges();
        if edges
            .iter()
            .flat_map(|e| e.to_array())
            .any(|x| q.quantize(x).is_none())
        {
            return Err(err(
                o.line,
                format!(
                    "{} edge does not fit in {} (use a guard bit)",
                    o.shape.prim_type().name(),
                    q.name()
                ),
            ));
        }
    }
    Ok((q, max_abs))
}

/// The scene's smallest feature: its size, line and type.
pub(super) struct Feature {
    pub size: f64,
    pub line: usize,
    pub what: &'static str,
}

/// The smallest feature of the scene, refused when it is below
/// `opt.min_feature_lsb` LSB of `q` (at the chip's precision).
pub(super) fn smallest(
    scene: &Scene,
    opt: &CompileOptions,
    q: QFormat,
    max_abs: f64,
) -> Result<Feature, SceneError> {
    let lsb = q.lsb();
    let mut small = Feature {
        size: f64::INFINITY,
        line: 0,
        what: "",
    };
    // The smallest feature against the least a record holds (in LSB of
    // the chip's precision): spheres in frames of their own
    // (`sphere_extra_frac`) hold features that much finer.
    let finer = |s: &Shape| match s {
        Shape::Sphere(_) => opt.sphere_extra_frac,
        _ => 0,
    };
    let least = |s: &Shape| {
        opt.min_feature_lsb * lsb * (-((opt.target_extra_frac + finer(s)) as f64)).exp2()
    };
    let mut worst: Option<(&crate::scene::Object, f64)> = None;
    for o in &scene.objects {
        let f = smallest_feature(&o.shape);
        if f < small.size {
            small = Feature {
                size: f,
                line: o.line,
                what: o.shape.prim_type().name(),
            };
        }
        let ratio = f / least(&o.shape);
        if worst.is_none_or(|(_, r)| ratio < r) {
            worst = Some((o, ratio));
        }
    }
    if let Some((o, ratio)) = worst.filter(|(_, r)| *r < 1.0) {
        let f = ratio * least(&o.shape);
        let held = match finer(&o.shape) {
            0 => String::new(),
            e => format!(" (its frame holds 2^-{e} LSB)"),
        };
        return Err(SceneError {
            file: scene.source.clone(),
            line: o.line,
            col: 0,
            message: format!(
                "cannot represent the scene in 16-bit fixed point: it spans +-{max_abs}, so the format is {} (LSB {lsb}), \
                 and this {} has a feature of {} = {:.2} LSB, below the {} LSB minimum{held}",
                q.name(),
                o.shape.prim_type().name(),
                f,
                f / lsb,
                opt.min_feature_lsb
            ),
        });
    }
    Ok(small)
}

/// The shape as the chip sees it: every coordinate rounded to `q`
/// (vertex normals dropped).
pub fn dequantized(s: &Shape, q: QFormat) -> Shape {
    s.quantized(&|x: f64| q.quantize(x).map_or(x, |v| q.value(v)))
}
