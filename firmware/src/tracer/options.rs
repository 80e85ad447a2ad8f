//! The generator's options: [`Options`] (what a render asks for: the
//! image, the traversal, the tree, the tests in parts, the chip) and
//! [`Numerics`] (the RC arithmetic's knobs), with the value types of
//! each option and their `FromStr` / `Display` (the command line's and
//! the JSON's spelling). Every other module of the tracer reads them; they
//! read nothing of the tracer but its constants.

use crate::bsp::{BspParams, SplitRule};
pub use rtl::rc::Datapath;

/// Offset of a spawned ray's origin along the normal, in LSBs. Default 0:
/// every kernel is one-sided and its primitive convex (or planar), so a ray
/// leaving the surface it starts on cannot hit that surface again however
/// the hit point was rounded (the sphere's near root and a plane's
/// back face are rejected), while an offset of a few LSB pushes the origin
/// of a shadow ray off a small sphere into the neighbour it touches, whose
/// kernel then rejects it (`sweep`'s `ray_offset_lsb` knob measures it).
pub const EPS_LSB: i32 = 0;

/// A fieldless option type from one list of its values and their
/// spellings: the enum, `ALL`, `name()`, and the `Display` and `FromStr`
/// the command line and the JSON use (a bad spelling names the option and
/// every value).
macro_rules! spelled {
    (
        $(#[$meta:meta])*
        pub enum $name:ident ($what:literal) {
            $($(#[$vmeta:meta])* $variant:ident = $text:literal,)*
        }
    ) => {
        $(#[$meta])*
        pub enum $name {
            $($(#[$vmeta])* $variant,)*
        }

        impl $name {
            /// Every value, in the order the help lists them.
            pub const ALL: [$name; [$($text,)*].len()] = [$($name::$variant,)*];

            /// Its spelling on the command line and in the JSON.
            pub fn name(self) -> &'static str {
                match self {
                    $($name::$variant => $text,)*
                }
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl std::str::FromStr for $name {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                $name::ALL.into_iter().find(|v| v.name() == s).ok_or_else(|| {
                    format!("{} '{s}': expected {}", $what, spellings(&[$($text,)*]))
                })
            }
        }
    };
}

/// `a, b or c`.
fn spellings(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [one] => one.to_string(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
    }
}

/// Generator options.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    pub width: u32,
    pub height: u32,
    /// Rays traced in parallel: 4, 8, 16, 32 or 64.
    pub ways: u32,
    /// Maximum ray depth, the eye ray being depth 1 (the paper's recursion
    /// level 2 = eye rays and one reflection).
    pub depth: u32,
    /// The BSP. `max_depth` 0 and `SplitRule::Auto` (the default) are
    /// resolved per traversal ([`super::resolve_bsp`]): the paper's median split
    /// to depth 15 for the paper's traversal; for the packet traversal that
    /// tree, a pbrt SAH tree and a chip-cost SAH tree (both to
    /// [`crate::bsp::auto_depth`]): `render` keeps the fastest on a probe
    /// of the frame, [`super::build`] the cheapest by the traversal's cost model.
    pub bsp: BspParams,
    /// How a resident scene's BSP nodes name their objects (the paper's
    /// Fig. 5 bit vectors by default).
    pub layout: NodeLayout,
    /// The chip's RC datapath: the paper's 16-bit chip (default) or the
    /// 32-bit variant, whose formats all have 16 more fraction bits.
    pub datapath: Datapath,
    /// How a packet walks the BSP tree: the paper's traversal, or masked
    /// packet traversal with per-ray intervals.
    pub traversal: Traversal,
    /// Packet traversal: which BSP subtrees are walked as one leaf of all
    /// the objects under them.
    pub collapse: Collapse,
    /// Streamed packet traversal: the sizes of the pieces a leaf's records
    /// are moved in.
    pub pieces: LeafPieces,
    /// Packet traversal: the shadow rays of the reflection levels traced
    /// a packet per light, or merged into full packets.
    pub shadows: ShadowPackets,
    /// Packet traversal: object tests run in parts, the rest skipped
    /// where no awake ray can still hit the object, or whole.
    pub test_cuts: TestCuts,
    /// Packet traversal: which child of a node a packet whose rays go
    /// both ways along its axis visits first.
    pub child_order: ChildOrder,
    /// Streamed packet traversal: where banded polygons' sub-edges are.
    pub sub_edges: SubEdges,
    /// Positions in the scene's one format or in local frames
    /// ([`Positions`]).
    pub positions: Positions,
}

spelled! {
    /// Streamed packet traversal: where a banded polygon's sub-edges are
    /// (`primitives::polygon::Form`).
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
    pub enum SubEdges ("sub-edges") {
        /// In main memory apart from the record where a record would be
        /// over [`super::primitives::polygon::APART_FROM`] words, a packet's bands
        /// of them moved by DMA once its points are known.
        #[default]
        Apart = "apart",
        /// In the record, moved with every leaf piece that holds it (the
        /// resident layout's form).
        InRecords = "records",
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            width: 256,
            height: 256,
            ways: 64,
            depth: 2,
            bsp: BspParams {
                max_depth: 0,
                rule: SplitRule::Auto,
                ..BspParams::default()
            },
            layout: NodeLayout::Fig5,
            datapath: Datapath::W16,
            traversal: Traversal::default(),
            collapse: Collapse::Auto,
            pieces: LeafPieces::default(),
            shadows: ShadowPackets::default(),
            test_cuts: TestCuts::default(),
            child_order: ChildOrder::default(),
            sub_edges: SubEdges::default(),
            positions: Positions::Global,
        }
    }
}

spelled! {
    /// Packet traversal: whether an object test runs in parts at its kernels'
    /// cuts ([`super::primitives::CutTest`]), the rest skipped where no awake ray can
    /// still hit the object, and who skips it: the broadcast unit, at a `cut`
    /// context in the kernel's run (`on`), or TinyRISC, which broadcasts each
    /// part after a status read (`tinyrisc`); or whole (`off`). `auto` (the
    /// default) is `on` under the run issue model and `tinyrisc` under the M1
    /// chip's instruction issue, where TinyRISC issues every context itself
    /// and would be held for the contexts a cut skips
    /// ([`TestCuts::for_issue`]; the firmware built without a timing takes
    /// `on`). The same image every way.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum TestCuts ("test cuts") {
        #[default]
        Auto = "auto",
        On = "on",
        Tinyrisc = "tinyrisc",
        Off = "off",
    }
}

impl TestCuts {
    /// `auto` resolved for the chip's issue model; the others as they are.
    pub fn for_issue(self, issue: rtl::tinyrisc::IssueModel) -> TestCuts {
        match (self, issue) {
            (TestCuts::Auto, rtl::tinyrisc::IssueModel::Run) => TestCuts::On,
            (TestCuts::Auto, rtl::tinyrisc::IssueModel::Instruction) => TestCuts::Tinyrisc,
            (t, _) => t,
        }
    }

    /// Tests run in parts at their cuts.
    pub fn in_parts(self) -> bool {
        self != TestCuts::Off
    }

    /// The kernels hold `cut` contexts (`on`, and `auto` unresolved).
    pub fn cut_contexts(self) -> bool {
        matches!(self, TestCuts::On | TestCuts::Auto)
    }
}

/// Which BSP subtrees the packet traversal walks as one leaf of all the
/// objects under them (testing them all with the rays that reach the
/// subtree costs less than walking it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Collapse {
    /// Where the expected cost of walking the subtree (node kernels and the
    /// leaves' object tests, weighted by the cells' surface areas) exceeds
    /// the cost of testing every object under it.
    #[default]
    Auto,
    /// Subtrees with at most this many objects (0: none).
    Objects(usize),
}

impl std::fmt::Display for Collapse {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Collapse::Auto => f.write_str("auto"),
            Collapse::Objects(n) => write!(f, "{n}"),
        }
    }
}

