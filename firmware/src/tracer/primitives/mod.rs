//! The chip's primitives, one module each, behind one interface
//! ([`ChipPrimitive`], listed in [`PRIMITIVES`]; an object's type is a
//! primitive's opaque or glass [`ChipType`]): its FB record (the writer and
//! the fields the TinyRISC code addresses), its RC kernel (one routine,
//! parameterised by the sides it accepts, the normals and the datapath),
//! the TinyRISC code that broadcasts one object's test, and the math in
//! its doc comment beside the error against the f64 shape of the same
//! name in `crate::scene::shape` (its `Surface::intersect`, measured by
//! `tb/tests/kernels.rs`).
//!
//! | module | chip types | kernels |
//! |---|---|---|
//! | [`sphere`] | sphere, glass sphere | `k_sphere`, `k_glass_sphere` |
//! | [`cylinder`] | cylinder, glass cylinder (caps: discs) | `k_cylinder`; `k_glass_cylinder_out`, `k_glass_cylinder_in` |
//! | [`cone`] | cone, glass cone (caps: discs) | `k_cone`; `k_glass_cone_out`, `k_glass_cone_in` |
//! | [`aabox`] | box, glass box | `k_box`, `k_glass_box` |
//! | [`planar`] | rectangle, triangle, disc (native scenes), glass ones; the caps' discs | `k_rectangle`, `k_triangle`, `k_disc_object`, `k_glass_rectangle`, `k_glass_triangle`, `k_glass_disc_object`; `k_disc`, `k_glass_disc` |
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
pub mod cone_local;
pub mod cylinder;
pub mod cylinder_local;
mod fit;
pub use fit::Fit;
pub mod planar;
pub mod polygon;
pub mod record;

mod parts;
pub use parts::{
    run_first_part, run_rest, run_with_cut_contexts, stream_field, tinyrisc_part, CutTest,
};
pub mod smooth_triangle;
pub mod sphere;
pub mod triangle_local;

use rtl::rc::Datapath;

use super::emit::{define, Code, Reg, K, R3};
use super::math::Approx;
use super::memory_map::ram;
use crate::scene::{PrimType, Scene, Shape};
use record::{Fitter, Layout, W};

