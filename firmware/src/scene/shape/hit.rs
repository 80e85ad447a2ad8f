//! Rays and surface hits in `f64`: what every shape's reference
//! intersection takes and returns.
//!
//! Primitives are one-sided (only a hit on the visible side counts) unless
//! `two_sided` (transmitting materials, NFF: "objects with T > 0 have two
//! sides"). The normal a hit carries is the unit normal of the visible side
//! (outward for ordinary objects), whichever side was hit; `front` says
//! whether the ray hit that side.

use super::Vec3;

/// A ray: origin and unit direction.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub o: Vec3,
    pub d: Vec3,
}

impl Ray {
    pub fn at(&self, t: f64) -> Vec3 {
        self.o + self.d * t
    }
}

/// A surface hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    pub t: f64,
    /// Unit geometric normal of the visible side.
    pub n: Vec3,
    /// Unit shading normal of the visible side (interpolated for `pp`).
    pub ns: Vec3,
    /// True if the ray arrived on the visible side.
    pub front: bool,
}

/// The interval and sidedness a hit must fall in.
#[derive(Clone, Copy, Debug)]
pub struct Span {
    pub tmin: f64,
    pub tmax: f64,
    pub two_sided: bool,
}

impl Span {
    /// Keep a candidate if it is in range, on an acceptable side, and
    /// nearer than `best`.
    pub(super) fn accept(&self, best: &mut Option<SurfaceHit>, t: f64, n: Vec3, d: Vec3) {
        if !(t > self.tmin && t < self.tmax) {
            return;
        }
        let front = d.dot(n) < 0.0;
        if !front && !self.two_sided {
            return;
        }
        if best.is_none_or(|b| t < b.t) {
            *best = Some(SurfaceHit { t, n, ns: n, front });
        }
    }
}

/// The two roots of `a t^2 + 2 b t + c = 0` in increasing order, computed
/// without cancellation.
pub(super) fn quadratic(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    if a == 0.0 {
        if b == 0.0 {
            return None;
        }
        let t = -c / (2.0 * b);
        return Some((t, t));
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let q = -(b + b.signum() * disc.sqrt());
    if q == 0.0 {
        return Some((0.0, 0.0));
    }
    let (t0, t1) = (q / a, c / q);
    Some((t0.min(t1), t0.max(t1)))
}
