//! The chip's primitives, one module each: its FB record (the writer and
//! the fields the TinyRISC code addresses), its RC kernel (one routine,
//! parameterised by the sides it accepts, the normals and the datapath),
//! the TinyRISC code that broadcasts one object's test, and the math in
//! its doc comment beside the error against the f64 shape of the same
//! name in `tb/src/reference/shapes.rs` (measured by `tb/tests/kernels.rs`).
//!
//! | module | chip types | kernels |
//! |---|---|---|
//! | [`sphere`] | sphere, glass sphere | `k_sphere`, `k_glass_sphere` |
//! | [`cylinder`] | cylinder, glass cylinder (caps: discs) | `k_cylinder`; `k_glass_cylinder_out`, `k_glass_cylinder_in` |
//! | [`cone`] | cone, glass cone (caps: discs) | `k_cone`; `k_glass_cone_out`, `k_glass_cone_in` |
//! | [`aabox`] | box, glass box | `k_box`, `k_glass_box` |
//! | [`planar`] | rectangle, triangle, disc (the caps), glass ones | `k_rectangle`, `k_triangle`, `k_disc`, `k_glass_rectangle`, `k_glass_triangle`, `k_glass_disc` |
//! | [`polygon`] | polygon, glass polygon | `k_polygon_head`, `k_polygon_edge`, `k_polygon_tail`; `k_glass_polygon_head`, `k_glass_polygon_tail` |
//! | [`smooth_triangle`] | triangle with vertex normals (NFF `pp`), glass one | `k_smooth_triangle`, `k_glass_smooth_triangle` |
//!
//! Every kernel reads its object's record from one FB stream (set 0) in
//! exactly the order its contexts read `fb0`; the writers follow the same
//! order, and a test checks that every kernel reads exactly as many words
//! as its record holds. A kernel leaves the hit where F is set: `tbest`
//! (r7), `HIT_N`, `HIT_OBJ`, `HIT_MAT` (and `HIT_BACK_OBJ` for the
//! two-sided kernels of transmitting objects).

pub mod aabox;
pub mod cone;
pub mod cylinder;
pub mod planar;
pub mod polygon;
pub mod record;
pub mod smooth_triangle;
pub mod sphere;

use rtl::rc::Datapath;

use super::emit::{define, Code, Reg, K, R2, R3};
use super::math::Approx;
use super::memory_map::ram;
use crate::scene::{PrimType, Shape};

/// The chip's object types, in test order (object test reordering).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChipType {
    Sphere,
    Cylinder,
    Box,
    Rectangle,
    Triangle,
    Polygon,
    /// Cones with unequal radii (tested after the cylinders).
    Cone,
    /// Triangles with vertex normals (NFF `pp`): the planar test, then the
    /// normals interpolated at the hit ([`smooth_triangle`]).
    SmoothTriangle,
    /// Spheres of a transmitting material: two-sided, for rays that enter
    /// and leave them.
    GlassSphere,
    /// Rectangles, triangles and polygons of a transmitting material
    /// (two-sided).
    GlassRectangle,
    GlassTriangle,
    GlassPolygon,
    /// Boxes of a transmitting material: entry and exit faces, the record
    /// twice.
    GlassBox,
    /// Cylinders of a transmitting material: the body twice (outside and
    /// inside), two-sided caps.
    GlassCylinder,
    /// Cones of a transmitting material, as the cylinders.
    GlassCone,
    /// Smooth triangles of a transmitting material.
    GlassSmoothTriangle,
}

impl ChipType {
    /// Every type, in test order.
    pub const ALL: [ChipType; 16] = [
        ChipType::Sphere,
        ChipType::GlassSphere,
        ChipType::Cylinder,
        ChipType::Cone,
        ChipType::Box,
        ChipType::Rectangle,
        ChipType::Triangle,
        ChipType::SmoothTriangle,
        ChipType::Polygon,
        ChipType::GlassRectangle,
        ChipType::GlassTriangle,
        ChipType::GlassPolygon,
        ChipType::GlassBox,
        ChipType::GlassCylinder,
        ChipType::GlassCone,
        ChipType::GlassSmoothTriangle,
    ];

