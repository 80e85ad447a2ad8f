//! The triangle, flat or with vertex normals (NFF `pp`).

use super::{sat_box, Aabb, PrimType, Ray, Span, Surface, SurfaceHit, Vec3};

/// A triangle, counter-clockwise seen from the visible side; optional
/// vertex normals for shading.
#[derive(Clone, Debug, PartialEq)]
pub struct Triangle {
    pub v: [Vec3; 3],
    pub normals: Option<[Vec3; 3]>,
}

impl Surface for Triangle {
    fn prim_type(&self) -> PrimType {
        PrimType::Triangle
    }

    fn translate(&mut self, d: Vec3) {
        self.v.iter_mut().for_each(|p| *p = *p + d);
    }

    fn bounds(&self) -> Aabb {
        Aabb::from_points(self.v.iter().copied())
    }

    /// Exact (the separating axis test).
    fn meets(&self, b: &Aabb) -> bool {
        sat_box(&self.v[..], b)
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
        if (v[1] - v[0]).cross(v[2] - v[0]).length() <= tiny * scale {
            Some("collinear or coincident vertices")
        } else if self
            .normals
            .is_some_and(|n| n.iter().any(|n| n.length() <= 0.0))
        {
            Some("a zero-length vertex normal")
        } else {
            None
        }
    }

    fn degeneracy(&self, scale: f64) -> Option<String> {
        let (v, tiny) = (&self.v, scale * 1e-12);
        if (v[1] - v[0]).cross(v[2] - v[0]).length() <= tiny * scale {
            return Some("triangle has collinear (or coincident) vertices".into());
        }
        if self
            .normals
            .is_some_and(|n| n.iter().any(|n| n.length() <= 0.0))
        {
            return Some("triangle has a zero vertex normal".into());
        }
        None
    }

    fn smallest_feature(&self) -> f64 {
        super::edges_and_height(&self.v)
    }

    fn tessellated_triangles(&self) -> usize {
        1
    }

    /// The vertex normals are not part of the chip's record: they go.
    fn quantized(&self, r: &dyn Fn(f64) -> f64) -> Self {
        Triangle {
            v: self.v.map(|p| p.map(r)),
            normals: None,
        }
    }

    /// Moller-Trumbore; vertex normals, if any, are interpolated for
    /// shading.
    fn intersect(&self, r: &Ray, span: Span) -> Option<SurfaceHit> {
        let v = &self.v;
        let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
        let pv = r.d.cross(e2);
        let det = e1.dot(pv);
        if det == 0.0 || (det < 0.0 && !span.two_sided) {
            return None;
        }
        let tv = r.o - v[0];
        let u = tv.dot(pv) / det;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let qv = tv.cross(e1);
        let w = r.d.dot(qv) / det;
        if w < 0.0 || u + w > 1.0 {
            return None;
        }
        let t = e2.dot(qv) / det;
        let n = e1.cross(e2).normalized();
        let mut best = None;
        span.accept(&mut best, t, n, r.d);
        if let (Some(h), Some(ns)) = (best.as_mut(), self.normals.as_ref()) {
            let s = (ns[0].normalized() * (1.0 - u - w)
                + ns[1].normalized() * u
                + ns[2].normalized() * w)
                .normalized();
            // A vertex normal on the far side would flip the shading: keep
            // the geometric normal's side.
            h.ns = if s.dot(n) > 0.0 { s } else { n };
        }
        best
    }
}
