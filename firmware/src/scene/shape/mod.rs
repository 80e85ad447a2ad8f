//! The primitives: their types, their geometry, and what the readers, the
//! scene compiler and the reference renderer ask of one (bounds,
//! validation, transforms, the `f64` intersection the chip's kernels are
//! held to).
//!
//! Each primitive is one file and one struct implementing [`Surface`]
//! (pbrt's habit: a shape's bounds, checks and intersection live in one
//! place); [`Shape`] holds any of them and passes each question to its
//! own.

mod aabox;
mod cone;
mod disc;
mod hit;
mod polygon;
mod rectangle;
mod sphere;
mod triangle;

pub use aabox::AaBox;
pub use cone::Cone;
pub use disc::Disc;
pub use hit::{Ray, Span, SurfaceHit};
pub use polygon::Polygon;
pub use rectangle::Rectangle;
pub use sphere::Sphere;
pub use triangle::Triangle;

use super::{Aabb, Vec3};

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
    Disc,
}

impl PrimType {
    pub const ALL: [PrimType; 8] = [
        PrimType::Sphere,
        PrimType::Cylinder,
        PrimType::Cone,
        PrimType::Box,
        PrimType::Rectangle,
        PrimType::Triangle,
        PrimType::Polygon,
        PrimType::Disc,
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
            PrimType::Disc => "disc",
        }
    }
    /// The plural: "spheres", "boxes".
    pub fn plural(self) -> &'static str {
        match self {
            PrimType::Sphere => "spheres",
            PrimType::Cylinder => "cylinders",
            PrimType::Cone => "cones",
            PrimType::Box => "boxes",
            PrimType::Rectangle => "rectangles",
            PrimType::Triangle => "triangles",
            PrimType::Polygon => "polygons",
            PrimType::Disc => "discs",
        }
    }
    pub fn index(self) -> usize {
        self as usize
    }
}

/// What one primitive is in `f64`: everything the scene readers, the scene
/// compiler's fit and the reference renderer ask of it. Adding a primitive
/// means one struct implementing this, one [`Shape`] variant in the
/// `shapes!` list below, and its chip side
/// (`tracer::primitives::ChipPrimitive`).
pub trait Surface {
    fn prim_type(&self) -> PrimType;
    /// Move by `d` (directions, radii and normals unchanged).
    fn translate(&mut self, d: Vec3);
    /// A bounding box (conservative for cones).
    fn bounds(&self) -> Aabb;
    /// May the shape meet the box `b`, which its bounding box meets? The
    /// default is the bounding boxes' answer; planar shapes and spheres
    /// answer exactly.
    fn meets(&self, _b: &Aabb) -> bool {
        true
    }
    /// Every number that defines the shape (for the non-finite check).
    fn numbers(&self) -> Vec<f64>;
    /// The scene-coordinate values (points and radii) its record holds.
    fn coordinates(&self) -> Vec<f64>;
    /// Vectors its record holds that are differences of points (a
    /// rectangle's edges): they must fit the format as they are.
    fn edges(&self) -> Vec<Vec3> {
        Vec::new()
    }
    /// Why it has no area to render, if so, given the scene's `scale`
    /// (the largest coordinate of its bounds).
    fn zero_area(&self, _scale: f64) -> Option<&'static str> {
        None
    }
    /// Why it cannot be rendered, if it cannot (its numbers are finite).
    fn degeneracy(&self, _scale: f64) -> Option<String> {
        None
    }
    /// The smallest length that defines it.
    fn smallest_feature(&self) -> f64;
    /// Triangles in its documented tessellation.
    fn tessellated_triangles(&self) -> usize;
    /// The shape with every coordinate passed through `r` (the chip's
    /// rounding).
    fn quantized(&self, r: &dyn Fn(f64) -> f64) -> Self
    where
        Self: Sized;
    /// The nearest hit of `r` in `span` (the reference the chip's kernel
    /// is held to).
    fn intersect(&self, r: &Ray, span: Span) -> Option<SurfaceHit>;
    /// Its normal turns across its surface (spheres, cylinders, cones).
    fn curved(&self) -> bool {
        false
    }
    /// Only its inside is visible.
    fn inside(&self) -> bool {
        false
    }
    /// A cylinder or cone with its end caps on.
    fn capped(&self) -> bool {
        false
    }
}

/// The shape enum, its conversions, its accessors and its dispatch, from
/// one list of (variant, struct, accessor).
macro_rules! shapes {
    ($($variant:ident($ty:ident) $as:ident,)*) => {
        /// The geometry of one object.
        #[derive(Clone, Debug, PartialEq)]
        pub enum Shape {
            $($variant($ty),)*
        }

        $(impl From<$ty> for Shape {
            fn from(s: $ty) -> Shape {
                Shape::$variant(s)
            }
        })*

        impl Shape {
            $(#[doc = concat!("The ", stringify!($ty), ", if it is one.")]
            pub fn $as(&self) -> Option<&$ty> {
                match self {
                    Shape::$variant(s) => Some(s),
                    #[allow(unreachable_patterns)]
                    _ => None,
                }
            }
            )*

            /// The [`Surface`] behind the shape.
            pub fn surface(&self) -> &dyn Surface {
                match self {
                    $(Shape::$variant(s) => s,)*
                }
            }

            fn surface_mut(&mut self) -> &mut dyn Surface {
                match self {
                    $(Shape::$variant(s) => s,)*
                }
            }

            /// The shape with every coordinate passed through `r`.
            pub fn quantized(&self, r: &dyn Fn(f64) -> f64) -> Shape {
                match self {
                    $(Shape::$variant(s) => Shape::$variant(s.quantized(r)),)*
                }
            }
        }
    };
}

