//! The disc: the points `p` of the plane through `center` normal to
//! `normal` with `|p - center| <= radius` (native scenes; the caps of
//! cylinders and cones are the same surface).

use super::{Aabb, PrimType, Ray, Span, Surface, SurfaceHit, Vec3};

/// A flat disc, visible on the side its `normal` points to.
#[derive(Clone, Debug, PartialEq)]
pub struct Disc {
    pub center: Vec3,
    /// Need not be of unit length (the disc's side, not its size).
    pub normal: Vec3,
    pub radius: f64,
}

impl Surface for Disc {
    fn prim_type(&self) -> PrimType {
        PrimType::Disc
    }

    fn translate(&mut self, d: Vec3) {
        self.center = self.center + d;
    }

    /// Exact: along each axis the disc reaches `radius sin` of the angle
    /// between the axis and the normal.
    fn bounds(&self) -> Aabb {
        let n = self.normal.normalized();
        let r = self.radius.abs();
        let reach = n.map(|x| r * (1.0 - x * x).max(0.0).sqrt());
        Aabb {
            min: self.center - reach,
            max: self.center + reach,
        }
    }

    /// Conservative: false only where the disc's plane misses the box.
    fn meets(&self, b: &Aabb) -> bool {
        let n = self.normal.normalized();
        let h = b.extent() * 0.5;
        let reach = h.x * n.x.abs() + h.y * n.y.abs() + h.z * n.z.abs();
        (b.center() - self.center).dot(n).abs() <= reach
    }

    fn numbers(&self) -> Vec<f64> {
        let mut out = self.center.to_array().to_vec();
        out.extend(self.normal.to_array());
        out.push(self.radius);
        out
    }

    /// The centre and the radius (the normal is a direction, held in Q1.14).
    fn coordinates(&self) -> Vec<f64> {
        let mut out = self.center.to_array().to_vec();
        out.push(self.radius);
        out
    }

    fn degeneracy(&self, scale: f64) -> Option<String> {
        let radius = self.radius;
        if radius <= 0.0 {
            return Some(format!("disc has radius {radius}: it must be > 0"));
        }
        if radius <= scale * 1e-12 {
            return Some(format!(
                "disc has radius {radius}: under 1e-12 of its coordinates"
            ));
        }
        if self.normal.length() <= 1e-12 * scale.max(1.0) {
            return Some("disc has a zero-length normal".into());
        }
        None
    }

    fn smallest_feature(&self) -> f64 {
        self.radius
    }

    /// 16 segments, as a cylinder's cap.
    fn tessellated_triangles(&self) -> usize {
        16
    }

    fn quantized(&self, r: &dyn Fn(f64) -> f64) -> Self {
        Disc {
            center: self.center.map(r),
            normal: self.normal,
            radius: r(self.radius),
        }
    }

    fn intersect(&self, r: &Ray, span: Span) -> Option<SurfaceHit> {
        let n = self.normal.normalized();
        let dn = r.d.dot(n);
        if dn == 0.0 {
            return None;
        }
        let t = (self.center - r.o).dot(n) / dn;
        let p = r.at(t) - self.center;
        if p.dot(p) > self.radius * self.radius {
            return None;
        }
        let mut best = None;
        span.accept(&mut best, t, n, r.d);
        best
    }
}
