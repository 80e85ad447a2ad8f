//! The scene model shared by the scene compiler and the host-side reference
//! renderer: primitives, materials, lights and a pinhole camera, in `f64`.
//!
//! Scenes come from two readers: [`nff`] (Eric Haines' Neutral File Format,
//! the SPD's) and [`native`] (TOML, which adds boxes, rectangles, cones with
//! end caps). Both report errors as `file:line:col: what was expected`, and
//! both run [`Scene::validate`], so a malformed primitive (zero radius,
//! coincident cone ends, a non-planar polygon) or a non-finite number is an
//! error, never a garbage image. A polygon, triangle or rectangle of zero
//! area (collinear or coincident vertices, a zero-length vertex normal) is
//! skipped with one warning per file, as classical SPD renderers skip it
//! ([`Scene::skip_degenerate`]); the scene is refused only when nothing is
//! left.

mod geometry;
pub mod native;
pub mod nff;
pub mod shape;
pub mod spd;

pub use geometry::{Aabb, Vec3};
pub use shape::{
    AaBox, Cone, Disc, Polygon, PrimType, Ray, Rectangle, Shape, Sphere, Surface, SurfaceHit,
    Triangle,
};

use std::fmt;
use std::path::Path;

/// Surface properties, NFF's `f` entity.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub color: Vec3,
    /// Diffuse coefficient.
    pub kd: f64,
    /// Specular coefficient: Phong highlight weight and reflection weight.
    pub ks: f64,
    /// Phong cosine power.
    pub shine: f64,
    /// Transmittance: weight of the refracted ray.
    pub t: f64,
    /// Index of refraction.
    pub ior: f64,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            color: Vec3::ONE,
            kd: 1.0,
            ks: 0.0,
            shine: 0.0,
            t: 0.0,
            ior: 1.0,
        }
    }
}

/// A point light; `color` None means "a non-zero intensity of no
/// particular value" (NFF): the renderer uses 1/sqrt(number of lights).
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub position: Vec3,
    pub color: Option<Vec3>,
}

/// A pinhole camera, NFF's `v` entity.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub from: Vec3,
    pub at: Vec3,
    pub up: Vec3,
    /// Full field of view in degrees, across the image (edge to edge).
    pub angle: f64,
    pub hither: f64,
    pub resolution: (u32, u32),
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            from: Vec3::new(0.0, 0.0, 10.0),
            at: Vec3::ZERO,
            up: Vec3::new(0.0, 1.0, 0.0),
            angle: 45.0,
            hither: 1e-3,
            resolution: (256, 256),
        }
    }
}

/// One object of the scene: its shape, its material, and where it came
/// from (for error messages).
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub shape: Shape,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// 1-based line of the source file that defined it (0 if none).
    pub line: usize,
}

/// The most objects a scene may hold: far above what the chip's image
/// takes (65,535 per primitive type) and what renders in reasonable time,
/// and a bound on the memory a scene file can make us take (about 400
/// bytes per object while it is read). Checked while parsing, at the first
/// object past it.
pub const MAX_OBJECTS: usize = 500_000;

/// The largest scene file read (reading an NFF takes about 7 bytes of
/// memory per byte of text), checked before reading it.
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// A whole scene.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Scene {
    /// File the scene was read from, for messages.
    pub source: String,
    pub camera: Camera,
    pub background: Vec3,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    pub objects: Vec<Object>,
    /// What the readers skipped or changed, for the user (one entry per
    /// kind, with the count and the first line).
    pub warnings: Vec<Warning>,
    /// Where the camera, each light and each material were defined (for
    /// messages; 0 where unknown).
    pub lines: SourceLines,
}

/// Lines of a scene file that defined what has no line of its own.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct SourceLines {
    pub camera: usize,
    pub lights: Vec<usize>,
    pub materials: Vec<usize>,
}

/// Something a scene asks for that is not rendered as asked: skipped
/// degenerate objects, or (from the scene compiler) features the chip does
/// not implement. One per kind: the count of objects and the first line.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Warning {
    /// A short, stable name of the kind (`degenerate`, `refraction`, ...).
    pub feature: String,
    /// The file the scene came from.
    pub file: String,
    /// 1-based line of the first object concerned (0: none or unknown).
    pub line: usize,
    /// Objects concerned.
    pub count: usize,
    /// What happens, in a sentence.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(f, "{}:{}: warning: {}", self.file, self.line, self.message)
        } else {
            write!(f, "{}: warning: {}", self.file, self.message)
        }
    }
}