impl std::str::FromStr for Collapse {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(Collapse::Auto);
        }
        s.parse::<usize>()
            .map(Collapse::Objects)
            .map_err(|_| format!("collapse '{s}': expected auto or a number of objects (0: never)"))
    }
}

/// The streamed packet traversal moves a leaf's records into the FB in
/// pieces (`docs/tracer.md`, "Leaves and pieces"): the first of at most
/// `first` words, the second of at most `second`, and what remains in as
/// few pieces of at most `rest` words as hold it, of about equal words (a
/// piece holds at least one record). The pieces of a leaf alternate
/// between FB bank 1 and the top of bank 0, and each piece after the first
/// moves while the tests of the piece before it run: a small first piece
/// is a short wait at every leaf, a small second piece a short wait after
/// the first piece's tests but one more turn of the loop, larger further
/// pieces fewer turns. `second` `None` is `auto`: `tb::render` keeps
/// `2 * first` or `rest`, whichever runs its probe faster; a build without
/// a probe takes `rest`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LeafPieces {
    pub first: usize,
    pub second: Option<usize>,
    pub rest: usize,
}

impl Default for LeafPieces {
    fn default() -> Self {
        LeafPieces {
            first: 64,
            second: None,
            rest: 256,
        }
    }
}

impl LeafPieces {
    /// The most words any limit may name (an FB bank).
    pub const MAX: usize = super::memory_map::STREAM_BANK;