    /// The order the types' kernels are loaded into context memory in.
    pub const LOAD_ORDER: [ChipType; 16] = [
        ChipType::Sphere,
        ChipType::GlassSphere,
        ChipType::Cylinder,
        ChipType::Cone,
        ChipType::Box,
        ChipType::Rectangle,
        ChipType::Triangle,
        ChipType::SmoothTriangle,
        ChipType::Polygon,
        ChipType::GlassRectangle,
        ChipType::GlassTriangle,
        ChipType::GlassCylinder,
        ChipType::GlassCone,
        ChipType::GlassSmoothTriangle,
        ChipType::GlassBox,
        ChipType::GlassPolygon,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ChipType::Sphere => "sphere",
            ChipType::Cylinder => "cylinder",
            ChipType::Box => "box",
            ChipType::Rectangle => "rectangle",
            ChipType::Triangle => "triangle",
            ChipType::Polygon => "polygon",
            ChipType::Cone => "cone",
            ChipType::SmoothTriangle => "smooth_triangle",
            ChipType::GlassSphere => "glass_sphere",
            ChipType::GlassRectangle => "glass_rectangle",
            ChipType::GlassTriangle => "glass_triangle",
            ChipType::GlassPolygon => "glass_polygon",
            ChipType::GlassBox => "glass_box",
            ChipType::GlassCylinder => "glass_cylinder",
            ChipType::GlassCone => "glass_cone",
            ChipType::GlassSmoothTriangle => "glass_smooth_triangle",
        }
    }

    /// The plural, in words: "spheres", "glass boxes", "smooth triangles".
    pub fn plural(self) -> String {
        let n = self.name().replace('_', " ");
        if n.ends_with("box") {
            n + "es"
        } else {
            n + "s"
        }
    }

    /// The chip type of an object: its primitive's, with smooth triangles
    /// and transmitting (two-sided) objects apart.
    pub fn of_object(s: &Shape, transmits: bool) -> ChipType {
        match s {
            Shape::Triangle {
                normals: Some(_), ..
            } if transmits => ChipType::GlassSmoothTriangle,
            Shape::Triangle {
                normals: Some(_), ..
            } => ChipType::SmoothTriangle,
            Shape::Sphere { .. } if transmits => ChipType::GlassSphere,
            Shape::Rectangle { .. } if transmits => ChipType::GlassRectangle,
            Shape::Triangle { .. } if transmits => ChipType::GlassTriangle,
            Shape::Polygon { .. } if transmits => ChipType::GlassPolygon,
            Shape::Box { .. } if transmits => ChipType::GlassBox,
            Shape::Cone { .. } if transmits && s.prim_type() == PrimType::Cylinder => {
                ChipType::GlassCylinder
            }
            Shape::Cone { .. } if transmits => ChipType::GlassCone,
            _ => match s.prim_type() {
                PrimType::Sphere => ChipType::Sphere,
                PrimType::Cylinder => ChipType::Cylinder,
                PrimType::Cone => ChipType::Cone,
                PrimType::Box => ChipType::Box,
                PrimType::Rectangle => ChipType::Rectangle,
                PrimType::Triangle => ChipType::Triangle,
                PrimType::Polygon => ChipType::Polygon,
            },
        }
    }

    /// Types whose kernels test both sides (the reference's rule for
    /// transmitting objects) and refract.
    pub fn refracts(self) -> bool {
        matches!(
            self,
            ChipType::GlassSphere
                | ChipType::GlassRectangle
                | ChipType::GlassTriangle
                | ChipType::GlassPolygon
                | ChipType::GlassBox
                | ChipType::GlassCylinder
                | ChipType::GlassCone
                | ChipType::GlassSmoothTriangle
        )
    }

    /// The sides this type's kernels accept.
    pub fn sides(self) -> Sides {
        if self.refracts() {
            Sides::Both
        } else {
            Sides::Front
        }
    }

    /// Words of one object's record (`fan`: the polygons' edges per record;
    /// `caps`: a cylinder's or cone's record carries caps).
    pub fn record_words(self, fit: &Fit, fan: usize, caps: bool) -> usize {
        match self {
            ChipType::Sphere | ChipType::GlassSphere => sphere::words(fit),
            ChipType::Cylinder | ChipType::GlassCylinder => {
                cylinder::words(fit, self.sides(), caps)
            }
            ChipType::Cone | ChipType::GlassCone => cone::words(self.sides(), caps),
            ChipType::Box | ChipType::GlassBox => aabox::words(self.sides()),
            ChipType::Rectangle
            | ChipType::Triangle
            | ChipType::GlassRectangle
            | ChipType::GlassTriangle => planar::WORDS,
            ChipType::SmoothTriangle | ChipType::GlassSmoothTriangle => smooth_triangle::WORDS,
            ChipType::Polygon | ChipType::GlassPolygon => polygon::words(fan, fit.polygon_form),
        }
    }

    /// The kernels this type's test runs, in their load order: (label,
    /// kernel). Types share some (the caps' discs, the polygons' edge).
    pub fn kernels(self, g: &Gen, fit: &Fit) -> Vec<(&'static str, K)> {
        let s = self.sides();
        match self {
            ChipType::Sphere | ChipType::GlassSphere => {
                vec![(sphere::kernel_name(s), sphere::kernel(g, fit, s))]
            }
            ChipType::Cylinder | ChipType::GlassCylinder => cylinder::kernels(g, fit, s),
            ChipType::Cone | ChipType::GlassCone => cone::kernels(g, s),
            ChipType::Box | ChipType::GlassBox => {
                vec![(aabox::kernel_name(s), aabox::kernel(g, s))]
            }
            ChipType::Rectangle | ChipType::GlassRectangle => {
                let i = planar::Inside::Rectangle;
                vec![(planar::kernel_name(i, s), planar::kernel(g, i, s))]
            }
            ChipType::Triangle | ChipType::GlassTriangle => {
                let i = planar::Inside::Triangle;
                vec![(planar::kernel_name(i, s), planar::kernel(g, i, s))]
            }
            ChipType::SmoothTriangle | ChipType::GlassSmoothTriangle => {
                vec![(
                    smooth_triangle::kernel_name(s),
                    smooth_triangle::kernel(g, s),
                )]
            }
            ChipType::Polygon | ChipType::GlassPolygon => polygon::kernels(g, s, fit.polygon_form),
        }
    }

    /// TinyRISC code broadcasting the test of one object of this type,
    /// whose FB record starts at the address in r7 (labels begin with
    /// `at`; clobbers r1..r3; `caps`: a cylinder's or cone's record
    /// carries caps, whose flag is checked).
    pub fn broadcast(self, t: &mut Code, at: &str, fit: &Fit, caps: bool) {
        let s = self.sides();
        match self {
            ChipType::Sphere | ChipType::GlassSphere => one(t, sphere::kernel_name(s)),
            ChipType::Box | ChipType::GlassBox => one(t, aabox::kernel_name(s)),
            ChipType::Rectangle | ChipType::GlassRectangle => {
                one(t, planar::kernel_name(planar::Inside::Rectangle, s))
            }
            ChipType::Triangle | ChipType::GlassTriangle => {
                one(t, planar::kernel_name(planar::Inside::Triangle, s))
            }
            ChipType::SmoothTriangle | ChipType::GlassSmoothTriangle => {
                one(t, smooth_triangle::kernel_name(s))
            }
            ChipType::Cylinder | ChipType::GlassCylinder => {
                cylinder::broadcast(t, at, fit, s, caps)
            }
            ChipType::Cone | ChipType::GlassCone => cone::broadcast(t, at, s, caps),
            ChipType::Polygon | ChipType::GlassPolygon => {
                polygon::broadcast(t, at, s, fit.polygon_form)
            }
        }
    }
}

