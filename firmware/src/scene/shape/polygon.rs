//! The planar polygon of 4 or more vertices, convex or concave.

use super::{is_corner, sat_box, Aabb, PrimType, Ray, Span, Surface, SurfaceHit, Vec3};

/// A planar polygon, convex or concave (even-odd rule), counter-clockwise
/// seen from the visible side; optional vertex normals (NFF `pp`).
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    pub v: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
}

impl Surface for Polygon {
    fn prim_type(&self) -> PrimType {
        PrimType::Polygon
    }

    fn translate(&mut self, d: Vec3) {
        self.v.iter_mut().for_each(|p| *p = *p + d);
    }

    fn bounds(&self) -> Aabb {
        Aabb::from_points(self.v.iter().copied())
    }

    /// Exact for convex polygons; a concave one is tested as its convex
    /// hull would be.
    fn meets(&self, b: &Aabb) -> bool {
        sat_box(&self.v, b)
    }

    fn numbers(&self) -> Vec<f64> {
        let vn = self.normals.iter().flatten();
        self.v.iter().chain(vn).flat_map(|p| p.to_array()).collect()
    }

    fn coordinates(&self) -> Vec<f64> {
        self.v.iter().flat_map(|p| p.to_array()).collect()
    }

    fn zero_area(&self, scale: f64) -> Option<&'static str> {
        let (v, tiny) = (&self.v, scale * 1e-12);
        let n = v.len();
        let newell = (0..n).fold(Vec3::ZERO, |a, i| a + v[i].cross(v[(i + 1) % n]));
        if n >= 3 && newell.length() <= tiny * scale {
            Some("collinear or coincident vertices")
        } else if n >= 3 && !is_corner(v[0], v[1], v[2], scale) {
            // no convex corner found: a sliver
            Some("collinear or coincident vertices")
        } else if self
            .normals
            .as_ref()
            .is_some_and(|n| n.iter().any(|n| n.length() <= 0.0))
        {
            Some("a zero-length vertex normal")
        } else {
            None
        }
    }

    fn degeneracy(&self, scale: f64) -> Option<String> {
        let v = &self.v;
        if v.len() < 3 {
            return Some(format!(
                "polygon has {} vertices: it needs at least 3",
                v.len()
            ));
        }
        if !is_corner(v[0], v[1], v[2], scale) {
            return Some("polygon's first three vertices are collinear".into());
        }
        // The plane of the first corner (what the renderers use); its
        // direction is accurate even where the corner is small.
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
        if let Some(ns) = &self.normals {
            if ns.iter().any(|n| n.length() <= 0.0) {
                return Some("polygon has a zero vertex normal".into());
            }
        }
        None
    }

    fn smallest_feature(&self) -> f64 {
        super::edges_and_height(&self.v)
    }

    fn tessellated_triangles(&self) -> usize {
        self.v.len() - 2
    }

    /// The vertex normals are not part of the chip's record: they go.
    fn quantized(&self, r: &dyn Fn(f64) -> f64) -> Self {
        Polygon {
            v: self.v.iter().map(|p| p.map(r)).collect(),
            normals: None,
        }
    }

    /// The even-odd rule in the plane of the two axes where the normal is
    /// smallest; the plane is the first three vertices'.
    fn intersect(&self, r: &Ray, span: Span) -> Option<SurfaceHit> {
        let v = &self.v;
        let n = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
        let dn = r.d.dot(n);
        if dn == 0.0 {
            return None;
        }
        let t = (v[0] - r.o).dot(n) / dn;
        if !(t > span.tmin && t < span.tmax) {
            return None;
        }
        let p = r.at(t);
        let drop = if n.x.abs() >= n.y.abs() && n.x.abs() >= n.z.abs() {
            0
        } else if n.y.abs() >= n.z.abs() {
            1
        } else {
            2
        };
        let (i, j) = match drop {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        };
        let (px, py) = (p.axis(i), p.axis(j));
        let mut inside = false;
        for k in 0..v.len() {
            let (a, b) = (v[k], v[(k + 1) % v.len()]);
            let (ax, ay, bx, by) = (a.axis(i), a.axis(j), b.axis(i), b.axis(j));
            if (ay > py) != (by > py) && px < ax + (py - ay) * (bx - ax) / (by - ay) {
                inside = !inside;
            }
        }
        if !inside {
            return None;
        }
        let mut best = None;
        span.accept(&mut best, t, n, r.d);
        best
    }
}