    /// Pieces of `first` words, then of `rest` (the second as the rest).
    pub fn two(first: usize, rest: usize) -> LeafPieces {
        LeafPieces {
            first,
            second: Some(rest),
            rest,
        }
    }

    /// The second piece's limit a build without a probe takes.
    pub fn second_or_rest(&self) -> usize {
        self.second.unwrap_or(self.rest)
    }

    /// `auto`'s other choice for the second piece (`None` where it would
    /// be the rest's).
    pub fn auto_second(&self) -> Option<usize> {
        (self.second.is_none() && 2 * self.first < self.rest).then_some(2 * self.first)
    }
}

impl std::fmt::Display for LeafPieces {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.second {
            None if *self == LeafPieces::default() => f.write_str("auto"),
            None => write!(f, "{},auto,{}", self.first, self.rest),
            Some(s) if s >= self.rest => write!(f, "{},{}", self.first, self.rest),
            Some(s) => write!(f, "{},{},{}", self.first, s, self.rest),
        }
    }
}

impl std::str::FromStr for LeafPieces {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(LeafPieces::default());
        }
        let bad = || {
            format!(
                "leaf pieces '{s}': expected auto, FIRST,REST or FIRST,SECOND,REST (SECOND a count or auto), word counts 1..={} with FIRST <= SECOND <= REST (e.g. 64,128,256)",
                LeafPieces::MAX
            )
        };
        let n = |x: &str| {
            x.trim()
                .parse::<usize>()
                .ok()
                .filter(|n| (1..=LeafPieces::MAX).contains(n))
        };
        let parts: Vec<&str> = s.split(',').collect();
        match parts[..] {
            [a, b] => match (n(a), n(b)) {
                (Some(first), Some(rest)) if first <= rest => Ok(LeafPieces::two(first, rest)),
                _ => Err(bad()),
            },
            [a, b, c] => {
                let second = if b.trim() == "auto" {
                    None
                } else {
                    Some(n(b).ok_or_else(bad)?)
                };
                match (n(a), n(c)) {
                    (Some(first), Some(rest))
                        if first <= rest
                            && second.is_none_or(|sec| first <= sec && sec <= rest) =>
                    {
                        Ok(LeafPieces {
                            first,
                            second,
                            rest,
                        })
                    }
                    _ => Err(bad()),
                }
            }
            _ => Err(bad()),
        }
    }
}

#[cfg(test)]
mod leaf_pieces_tests {
    use super::LeafPieces;

    #[test]
    fn leaf_pieces_read_and_print_as_written() {
        let p = |s: &str| s.parse::<LeafPieces>();
        let pc = |first, second, rest| LeafPieces {
            first,
            second,
            rest,
        };
        assert_eq!(p("auto"), Ok(pc(64, None, 256)));
        assert_eq!(p("64,256"), Ok(pc(64, Some(256), 256)));
        assert_eq!(p("64,128,256"), Ok(pc(64, Some(128), 256)));
        assert_eq!(p("32,auto,512"), Ok(pc(32, None, 512)));
        for s in ["auto", "64,256", "64,128,256", "32,auto,512"] {
            assert_eq!(p(s).unwrap().to_string(), s);
        }
        // A second piece as large as the rest is no second piece.
        assert_eq!(p("64,256,256").unwrap().to_string(), "64,256");
        for bad in [
            "",
            "64",
            "0,64",
            "64,32",
            "64,300,256",
            "64,32,256",
            "64,auto",
            "1,2,3,4",
            "64,x,256",
        ] {
            assert!(p(bad).is_err(), "{bad}");
        }
        assert_eq!(pc(64, None, 256).auto_second(), Some(128));
        assert_eq!(pc(64, None, 128).auto_second(), None);
        assert_eq!(pc(64, Some(128), 256).auto_second(), None);
    }
}