/// A test whose first kernel has cuts ([`super::emit::K::cut`]): the
/// packet traversal runs it in parts ([`run_with_cuts`]).
#[derive(Clone, Copy, Debug)]
pub struct CutTest {
    /// The kernel.
    pub kernel: &'static str,
    /// The record field its stream starts at.
    pub field: &'static str,
    /// Its cuts, in order: name, and what F holds there.
    pub cuts: &'static [(&'static str, &'static str)],
    /// What F holds at its end, where the test goes on with further
    /// kernels that run only if some awake RC has F then (a polygon's
    /// edges and tail).
    pub then: Option<&'static str>,
}

impl ChipType {
    /// The test that runs in parts, for the types that have one (opaque
    /// spheres, cylinders and cones, and the planar types opaque or glass:
    /// most of their tests miss, and the miss is known early in the
    /// kernel; a glass polygon's head decides its edges).
    pub fn cut_test(self) -> Option<CutTest> {
        match self {
            ChipType::Sphere => Some(CutTest {
                kernel: sphere::kernel_name(Sides::Front),
                field: "0",
                cuts: &sphere::CUTS,
                then: None,
            }),
            ChipType::Cylinder => Some(CutTest {
                kernel: "k_cylinder",
                field: "CYL_BODY",
                cuts: &cylinder::CUTS,
                then: None,
            }),
            ChipType::Cone => Some(CutTest {
                kernel: "k_cone",
                field: "CONE_BODY",
                cuts: &cone::CUTS,
                then: None,
            }),
            ChipType::Rectangle
            | ChipType::Triangle
            | ChipType::GlassRectangle
            | ChipType::GlassTriangle => Some(CutTest {
                kernel: planar::kernel_name(planar_inside(self), self.sides()),
                field: "0",
                cuts: &planar::CUTS,
                then: None,
            }),
            ChipType::SmoothTriangle | ChipType::GlassSmoothTriangle => Some(CutTest {
                kernel: smooth_triangle::kernel_name(self.sides()),
                field: "0",
                cuts: &planar::CUTS,
                then: None,
            }),
            ChipType::Polygon | ChipType::GlassPolygon => Some(CutTest {
                kernel: polygon::head_name(self.sides()),
                field: "POLY_HEAD",
                cuts: &[],
                then: Some("the plane hit before tbest"),
            }),
            _ => None,
        }
    }

