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

pub mod native;
pub mod nff;
pub mod spd;

use std::fmt;
use std::ops::{Add, Div, Mul, Neg, Sub};
use std::path::Path;

/// A 3-vector of `f64`: points, directions and RGB colours.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "Vec<f64>", into = "[f64; 3]")]
pub struct Vec3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl From<[f64; 3]> for Vec3 {
    fn from(a: [f64; 3]) -> Self {
        Vec3::new(a[0], a[1], a[2])
    }
}
/// A vector read from a scene file: exactly three numbers.
impl TryFrom<Vec<f64>> for Vec3 {
    type Error = String;
    fn try_from(v: Vec<f64>) -> Result<Self, String> {
        match v[..] {
            [x, y, z] => Ok(Vec3::new(x, y, z)),
            _ => Err(format!("expected 3 numbers [x, y, z], found {}", v.len())),
        }
    }
}
impl From<Vec3> for [f64; 3] {
    fn from(v: Vec3) -> Self {
        [v.x, v.y, v.z]
    }
}

impl Vec3 {
    pub const ZERO: Vec3 = Vec3 {
        x: 0.0,
        y: 0.0,
        z: 0.0,
    };
    pub const ONE: Vec3 = Vec3 {
        x: 1.0,
        y: 1.0,
        z: 1.0,
    };
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Vec3 { x, y, z }
    }
    pub fn dot(self, o: Vec3) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    pub fn cross(self, o: Vec3) -> Vec3 {
        Vec3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    pub fn length(self) -> f64 {
        self.dot(self).sqrt()
    }
    pub fn normalized(self) -> Vec3 {
        self / self.length()
    }
    pub fn mul_elem(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x * o.x, self.y * o.y, self.z * o.z)
    }
    pub fn min(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x.min(o.x), self.y.min(o.y), self.z.min(o.z))
    }
    pub fn max(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x.max(o.x), self.y.max(o.y), self.z.max(o.z))
    }
    pub fn axis(self, a: usize) -> f64 {
        match a {
            0 => self.x,
            1 => self.y,
            _ => self.z,
        }
    }
    pub fn max_abs(self) -> f64 {
        self.x.abs().max(self.y.abs()).max(self.z.abs())
    }
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
    pub fn to_array(self) -> [f64; 3] {
        [self.x, self.y, self.z]
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    fn add(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl Sub for Vec3 {
    type Output = Vec3;
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl Mul<f64> for Vec3 {
    type Output = Vec3;
    fn mul(self, s: f64) -> Vec3 {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}
impl Div<f64> for Vec3 {
    type Output = Vec3;
    fn div(self, s: f64) -> Vec3 {
        Vec3::new(self.x / s, self.y / s, self.z / s)
    }
}
impl Neg for Vec3 {
    type Output = Vec3;
    fn neg(self) -> Vec3 {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
        max: Vec3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
    };
    pub fn from_points(pts: impl IntoIterator<Item = Vec3>) -> Aabb {
        pts.into_iter().fold(Aabb::EMPTY, |b, p| b.grow(p))
    }
    pub fn grow(self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
    pub fn surface_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
    /// Do the two boxes overlap (touching counts)?
    pub fn overlaps(&self, o: &Aabb) -> bool {
        self.min.x <= o.max.x
            && o.min.x <= self.max.x
            && self.min.y <= o.max.y
            && o.min.y <= self.max.y
            && self.min.z <= o.max.z
            && o.min.z <= self.max.z
    }
}

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

/// The primitive types, in the order the scene image lists them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum PrimType {
    Sphere,
    Cylinder,
    Cone,
    Box,
    Rectangle,
    Triangle,
    Polygon,
}

impl PrimType {
    pub const ALL: [PrimType; 7] = [
        PrimType::Sphere,
        PrimType::Cylinder,
        PrimType::Cone,
        PrimType::Box,
        PrimType::Rectangle,
        PrimType::Triangle,
        PrimType::Polygon,
    ];
    pub fn name(self) -> &'static str {
        match self {
            PrimType::Sphere => "sphere",
            PrimType::Cylinder => "cylinder",
            PrimType::Cone => "cone",
            PrimType::Box => "box",
            PrimType::Rectangle => "rectangle",
            PrimType::Triangle => "triangle",
            PrimType::Polygon => "polygon",
        }
    }
    pub fn index(self) -> usize {
        self as usize
    }
}

/// The geometry of one object.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// `inside`: only the inside is visible (NFF negative radius).
    Sphere {
        center: Vec3,
        radius: f64,
        inside: bool,
    },
    /// A cylinder (equal radii) or truncated cone between two points, open
    /// unless `caps` (native format only). `inside` as for the sphere.
    Cone {
        base: Vec3,
        base_radius: f64,
        apex: Vec3,
        apex_radius: f64,
        inside: bool,
        caps: bool,
    },
    /// An axis-aligned box, visible from outside.
    Box { min: Vec3, max: Vec3 },
    /// A rectangle `corner + u*edge1 + v*edge2`, u, v in [0, 1]; edges
    /// perpendicular; visible on the side of `edge1 x edge2`.
    Rectangle {
        corner: Vec3,
        edge1: Vec3,
        edge2: Vec3,
    },
    /// Counter-clockwise seen from the visible side; optional vertex
    /// normals (NFF `pp`) for shading.
    Triangle {
        v: [Vec3; 3],
        normals: Option<[Vec3; 3]>,
    },
    /// A planar polygon of 4 or more vertices, convex or concave (even-odd
    /// rule), counter-clockwise seen from the visible side.
    Polygon {
        v: Vec<Vec3>,
        normals: Option<Vec<Vec3>>,
    },
}

impl Shape {
    pub fn prim_type(&self) -> PrimType {
        match self {
            Shape::Sphere { .. } => PrimType::Sphere,
            Shape::Cone {
                base_radius,
                apex_radius,
                ..
            } => {
                if base_radius == apex_radius {
                    PrimType::Cylinder
                } else {
                    PrimType::Cone
                }
            }
            Shape::Box { .. } => PrimType::Box,
            Shape::Rectangle { .. } => PrimType::Rectangle,
            Shape::Triangle { .. } => PrimType::Triangle,
            Shape::Polygon { .. } => PrimType::Polygon,
        }
    }

    /// The shape moved by `d` (directions, radii and normals unchanged).
    pub fn translated(&self, d: Vec3) -> Shape {
        let mut s = self.clone();
        match &mut s {
            Shape::Sphere { center, .. } => *center = *center + d,
            Shape::Cone { base, apex, .. } => {
                *base = *base + d;
                *apex = *apex + d;
            }
            Shape::Box { min, max } => {
                *min = *min + d;
                *max = *max + d;
            }
            Shape::Rectangle { corner, .. } => *corner = *corner + d,
            Shape::Triangle { v, .. } => v.iter_mut().for_each(|p| *p = *p + d),
            Shape::Polygon { v, .. } => v.iter_mut().for_each(|p| *p = *p + d),
        }
        s
    }

    /// A bounding box of the shape (conservative for cones).
    pub fn bounds(&self) -> Aabb {
        match self {
            Shape::Sphere { center, radius, .. } => {
                let r = Vec3::ONE * radius.abs();
                Aabb {
                    min: *center - r,
                    max: *center + r,
                }
            }
            Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
                ..
            } => {
                // Exact bound of a disc of radius r with axis a: the extent
                // along coordinate i is r * sqrt(1 - a_i^2).
                let a = (*apex - *base).normalized();
                let e = |r: f64| {
                    Vec3::new(
                        r * (1.0 - a.x * a.x).max(0.0).sqrt(),
                        r * (1.0 - a.y * a.y).max(0.0).sqrt(),
                        r * (1.0 - a.z * a.z).max(0.0).sqrt(),
                    )
                };
                let (eb, ea) = (e(base_radius.abs()), e(apex_radius.abs()));
                Aabb {
                    min: (*base - eb).min(*apex - ea),
                    max: (*base + eb).max(*apex + ea),
                }
            }
            Shape::Box { min, max } => Aabb {
                min: *min,
                max: *max,
            },
            Shape::Rectangle {
                corner,
                edge1,
                edge2,
            } => Aabb::from_points([
                *corner,
                *corner + *edge1,
                *corner + *edge2,
                *corner + *edge1 + *edge2,
            ]),
            Shape::Triangle { v, .. } => Aabb::from_points(v.iter().copied()),
            Shape::Polygon { v, .. } => Aabb::from_points(v.iter().copied()),
        }
    }

    /// May the shape meet the box `b`? Exact for spheres and planar convex
    /// shapes (the separating axis test: the box's axes, the shape's
    /// normal, and each edge crossed with each box axis), conservative
    /// otherwise (concave polygons are tested as their convex hull would
    /// be; boxes, cylinders and cones by their bounding boxes). The BSP
    /// uses it so that a triangle goes only to the cells it meets, not to
    /// every cell its bounding box meets.
    pub fn may_overlap(&self, b: &Aabb) -> bool {
        if !self.bounds().overlaps(b) {
            return false;
        }
        let c = b.center();
        let h = b.extent() * 0.5;
        match self {
            Shape::Sphere { center, radius, .. } => {
                let mut d2 = 0.0;
                for a in 0..3 {
                    let x = center.axis(a);
                    let e = (b.min.axis(a) - x).max(x - b.max.axis(a)).max(0.0);
                    d2 += e * e;
                }
                d2 <= radius * radius
            }
            Shape::Triangle { v, .. } => sat_planar(&v[..], c, h),
            Shape::Polygon { v, .. } => sat_planar(v, c, h),
            Shape::Rectangle {
                corner,
                edge1,
                edge2,
            } => sat_planar(
                &[
                    *corner,
                    *corner + *edge1,
                    *corner + *edge1 + *edge2,
                    *corner + *edge2,
                ],
                c,
                h,
            ),
            Shape::Box { .. } | Shape::Cone { .. } => true,
        }
    }

    /// Every number that defines the shape (for the non-finite check).
    fn numbers(&self) -> Vec<f64> {
        let mut out = Vec::new();
        let mut p = |v: &Vec3| out.extend_from_slice(&v.to_array());
        match self {
            Shape::Sphere { center, .. } => p(center),
            Shape::Cone { base, apex, .. } => {
                p(base);
                p(apex)
            }
            Shape::Box { min, max } => {
                p(min);
                p(max)
            }
            Shape::Rectangle {
                corner,
                edge1,
                edge2,
            } => {
                p(corner);
                p(edge1);
                p(edge2)
            }
            Shape::Triangle { v, normals } => {
                v.iter().for_each(&mut p);
                normals.iter().flatten().for_each(&mut p);
            }
            Shape::Polygon { v, normals } => {
                v.iter().for_each(&mut p);
                normals.iter().flatten().for_each(&mut p);
            }
        }
        match self {
            Shape::Sphere { radius, .. } => out.push(*radius),
            Shape::Cone {
                base_radius,
                apex_radius,
                ..
            } => {
                out.push(*base_radius);
                out.push(*apex_radius)
            }
            _ => {}
        }
        out
    }

    /// A polygon with the same outline, its vertices rotated so that the
    /// first three make a convex corner that is not collinear (the
    /// renderers take the plane's normal from them), and 3-vertex polygons
    /// as triangles. Vertices are not changed or dropped; a polygon of zero
    /// area is returned as it is (and [`Shape::zero_area`] names it).
    pub fn polygon(v: Vec<Vec3>, normals: Option<Vec<Vec3>>) -> Shape {
        if v.len() == 3 {
            return Shape::Triangle {
                v: [v[0], v[1], v[2]],
                normals: normals.map(|n| [n[0], n[1], n[2]]),
            };
        }
        let n = v.len();
        if n < 3 || v.iter().any(|p| !p.is_finite()) {
            return Shape::Polygon { v, normals };
        }
        // Newell's normal: the outline's orientation, whatever its corners.
        let newell = (0..n).fold(Vec3::ZERO, |a, i| a + v[i].cross(v[(i + 1) % n]));
        let b = Aabb::from_points(v.iter().copied());
        let scale = b.min.max_abs().max(b.max.max_abs()).max(1e-300);
        let tiny = scale * scale * 1e-12;
        let corner = |k: usize| (v[(k + 1) % n] - v[k]).cross(v[(k + 2) % n] - v[k]);
        let Some(k) = (0..n).find(|&k| {
            let c = corner(k);
            c.length() > tiny && c.dot(newell) > 0.0
        }) else {
            return Shape::Polygon { v, normals };
        };
        let rot = |mut x: Vec<Vec3>| {
            x.rotate_left(k);
            x
        };
        Shape::Polygon {
            v: rot(v),
            normals: normals.map(rot),
        }
    }

    /// Why this shape has no area to render, if so: a polygon or triangle
    /// whose vertices are collinear or coincident (or with a zero-length
    /// vertex normal), a rectangle with a zero-length edge. Such a shape is
    /// skipped with a warning ([`Scene::skip_degenerate`]), not refused.
    pub fn zero_area(&self) -> Option<&'static str> {
        if self.numbers().iter().any(|x| !x.is_finite()) {
            return None; // refused by `degeneracy`
        }
        let b = self.bounds();
        let scale = b.min.max_abs().max(b.max.max_abs()).max(1e-300);
        let tiny = scale * 1e-12;
        let zero_normal = |ns: &[Vec3]| ns.iter().any(|n| n.length() <= 0.0);
        match self {
            Shape::Triangle { v, normals } => {
                if (v[1] - v[0]).cross(v[2] - v[0]).length() <= tiny * scale {
                    Some("collinear or coincident vertices")
                } else if normals.as_ref().is_some_and(|n| zero_normal(n)) {
                    Some("a zero-length vertex normal")
                } else {
                    None
                }
            }
            Shape::Polygon { v, normals } => {
                let n = v.len();
                let newell = (0..n).fold(Vec3::ZERO, |a, i| a + v[i].cross(v[(i + 1) % n]));
                if n >= 3 && newell.length() <= tiny * scale {
                    Some("collinear or coincident vertices")
                } else if n >= 3 && (v[1] - v[0]).cross(v[2] - v[0]).length() <= tiny * scale {
                    // no convex corner found: a sliver
                    Some("collinear or coincident vertices")
                } else if normals.as_ref().is_some_and(|n| zero_normal(n)) {
                    Some("a zero-length vertex normal")
                } else {
                    None
                }
            }
            Shape::Rectangle { edge1, edge2, .. } => {
                (edge1.length() <= tiny || edge2.length() <= tiny).then_some("a zero-length edge")
            }
            _ => None,
        }
    }

    /// Why this shape cannot be rendered, if it cannot.
    pub fn degeneracy(&self) -> Option<String> {
        if self.numbers().iter().any(|x| !x.is_finite()) {
            return Some(format!(
                "{} has a non-finite coordinate (NaN or infinity)",
                self.prim_type().name()
            ));
        }
        let scale = {
            let b = self.bounds();
            b.min.max_abs().max(b.max.max_abs()).max(1e-300)
        };
        let tiny = scale * 1e-12;
        match self {
            Shape::Sphere { radius, .. } => {
                if *radius <= 0.0 {
                    return Some(format!("sphere has radius {radius}: it must be > 0"));
                }
            }
            Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
                ..
            } => {
                if (*apex - *base).length() <= tiny {
                    return Some("cone/cylinder has coincident base and apex points".into());
                }
                if *base_radius < 0.0 || *apex_radius < 0.0 {
                    return Some("cone/cylinder radii must both be >= 0".into());
                }
                if *base_radius == 0.0 && *apex_radius == 0.0 {
                    return Some("cone/cylinder has zero radius at both ends".into());
                }
            }
            Shape::Box { min, max } => {
                if !(min.x < max.x && min.y < max.y && min.z < max.z) {
                    return Some(
                        "box has min >= max on some axis (zero or negative volume)".into(),
                    );
                }
            }
            Shape::Rectangle { edge1, edge2, .. } => {
                let (l1, l2) = (edge1.length(), edge2.length());
                if l1 <= tiny || l2 <= tiny {
                    return Some("rectangle has a zero-length edge".into());
                }
                if edge1.dot(*edge2).abs() > 1e-6 * l1 * l2 {
                    return Some("rectangle edges are not perpendicular".into());
                }
            }
            Shape::Triangle { v, normals } => {
                if (v[1] - v[0]).cross(v[2] - v[0]).length() <= tiny * scale {
                    return Some("triangle has collinear (or coincident) vertices".into());
                }
                if let Some(n) = normals {
                    if n.iter().any(|n| n.length() <= 0.0) {
                        return Some("triangle has a zero vertex normal".into());
                    }
                }
            }
            Shape::Polygon { v, normals } => {
                if v.len() < 3 {
                    return Some(format!(
                        "polygon has {} vertices: it needs at least 3",
                        v.len()
                    ));
                }
                let n = (v[1] - v[0]).cross(v[2] - v[0]);
                if n.length() <= tiny * scale {
                    return Some("polygon's first three vertices are collinear".into());
                }
                let n = n.normalized();
                let ext = self.bounds().extent().max_abs();
                for (i, p) in v.iter().enumerate() {
                    if (*p - v[0]).dot(n).abs() > 1e-4 * ext {
                        return Some(format!(
                            "polygon vertex {} is not in the plane of the first three",
                            i + 1
                        ));
                    }
                }
                if let Some(ns) = normals {
                    if ns.iter().any(|n| n.length() <= 0.0) {
                        return Some("polygon has a zero vertex normal".into());
                    }
                }
            }
        }
        None
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
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
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
    pub fn type_counts(&self) -> [usize; 7] {
        let mut n = [0; 7];
        for o in &self.objects {
            n[o.shape.prim_type().index()] += 1;
        }
        n
    }
}