spelled! {
    /// How the 64 rays of a packet walk the BSP tree (`docs/tracer.md`,
    /// "Traversal").
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum Traversal ("traversal") {
        /// The paper's: the packet's segments `[o, o + tbest d]` are classified
        /// against each split plane; where the rays disagree, every object
        /// under the node is tested (resident) or both children are visited
        /// with every ray awake (streamed).
        Paper = "paper",
        /// Masked packet traversal: each ray keeps its parametric interval
        /// inside the current cell; a child is visited only by the rays whose
        /// interval reaches it (the others sleep), near child first, the far
        /// child pushed with every ray's interval; a ray whose hit lies before
        /// a popped cell drops out. The default.
        #[default]
        Packet = "packet",
    }
}

spelled! {
    /// How the BSP nodes of the resident layout name the objects under them
    /// (`layout.rs`; the streamed layout has no per-node object sets, only
    /// per-leaf lists, whichever is chosen).
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum NodeLayout ("node layout") {
        /// The paper's Fig. 5: per node, per type present, a membership bit
        /// vector over all objects of that type, walked by the Fig. 6 loop.
        #[default]
        Fig5 = "fig5",
        /// Per node, per type present, a count and the ascending slot indices
        /// of the node's objects of that type (the set bits of the Fig. 5
        /// vector, as a list): the same objects in the same order.
        Compact = "compact",
    }
}

/// Numerical knobs of the generated kernels (for speed/accuracy studies);
/// the defaults are the configuration measured in `docs/tracer.md`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Numerics {
    /// Newton-Raphson steps after each table lookup (reciprocal and
    /// reciprocal square root), 0..=3.
    pub newton_steps: u32,
    /// Guard bits of the coordinate format above the scene's largest
    /// object or eye coordinate, 2..=4.
    pub guard_bits: u32,
    /// Offset of spawned rays along the normal, in LSBs, 0..=64.
    pub eps_lsb: i32,
    /// Entries of the reciprocal and reciprocal square root tables in every
    /// RC's RAM: 16, 32, 64 or 128 ([`super::math::TABLE_SIZES`]).
    pub table_entries: u32,
    /// Fine or coarse normals ([`Normals`]).
    pub normals: Normals,
}

spelled! {
    /// Normals of spheres and cylinders. Fine: the eye on the coordinate
    /// format's grid (the scene moved by less than an LSB), and the sphere
    /// and cylinder tests' perpendicular vector formed from unrounded
    /// quantities and made perpendicular to the ray
    /// ([`super::primitives::sphere::kernel`], [`super::primitives::cylinder::kernel`]): 9 more cycles per
    /// sphere test, 19 per cylinder test. Coarse: the kernels as first
    /// written (the cycle counts the comparison with the paper was made
    /// with). Auto: fine on the 16-bit chip, whose accuracy they decide,
    /// coarse on the 32-bit chip, whose 16 more fraction bits leave nothing
    /// to gain that shows for the cycles (`sweep`'s `normals` knob
    /// measures both).
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
    pub enum Normals ("normals") {
        #[default]
        Auto = "auto",
        Fine = "fine",
        Coarse = "coarse",
    }
}

spelled! {
    /// Where the 16-bit chip holds positions. Global: one fixed-point
    /// format for the whole scene (coordinates, origins, `t`). Local: ray
    /// origins carry a remainder (`RAY_OL`, 2^-14 LSB), and a sphere, flat
    /// triangle, open cylinder or cone seen from one side is tested in a frame of its own,
    /// its centre the origin and its LSB `2^-e` of the scene's, `e`
    /// fitted to its extent ([`crate::scene_image::local_exponent`]); its
    /// hit point comes back to the scene's format with the remainder
    /// (`HIT_PL`), and eye rays' directions carry one (`RAY_DL`).
    /// Refracted rays start at the rounded hit point. The packet traversal
    /// on the 16-bit chip; shadow rays a packet per light. Auto: `render` takes local ones on the 16-bit chip where
    /// its probe with global ones falls under the bar of `--datapath
    /// auto` (or the scene's format cannot hold the scene) and local ones
    /// do better; the tracer itself builds auto as global.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
    pub enum Positions ("positions") {
        #[default]
        Global = "global",
        Local = "local",
        Auto = "auto",
    }
}