shapes! {
    Sphere(Sphere) as_sphere,
    Cone(Cone) as_cone,
    Box(AaBox) as_box,
    Rectangle(Rectangle) as_rectangle,
    Triangle(Triangle) as_triangle,
    Polygon(Polygon) as_polygon,
    Disc(Disc) as_disc,
}

impl Shape {
    pub fn prim_type(&self) -> PrimType {
        self.surface().prim_type()
    }

    /// A cylinder or cone with its end caps on.
    pub fn capped(&self) -> bool {
        self.surface().capped()
    }

    /// The shape moved by `d` (directions, radii and normals unchanged).
    pub fn translated(&self, d: Vec3) -> Shape {
        let mut s = self.clone();
        s.surface_mut().translate(d);
        s
    }

    /// A bounding box of the shape (conservative for cones).
    pub fn bounds(&self) -> Aabb {
        self.surface().bounds()
    }

    /// May the shape meet the box `b`? Exact for spheres and planar convex
    /// shapes (the separating axis test: the box's axes, the shape's
    /// normal, and each edge crossed with each box axis), conservative
    /// otherwise (concave polygons are tested as their convex hull would
    /// be; boxes, cylinders and cones by their bounding boxes). The BSP
    /// uses it so that a triangle goes only to the cells it meets, not to
    /// every cell its bounding box meets.
    pub fn may_overlap(&self, b: &Aabb) -> bool {
        self.bounds().overlaps(b) && self.surface().meets(b)
    }

    /// The nearest hit of `r` with `t` in `(tmin, tmax)` on an acceptable
    /// side (see [`Span`]).
    pub fn intersect(&self, r: &Ray, tmin: f64, tmax: f64, two_sided: bool) -> Option<SurfaceHit> {
        let span = Span {
            tmin,
            tmax,
            two_sided,
        };
        self.surface().intersect(r, span)
    }

    /// A polygon with the same outline, its vertices rotated so that the
    /// first three make a convex corner that is not collinear (the
    /// renderers take the plane's normal from them), and 3-vertex polygons
    /// as triangles. Vertices are not changed or dropped; a polygon of zero
    /// area is returned as it is (and [`Shape::zero_area`] names it).
    pub fn polygon(v: Vec<Vec3>, normals: Option<Vec<Vec3>>) -> Shape {
        if v.len() == 3 {
            return Shape::Triangle(Triangle {
                v: [v[0], v[1], v[2]],
                normals: normals.map(|n| [n[0], n[1], n[2]]),
            });
        }
        let n = v.len();
        if n < 3 || v.iter().any(|p| !p.is_finite()) {
            return Shape::Polygon(Polygon { v, normals });
        }
        // Newell's normal: the outline's orientation, whatever its corners.
        let newell = (0..n).fold(Vec3::ZERO, |a, i| a + v[i].cross(v[(i + 1) % n]));
        let b = Aabb::from_points(v.iter().copied());
        let scale = b.min.max_abs().max(b.max.max_abs()).max(1e-300);
        let Some(k) = (0..n).find(|&k| {
            let (a, b, c) = (v[k], v[(k + 1) % n], v[(k + 2) % n]);
            is_corner(a, b, c, scale) && (b - a).cross(c - a).dot(newell) > 0.0
        }) else {
            return Shape::Polygon(Polygon { v, normals });
        };
        let rot = |mut x: Vec<Vec3>| {
            x.rotate_left(k);
            x
        };
        Shape::Polygon(Polygon {
            v: rot(v),
            normals: normals.map(rot),
        })
    }

    /// The largest coordinate of the shape's bounds (at least 1e-300): the
    /// scale its zero tests are relative to.
    fn scale(&self) -> f64 {
        let b = self.bounds();
        b.min.max_abs().max(b.max.max_abs()).max(1e-300)
    }

    fn finite(&self) -> bool {
        self.surface().numbers().iter().all(|x| x.is_finite())
    }

    /// Why this shape has no area to render, if so: a polygon or triangle
    /// whose vertices are collinear or coincident (or with a zero-length
    /// vertex normal), a rectangle with a zero-length edge. Such a shape is
    /// skipped with a warning ([`Scene::skip_degenerate`]), not refused.
    ///
    /// [`Scene::skip_degenerate`]: super::Scene::skip_degenerate
    pub fn zero_area(&self) -> Option<&'static str> {
        if !self.finite() {
            return None; // refused by `degeneracy`
        }
        self.surface().zero_area(self.scale())
    }

    /// Why this shape cannot be rendered, if it cannot.
    pub fn degeneracy(&self) -> Option<String> {
        if !self.finite() {
            return Some(format!(
                "{} has a non-finite coordinate (NaN or infinity)",
                self.prim_type().name()
            ));
        }
        self.surface().degeneracy(self.scale())
    }
}

