//! The sphere: `|p - center| = radius`.

use super::{Aabb, PrimType, Ray, Span, Surface, SurfaceHit, Vec3};

/// A sphere; `inside`: only the inside is visible (NFF negative radius).
#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f64,
    pub inside: bool,
}

impl Surface for Sphere {
    fn prim_type(&self) -> PrimType {
        PrimType::Sphere
    }

    fn translate(&mut self, d: Vec3) {
        self.center = self.center + d;
    }

    fn bounds(&self) -> Aabb {
        let r = Vec3::ONE * self.radius.abs();
        Aabb {
            min: self.center - r,
            max: self.center + r,
        }
    }

    /// Exact: the box's nearest point against the radius.
    fn meets(&self, b: &Aabb) -> bool {
        let mut d2 = 0.0;
        for a in 0..3 {
            let x = self.center.axis(a);
            let e = (b.min.axis(a) - x).max(x - b.max.axis(a)).max(0.0);
            d2 += e * e;
        }
        d2 <= self.radius * self.radius
    }

    fn numbers(&self) -> Vec<f64> {
        let mut out = self.center.to_array().to_vec();
        out.push(self.radius);
        out
    }

    fn coordinates(&self) -> Vec<f64> {
        self.numbers()
    }

    fn degeneracy(&self, _scale: f64) -> Option<String> {
        let radius = self.radius;
        (radius <= 0.0).then(|| format!("sphere has radius {radius}: it must be > 0"))
    }

    fn smallest_feature(&self) -> f64 {
        self.radius
    }

    fn tessellated_triangles(&self) -> usize {
        224
    }

    fn quantized(&self, r: &dyn Fn(f64) -> f64) -> Self {
        Sphere {
            center: self.center.map(r),
            radius: r(self.radius),
            inside: self.inside,
        }
    }

    /// The discriminant is computed from the distance of the centre to the
    /// ray line (pbrt-v4), which keeps small spheres seen from far away
    /// accurate.
    fn intersect(&self, r: &Ray, span: Span) -> Option<SurfaceHit> {
        let (c, radius) = (self.center, self.radius);
        let oc = r.o - c;
        let b = oc.dot(r.d);
        let f = oc - r.d * b; // from the centre to the closest point of the line
        let disc = radius * radius - f.dot(f);
        if disc < 0.0 {
            return None;
        }
        let cc = oc.dot(oc) - radius * radius;
        let q = -(b + b.signum() * disc.sqrt());
        let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q, cc / q) };
        let mut best = None;
        for t in [t0.min(t1), t0.max(t1)] {
            let n = (r.at(t) - c) / radius;
            let n = if self.inside { -n } else { n };
            span.accept(&mut best, t, n, r.d);
        }
        best
    }

    fn curved(&self) -> bool {
        true
    }

    fn inside(&self) -> bool {
        self.inside
    }
}