    /// What a cut test's object runs after its first kernel, its record
    /// at `rec`, labels beginning with `at`: where some awake RC has F
    /// ([`CutTest::then`]), a polygon's edges and tail.
    fn broadcast_then(self, t: &mut Code, at: &str, rec: Reg, fit: &Fit) {
        if matches!(self, ChipType::Polygon | ChipType::GlassPolygon) {
            polygon::broadcast_edges(t, at, self.sides(), rec, fit.polygon_form);
        }
    }

    /// What a cut test's object runs after its first kernel whatever F (a
    /// cylinder's or cone's caps, where the scene has some: `caps`), its
    /// record at `rec`; labels begin with `at`.
    pub fn broadcast_after_cut_test(self, t: &mut Code, at: &str, rec: Reg, caps: bool) {
        if !caps {
            return;
        }
        match self {
            ChipType::Cylinder => cylinder::broadcast_caps(t, at, rec),
            ChipType::Cone => cone::broadcast_caps(t, at, rec),
            _ => {}
        }
    }
}

/// A cylinder's or cone's caps, two disc records from `caps` of the
/// record at `rec`, where its flag (`flag`) is set.
fn caps(t: &mut Code, nocap: &str, rec: Reg, flag: &str, cap: &str, caps: [&str; 2]) {
    t.lfb(R3, super::emit::at(flag, rec)).beqz(R3, nocap);
    for c in caps {
        t.m("BCAST_REC", format!("{cap}, {rec}, {c}"));
    }
    t.c("the caps");
    t.label(nocap);
}

fn planar_inside(t: ChipType) -> planar::Inside {
    if matches!(t, ChipType::Triangle | ChipType::GlassTriangle) {
        planar::Inside::Triangle
    } else {
        planar::Inside::Rectangle
    }
}

/// Broadcast the first part of a test in parts ([`CutTest`] `c`) on the
/// record at `first`: its kernel up to the first cut (`BCAST_UPTO`), or the
/// whole kernel where it has no cut. TinyRISC's work while it runs comes
/// next, then [`run_rest`].
pub fn run_first_part(t: &mut Code, c: &CutTest, first: Reg) {
    let (k, field) = (c.kernel, c.field);
    match c.cuts.first() {
        Some((name, holds)) => {
            let cut = super::emit::cut_label(k, name);
            t.m("BCAST_UPTO", format!("{k}, {cut}, {first}, {field}"))
                .c(format!("up to F: {holds}"));
        }
        None => {
            t.m("BCAST_REC", format!("{k}, {first}, {field}"));
            if let Some(holds) = c.then {
                t.c(format!("F: {holds}"));
            }
        }
    }
}

/// Whether TinyRISC's parts (`--test-cuts tinyrisc`) end at the cut
/// `name`. The cuts before a test's normal and commit (a cylinder's
/// `height`, a planar test's `inside`) leave 6 to 54 contexts, less than
/// the status read and second issue of a part cost TinyRISC there: only
/// the broadcast unit's `cut` contexts end a run at them.
pub fn tinyrisc_part(name: &str) -> bool {
    name != cylinder::CUTS[3].0 && name != planar::CUTS[1].0
}