/// One primitive of the chip: everything the tracer knows of it, for
/// both its kinds (opaque, [`Sides::Front`]; glass, [`Sides::Both`]).
/// Each module implements it once; [`PRIMITIVES`] lists them and
/// [`ChipType::primitive`] finds an object type's. Adding a primitive is
/// a module, its line in both and its tests (`docs/adding-a-primitive.md`).
pub trait ChipPrimitive: Sync {
    /// The opaque and the glass type's names (`sphere`, `glass_sphere`).
    fn names(&self) -> [&'static str; 2];

    /// One object's record, declared once: its fields in stream order and
    /// their words (`fan`: a polygon record's edges; `caps`: a cylinder's
    /// or cone's record carries caps). The record's words, the header's
    /// field names and the check of the writer come from it.
    fn layout(&self, sides: Sides, fit: &Fit, fan: usize, caps: bool) -> Layout;

    /// Words of one object's record: its [`ChipPrimitive::layout`]'s.
    fn record_words(&self, sides: Sides, fit: &Fit, fan: usize, caps: bool) -> usize {
        self.layout(sides, fit, fan, caps).words()
    }

    /// The kernels its test runs, in load order: (label, kernel). Each
    /// reads from the FB stream exactly the words its record holds.
    fn kernels(&self, sides: Sides, g: &Gen, fit: &Fit) -> Vec<(&'static str, K)>;

    /// TinyRISC code broadcasting one object's whole test, its record at
    /// r7 (labels begin with `at`; clobbers r1..r3).
    fn broadcast(&self, sides: Sides, t: &mut Code, at: &str, fit: &Fit, caps: bool);

    /// The test the packet traversal runs in parts, where it has one: its
    /// first kernel's cuts ([`K::cut`]).
    fn cut_test(&self, _sides: Sides, _fit: &Fit) -> Option<CutTest> {
        None
    }

    /// After a cut test's first kernel, where some awake RC has F
    /// ([`CutTest::then`]): the test's further kernels, its record at
    /// `rec` (a polygon's edges and tail).
    fn broadcast_then(&self, _sides: Sides, _t: &mut Code, _at: &str, _rec: Reg, _fit: &Fit) {}

    /// After a cut test's first kernel whatever F: what its record holds
    /// besides (a cylinder's or cone's caps, where its records carry them).
    fn broadcast_after_cut_test(
        &self,
        _sides: Sides,
        _t: &mut Code,
        _at: &str,
        _rec: Reg,
        _caps: bool,
    ) {
    }

    /// Its records may carry caps, two discs (a cylinder's or cone's):
    /// then a record that carries them starts with a caps flag, the body
    /// after it (a cut test's stream starts at its field, else at the
    /// record), the discs' scale shift `KT_DISC` and `INSIDE_TOL` are in
    /// the header, and an object's caps cost two disc runs.
    fn disc_caps(&self) -> bool {
        false
    }

    /// The header lines naming the record's fields that the broadcast
    /// addresses (`sides`: the sides of the scene's types of this
    /// primitive; `caps`: its records carry caps).
    fn record_header(&self, fit: &Fit, sides: &[Sides], caps: bool) -> Vec<String> {
        let layouts: Vec<Layout> = [Sides::Front, Sides::Both]
            .into_iter()
            .filter(|s| sides.contains(s))
            .map(|s| self.layout(s, fit, 0, caps))
            .collect();
        Layout::header(&layouts)
    }

    /// The header lines of its scale shifts in `fit`.
    fn fit_header(&self, _fit: &Fit) -> Vec<String> {
        Vec::new()
    }

    /// Its test includes a planar inside test (`INSIDE_TOL`; caps' discs
    /// have one).
    fn has_inside_test(&self) -> bool {
        self.disc_caps()
    }

    /// Its glass kind ignores roots within `SELF_LSB` of a ray's start
    /// (curved glass and boxes; planar glass skips the object a ray
    /// leaves by its id instead).
    fn glass_self_margin(&self) -> bool {
        true
    }

    /// The geometry its record is written from, computed once per object
    /// (`s`: LSBs per scene unit) for the scene's fit and the record.
    fn geometry(&self, _shape: &Shape, _s: f64) -> Geometry {
        Geometry::None
    }

    /// Its shading normal is interpolated (smooth shading's kernels).
    fn smooth(&self) -> bool {
        false
    }

    /// Its part of the scene's [`Fit`]: its kernels' scale shifts and
    /// record variants, from the scene's objects (`geo`: their
    /// [`ChipPrimitive::geometry`]; `s`: LSBs per scene unit).
    fn fit(&self, _scene: &Scene, _geo: &[Geometry], _s: f64, _f: &Fitter, _fit: &mut Fit) {}

    /// Whether `shape` is an object of this primitive.
    fn is_of(&self, shape: &Shape) -> bool {
        of_shape(shape).names() == self.names()
    }

    /// What the packet traversal's cost model prices its opaque test with
    /// (`g`, `fit`: the kernels of tests in parts).
    fn test_cost(&self, g: &Gen, fit: &Fit) -> TestCost;

    /// The further kernel runs an object's test takes beside
    /// [`TestCost::first`] and [`TestCost::rest`], each of
    /// [`TestCost::each`] contexts (a polygon's edges, a cylinder's caps;
    /// `s`: LSBs per scene unit).
    fn cost_runs(&self, shape: &Shape, _s: f64) -> usize {
        if self.disc_caps() && shape.capped() {
            2
        } else {
            0
        }
    }

    /// The edges of an object's record (a polygon's, or its sub-edges in
    /// `banded` records; others none): its record's words are
    /// [`ChipPrimitive::record_words`] of it.
    fn fan(&self, _shape: &Shape, _s: f64, _banded: bool) -> usize {
        0
    }

    /// Write one object's record: exactly [`ChipPrimitive::record_words`]
    /// words, in the order its kernels read them.
    fn write(&self, w: &mut W, o: &Object) -> Result<(), RecordError>;

    /// How far its kernels' hits may be from its f64 shape's
    /// (`Surface::intersect`): `tb/tests/kernels.rs` holds every kernel,
    /// opaque and glass, to it on both chips.
    fn error_bound(&self) -> ErrorBound;
}

/// How far a primitive's kernel may be from the f64 reference, on 256
/// rays from around the object (most of them hitting it, some grazing),
/// per chip: `[16-bit, 32-bit]`.
#[derive(Clone, Copy, Debug)]
pub struct ErrorBound {
    /// The largest error of `t`, in LSB of the chip's scene format.
    pub t_lsb: [f64; 2],
    /// The mean error of `t` over the hits, LSB.
    pub mean_t_lsb: [f64; 2],
    /// The largest error of the (shading) unit normal.
    pub normal: [f64; 2],
}

impl ErrorBound {
    /// `t` within `t_lsb` LSB on either chip, within 1.5 LSB on average;
    /// the normal within `normal_16` on the 16-bit chip (its Q1.14
    /// normals) and 1e-6 on the 32-bit one.
    pub const fn lsb(t_lsb: f64, normal_16: f64) -> ErrorBound {
        ErrorBound {
            t_lsb: [t_lsb, t_lsb],
            mean_t_lsb: [1.5, 1.5],
            normal: [normal_16, 1e-6],
        }
    }

    /// The bound on the chip of `dp`.
    pub fn on(&self, dp: Datapath) -> (f64, f64, f64) {
        let i = (dp.bits() > 16) as usize;
        (self.t_lsb[i], self.mean_t_lsb[i], self.normal[i])
    }
}

/// The primitive of an object's shape.
pub fn of_shape(shape: &Shape) -> &'static dyn ChipPrimitive {
    ChipType::of_object(shape, false).primitive()
}

/// An opaque test's contexts as the cost model prices them.
#[derive(Clone, Copy, Debug, Default)]
pub struct TestCost {
    /// Up to the first cut (a kernel without cuts: the whole first kernel).
    pub first: usize,
    /// After it.
    pub rest: usize,
    /// Of each further run ([`ChipPrimitive::cost_runs`]).
    pub each: usize,
}

impl TestCost {
    /// The contexts of kernel `k` up to its first cut and after it.
    pub fn of(k: &K) -> TestCost {
        TestCost {
            first: k.first_part(),
            rest: k.len() - k.first_part(),
            each: 0,
        }
    }
}

/// Every primitive, in the order their header lines come.
pub const PRIMITIVES: [&dyn ChipPrimitive; 9] = [
    &sphere::Sphere,
    &cylinder::Cylinder,
    &cone::Cone,
    &aabox::AaBox,
    &planar::RECTANGLE,
    &planar::TRIANGLE,
    &polygon::Polygon,
    &smooth_triangle::SmoothTriangle,
    &planar::DISC,
];

/// The geometry a primitive's record is written from
/// ([`ChipPrimitive::geometry`]).
pub enum Geometry {
    /// Spheres, boxes, polygons: from the shape itself.
    None,
    /// Rectangles and triangles (one), a cylinder's caps (two).
    Planars(Vec<planar::Planar>),
    /// A cone: its fit and caps.
    Cone(Box<(cone::ConeFit, [planar::Planar; 2])>),
}

impl Geometry {
    /// The planar records it holds (the scale shifts `KT_*` fit them).
    pub fn planars(&self) -> &[planar::Planar] {
        match self {
            Geometry::Planars(p) => p,
            Geometry::Cone(fc) => &fc.1,
            Geometry::None => &[],
        }
    }
}

/// One object's record as [`ChipPrimitive::write`] writes it.
pub struct Object<'a> {
    pub shape: &'a Shape,
    pub geometry: &'a Geometry,
    pub fit: &'a Fit,
    pub sides: Sides,
    /// The record carries caps (cylinders and cones).
    pub caps: bool,
    /// The record's words (a polygon's: padded to the largest fan).
    pub size: usize,
    /// A sphere's `invr` of its unrounded radius (the streamed format).
    pub unrounded: bool,
    /// Object id and (distinct) material index.
    pub id: usize,
    pub mat: usize,
}