/// The smallest of a planar outline's edges and its first corner's height.
fn edges_and_height(v: &[Vec3]) -> f64 {
    let mut m = f64::INFINITY;
    let mut longest: f64 = 0.0;
    for k in 0..v.len() {
        let e = (v[(k + 1) % v.len()] - v[k]).length();
        m = m.min(e);
        longest = longest.max(e);
    }
    let area2 = (v[1] - v[0]).cross(v[2] - v[0]).length();
    m.min(area2 / longest)
}

/// [`sat_planar`] against the box `b`.
fn sat_box(v: &[Vec3], b: &Aabb) -> bool {
    sat_planar(v, b.center(), b.extent() * 0.5)
}

/// Whether `a`, `b`, `c` make a corner: both edges longer than `scale`
/// x 1e-12 and the sine of the angle between them over 1e-12, whatever the
/// edges' length (a 100,000-gon's corners are 6e-5 across).
fn is_corner(a: Vec3, b: Vec3, c: Vec3, scale: f64) -> bool {
    let (e1, e2) = (b - a, c - a);
    let (l1, l2) = (e1.length(), e2.length());
    let tiny = scale * 1e-12;
    l1 > tiny && l2 > tiny && e1.cross(e2).length() > 1e-12 * l1 * l2
}

/// Separating axis test of a planar polygon (vertices `v`) against the box
/// of centre `c` and half-extent `h`: false only when an axis separates
/// them (the box's axes are covered by the bounding-box test before).
fn sat_planar(v: &[Vec3], c: Vec3, h: Vec3) -> bool {
    // The vertices relative to the box's centre; on the stack for all but
    // polygons of many vertices (the BSP build calls this for every object
    // and cell it may meet).
    let mut near = [Vec3::ZERO; 16];
    let far: Vec<Vec3>;
    let p: &[Vec3] = if v.len() <= near.len() {
        for (d, &x) in near.iter_mut().zip(v) {
            *d = x - c;
        }
        &near[..v.len()]
    } else {
        far = v.iter().map(|&x| x - c).collect();
        &far
    };
    // An axis separates when every vertex projects beyond the box's
    // radius on one side: the scan stops at the first two vertices that
    // show it does not (one at most `r`, one at least `-r`), which for an
    // axis that does not separate comes after a few of them.
    let separates = |ax: Vec3| {
        let r = h.x * ax.x.abs() + h.y * ax.y.abs() + h.z * ax.z.abs();
        let (mut below, mut above) = (false, false);
        for q in p {
            let d = q.dot(ax);
            below |= d <= r;
            above |= d >= -r;
            if below && above {
                return false;
            }
        }
        true
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
mod tests;

#[cfg(test)]
mod sat_tests {
    use super::*;

    /// The textbook form of the test: every axis's whole interval of the
    /// polygon's projections against the box's radius.
    fn sat_by_intervals(v: &[Vec3], c: Vec3, h: Vec3) -> bool {
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

    /// The early-stopping scan decides as the intervals do: random planar
    /// polygons (3 to 40 vertices, some a gear's many short edges) against
    /// boxes around them, touching ones included (coordinates on a coarse
    /// grid, so that projections meet the radius exactly).
    #[test]
    fn the_scan_decides_as_the_intervals() {
        let mut x = 2024u64;
        let mut rnd = |k: u64| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((x >> 33) % k) as f64
        };
        let (mut apart, mut meet) = (0, 0);
        for _ in 0..20_000 {
            let n = 3 + rnd(38) as usize;
            // A polygon in a random axis-aligned or slanted plane.
            let (cx, cy, rad) = (rnd(9) - 4.0, rnd(9) - 4.0, 1.0 + rnd(4));
            let tilt = (rnd(5) - 2.0) / 4.0;
            let v: Vec<Vec3> = (0..n)
                .map(|k| {
                    let t = k as f64 / n as f64 * std::f64::consts::TAU;
                    let rr = if k % 2 == 0 { rad } else { rad * 0.75 };
                    let (px, py) = (cx + rr * t.cos(), cy + rr * t.sin());
                    Vec3::new(px, py, tilt * px + 0.5 * rnd(3))
                })
                .collect();
            let c = Vec3::new(rnd(17) - 8.0, rnd(17) - 8.0, rnd(9) - 4.0) * 0.5;
            let h = Vec3::new(1.0 + rnd(4), 1.0 + rnd(4), 1.0 + rnd(4)) * 0.5;
            let want = sat_by_intervals(&v, c, h);
            assert_eq!(sat_planar(&v, c, h), want, "{v:?} {c:?} {h:?}");
            if want {
                meet += 1;
            } else {
                apart += 1;
            }
        }
        assert!(apart > 1000 && meet > 1000, "{apart} apart, {meet} meet");
    }
}