impl Normals {
    /// Fine normals on `datapath`?
    pub fn fine_on(self, datapath: rtl::rc::Datapath) -> bool {
        match self {
            Normals::Auto => datapath == rtl::rc::Datapath::W16,
            Normals::Fine => true,
            Normals::Coarse => false,
        }
    }
}

impl Numerics {
    /// The kernels' reciprocal / square root approximation.
    pub fn approx(&self) -> super::math::Approx {
        super::math::Approx {
            newton_steps: self.newton_steps,
            table_entries: self.table_entries,
        }
    }
}

impl Default for Numerics {
    fn default() -> Self {
        Numerics {
            newton_steps: 2,
            guard_bits: 2,
            eps_lsb: EPS_LSB,
            table_entries: super::math::TABLE_ENTRIES,
            normals: Normals::Auto,
        }
    }
}

spelled! {
    /// How the shadow rays of the reflection levels are packed.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum ShadowPackets ("shadow packets") {
        /// `render` runs both on a probe of the frame and keeps the faster;
        /// a build without a probe ([`super::build`]) packs a packet per light.
        #[default]
        Auto = "auto",
        /// One packet per light at every level: the rays stay in the RCs that
        /// spawned them (the paper's).
        PerLight = "light",
        /// From the first reflection level on, the rays of all the lights
        /// packed into as few packets as hold them (packet traversal, 2 to
        /// [`super::shadows::MAX_LIGHTS`] lights).
        Merged = "merged",
    }
}

/// The rule of one axis for a packet whose awake rays do not all go the
/// same way along it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AxisOrder {
    /// The near child of most of the awake rays.
    #[default]
    Majority,
    /// The near child of the rays going down along the axis: the child
    /// above the split plane first.
    Down,
    /// The near child of the rays going up: the child below first.
    Up,
}

impl AxisOrder {
    fn letter(self) -> char {
        match self {
            AxisOrder::Majority => 'm',
            AxisOrder::Down => 'd',
            AxisOrder::Up => 'u',
        }
    }

    fn word(self) -> &'static str {
        match self {
            AxisOrder::Majority => "majority",
            AxisOrder::Down => "down",
            AxisOrder::Up => "up",
        }
    }
}

/// The packet traversal's child order of mixed packets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ChildOrder {
    /// `render` chooses: the ways the view's rays end ([`ChildOrder::from_hits`]),
    /// kept where faster than the majority on the probe of the frame; a
    /// build without a probe ([`crate::tracer::build`]) takes the majority.
    #[default]
    Auto,
    /// Per axis x, y, z: the rule of closest-hit passes and of any-hit
    /// passes.
    Fixed {
        closest: [AxisOrder; 3],
        any: [AxisOrder; 3],
    },
}

/// How far (in standard deviations of a fair split) the rays that end
/// must lean one way along an axis for [`ChildOrder::from_hits`] to serve
/// that way.
pub const SIGNIFICANT: f64 = 3.0;

/// How many of the sampled rays that end (hit, or are blocked) went down
/// and up along each axis: `[axis][0]` down (negative component),
/// `[axis][1]` up (positive).
pub type EndCounts = [[u64; 2]; 3];

impl ChildOrder {
    /// Every axis by the majority, in both kinds of pass.
    pub const MAJORITY: ChildOrder = ChildOrder::Fixed {
        closest: [AxisOrder::Majority; 3],
        any: [AxisOrder::Majority; 3],
    };

