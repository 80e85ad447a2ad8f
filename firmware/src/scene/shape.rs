//! The primitives: their types, their geometry, and what the readers,
//! the scene compiler and the reference renderer ask of one (bounds,
//! validation, transforms).

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

    /// A cylinder or cone with its end caps on.
    pub fn capped(&self) -> bool {
        matches!(self, Shape::Cone { caps: true, .. })
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
        let Some(k) = (0..n).find(|&k| {
            let (a, b, c) = (v[k], v[(k + 1) % n], v[(k + 2) % n]);
            is_corner(a, b, c, scale) && (b - a).cross(c - a).dot(newell) > 0.0
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
                } else if n >= 3 && !is_corner(v[0], v[1], v[2], scale) {
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
                if !is_corner(v[0], v[1], v[2], scale) {
                    return Some("polygon's first three vertices are collinear".into());
                }
                // The plane of the first corner (what the renderers use);
                // its direction is accurate even where the corner is small.
                let n = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
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
mod tests {
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
