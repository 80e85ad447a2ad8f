//! Ray-primitive intersection in `f64`, one function per primitive (pbrt
//! style: each shape's intersection lives in one place). These are the
//! golden versions of the chip's fixed-point kernels.
//!
//! Every function returns the nearest hit with `t` in `(tmin, tmax)` whose
//! side is acceptable: primitives are one-sided (only a hit on the visible
//! side counts) unless `two_sided` (transmitting materials, NFF: "objects
//! with T > 0 have two sides"). The normal returned is the unit normal of
//! the visible side (outward for ordinary objects), whichever side was hit;
//! `front` says whether the ray hit that side.

use firmware::scene::{Shape, Vec3};

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

/// Keep a candidate if it is in range, on an acceptable side, and nearer.
fn accept(
    best: &mut Option<SurfaceHit>,
    t: f64,
    n: Vec3,
    d: Vec3,
    tmin: f64,
    tmax: f64,
    two_sided: bool,
) {
    if !(t > tmin && t < tmax) {
        return;
    }
    let front = d.dot(n) < 0.0;
    if !front && !two_sided {
        return;
    }
    if best.is_none_or(|b| t < b.t) {
        *best = Some(SurfaceHit { t, n, ns: n, front });
    }
}

/// Intersect a ray with any shape.
pub fn intersect(
    shape: &Shape,
    r: &Ray,
    tmin: f64,
    tmax: f64,
    two_sided: bool,
) -> Option<SurfaceHit> {
    match shape {
        Shape::Sphere {
            center,
            radius,
            inside,
        } => sphere(*center, *radius, *inside, r, tmin, tmax, two_sided),
        Shape::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
            inside,
            caps,
        } => cone(
            *base,
            *base_radius,
            *apex,
            *apex_radius,
            *inside,
            *caps,
            r,
            tmin,
            tmax,
            two_sided,
        ),
        Shape::Box { min, max } => aabox(*min, *max, r, tmin, tmax, two_sided),
        Shape::Rectangle {
            corner,
            edge1,
            edge2,
        } => rectangle(*corner, *edge1, *edge2, r, tmin, tmax, two_sided),
        Shape::Triangle { v, normals } => triangle(v, normals.as_ref(), r, tmin, tmax, two_sided),
        Shape::Polygon { v, .. } => polygon(v, r, tmin, tmax, two_sided),
    }
}

/// The two roots of `a t^2 + 2 b t + c = 0` in increasing order, computed
/// without cancellation.
fn quadratic(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
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

/// Sphere: `|p - c| = r`. The discriminant is computed from the distance of
/// the centre to the ray line (pbrt-v4), which keeps small spheres seen
/// from far away accurate.
pub fn sphere(
    c: Vec3,
    radius: f64,
    inside: bool,
    r: &Ray,
    tmin: f64,
    tmax: f64,
    two_sided: bool,
) -> Option<SurfaceHit> {
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
        let n = if inside { -n } else { n };
        accept(&mut best, t, n, r.d, tmin, tmax, two_sided);
    }
    best
}

/// Open or capped cylinder/cone between `base` (radius `rb`) and `apex`
/// (radius `ra`): `|radial(p)| = rb + (ra - rb) * s / h`, `s` in `[0, h]`.
#[allow(clippy::too_many_arguments)]
pub fn cone(
    base: Vec3,
    rb: f64,
    apex: Vec3,
    ra: f64,
    inside: bool,
    caps: bool,
    r: &Ray,
    tmin: f64,
    tmax: f64,
    two_sided: bool,
) -> Option<SurfaceHit> {
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
    let sign = if inside { -1.0 } else { 1.0 };
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
            accept(&mut best, t, n, r.d, tmin, tmax, two_sided);
        }
    }
    if caps && dv != 0.0 {
        for (centre, rad, n) in [(base, rb, -a), (apex, ra, a)] {
            let t = (centre - r.o).dot(n) / r.d.dot(n);
            let p = r.at(t) - centre;
            if p.dot(p) <= rad * rad {
                accept(&mut best, t, n * sign, r.d, tmin, tmax, two_sided);
            }
        }
    }
    best
}