/// Separating axis test of a planar polygon (vertices `v`) against the box
/// of centre `c` and half-extent `h`: false only when an axis separates
/// them (the box's axes are covered by the bounding-box test before).
fn sat_planar(v: &[Vec3], c: Vec3, h: Vec3) -> bool {
    let p: Vec<Vec3> = v.iter().map(|&x| x - c).collect();
    let separates = |ax: Vec3| {
        let r = h.x * ax.x.abs() + h.y * ax.y.abs() + h.z * ax.z.abs();
        let (lo, hi) = p
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
                let d = q.dot(ax);
                (lo.min(d), hi.max(d))
            });
        lo > r || hi < -r
    };
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    if n.dot(n) > 0.0 && separates(n) {
        return false;
    }
    let axes = [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
    ];
    for k in 0..p.len() {
        let e = p[(k + 1) % p.len()] - p[k];
        for a in axes {
            let ax = e.cross(a);
            if ax.dot(ax) > 0.0 && separates(ax) {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cone_bounds_of_axis_aligned_cylinder() {
        let s = Shape::Cone {
            base: Vec3::new(0.0, 0.0, 0.0),
            base_radius: 1.0,
            apex: Vec3::new(0.0, 0.0, 2.0),
            apex_radius: 1.0,
            inside: false,
            caps: false,
        };
        let b = s.bounds();
        assert_eq!(b.min, Vec3::new(-1.0, -1.0, 0.0));
        assert_eq!(b.max, Vec3::new(1.0, 1.0, 2.0));
        assert_eq!(s.prim_type(), PrimType::Cylinder);
    }

    #[test]
    fn degenerate_shapes_are_named() {
        let t = Shape::Triangle {
            v: [Vec3::ZERO, Vec3::ONE, Vec3::ONE * 2.0],
            normals: None,
        };
        assert!(t.degeneracy().unwrap().contains("collinear"));
        let s = Shape::Sphere {
            center: Vec3::ZERO,
            radius: 0.0,
            inside: false,
        };
        assert!(s.degeneracy().unwrap().contains("radius"));
        let s = Shape::Sphere {
            center: Vec3::new(f64::NAN, 0.0, 0.0),
            radius: 1.0,
            inside: false,
        };
        assert!(s.degeneracy().unwrap().contains("non-finite"));
    }
}