/// An error in a scene file: `file:line:col: message`.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    pub file: String,
    pub line: usize,
    /// 0 when unknown.
    pub col: usize,
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.col > 0 {
            write!(
                f,
                "{}:{}:{}: {}",
                self.file, self.line, self.col, self.message
            )
        } else if self.line > 0 {
            write!(f, "{}:{}: {}", self.file, self.line, self.message)
        } else {
            write!(f, "{}: {}", self.file, self.message)
        }
    }
}

impl std::error::Error for SceneError {}

impl Scene {
    /// Read a scene, choosing the reader by extension: `.nff` for NFF,
    /// `.toml` for the native format.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let name = path.display().to_string();
        if let Ok(m) = std::fs::metadata(path) {
            if m.is_file() && m.len() > MAX_FILE_BYTES {
                return Err(SceneError {
                    file: name,
                    line: 0,
                    col: 0,
                    message: format!(
                        "the file is {:.0} MB; scene files are read up to {} MB (reading one takes about 7 times its size in memory)",
                        m.len() as f64 / 1e6,
                        MAX_FILE_BYTES >> 20
                    ),
                });
            }
        }
        let text = crate::input::read_to_string(path).map_err(|e| SceneError {
            file: name.clone(),
            line: 0,
            col: 0,
            message: format!("cannot read scene: {e}"),
        })?;
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
            .as_deref()
        {
            Some("nff") => nff::parse(&text, &name),
            Some("toml") => native::parse(&text, &name),
            _ => Err(SceneError {
                file: name,
                line: 0,
                col: 0,
                message: "unknown scene format: expected a .nff or .toml file".into(),
            }),
        }
    }

    /// Drop every polygon, triangle and rectangle of zero area
    /// ([`Shape::zero_area`]) and say so in one warning (the count and the
    /// first line); refused when nothing is left to render.
    pub fn skip_degenerate(&mut self) -> Result<(), SceneError> {
        let before = self.objects.len();
        let mut first: Option<(usize, &'static str)> = None;
        self.objects.retain(|o| match o.shape.zero_area() {
            Some(why) => {
                first.get_or_insert((o.line, why));
                false
            }
            None => true,
        });
        let Some((line, why)) = first else {
            return Ok(());
        };
        let count = before - self.objects.len();
        let what = if count == 1 {
            "1 degenerate polygon".to_string()
        } else {
            format!("{count} degenerate polygons")
        };
        if self.objects.is_empty() {
            return Err(SceneError {
                file: self.source.clone(),
                line,
                col: 0,
                message: if count == 1 {
                    format!("nothing to render: the only object is a degenerate polygon ({why})")
                } else {
                    format!(
                        "nothing to render: all {count} objects are degenerate polygons (the first, here, has {why})"
                    )
                },
            });
        }
        self.warnings.push(Warning {
            feature: "degenerate".into(),
            file: self.source.clone(),
            line,
            count,
            message: format!(
                "skipped {what} (triangles, polygons or rectangles of zero area; the first, here, has {why}); the reference skips them too"
            ),
        });
        Ok(())
    }

    /// Check every number and primitive; the first problem is reported with
    /// the line of the entity that caused it.
    pub fn validate(&self) -> Result<(), SceneError> {
        let err = |line: usize, message: String| SceneError {
            file: self.source.clone(),
            line,
            col: 0,
            message,
        };
        let c = &self.camera;
        let cl = self.lines.camera;
        let light_line = |i: usize| self.lines.lights.get(i).copied().unwrap_or(0);
        let material_line = |i: usize| self.lines.materials.get(i).copied().unwrap_or(0);
        if !(c.from.is_finite()
            && c.at.is_finite()
            && c.up.is_finite()
            && c.angle.is_finite()
            && c.hither.is_finite())
        {
            return Err(err(cl, "camera has a non-finite number".into()));
        }
        if (c.at - c.from).length() == 0.0 {
            return Err(err(cl, "camera 'from' and 'at' coincide".into()));
        }
        if (c.at - c.from).cross(c.up).length() == 0.0 {
            return Err(err(
                cl,
                "camera 'up' is zero or parallel to the view direction".into(),
            ));
        }
        if !(c.angle > 0.0 && c.angle < 180.0) {
            return Err(err(
                cl,
                format!("camera angle {} must be in (0, 180) degrees", c.angle),
            ));
        }
        if !(1..=16384).contains(&c.resolution.0) || !(1..=16384).contains(&c.resolution.1) {
            return Err(err(
                cl,
                format!(
                    "camera resolution {}x{} must be between 1x1 and 16384x16384",
                    c.resolution.0, c.resolution.1
                ),
            ));
        }
        if !self.background.is_finite() {
            return Err(err(0, "background colour has a non-finite number".into()));
        }
        for (i, l) in self.lights.iter().enumerate() {
            if !l.position.is_finite() || l.color.is_some_and(|c| !c.is_finite()) {
                return Err(err(light_line(i), "light has a non-finite number".into()));
            }
        }
        for (i, m) in self.materials.iter().enumerate() {
            let ml = material_line(i);
            if !(m.color.is_finite()
                && m.kd.is_finite()
                && m.ks.is_finite()
                && m.shine.is_finite()
                && m.t.is_finite()
                && m.ior.is_finite())
            {
                return Err(err(ml, "material has a non-finite number".into()));
            }
            if m.shine < 0.0 {
                return Err(err(
                    ml,
                    format!(
                        "material has Phong exponent (shine) {}: it must be >= 0",
                        m.shine
                    ),
                ));
            }
            if m.ior <= 0.0 && m.t > 0.0 {
                return Err(err(
                    ml,
                    format!(
                        "transmitting material has index of refraction {}: it must be > 0",
                        m.ior
                    ),
                ));
            }
        }
        for o in &self.objects {
            if let Some(msg) = o
                .shape
                .degeneracy()
                .filter(|_| o.shape.zero_area().is_none())
            {
                return Err(err(o.line, msg));
            }
            if o.material >= self.materials.len() {
                return Err(err(o.line, "object refers to a missing material".into()));
            }
        }
        Ok(())
    }

    /// The scene moved by `d`: objects, eye, look-at point and lights (the
    /// image is the same).
    pub fn translated(&self, d: Vec3) -> Scene {
        let mut s = self.clone();
        for o in &mut s.objects {
            o.shape = o.shape.translated(d);
        }
        s.camera.from = s.camera.from + d;
        s.camera.at = s.camera.at + d;
        for l in &mut s.lights {
            l.position = l.position + d;
        }
        s
    }

    /// Bounds of all objects.
    pub fn bounds(&self) -> Aabb {
        self.objects
            .iter()
            .fold(Aabb::EMPTY, |b, o| b.union(o.shape.bounds()))
    }

    /// How many objects of each type, indexed by [`PrimType::index`].
    pub fn type_counts(&self) -> [usize; PrimType::ALL.len()] {
        let mut n = [0; PrimType::ALL.len()];
        for o in &self.objects {
            n[o.shape.prim_type().index()] += 1;
        }
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cone_bounds_of_axis_aligned_cylinder() {
        let s = Shape::from(Cone {
            base: Vec3::new(0.0, 0.0, 0.0),
            base_radius: 1.0,
            apex: Vec3::new(0.0, 0.0, 2.0),
            apex_radius: 1.0,
            inside: false,
            caps: false,
        });
        let b = s.bounds();
        assert_eq!(b.min, Vec3::new(-1.0, -1.0, 0.0));
        assert_eq!(b.max, Vec3::new(1.0, 1.0, 2.0));
        assert_eq!(s.prim_type(), PrimType::Cylinder);
    }

    #[test]
    fn degenerate_shapes_are_named() {
        let t = Shape::from(Triangle {
            v: [Vec3::ZERO, Vec3::ONE, Vec3::ONE * 2.0],
            normals: None,
        });
        assert!(t.degeneracy().unwrap().contains("collinear"));
        let s = Shape::from(Sphere {
            center: Vec3::ZERO,
            radius: 0.0,
            inside: false,
        });
        assert!(s.degeneracy().unwrap().contains("radius"));
        let s = Shape::from(Sphere {
            center: Vec3::new(f64::NAN, 0.0, 0.0),
            radius: 1.0,
            inside: false,
        });
        assert!(s.degeneracy().unwrap().contains("non-finite"));
    }
}
