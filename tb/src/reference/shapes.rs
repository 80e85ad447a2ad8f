//! Ray-primitive intersection in `f64`: the golden versions of the chip's
//! fixed-point kernels. Each primitive's intersection lives with the rest
//! of its geometry in `firmware::scene::shape` (one file per primitive,
//! pbrt style, behind [`firmware::scene::Surface`]); this module names
//! them for the reference renderer.
//!
//! A hit counts only on the visible side unless `two_sided` (transmitting
//! materials, NFF: "objects with T > 0 have two sides"); its normal is the
//! unit normal of the visible side, and `front` says whether the ray hit
//! that side.

use firmware::scene::Shape;
pub use firmware::scene::{Ray, SurfaceHit};

/// The nearest hit of `r` on `shape` with `t` in `(tmin, tmax)`.
pub fn intersect(
    shape: &Shape,
    r: &Ray,
    tmin: f64,
    tmax: f64,
    two_sided: bool,
) -> Option<SurfaceHit> {
    shape.intersect(r, tmin, tmax, two_sided)
}
