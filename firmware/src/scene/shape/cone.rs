//! The cylinder and the truncated cone: `|radial(p)| = rb + (ra - rb) s / h`
//! for `s` in `[0, h]` along the axis from `base` to `apex`.

use super::hit::quadratic;
use super::{Aabb, PrimType, Ray, Span, Surface, SurfaceHit, Vec3};

/// A cylinder (equal radii) or truncated cone between two points, open
/// unless `caps` (native format only). `inside` as for the sphere.
#[derive(Clone, Debug, PartialEq)]
pub struct Cone {
    pub base: Vec3,
    pub base_radius: f64,
    pub apex: Vec3,
    pub apex_radius: f64,
    pub inside: bool,
    pub caps: bool,
}

impl Surface for Cone {
    fn prim_type(&self) -> PrimType {
        if self.base_radius == self.apex_radius {
            PrimType::Cylinder
        } else {
            PrimType::Cone
        }
    }

    fn translate(&mut self, d: Vec3) {
        self.base = self.base + d;
        self.apex = self.apex + d;
    }

    /// Exact bound of a disc of radius r with axis a: the extent along
    /// coordinate i is r * sqrt(1 - a_i^2).
    fn bounds(&self) -> Aabb {
        let a = (self.apex - self.base).normalized();
        let e = |r: f64| {
            Vec3::new(
                r * (1.0 - a.x * a.x).max(0.0).sqrt(),
                r * (1.0 - a.y * a.y).max(0.0).sqrt(),
                r * (1.0 - a.z * a.z).max(0.0).sqrt(),
            )
        };
        let (eb, ea) = (e(self.base_radius.abs()), e(self.apex_radius.abs()));
        Aabb {
            min: (self.base - eb).min(self.apex - ea),
            max: (self.base + eb).max(self.apex + ea),
        }
    }

    fn numbers(&self) -> Vec<f64> {
        self.coordinates()
    }

    fn coordinates(&self) -> Vec<f64> {
        let mut out = self.base.to_array().to_vec();
        out.extend_from_slice(&self.apex.to_array());
        out.push(self.base_radius);
        out.push(self.apex_radius);
        out
    }

    fn degeneracy(&self, scale: f64) -> Option<String> {
        let tiny = scale * 1e-12;
        if (self.apex - self.base).length() <= tiny {
            return Some("cone/cylinder has coincident base and apex points".into());
        }
        if self.base_radius < 0.0 || self.apex_radius < 0.0 {
            return Some("cone/cylinder radii must both be >= 0".into());
        }
        if self.base_radius == 0.0 && self.apex_radius == 0.0 {
            return Some("cone/cylinder has zero radius at both ends".into());
        }
        None
    }

    fn smallest_feature(&self) -> f64 {
        let r = self.base_radius.max(self.apex_radius);
        r.min((self.apex - self.base).length())
    }

    /// 16 segments (32 triangles), plus 16 per cap of non-zero radius.
    fn tessellated_triangles(&self) -> usize {
        let capn = if self.caps {
            16 * ((self.base_radius > 0.0) as usize + (self.apex_radius > 0.0) as usize)
        } else {
            0
        };
        32 + capn
    }

    fn quantized(&self, r: &dyn Fn(f64) -> f64) -> Self {
        Cone {
            base: self.base.map(r),
            base_radius: r(self.base_radius),
            apex: self.apex.map(r),
            apex_radius: r(self.apex_radius),
            inside: self.inside,
            caps: self.caps,
        }
    }

    fn intersect(&self, r: &Ray, span: Span) -> Option<SurfaceHit> {
        let (base, rb, apex, ra) = (self.base, self.base_radius, self.apex, self.apex_radius);
        let axis = apex - base;
        let h = axis.length();
        let a = axis / h;
        let k = (ra - rb) / h;
        let oc = r.o - base;
        let (dv, ov) = (r.d.dot(a), oc.dot(a));
        let (dp, op) = (r.d - a * dv, oc - a * ov);
        let r0 = rb + k * ov; // radius at the origin's axial position
        let qa = dp.dot(dp) - k * k * dv * dv;
        let qb = op.dot(dp) - r0 * k * dv;
        let qc = op.dot(op) - r0 * r0;
        let sign = if self.inside { -1.0 } else { 1.0 };
        let mut best = None;
        if let Some((t0, t1)) = quadratic(qa, qb, qc) {
            for t in [t0, t1] {
                let s = ov + t * dv;
                if !(0.0..=h).contains(&s) || rb + k * s < 0.0 {
                    continue;
                }
                let radial = op + dp * t;
                let len = radial.length();
                if len == 0.0 {
                    continue; // the tip of a cone
                }
                let n = (radial / len - a * k).normalized() * sign;
                span.accept(&mut best, t, n, r.d);
            }
        }
        if self.caps && dv != 0.0 {
            for (centre, rad, n) in [(base, rb, -a), (apex, ra, a)] {
                let t = (centre - r.o).dot(n) / r.d.dot(n);
                let p = r.at(t) - centre;
                if p.dot(p) <= rad * rad {
                    span.accept(&mut best, t, n * sign, r.d);
                }
            }
        }
        best
    }

    fn curved(&self) -> bool {
        true
    }

    fn inside(&self) -> bool {
        self.inside
    }

    fn capped(&self) -> bool {
        self.caps
    }
}