/// The rest of a test of type `ty` in parts ([`CutTest`] `c`) after
/// [`run_first_part`], on the record at `rec`: each part after a cut, and
/// then the further kernels (`then`), only where some awake RC has F
/// (`rcany`), else on to `none`. Labels begin with `at`; `fit`: the
/// records' variants. Clobbers r1..r3.
pub fn run_rest(
    t: &mut Code,
    ty: ChipType,
    c: &CutTest,
    fit: &Fit,
    rec: Reg,
    at: &str,
    none: &str,
) {
    let (k, field) = (c.kernel, c.field);
    let run_from = |t: &mut Code, from: &str, to: &str| {
        t.m(
            "BCAST_FROM_ANY",
            format!("{from}, {to}, {rec}, {field}, {none}"),
        );
    };
    let parts: Vec<&(&str, &str)> = c.cuts.iter().filter(|(n, _)| tinyrisc_part(n)).collect();
    let cuts: Vec<String> = parts
        .iter()
        .map(|(name, _)| super::emit::cut_label(k, name))
        .collect();
    for (i, (_, holds)) in parts.iter().enumerate().skip(1) {
        run_from(t, &cuts[i - 1], &cuts[i]);
        t.c(format!("up to F: {holds}"));
    }
    if let Some(last) = cuts.last() {
        run_from(t, last, &format!("{k}_end"));
        t.c("the rest, if some awake ray can still hit it");
        if let Some(holds) = c.then {
            t.c(format!("F: {holds}"));
        }
    }
    if c.then.is_some() {
        t.rcany(R3).beqz(R3, none).c("no awake ray can hit it");
        ty.broadcast_then(t, at, rec, fit);
    }
}

/// The record field a cut test's stream starts at ([`CutTest::field`]),
/// `"0"` where that is the record itself: a cylinder's or cone's record
/// without caps (`caps` false) is its body.
pub fn stream_field(ty: ChipType, c: &CutTest, caps: bool) -> &'static str {
    match ty {
        ChipType::Cylinder | ChipType::Cone if !caps => "0",
        _ => c.field,
    }
}

/// A test in parts ([`CutTest`] `c`) of type `ty` as one run of its
/// kernel, whose `cut` contexts end it where no awake RC has F
/// ([`super::emit::K::text_with_cuts`]), on the record at `rec`, its
/// stream from `field` ([`stream_field`]); then the further kernels
/// (`then`) only where some awake RC has F (`rcany`), else on to `none`.
/// `kernel`: a register that holds the kernel's address (a type loop
/// sets it once), else the address is set here. Labels begin with `at`;
/// `fit`: the records' variants. Clobbers r1..r3.
#[allow(clippy::too_many_arguments)]
pub fn run_with_cut_contexts(
    t: &mut Code,
    ty: ChipType,
    c: &CutTest,
    field: &str,
    kernel: Option<Reg>,
    fit: &Fit,
    rec: Reg,
    at: &str,
    none: &str,
) {
    let k = c.kernel;
    match (kernel, field) {
        (None, "0") => {
            t.m("BCAST_AT", format!("{k}, {rec}"));
        }
        (None, _) => {
            t.m("BCAST_REC", format!("{k}, {rec}, {field}"));
        }
        (Some(kr), "0") => {
            t.sbcb(kr, rec, klen(k));
        }
        (Some(kr), _) => {
            t.addi(R2, rec, field).sbcb(kr, R2, klen(k));
        }
    }
    if c.cuts.is_empty() {
        t.c("the test");
    } else {
        t.c("the test; its cuts end the run where no awake ray can still hit it");
    }
    if let Some(holds) = c.then {
        t.rcany(R3).c(format!("F: {holds}"));
        t.beqz(R3, none).c("no awake ray can hit it");
        ty.broadcast_then(t, at, rec, fit);
    }
}

/// The kernels whose runs start an object test (their RCs at the first
/// context are the rays tested): the render's count of tests per ray.
pub const TEST_KERNELS: [&str; 16] = [
    "k_sphere",
    "k_glass_sphere",
    "k_cylinder",
    "k_cone",
    "k_box",
    "k_rectangle",
    "k_glass_rectangle",
    "k_triangle",
    "k_glass_triangle",
    "k_smooth_triangle",
    "k_polygon_head",
    "k_glass_polygon_head",
    "k_glass_box",
    "k_glass_cylinder_out",
    "k_glass_cone_out",
    "k_glass_smooth_triangle",
];