/// Why a record cannot be written.
#[derive(Debug)]
pub enum RecordError {
    /// This object's (the scene file's line of the object).
    Object(String),
    /// The scene's (no one line).
    Scene(String),
}

impl RecordError {
    /// A shape of another primitive given to a primitive's writer.
    fn mismatch(name: &str) -> RecordError {
        RecordError::Scene(format!("internal: a {name} record of another shape"))
    }
}

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
    /// Discs (native scenes): the planar test with the caps' inside test.
    Disc,
    /// Discs of a transmitting material (two-sided).
    GlassDisc,
}

impl ChipType {
    /// Every type, in test order.
    pub const ALL: [ChipType; 18] = [
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
        ChipType::Disc,
        ChipType::GlassDisc,
    ];

    /// The order the types' kernels are loaded into context memory in.
    pub const LOAD_ORDER: [ChipType; 18] = [
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
        ChipType::Disc,
        ChipType::GlassDisc,
    ];

    /// The type's name: its primitive's, `glass_` before it for the glass
    /// type.
    pub fn name(self) -> &'static str {
        self.primitive().names()[self.refracts() as usize]
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
        let smooth = s.as_triangle().is_some_and(|t| t.normals.is_some());
        match (s.prim_type(), smooth, transmits) {
            (PrimType::Triangle, true, true) => ChipType::GlassSmoothTriangle,
            (PrimType::Triangle, true, false) => ChipType::SmoothTriangle,
            (PrimType::Sphere, _, true) => ChipType::GlassSphere,
            (PrimType::Rectangle, _, true) => ChipType::GlassRectangle,
            (PrimType::Triangle, _, true) => ChipType::GlassTriangle,
            (PrimType::Polygon, _, true) => ChipType::GlassPolygon,
            (PrimType::Box, _, true) => ChipType::GlassBox,
            (PrimType::Cylinder, _, true) => ChipType::GlassCylinder,
            (PrimType::Cone, _, true) => ChipType::GlassCone,
            (PrimType::Sphere, _, false) => ChipType::Sphere,
            (PrimType::Cylinder, _, false) => ChipType::Cylinder,
            (PrimType::Cone, _, false) => ChipType::Cone,
            (PrimType::Box, _, false) => ChipType::Box,
            (PrimType::Rectangle, _, false) => ChipType::Rectangle,
            (PrimType::Triangle, _, false) => ChipType::Triangle,
            (PrimType::Polygon, _, false) => ChipType::Polygon,
            (PrimType::Disc, _, true) => ChipType::GlassDisc,
            (PrimType::Disc, _, false) => ChipType::Disc,
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
                | ChipType::GlassDisc
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

    /// The primitive this type is the opaque or the glass kind of.
    pub fn primitive(self) -> &'static dyn ChipPrimitive {
        match self {
            ChipType::Sphere | ChipType::GlassSphere => &sphere::Sphere,
            ChipType::Cylinder | ChipType::GlassCylinder => &cylinder::Cylinder,
            ChipType::Cone | ChipType::GlassCone => &cone::Cone,
            ChipType::Box | ChipType::GlassBox => &aabox::AaBox,
            ChipType::Rectangle | ChipType::GlassRectangle => &planar::RECTANGLE,
            ChipType::Triangle | ChipType::GlassTriangle => &planar::TRIANGLE,
            ChipType::Polygon | ChipType::GlassPolygon => &polygon::Polygon,
            ChipType::SmoothTriangle | ChipType::GlassSmoothTriangle => {
                &smooth_triangle::SmoothTriangle
            }
            ChipType::Disc | ChipType::GlassDisc => &planar::DISC,
        }
    }

