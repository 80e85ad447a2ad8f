//! The rectangle `corner + u edge1 + v edge2`, `u`, `v` in `[0, 1]`.

use super::{sat_box, Aabb, PrimType, Ray, Span, Surface, SurfaceHit, Vec3};

/// A rectangle; its edges are perpendicular, and it is visible on the
/// side of `edge1 x edge2`.
#[derive(Clone, Debug, PartialEq)]
pub struct Rectangle {
    pub corner: Vec3,
    pub edge1: Vec3,
    pub edge2: Vec3,
}

impl Rectangle {
    fn corners(&self) -> [Vec3; 4] {
        let (c, e1, e2) = (self.corner, self.edge1, self.edge2);
        [c, c + e1, c + e1 + e2, c + e2]
    }
}

impl Surface for Rectangle {
    fn prim_type(&self) -> PrimType {
        PrimType::Rectangle
    }

    fn translate(&mut self, d: Vec3) {
        self.corner = self.corner + d;
    }

    fn bounds(&self) -> Aabb {
        Aabb::from_points(self.corners())
    }

    /// Exact (the separating axis test).
    fn meets(&self, b: &Aabb) -> bool {
        sat_box(&self.corners(), b)
    }

    fn numbers(&self) -> Vec<f64> {
        [self.corner, self.edge1, self.edge2]
            .iter()
            .flat_map(|p| p.to_array())
            .collect()
    }

    /// The corner only: the edges are differences of two points, which the
    /// guard bit covers ([`Surface::edges`]).
    fn coordinates(&self) -> Vec<f64> {
        self.corner.to_array().to_vec()
    }

    fn edges(&self) -> Vec<Vec3> {
        vec![self.edge1, self.edge2]
    }

    fn zero_area(&self, scale: f64) -> Option<&'static str> {
        let tiny = scale * 1e-12;
        (self.edge1.length() <= tiny || self.edge2.length() <= tiny).then_some("a zero-length edge")
    }

    fn degeneracy(&self, scale: f64) -> Option<String> {
        let tiny = scale * 1e-12;
        let (l1, l2) = (self.edge1.length(), self.edge2.length());
        if l1 <= tiny || l2 <= tiny {
            return Some("rectangle has a zero-length edge".into());
        }
        if self.edge1.dot(self.edge2).abs() > 1e-6 * l1 * l2 {
            return Some("rectangle edges are not perpendicular".into());
        }
        None
    }

    fn smallest_feature(&self) -> f64 {
        self.edge1.length().min(self.edge2.length())
    }

    fn tessellated_triangles(&self) -> usize {
        2
    }

    fn quantized(&self, r: &dyn Fn(f64) -> f64) -> Self {
        Rectangle {
            corner: self.corner.map(r),
            edge1: self.edge1.map(r),
            edge2: self.edge2.map(r),
        }
    }

    fn intersect(&self, r: &Ray, span: Span) -> Option<SurfaceHit> {
        let (corner, e1, e2) = (self.corner, self.edge1, self.edge2);
        let n = e1.cross(e2).normalized();
        let dn = r.d.dot(n);
        if dn == 0.0 {
            return None;
        }
        let t = (corner - r.o).dot(n) / dn;
        let p = r.at(t) - corner;
        let (u, v) = (p.dot(e1) / e1.dot(e1), p.dot(e2) / e2.dot(e2));
        if !((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)) {
            return None;
        }
        let mut best = None;
        span.accept(&mut best, t, n, r.d);
        best
    }
}
