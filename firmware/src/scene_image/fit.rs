//! Fitting the number format to a scene: the coordinates a record holds,
//! the largest of them, the smallest feature, and the shape as the chip
//! sees it once rounded.

use crate::scene::{Scene, SceneError, Shape, Vec3};

use super::{CompileOptions, QFormat};

/// Triangles in the documented tessellation of a shape: spheres 16
/// segments x 8 rings (224), cylinders and cones 16 segments (32, plus 16
/// per cap), boxes 12, rectangles 2, polygons n - 2.
pub fn tessellated_triangles(s: &Shape) -> usize {
    s.surface().tessellated_triangles()
}

/// The largest exponent of a local frame (`CompileOptions::local_frames`):
/// its LSB `2^-12` of the scene's (the records' remainders of 2^-14 LSB
/// keep two bits below it).
pub const LOCAL_E_MAX: u32 = 12;

/// The shapes of `scene` the chip tests in a frame of their own with
/// local positions (spheres, flat triangles, and cylinders and cones
/// where none of the scene's of that type has caps): the frame's centre
/// (the sphere's, the triangle's centroid, the axis' midpoint) and its
/// extent, the farthest point of the shape from it (scene units).
pub fn local_frame(scene: &Scene, s: &Shape) -> Option<(Vec3, f64)> {
    if let Some(sp) = s.as_sphere() {
        return Some((sp.center, sp.radius.abs()));
    }
    if let Some(c) = s.as_cone() {
        let ty = s.prim_type();
        let capped = scene
            .objects
            .iter()
            .any(|o| o.shape.prim_type() == ty && o.shape.capped());
        let h = (c.apex - c.base).length() * 0.5;
        let r = c.base_radius.abs().max(c.apex_radius.abs());
        return (!capped).then(|| ((c.base + c.apex) * 0.5, (h * h + r * r).sqrt()));
    }
    let t = s.as_triangle().filter(|t| t.normals.is_none())?;
    let c = (t.v[0] + t.v[1] + t.v[2]) * (1.0 / 3.0);
    let r = t.v.iter().map(|v| (*v - c).length()).fold(0.0, f64::max);
    Some((c, r))
}

/// The exponent `e` of a local frame (its LSB `2^-e` of the scene's) for
/// a shape of extent `r` LSB about its centre: the largest up to
/// [`LOCAL_E_MAX`] with `(2 r + 3) 2^e < 2^14`, so that the vector from
/// the centre to a ray's point nearest it (within `r` where the ray may
/// hit, and up to 3 LSB along the ray from the rounding of that point's
/// distance and of the Q1.14 direction's length) and the distance from
/// there to the hit (within `2 r`) fit with a guard bit; 0 without the
/// guard bit (`2 r + 3 < 2^15`); none beyond (a shape over a quarter of
/// the format's range).
pub fn local_exponent(r: f64) -> Option<u32> {
    (0..=LOCAL_E_MAX)
        .rev()
        .find(|&e| (2.0 * r + 3.0) * (e as f64).exp2() < 16384.0)
        .or((2.0 * r + 3.0 < 32768.0).then_some(0))
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
    // the chip's precision): shapes in frames of their own
    // (`local_frames`) hold features `2^e` times finer.
    let frame = |s: &Shape| {
        local_frame(scene, s)
            .filter(|_| opt.local_frames)
            .map(|(_, r)| local_exponent(r / lsb))
    };
    if let Some(o) = scene
        .objects
        .iter()
        .find(|o| frame(&o.shape).is_some_and(|e| e.is_none()))
    {
        let r = local_frame(scene, &o.shape).map_or(0.0, |(_, r)| r);
        return Err(SceneError {
            file: scene.source.clone(),
            line: o.line,
            col: 0,
            message: format!(
                "cannot test this {} in a frame of its own (local positions): it reaches {r} = {:.0} LSB of {} from its centre, \
                 over a quarter of the format's range",
                o.shape.prim_type().name(),
                r / lsb,
                q.name()
            ),
        });
    }
    let finer = |s: &Shape| frame(s).flatten().unwrap_or(0);
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
        let held = match (opt.target_extra_frac, finer(&o.shape)) {
            (0, 0) => String::new(),
            (0, e) => format!(" (its frame holds 2^-{e} LSB)"),
            (x, 0) => format!(" (the chip's records hold 2^-{x} LSB)"),
            (x, e) => format!(" (its frame in the chip's records holds 2^-{} LSB)", x + e),
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