/// Every kernel of every primitive's test (the first ones are
/// [`TEST_KERNELS`]; caps, polygon edges and tails, the glass bodies'
/// second sides besides), for `render --profile`'s causes.
pub fn all_test_kernels() -> Vec<&'static str> {
    let g = Gen {
        datapath: Datapath::W16,
        approx: crate::tracer::math::Approx::default(),
        fine_normals: true,
        test_cuts: true,
        published: false,
    };
    let mut v: Vec<&'static str> = Vec::new();
    for polygon_form in [polygon::Form::Plain, polygon::Form::Banded] {
        let fit = Fit {
            polygon_form,
            ..Fit::default()
        };
        for t in ChipType::ALL {
            for (name, _) in t.kernels(&g, &fit) {
                if !v.contains(&name) {
                    v.push(name);
                }
            }
        }
    }
    v
}

/// Which faces a kernel accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sides {
    /// The front only: an opaque object, seen from outside (or from inside
    /// where NFF says so).
    Front,
    /// Both, the reference's rule for a transmitting object: a back hit
    /// turns the normal to the ray and is recorded in `HIT_BACK_OBJ`; a
    /// ray does not hit again the surface it leaves.
    Both,
}

/// One run of a curved body's kernel. A transmitting cylinder or cone's
/// record holds its body twice, with `sg` and `-sg`, and the kernel runs
/// once per copy: the outside, then the inside.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Body {
    /// An opaque body: one run.
    Opaque,
    /// A transmitting body's outer surface.
    Outer,
    /// A transmitting body's inner surface (a back hit).
    Inner,
}

/// What every kernel generator is told of the chip and the numerics.
#[derive(Clone, Copy, Debug)]
pub struct Gen {
    pub datapath: Datapath,
    pub approx: Approx,
    /// Fine normals ([`super::Normals`], resolved for the datapath).
    pub fine_normals: bool,
    /// The kernels run in parts ([`super::TestCuts`]): the cylinder's
    /// starts with a cheap bound and a cut after it.
    pub test_cuts: bool,
    /// The paper's traversal: the kernels keep the contexts its published
    /// cycle counts were measured with (the cylinder normalises its 2D
    /// direction as a 3D vector with a zero third component).
    pub published: bool,
}

/// The scale shifts and record variants fitted to the scene (the layout
/// computes them; the kernels name them, the header defines them).
#[derive(Clone, Copy, Debug, Default)]
pub struct Fit {
    /// Spheres: `invr = 2^(14+ks) / r`, the perpendicular vector's extra
    /// fraction bits, and whether the records carry the centre's rounding
    /// remainder ([`sphere::FINE_BELOW_LSB`]).
    pub ks_sphere: u32,
    pub ep_sphere: u32,
    pub sphere_fine: bool,
    /// Some opaque sphere is seen from inside (NFF's negative radius,
    /// `sg` = -1): the sphere kernel's first part cannot then reject a
    /// sphere whose centre is behind the ray.
    pub sphere_inside: bool,
    /// Some opaque cylinder is seen from inside: likewise for the
    /// cylinder's bound.
    pub cyl_inside: bool,
    /// The opaque cylinder kernel starts with its bound (tests in parts,
    /// [`Gen::test_cuts`]): its records hold `r` before `invr`, which the
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
    /// The header lines of the shifts of the types present.
    pub fn header(&self, types: &[ChipType]) -> Vec<String> {
        let has = |f: &dyn Fn(ChipType) -> bool| types.iter().any(|t| f(*t));
        let mut v = Vec::new();
        if has(&|t| matches!(t, ChipType::Sphere | ChipType::GlassSphere)) {
            v.push(define(
                "KS_SPHERE",
                self.ks_sphere,
                "spheres: invr = 2^(Q14+KS_SPHERE) / r",
            ));
            v.push(define(
                "EP_SPHERE",
                self.ep_sphere,
                "spheres: extra fraction bits of the perpendicular vector",
            ));
        }
        let cyl = has(&|t| matches!(t, ChipType::Cylinder | ChipType::GlassCylinder));
        let cone = has(&|t| matches!(t, ChipType::Cone | ChipType::GlassCone));
        if cyl {
            v.push(define(
                "KS_CYL",
                self.ks_cyl,
                "cylinders: invr = 2^(Q14+KS_CYL) / r",
            ));
            v.push(define(
                "EP_CYL",
                self.ep_cyl,
                "cylinders: extra fraction bits of p",
            ));
        }
        if cone {
            v.push(define(
                "KS_CONE",
                self.ks_cone,
                "cones: invS = 2^(Q14+KS_CONE) / S",
            ));
            v.push(define(
                "EP_CONE",
                self.ep_cone,
                "cones: extra fraction bits of p",
            ));
        }
        let rect = has(&|t| matches!(t, ChipType::Rectangle | ChipType::GlassRectangle));
        let tri = has(&|t| {
            matches!(
                t,
                ChipType::Triangle
                    | ChipType::GlassTriangle
                    | ChipType::SmoothTriangle
                    | ChipType::GlassSmoothTriangle
            )
        });
        if rect {
            v.push(define(
                "KT_RECT",
                self.kt[0],
                "rectangles: edge duals scaled by 2^KT_RECT",
            ));
        }
        if tri {
            v.push(define(
                "KT_TRI",
                self.kt[1],
                "triangles: edge duals scaled by 2^KT_TRI",
            ));
        }
        if cyl || cone {
            v.push(define(
                "KT_DISC",
                self.kt[2],
                "discs (caps): axes scaled by 2^KT_DISC",
            ));
        }
        if rect || tri || cyl || cone {
            v.push(define(
                "INSIDE_TOL",
                planar::INSIDE_TOL,
                "tolerance of the planar inside tests, Q.14",
            ));
        }
        if types.iter().any(|t| {
            t.refracts() && *t != ChipType::GlassRectangle && *t != ChipType::GlassTriangle
        }) {
            v.push(define(
                "SELF_LSB",
                SELF_LSB,
                "a ray leaving a curved glass surface ignores roots this close (LSB)",
            ));
        }
        v
    }
}