    /// Words of one object's record (`fan`: the polygons' edges per record;
    /// `caps`: a cylinder's or cone's record carries caps).
    pub fn record_words(self, fit: &Fit, fan: usize, caps: bool) -> usize {
        self.primitive().record_words(self.sides(), fit, fan, caps)
    }

    /// The kernels this type's test runs, in their load order: (label,
    /// kernel). Types share some (the caps' discs, the polygons' edge).
    pub fn kernels(self, g: &Gen, fit: &Fit) -> Vec<(&'static str, K)> {
        self.primitive().kernels(self.sides(), g, fit)
    }

    /// TinyRISC code broadcasting the test of one object of this type,
    /// whose FB record starts at the address in r7 (labels begin with
    /// `at`; clobbers r1..r3; `caps`: a cylinder's or cone's record
    /// carries caps, whose flag is checked).
    pub fn broadcast(self, t: &mut Code, at: &str, fit: &Fit, caps: bool) {
        self.primitive().broadcast(self.sides(), t, at, fit, caps)
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

/// The kernels whose runs start an object test (their RCs at the first
/// context are the rays tested): the render's count of tests per ray.
pub const TEST_KERNELS: [&str; 18] = [
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
    "k_disc_object",
    "k_glass_disc_object",
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
mod tests;
