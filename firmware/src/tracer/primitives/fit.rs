//! The scale shifts and record variants fitted to the scene ([`Fit`]).

use super::{define, planar, polygon, ChipType, PRIMITIVES, SELF_LSB};

/// The scale shifts and record variants fitted to the scene (the layout
/// computes them; the kernels name them, the header defines them).
#[derive(Clone, Copy, Debug, Default)]
pub struct Fit {
    /// Spheres: `invr = 2^(14+ks) / r`, the perpendicular vector's extra
    /// fraction bits, and whether the records carry the centre's rounding
    /// remainder ([`super::sphere::FINE_BELOW_LSB`]).
    pub ks_sphere: u32,
    pub ep_sphere: u32,
    pub sphere_fine: bool,
    /// Local positions ([`crate::tracer::Positions::Local`]): ray origins with
    /// remainders; sphere and triangle records in frames of their own
    /// ([`super::sphere::layout`], [`super::triangle_local`]), `ks_sphere` fitted to the
    /// spheres' radii there, `kt_local` to the triangles' edge duals.
    pub local: bool,
    pub kt_local: u32,
    /// Local positions, every rectangle and disc small enough for a frame
    /// ([`super::triangle_local::fits`]): opaque rectangles and discs in
    /// frames of their own as the triangles, `kt_local` fitted to their
    /// duals too.
    pub planar_frames: bool,
    /// Local positions: the polygons' crossing test in `2^-poly_k` LSB
    /// ([`super::polygon::fine_k`]).
    pub poly_k: u32,
    /// Local positions, no cylinder with caps: opaque cylinders in frames
    /// of their own ([`super::cylinder_local`]), `KS_CYLL` fitted to
    /// their radii there.
    pub cyl_local: bool,
    pub ks_cyll: u32,
    /// Local positions, no cone with caps: opaque cones in frames of
    /// their own ([`super::cone_local`]), `KS_CONEL` fitted to their
    /// bounding spheres there.
    pub cone_local: bool,
    pub ks_conel: u32,
    /// Some opaque sphere is seen from inside (NFF's negative radius,
    /// `sg` = -1): the sphere kernel's first part cannot then reject a
    /// sphere whose centre is behind the ray.
    pub sphere_inside: bool,
    /// Some opaque cylinder is seen from inside: likewise for the
    /// cylinder's bound.
    pub cyl_inside: bool,
    /// The opaque cylinder kernel starts with its bound (tests in parts,
    /// [`super::Gen::test_cuts`]): its records hold `r` before `invr`, which the
    /// kernel reads only after the bound's cut.
    pub cyl_bound: bool,
    /// Cylinders and cones: the same shifts.
    pub ks_cyl: u32,
    pub ep_cyl: u32,
    pub ks_cone: u32,
    pub ep_cone: u32,
    /// Planar inside tests: the scale shift of the edge duals, per kind
    /// (rectangle, triangle, disc).
    pub kt: [u32; 3],
    /// Fine normals (the cylinder record's remainders).
    pub fine_normals: bool,
    /// The polygons' record form: plain, in bands
    /// ([`polygon::BANDED_FROM`]), or in bands with the sub-edges apart
    /// in main memory (streamed layouts).
    pub polygon_form: polygon::Form,
}

impl Fit {
    /// The header lines of the shifts of the types present: each
    /// primitive's ([`super::ChipPrimitive::fit_header`], a line two primitives
    /// share once), then the ones some primitives share.
    pub fn header(&self, types: &[ChipType]) -> Vec<String> {
        let has = |f: &dyn Fn(ChipType) -> bool| types.iter().any(|t| f(*t));
        let mut v: Vec<String> = Vec::new();
        for p in PRIMITIVES {
            if has(&|t| t.primitive().names() == p.names()) {
                for l in p.fit_header(self) {
                    if !v.contains(&l) {
                        v.push(l);
                    }
                }
            }
        }
        let kt_disc = v.iter().any(|l| l.starts_with("KT_DISC "));
        if has(&|t| t.primitive().disc_caps()) && !kt_disc {
            v.push(define(
                "KT_DISC",
                self.kt[2],
                "discs (caps): axes scaled by 2^KT_DISC",
            ));
        }
        if has(&|t| t.primitive().has_inside_test()) {
            v.push(define(
                "INSIDE_TOL",
                planar::INSIDE_TOL,
                "tolerance of the planar inside tests, Q.14",
            ));
        }
        if has(&|t| t.refracts() && t.primitive().glass_self_margin()) {
            v.push(define(
                "SELF_LSB",
                SELF_LSB,
                "a ray leaving a curved glass surface ignores roots this close (LSB)",
            ));
        }
        v
    }
}