/// A ray starting on a transmitting curved surface (or box) ignores its
/// roots closer than this (LSB of the 16-bit chip's scene format; the same
/// distance on the 32-bit chip): its own surface, however the start point
/// was rounded (the sphere's `t` errs by up to 5 LSB, `tb/tests/kernels.rs`;
/// the reference nudges the start off the surface instead). Planar kernels
/// skip the object the ray leaves by its id instead (`ORIG_OBJ`).
pub const SELF_LSB: i32 = 8;

/// `rX = SELF_LSB` in the scene format of the datapath.
fn self_margin(k: &mut K, x: u8, dp: Datapath) {
    k.c(format!("movb r{x}, #SELF_LSB"));
    if dp.bits() > 16 {
        // the margin in LSB of the 16-bit chip's format
        k.c(format!("sll r{x}, r{x}, #X"));
    }
}

/// Store the candidate hit's normal (three words streamed), object and
/// material (streamed) where F is set; `t` becomes `tbest`.
fn commit_streamed_normal(k: &mut K, t: u8) {
    k.c(format!("(f) mov r7, r{t}"));
    for i in 0..3 {
        k.c(format!("(f) st fb0, [#{}]", ram::HIT_N + i));
    }
    k.c(format!("(f) st fb0, [#{}]", ram::HIT_OBJ))
        .c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
}

/// [`commit_streamed_normal`] of a two-sided kernel: the streamed normal
/// turned where the back was hit (`TMP3`), and `HIT_BACK_OBJ`; not where
/// the object is the one the ray leaves (`ORIG_OBJ`).
fn commit_streamed_normal_two(k: &mut K, t: u8) {
    k.c(format!("ld r12, [r0 + #{}]", ram::TMP3))
        .c("movb r14, #1")
        .c("sub r14, r14, r12")
        .c("sub r14, r14, r12")
        .note("1 - 2 back")
        .c("mul r10, fb0, r14")
        .c("mul r11, fb0, r14")
        .c("mul r13, fb0, r14")
        .c("mov r8, fb0")
        .c(format!("ld r15, [r0 + #{}]", ram::ORIG_OBJ))
        .c("(f) cmp.ne r8, r15")
        .c(format!("(f) mov r7, r{t}"));
    for (i, x) in [10, 11, 13].into_iter().enumerate() {
        k.c(format!("(f) st r{x}, [#{}]", ram::HIT_N + i as u32));
    }
    k.c(format!("(f) st r8, [#{}]", ram::HIT_OBJ))
        .c("neg r12, r12")
        .c("add r13, r8, #1")
        .c("and r13, r13, r12")
        .c("sub r13, r13, #1")
        .c(format!("(f) st r13, [#{}]", ram::HIT_BACK_OBJ))
        .c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
}

/// The end of a curved body kernel: where F, the streamed object id and
/// material; for a run of a transmitting body also `HIT_BACK_OBJ` (the id
/// on the inside run, -1 outside). Clobbers r8.
fn commit_obj_mat(k: &mut K, body: Body) {
    match body {
        Body::Opaque => {
            k.c(format!("(f) st fb0, [#{}]", ram::HIT_OBJ));
        }
        Body::Outer | Body::Inner => {
            k.c("mov r8, fb0")
                .c(format!("(f) st r8, [#{}]", ram::HIT_OBJ));
            if body == Body::Outer {
                k.c("movb r8, #-1");
            }
            k.c(format!("(f) st r8, [#{}]", ram::HIT_BACK_OBJ));
        }
    }
    k.c(format!("(f) st fb0, [#{}]", ram::HIT_MAT));
}