/// Axis-aligned box, visible from outside (slab method).
pub(crate) fn aabox(
    min: Vec3,
    max: Vec3,
    r: &Ray,
    tmin: f64,
    tmax: f64,
    two_sided: bool,
) -> Option<SurfaceHit> {
    let (mut t_in, mut t_out) = (f64::NEG_INFINITY, f64::INFINITY);
    let (mut n_in, mut n_out) = (Vec3::ZERO, Vec3::ZERO);
    for ax in 0..3 {
        let (o, d) = (r.o.axis(ax), r.d.axis(ax));
        let (lo, hi) = (min.axis(ax), max.axis(ax));
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
    accept(&mut best, t_in, n_in, r.d, tmin, tmax, two_sided);
    accept(&mut best, t_out, n_out, r.d, tmin, tmax, two_sided);
    best
}

/// Rectangle `corner + u edge1 + v edge2`, visible on the `edge1 x edge2`
/// side.
pub fn rectangle(
    corner: Vec3,
    e1: Vec3,
    e2: Vec3,
    r: &Ray,
    tmin: f64,
    tmax: f64,
    two_sided: bool,
) -> Option<SurfaceHit> {
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
    accept(&mut best, t, n, r.d, tmin, tmax, two_sided);
    best
}

/// Triangle (Moller-Trumbore), visible on the side from which its vertices
/// run counter-clockwise; vertex normals, if any, are interpolated for
/// shading.
pub fn triangle(
    v: &[Vec3; 3],
    normals: Option<&[Vec3; 3]>,
    r: &Ray,
    tmin: f64,
    tmax: f64,
    two_sided: bool,
) -> Option<SurfaceHit> {
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let pv = r.d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 || (det < 0.0 && !two_sided) {
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
    accept(&mut best, t, n, r.d, tmin, tmax, two_sided);
    if let (Some(h), Some(ns)) = (best.as_mut(), normals) {
        let s =
            (ns[0].normalized() * (1.0 - u - w) + ns[1].normalized() * u + ns[2].normalized() * w)
                .normalized();
        // A vertex normal on the far side would flip the shading: keep the
        // geometric normal's side.
        h.ns = if s.dot(n) > 0.0 { s } else { n };
    }
    best
}

/// Planar polygon, convex or concave (even-odd rule), visible on the side
/// from which its first three vertices run counter-clockwise.
pub fn polygon(v: &[Vec3], r: &Ray, tmin: f64, tmax: f64, two_sided: bool) -> Option<SurfaceHit> {
    let n = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
    let dn = r.d.dot(n);
    if dn == 0.0 {
        return None;
    }
    let t = (v[0] - r.o).dot(n) / dn;
    if !(t > tmin && t < tmax) {
        return None;
    }
    let p = r.at(t);
    // Project on the plane of the two axes where the normal is smallest.
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
    accept(&mut best, t, n, r.d, tmin, tmax, two_sided);
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f64; 3], d: [f64; 3]) -> Ray {
        Ray {
            o: o.into(),
            d: Vec3::from(d).normalized(),
        }
    }
    const INF: f64 = f64::INFINITY;

    #[test]
    fn sphere_front_back_and_inside() {
        let s = Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 2.0,
            inside: false,
        };
        let h = intersect(&s, &ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), 0.0, INF, false).unwrap();
        assert_eq!(h.t, 3.0);
        assert_eq!(h.n, Vec3::new(0.0, 0.0, -1.0));
        // From inside, one-sided: the exit is the back side, not seen.
        assert!(intersect(&s, &ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]), 0.0, INF, false).is_none());
        let h = intersect(&s, &ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]), 0.0, INF, true).unwrap();
        assert_eq!((h.t, h.front), (2.0, false));
        // Negative NFF radius: only the inside is visible.
        let s = Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 2.0,
            inside: true,
        };
        let h = intersect(&s, &ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), 0.0, INF, false).unwrap();
        assert_eq!((h.t, h.n), (7.0, Vec3::new(0.0, 0.0, -1.0)));
        // Grazing at x = 1.2: t = 5 - sqrt(4 - 1.44) = 3.4.
        let h = intersect(
            &Shape::Sphere {
                center: Vec3::new(0.0, 0.0, 5.0),
                radius: 2.0,
                inside: false,
            },
            &ray([1.2, 0.0, 0.0], [0.0, 0.0, 1.0]),
            0.0,
            INF,
            false,
        )
        .unwrap();
        assert!((h.t - 3.4).abs() < 1e-12);
    }

    #[test]
    fn cylinder_cone_and_caps() {
        // Cylinder along z from 0 to 2, radius 1; ray along -x at z = 1.
        let c = Shape::Cone {
            base: Vec3::ZERO,
            base_radius: 1.0,
            apex: Vec3::new(0.0, 0.0, 2.0),
            apex_radius: 1.0,
            inside: false,
            caps: false,
        };
        let h = intersect(&c, &ray([5.0, 0.0, 1.0], [-1.0, 0.0, 0.0]), 0.0, INF, false).unwrap();
        assert!((h.t - 4.0).abs() < 1e-12 && (h.n - Vec3::new(1.0, 0.0, 0.0)).length() < 1e-12);
        // Above the top: missed (open).
        assert!(intersect(&c, &ray([5.0, 0.0, 2.5], [-1.0, 0.0, 0.0]), 0.0, INF, false).is_none());
        // Down the axis: open, the inside wall is a back side.
        assert!(intersect(&c, &ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0]), 0.0, INF, false).is_none());
        let capped = Shape::Cone {
            base: Vec3::ZERO,
            base_radius: 1.0,
            apex: Vec3::new(0.0, 0.0, 2.0),
            apex_radius: 1.0,
            inside: false,
            caps: true,
        };
        let h = intersect(
            &capped,
            &ray([0.5, 0.0, 5.0], [0.0, 0.0, -1.0]),
            0.0,
            INF,
            false,
        )
        .unwrap();
        assert_eq!((h.t, h.n), (3.0, Vec3::new(0.0, 0.0, 1.0)));
        // Cone radius 1 at z=0 to 0.5 at z=2: at z=1 radius is 0.75; the
        // outward normal leans up by atan(0.25).
        let k = Shape::Cone {
            base: Vec3::ZERO,
            base_radius: 1.0,
            apex: Vec3::new(0.0, 0.0, 2.0),
            apex_radius: 0.5,
            inside: false,
            caps: false,
        };
        let h = intersect(&k, &ray([5.0, 0.0, 1.0], [-1.0, 0.0, 0.0]), 0.0, INF, false).unwrap();
        assert!((h.t - 4.25).abs() < 1e-12, "{}", h.t);
        let e = Vec3::new(1.0, 0.0, 0.25).normalized();
        assert!((h.n - e).length() < 1e-12, "{:?}", h.n);
    }

    #[test]
    fn box_rectangle_triangle_polygon() {
        let b = Shape::Box {
            min: Vec3::new(-1.0, -1.0, -1.0),
            max: Vec3::new(1.0, 2.0, 3.0),
        };
        let h = intersect(
            &b,
            &ray([0.0, 10.0, 0.0], [0.0, -1.0, 0.0]),
            0.0,
            INF,
            false,
        )
        .unwrap();
        assert_eq!((h.t, h.n), (8.0, Vec3::new(0.0, 1.0, 0.0)));
        assert!(intersect(&b, &ray([0.0, 0.0, 0.0], [0.0, -1.0, 0.0]), 0.0, INF, false).is_none());
        let r = Shape::Rectangle {
            corner: Vec3::ZERO,
            edge1: Vec3::new(2.0, 0.0, 0.0),
            edge2: Vec3::new(0.0, 1.0, 0.0),
        };
        assert_eq!(
            intersect(&r, &ray([1.9, 0.9, 4.0], [0.0, 0.0, -1.0]), 0.0, INF, false)
                .unwrap()
                .t,
            4.0
        );
        assert!(intersect(&r, &ray([2.1, 0.5, 4.0], [0.0, 0.0, -1.0]), 0.0, INF, false).is_none());
        assert!(
            intersect(&r, &ray([1.0, 0.5, -4.0], [0.0, 0.0, 1.0]), 0.0, INF, false).is_none(),
            "back side"
        );
        let tri = Shape::Triangle {
            v: [
                Vec3::ZERO,
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            normals: None,
        };
        assert_eq!(
            intersect(
                &tri,
                &ray([0.2, 0.2, 1.0], [0.0, 0.0, -1.0]),
                0.0,
                INF,
                false
            )
            .unwrap()
            .t,
            1.0
        );
        assert!(intersect(
            &tri,
            &ray([0.6, 0.6, 1.0], [0.0, 0.0, -1.0]),
            0.0,
            INF,
            false
        )
        .is_none());
        assert!(intersect(
            &tri,
            &ray([0.2, 0.2, -1.0], [0.0, 0.0, 1.0]),
            0.0,
            INF,
            false
        )
        .is_none());
        // Concave arrow: (0,0) (2,0) (2,2) (1,1) (0,2); the notch at (1,1.5)
        // is outside, (1,0.5) and (1.8,1.5) inside.
        let v = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [1.0, 1.0], [0.0, 2.0]]
            .map(|[x, y]| Vec3::new(x, y, 0.0))
            .to_vec();
        let p = Shape::Polygon { v, normals: None };
        let hit = |x: f64, y: f64| {
            intersect(&p, &ray([x, y, 1.0], [0.0, 0.0, -1.0]), 0.0, INF, false).is_some()
        };
        assert!(hit(1.0, 0.5) && hit(1.8, 1.5) && !hit(1.0, 1.5) && !hit(2.5, 0.5));
    }
}