    /// The rules that serve the rays that end: per axis, `down` where
    /// more of the sampled rays that end went down than up, `up` where
    /// more went up, each only where the difference is more than
    /// [`SIGNIFICANT`] standard deviations of a fair split (`sqrt(n)` of
    /// `n` such rays): an even split, and one the sample cannot tell from
    /// even, keeps the majority, which serves each packet's own rays; so
    /// does an axis along which every sampled ray went the same way (its
    /// packets agree). `closest`: the secondary (reflected, refracted)
    /// rays that hit something, and all of them, by axis and way; `any`:
    /// the shadow rays that were blocked, and all of them.
    pub fn from_hits(
        closest: (&EndCounts, &EndCounts),
        any: (&EndCounts, &EndCounts),
    ) -> ChildOrder {
        let rule = |(ended, all): (&EndCounts, &EndCounts)| {
            let mut r = [AxisOrder::Majority; 3];
            for a in 0..3 {
                let [down, up] = ended[a];
                let mixed = all[a][0] > 0 && all[a][1] > 0;
                let clear = down.abs_diff(up) as f64 > SIGNIFICANT * ((down + up) as f64).sqrt();
                r[a] = if !mixed || !clear {
                    AxisOrder::Majority
                } else if down > up {
                    AxisOrder::Down
                } else {
                    AxisOrder::Up
                };
            }
            r
        };
        ChildOrder::Fixed {
            closest: rule(closest),
            any: rule(any),
        }
    }

    /// The rules, `Auto` taken as the majority (what [`crate::tracer::build`]
    /// builds).
    pub fn rules(self) -> ([AxisOrder; 3], [AxisOrder; 3]) {
        match self {
            ChildOrder::Auto => ([AxisOrder::Majority; 3], [AxisOrder::Majority; 3]),
            ChildOrder::Fixed { closest, any } => (closest, any),
        }
    }

    /// In words, for reports: "majority", or per kind of pass the axes
    /// whose rule is not the majority ("closest hit: x up, y up, z down;
    /// any hit: majority").
    pub fn describe(self) -> String {
        if self == ChildOrder::Auto {
            return "auto".into();
        }
        let (closest, any) = self.rules();
        if closest == any && closest == [AxisOrder::Majority; 3] {
            return "majority".into();
        }
        let axes = |r: [AxisOrder; 3]| {
            if r == [AxisOrder::Majority; 3] {
                return "majority".to_string();
            }
            r.iter()
                .zip(["x", "y", "z"])
                .map(|(o, a)| format!("{a} {}", o.word()))
                .collect::<Vec<_>>()
                .join(", ")
        };
        format!("closest hit: {}; any hit: {}", axes(closest), axes(any))
    }
}

impl std::fmt::Display for ChildOrder {
    /// `auto`, `majority`, or the letters of the closest-hit and any-hit
    /// rules (`uud,umm`: see [`std::str::FromStr`]).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            ChildOrder::Auto => f.write_str("auto"),
            o if o == ChildOrder::MAJORITY => f.write_str("majority"),
            ChildOrder::Fixed { closest, any } => {
                let s: String = closest.iter().map(|o| o.letter()).collect();
                let a: String = any.iter().map(|o| o.letter()).collect();
                write!(f, "{s},{a}")
            }
        }
    }
}

impl std::str::FromStr for ChildOrder {
    type Err = String;
    /// `auto`, `majority`, or `XYZ[,XYZ]`: for closest-hit passes and
    /// (after the comma; majority without it) any-hit passes, one letter
    /// per axis x, y, z: `m` the majority, `d` the rays going down (the
    /// child above first), `u` the rays going up (the child below first).
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => return Ok(ChildOrder::Auto),
            "majority" => return Ok(ChildOrder::MAJORITY),
            _ => {}
        }
        let bad = || {
            format!(
                "child order '{s}': expected auto, majority or three letters m, d or u per kind of pass, \
                 the axes x, y, z of closest-hit passes, then optionally a comma and those of any-hit passes (e.g. uud or uud,umm)"
            )
        };
        let axes = |g: &str| -> Option<[AxisOrder; 3]> {
            let v: Vec<AxisOrder> = g
                .chars()
                .map(|c| match c {
                    'm' => Some(AxisOrder::Majority),
                    'd' => Some(AxisOrder::Down),
                    'u' => Some(AxisOrder::Up),
                    _ => None,
                })
                .collect::<Option<_>>()?;
            v.try_into().ok()
        };
        let (c, a) = match s.split_once(',') {
            Some((c, a)) => (c, Some(a)),
            None => (s, None),
        };
        let closest = axes(c).ok_or_else(bad)?;
        let any = match a {
            Some(a) => axes(a).ok_or_else(bad)?,
            None => [AxisOrder::Majority; 3],
        };
        Ok(ChildOrder::Fixed { closest, any })
    }
}
