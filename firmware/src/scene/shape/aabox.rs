//! The axis-aligned box, visible from outside.

use super::{Aabb, PrimType, Ray, Span, Surface, SurfaceHit, Vec3};

/// An axis-aligned box from `min` to `max`.
#[derive(Clone, Debug, PartialEq)]
pub struct AaBox {
    pub min: Vec3,
    pub max: Vec3,
}

impl Surface for AaBox {
    fn prim_type(&self) -> PrimType {
        PrimType::Box
    }

    fn translate(&mut self, d: Vec3) {
        self.min = self.min + d;
        self.max = self.max + d;
    }

    fn bounds(&self) -> Aabb {
        Aabb {
            min: self.min,
            max: self.max,
        }
    }

    fn numbers(&self) -> Vec<f64> {
        self.coordinates()
    }

    fn coordinates(&self) -> Vec<f64> {
        let mut out = self.min.to_array().to_vec();
        out.extend_from_slice(&self.max.to_array());
        out
    }

    fn degeneracy(&self, _scale: f64) -> Option<String> {
        let (min, max) = (self.min, self.max);
        (!(min.x < max.x && min.y < max.y && min.z < max.z))
            .then(|| "box has min >= max on some axis (zero or negative volume)".into())
    }

    fn smallest_feature(&self) -> f64 {
        let e = self.max - self.min;
        e.x.min(e.y).min(e.z)
    }

    fn tessellated_triangles(&self) -> usize {
        12
    }

    fn quantized(&self, r: &dyn Fn(f64) -> f64) -> Self {
        AaBox {
            min: self.min.map(r),
            max: self.max.map(r),
        }
    }

    /// The slab method.
    fn intersect(&self, r: &Ray, span: Span) -> Option<SurfaceHit> {
        let (mut t_in, mut t_out) = (f64::NEG_INFINITY, f64::INFINITY);
        let (mut n_in, mut n_out) = (Vec3::ZERO, Vec3::ZERO);
        for ax in 0..3 {
            let (o, d) = (r.o.axis(ax), r.d.axis(ax));
            let (lo, hi) = (self.min.axis(ax), self.max.axis(ax));
            let unit = |s: f64| match ax {
                0 => Vec3::new(s, 0.0, 0.0),
                1 => Vec3::new(0.0, s, 0.0),
                _ => Vec3::new(0.0, 0.0, s),
            };
            if d == 0.0 {
                if o < lo || o > hi {
                    return None;
                }
                continue;
            }
            let (ta, tb) = ((lo - o) / d, (hi - o) / d);
            let (near, far, nn, nf) = if ta < tb {
                (ta, tb, unit(-1.0), unit(1.0))
            } else {
                (tb, ta, unit(1.0), unit(-1.0))
            };
            if near > t_in {
                t_in = near;
                n_in = nn;
            }
            if far < t_out {
                t_out = far;
                n_out = nf;
            }
        }
        if t_in > t_out {
            return None;
        }
        let mut best = None;
        span.accept(&mut best, t_in, n_in, r.d);
        span.accept(&mut best, t_out, n_out, r.d);
        best
    }
}