/// A kernel's context-memory address, as an assembler expression.
pub fn kaddr(n: &str) -> String {
    format!("({n} - CTXBASE) / 4")
}

/// A kernel's length in contexts, as an assembler expression.
pub fn klen(n: &str) -> String {
    format!("({n}_end - {n}) / 4")
}

/// Broadcast kernel `n` with the record at r7 as its stream.
fn one(t: &mut Code, n: &str) {
    t.m("BCAST_AT", format!("{n}, r7"));
}

/// A unit vector perpendicular to the unit vector `a` (the frame of a
/// cylinder's or cone's caps and body).
pub fn perpendicular(a: crate::scene::Vec3) -> crate::scene::Vec3 {
    let t = if a.x.abs() < 0.6 {
        crate::scene::Vec3::new(1.0, 0.0, 0.0)
    } else {
        crate::scene::Vec3::new(0.0, 1.0, 0.0)
    };
    a.cross(t).normalized()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every kernel reads exactly the words its record (or its part of the
    /// record) holds, in every variant: a kernel reading one word less or
    /// more than the writer wrote would stream the next record's words.
    #[test]
    fn every_kernel_reads_exactly_its_record() {
        for fine_normals in [false, true] {
            for sphere_fine in [false, true] {
                for dp in [Datapath::W16, Datapath::W32] {
                    let g = Gen {
                        datapath: dp,
                        approx: Approx::default(),
                        fine_normals,
                        test_cuts: fine_normals,
                        published: !fine_normals,
                    };
                    let fit = Fit {
                        sphere_fine,
                        fine_normals,
                        cyl_bound: fine_normals,
                        ..Fit::default()
                    };
                    for s in [Sides::Front, Sides::Both] {
                        assert_eq!(sphere::kernel(&g, &fit, s).fb_reads, sphere::words(&fit));
                        assert_eq!(aabox::kernel(&g, s).fb_reads, aabox::words(s));
                        for i in [
                            planar::Inside::Triangle,
                            planar::Inside::Rectangle,
                            planar::Inside::Disc,
                        ] {
                            assert_eq!(planar::kernel(&g, i, s).fb_reads, planar::WORDS);
                        }
                        assert_eq!(
                            smooth_triangle::kernel(&g, s).fb_reads,
                            smooth_triangle::WORDS
                        );
                        let p: Vec<usize> = polygon::kernels(&g, s, polygon::Form::Plain)
                            .iter()
                            .map(|(_, k)| k.fb_reads)
                            .collect();
                        assert_eq!(
                            p,
                            [
                                polygon::HEAD_WORDS,
                                polygon::EDGE_WORDS,
                                polygon::TAIL_WORDS
                            ]
                        );
                        // Banded (sub-edges in the record or apart): the
                        // head, a sub-edge, the probes' bound.
                        for form in [polygon::Form::Banded, polygon::Form::Apart] {
                            let p: Vec<usize> = polygon::kernels(&g, s, form)
                                .iter()
                                .map(|(_, k)| k.fb_reads)
                                .collect();
                            assert_eq!(
                                p,
                                [
                                    polygon::HEAD_WORDS,
                                    polygon::BAND_EDGE_WORDS,
                                    1,
                                    1,
                                    polygon::TAIL_WORDS
                                ]
                            );
                        }
                        // Caps flag (read by TinyRISC), the body runs, two
                        // caps; without caps, the body runs alone.
                        let cyl: usize = cylinder::kernels(&g, &fit, s)
                            .iter()
                            .map(|(_, k)| k.fb_reads)
                            .sum();
                        assert_eq!(1 + cyl + planar::WORDS, cylinder::words(&fit, s, true));
                        assert_eq!(cyl - planar::WORDS, cylinder::words(&fit, s, false));
                        let cone: usize =
                            cone::kernels(&g, s).iter().map(|(_, k)| k.fb_reads).sum();
                        assert_eq!(1 + cone + planar::WORDS, cone::words(s, true));
                        assert_eq!(cone - planar::WORDS, cone::words(s, false));
                    }
                }
            }
        }
    }
}
