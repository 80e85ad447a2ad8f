//! The ray tracer firmware: a generator that writes, for one scene and one
//! set of options, the TinyRISC program and the RC context kernels (one
//! assembly source for [`crate::asm`]) and the frame-buffer image they read.
//!
//! What runs where (the paper's sections III to VIII):
//!
//! * **RCs** (one ray per RC, 8x8 tile = 64 rays): eye-ray generation and
//!   normalisation, ray-object kernels ([`kernels`]: sphere, open cylinder
//!   with optional end caps, box as its six faces, rectangle, triangle,
//!   polygon as a fan of triangles), BSP node status (which side of the
//!   split plane each ray's segment reaches), Phong shading, shadow and
//!   reflection ray set-up, the local stack in RC RAM.
//! * **TinyRISC** ([`control`]): the tile loop; depth-first BSP traversal
//!   steered by the RCs' status (all rays agree: follow; they disagree:
//!   test every object under the node via the Fig. 5 bit vectors and the
//!   Fig. 6 address loop, or the node's index lists with
//!   [`NodeLayout::Compact`]); mailboxes in the FB so an object is tested once
//!   per pass (object merging); object tests grouped by type (reordering);
//!   at a leaf the RCs whose hit is found sleep; pixels out through the FB
//!   by DMA, overlapped with the next tile.
//!
//! Number formats: coordinates and distances in the scene's `Qm.n` (fitted
//! with two guard bits by [`crate::scene_image`]), directions and normals
//! Q1.14, colours Q3.12. Reciprocal and reciprocal square root: tables of
//! 128 entries (a knob: 16..=128) in every RC's RAM plus two Newton-Raphson
//! steps.

pub mod emit;
pub mod kernel_names;
pub mod layout;
pub mod math;
pub mod memory_map;
pub mod primitives;
pub mod program;
pub mod shading;
pub mod shadows;
pub mod tiles;
pub mod traversal;

use crate::bsp::{BspParams, SplitRule};
use crate::scene::Scene;
use crate::scene_image::{compile, CompileOptions, Report};
pub use rtl::rc::Datapath;
pub use shadows::ShadowPackets;
pub use traversal::child_order::{AxisOrder, ChildOrder};

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
    /// resolved per traversal ([`resolve_bsp`]): the paper's median split
    /// to depth 15 for the paper's traversal; for the packet traversal that
    /// tree, a pbrt SAH tree and a chip-cost SAH tree (both to
    /// [`crate::bsp::auto_depth`]): `render` keeps the fastest on a probe
    /// of the frame, [`build`] the cheapest by the traversal's cost model.
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
}

/// Streamed packet traversal: where a banded polygon's sub-edges are
/// (`primitives::polygon::Form`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SubEdges {
    /// In main memory apart from the record where a record would be
    /// over [`primitives::polygon::APART_FROM`] words, a packet's bands
    /// of them moved by DMA once its points are known.
    #[default]
    Apart,
    /// In the record, moved with every leaf piece that holds it (the
    /// resident layout's form).
    InRecords,
}

impl std::fmt::Display for SubEdges {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SubEdges::Apart => "apart",
            SubEdges::InRecords => "records",
        })
    }
}

impl std::str::FromStr for SubEdges {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "apart" => Ok(SubEdges::Apart),
            "records" => Ok(SubEdges::InRecords),
            _ => Err(format!("sub-edges '{s}': expected apart or records")),
        }
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
        }
    }
}

/// Packet traversal: whether an object test runs in parts at its kernels'
/// cuts ([`primitives::CutTest`]), the rest skipped where no awake ray can
/// still hit the object, and who skips it: the broadcast unit, at a `cut`
/// context in the kernel's run (`on`), or TinyRISC, which broadcasts each
/// part after a status read (`tinyrisc`); or whole (`off`). `auto` (the
/// default) is `on` under the run issue model and `tinyrisc` under the M1
/// chip's instruction issue, where TinyRISC issues every context itself
/// and would be held for the contexts a cut skips
/// ([`TestCuts::for_issue`]; the firmware built without a timing takes
/// `on`). The same image every way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TestCuts {
    #[default]
    Auto,
    On,
    Tinyrisc,
    Off,
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

impl std::fmt::Display for TestCuts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            TestCuts::Auto => "auto",
            TestCuts::On => "on",
            TestCuts::Tinyrisc => "tinyrisc",
            TestCuts::Off => "off",
        })
    }
}

impl std::str::FromStr for TestCuts {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(TestCuts::Auto),
            "on" => Ok(TestCuts::On),
            "tinyrisc" => Ok(TestCuts::Tinyrisc),
            "off" => Ok(TestCuts::Off),
            _ => Err(format!(
                "test cuts '{s}': expected auto, on, tinyrisc or off"
            )),
        }
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
    pub const MAX: usize = layout::STREAM_BANK;

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

/// How the 64 rays of a packet walk the BSP tree (`docs/tracer.md`,
/// "Traversal").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Traversal {
    /// The paper's: the packet's segments `[o, o + tbest d]` are classified
    /// against each split plane; where the rays disagree, every object
    /// under the node is tested (resident) or both children are visited
    /// with every ray awake (streamed).
    Paper,
    /// Masked packet traversal: each ray keeps its parametric interval
    /// inside the current cell; a child is visited only by the rays whose
    /// interval reaches it (the others sleep), near child first, the far
    /// child pushed with every ray's interval; a ray whose hit lies before
    /// a popped cell drops out. The default.
    #[default]
    Packet,
}

impl Traversal {
    pub const ALL: [Traversal; 2] = [Traversal::Paper, Traversal::Packet];
    pub fn name(self) -> &'static str {
        match self {
            Traversal::Paper => "paper",
            Traversal::Packet => "packet",
        }
    }
}

impl std::fmt::Display for Traversal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Traversal {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Traversal::ALL
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| format!("unknown traversal '{s}': expected paper or packet"))
    }
}

/// How the BSP nodes of the resident layout name the objects under them
/// (`layout.rs`; the streamed layout has no per-node object sets, only
/// per-leaf lists, whichever is chosen).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum NodeLayout {
    /// The paper's Fig. 5: per node, per type present, a membership bit
    /// vector over all objects of that type, walked by the Fig. 6 loop.
    #[default]
    Fig5,
    /// Per node, per type present, a count and the ascending slot indices
    /// of the node's objects of that type (the set bits of the Fig. 5
    /// vector, as a list): the same objects in the same order.
    Compact,
}

impl NodeLayout {
    pub const ALL: [NodeLayout; 2] = [NodeLayout::Fig5, NodeLayout::Compact];
    pub fn name(self) -> &'static str {
        match self {
            NodeLayout::Fig5 => "fig5",
            NodeLayout::Compact => "compact",
        }
    }
}

impl std::fmt::Display for NodeLayout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for NodeLayout {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        NodeLayout::ALL
            .into_iter()
            .find(|l| l.name() == s)
            .ok_or_else(|| format!("unknown node layout '{s}': expected fig5 or compact"))
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
    /// RC's RAM: 16, 32, 64 or 128 ([`math::TABLE_SIZES`]).
    pub table_entries: u32,
    /// Fine or coarse normals ([`Normals`]).
    pub normals: Normals,
}

/// Normals of spheres and cylinders. Fine: the eye on the coordinate
/// format's grid (the scene moved by less than an LSB), and the sphere
/// and cylinder tests' perpendicular vector formed from unrounded
/// quantities and made perpendicular to the ray
/// ([`kernels::sphere_with`], [`kernels::cylinder`]): 9 more cycles per
/// sphere test, 19 per cylinder test. Coarse: the kernels as first
/// written (the cycle counts the comparison with the paper was made
/// with). Auto: fine on the 16-bit chip, whose accuracy they decide
/// (jacks-2: 29.5 to 33.2 dB), coarse on the 32-bit chip, whose 16 more
/// fraction bits leave nothing to gain that shows (jacks-2: 56.0 dB
/// coarse, 66.6 fine, for 5% of the frame rate).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Normals {
    #[default]
    Auto,
    Fine,
    Coarse,
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

    pub fn name(self) -> &'static str {
        match self {
            Normals::Auto => "auto",
            Normals::Fine => "fine",
            Normals::Coarse => "coarse",
        }
    }
}

impl std::str::FromStr for Normals {
    type Err = String;
    fn from_str(s: &str) -> Result<Normals, String> {
        match s {
            "auto" => Ok(Normals::Auto),
            "fine" => Ok(Normals::Fine),
            "coarse" => Ok(Normals::Coarse),
            _ => Err(format!("expected auto, fine or coarse, found '{s}'")),
        }
    }
}

impl Numerics {
    /// The kernels' reciprocal / square root approximation.
    pub fn approx(&self) -> math::Approx {
        math::Approx {
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
            eps_lsb: shading::EPS_LSB,
            table_entries: math::TABLE_ENTRIES,
            normals: Normals::Auto,
        }
    }
}

/// Tile width and height for a number of ways.
pub fn tile_shape(ways: u32) -> Option<(u32, u32)> {
    match ways {
        4 => Some((2, 2)),
        8 => Some((4, 2)),
        16 => Some((4, 4)),
        32 => Some((8, 4)),
        64 => Some((8, 8)),
        _ => None,
    }
}

/// Main-memory map of the program.
pub mod mem {
    pub const CTX_BASE: u32 = 0x2_0000;
    /// The FB image, copied into the FB by DMA at start.
    pub const FB_IMAGE: u32 = 0x4_0000;
    /// Tile list: count, then (px0, py0, output address) words.
    pub const TILE_LIST: u32 = 0x6_0000;
    /// Output: 256 FB words per tile (R, G, B, object id; 64 lanes each),
    /// half-words on the 16-bit chip, words on the 32-bit chip
    /// ([`super::Firmware::out_tile_bytes`]).
    pub const OUTPUT: u32 = 0x8_0000;
    pub const OUT_TILE_BYTES: u32 = 512;
    /// The streamed layout's scene image (nodes, leaf lists, leaf blocks,
    /// mailboxes), up to [`STREAM_END`].
    pub const STREAM: u32 = 0x10_0000;
    pub const STREAM_END: u32 = 0x100_0000;
}

/// The generated firmware.
#[derive(Clone, Debug)]
pub struct Firmware {
    /// The whole assembly source (TinyRISC code, data and contexts).
    pub source: String,
    /// The frame-buffer image (set 0), loaded at [`mem::FB_IMAGE`] as
    /// [`Firmware::fb_bytes`]: word values (16-bit, or 32-bit on the 32-bit
    /// chip).
    pub fb: Vec<i32>,
    pub datapath: Datapath,
    pub report: Report,
    pub tile_w: u32,
    pub tile_h: u32,
    /// Fraction bits of the scene format.
    pub frac: u32,
    pub context_words: usize,
    /// Names of the kernels loaded (types present only) and their lengths.
    pub kernels: Vec<(String, usize)>,
    /// Where everything is in the FB image, and the kernels' scale shifts.
    pub layout: layout::FbImage,
    /// The BSP built (the options' automatic choices resolved).
    pub bsp: BspParams,
    /// How the reflection levels' shadow rays are packed: `PerLight` or
    /// `Merged` (never `Auto`).
    pub shadows: ShadowPackets,
    /// The packet traversal's child order of mixed packets (never `Auto`:
    /// built as the majority; the paper's traversal has none, `MAJORITY`).
    pub child_order: ChildOrder,
    /// A streamed leaf's pieces (the second's `auto` resolved: built as
    /// the rest's).
    pub pieces: LeafPieces,
}

impl Firmware {
    /// The FB image as main memory holds it for `ldfb`: 2 bytes per word on
    /// the 16-bit chip, 4 on the 32-bit chip.
    pub fn fb_bytes(&self) -> Vec<u8> {
        layout::fb_word_bytes(&self.fb, self.datapath.bits() - 16)
    }

    /// Bytes of one FB word.
    pub fn fb_word_bytes(&self) -> u32 {
        self.datapath.fb_word_bytes()
    }

    /// Bytes of one tile's output in main memory (256 FB words).
    pub fn out_tile_bytes(&self) -> u32 {
        256 * self.fb_word_bytes()
    }

    /// The scene format `Qm.n` of this chip.
    pub fn format(&self) -> String {
        format!("Q{}.{}", self.datapath.bits() - 1 - self.frac, self.frac)
    }
}

// The program leaves its statistics in main memory at the symbols
// `T_START`, `T_END` (cycle counter at the start and the end of the tile
// loop), `TESTS` (object tests broadcast) and `PASSES` (ray passes).

/// The deepest ray tree the tracer builds (the eye ray is depth 1; the
/// SPD's scenes ask for 5): a stack frame per level in RC RAM. The
/// reference renderer takes the same limit, so the two always compare.
pub const MAX_RAY_DEPTH: u32 = 8;

/// Build the firmware for `scene`.
pub fn build(scene: &Scene, opt: &Options) -> Result<Firmware, String> {
    build_with(scene, opt, &Numerics::default())
}

/// Build the firmware for `scene` with explicit numerical knobs.
pub fn build_with(scene: &Scene, opt: &Options, nm: &Numerics) -> Result<Firmware, String> {
    build_as(scene, opt, nm, false)
}

/// `fw`, built by [`build_with`] for `scene` and `opt`, with its program
/// generated again for the child order `order`
/// ([`traversal::child_order`]): the same data image, layout and BSP, the
/// same program but for `trace`'s orders of mixed packets, without
/// building the scene's layout again.
pub fn with_child_order(
    scene: &Scene,
    fw: &Firmware,
    opt: &Options,
    nm: &Numerics,
    order: ChildOrder,
) -> Result<Firmware, String> {
    let o = Options {
        bsp: fw.bsp,
        shadows: fw.shadows,
        pieces: fw.pieces,
        child_order: order,
        ..*opt
    };
    let prog = program::program(scene, &fw.layout, &o, nm, fw.tile_w, fw.tile_h)?;
    Ok(Firmware {
        source: prog.source,
        context_words: prog.context_words,
        kernels: prog.kernels,
        child_order: resolved_child_order(&o),
        ..fw.clone()
    })
}

/// The child order a build for `opt` takes: `Auto` as the majority, and
/// none (the majority) for the paper's traversal.
fn resolved_child_order(opt: &Options) -> ChildOrder {
    match opt.child_order {
        ChildOrder::Auto => ChildOrder::MAJORITY,
        o if opt.traversal == Traversal::Packet => o,
        _ => ChildOrder::MAJORITY,
    }
}

/// Build the firmware with the streamed layout whether or not the scene
/// fits the FB (for tests and comparisons; [`build_with`] streams only the
/// scenes that do not fit).
pub fn build_streamed_with(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
) -> Result<Firmware, String> {
    build_as(scene, opt, nm, true)
}

/// The BSP trees to try for `opt` (automatic choices resolved): one, or
/// for the packet traversal with `SplitRule::Auto` the paper's median tree,
/// a pbrt SAH tree and a chip-cost SAH tree, of which the build keeps the
/// cheapest by the packet traversal's cost model (`render` probes them
/// instead).
pub fn resolve_bsp(opt: &Options, objects: usize) -> Vec<BspParams> {
    let b = opt.bsp;
    let depth = |rule: SplitRule| match (b.max_depth, rule) {
        (0, SplitRule::Sah | SplitRule::Chip) => crate::bsp::auto_depth(objects),
        (0, _) => 15,
        (d, _) => d,
    };
    let with = |rule: SplitRule| BspParams {
        rule,
        max_depth: depth(rule),
        ..b
    };
    match (opt.traversal, b.rule) {
        (Traversal::Paper, SplitRule::Auto) => vec![with(SplitRule::Median)],
        (Traversal::Packet, SplitRule::Auto) => vec![
            with(SplitRule::Median),
            with(SplitRule::Sah),
            with(SplitRule::Chip),
        ],
        (_, rule) => vec![with(rule)],
    }
}

/// Build, with the scene moved by less than an LSB so that the eye lies on
/// the grid of the coordinate format: every eye ray then starts exactly
/// at the eye. Rounded, the eye would move every eye ray by up to half an
/// LSB per axis, the same shift for the whole frame; the picture barely
/// moves, but the normal a ray finds on a sphere a few dozen LSB across
/// turns by that shift over the radius, and a reflection in it by twice
/// that over the distance the reflected ray travels: on SPD balls (size
/// 2, 256x256, 16-bit) 30.0 dB against 33.3 dB with the eye on the grid.
/// The scene's images are the same in exact arithmetic (objects, eye and
/// lights move together). Where the move would change the format (an
/// extent within an LSB of a format's limit), the unmoved build is kept.
/// Scenes without curved objects (spheres, cylinders, cones) are not
/// moved: a plane's normal does not turn with the ray, and the move would
/// only round every vertex afresh (gears-1 lost 0.3 dB to it, the pp torus
/// 0.4 dB, tetra-2's median tree changed shape).
fn build_as(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    force_stream: bool,
) -> Result<Firmware, String> {
    let curved = scene.objects.iter().any(|o| {
        matches!(
            o.shape,
            crate::scene::Shape::Sphere { .. } | crate::scene::Shape::Cone { .. }
        )
    });
    if !nm.normals.fine_on(opt.datapath) || !curved {
        return build_any_bsp(scene, opt, nm, force_stream);
    }
    // The move that puts the eye on the grid of `frac`.
    let to_grid = |frac: u32| {
        let lsb = (-(frac as f64)).exp2();
        let eye = scene.camera.from;
        let snap = |x: f64| (x / lsb).round() * lsb - x;
        crate::scene::Vec3::new(snap(eye.x), snap(eye.y), snap(eye.z))
    };
    // Built once where the format is foreseen (a resident layout's: the
    // compiler's fit refined by the layout's), else built, moved and
    // built again.
    let foreseen = crate::scene_image::fitted_frac(scene, nm.guard_bits)
        .map(|c| layout::fit_frac(scene, c, nm.guard_bits) + opt.datapath.bits() - 16);
    if let Some(frac) = foreseen {
        let d = to_grid(frac);
        if let Ok(fw) = build_any_bsp(&scene.translated(d), opt, nm, force_stream) {
            if fw.frac == frac {
                return Ok(fw);
            }
        }
    }
    let fw = build_any_bsp(scene, opt, nm, force_stream)?;
    let d = to_grid(fw.frac);
    if d == crate::scene::Vec3::ZERO {
        return Ok(fw);
    }
    match build_any_bsp(&scene.translated(d), opt, nm, force_stream) {
        Ok(moved) if moved.frac == fw.frac => Ok(moved),
        _ => Ok(fw),
    }
}

fn build_any_bsp(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    force_stream: bool,
) -> Result<Firmware, String> {
    let mut best: Option<Firmware> = None;
    let mut first_err = None;
    for bsp in resolve_bsp(opt, scene.objects.len()) {
        match build_one(scene, &Options { bsp, ..*opt }, nm, force_stream) {
            Ok(fw) => {
                if best
                    .as_ref()
                    .is_none_or(|b| fw.layout.expected_cost < b.layout.expected_cost)
                {
                    best = Some(fw);
                }
            }
            Err(e) => {
                first_err.get_or_insert(e);
            }
        }
    }
    best.ok_or_else(|| first_err.unwrap_or_else(|| "internal: no BSP to build".into()))
}

fn build_one(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    force_stream: bool,
) -> Result<Firmware, String> {
    if nm.newton_steps > 3 || !(2..=4).contains(&nm.guard_bits) || !(0..=64).contains(&nm.eps_lsb) {
        return Err(format!(
            "numerics {nm:?}: newton_steps must be 0..=3, guard_bits 2..=4, eps_lsb 0..=64"
        ));
    }
    if !math::TABLE_SIZES.contains(&nm.table_entries) {
        return Err(format!(
            "table size {}: must be 16, 32, 64 or 128 entries (each table has a 128-word slot of the RC's 512-word RAM)",
            nm.table_entries
        ));
    }
    let (tw, th) = tile_shape(opt.ways)
        .ok_or_else(|| format!("--ways {}: must be 4, 8, 16, 32 or 64", opt.ways))?;
    if opt.depth == 0 || opt.depth > MAX_RAY_DEPTH {
        return Err(format!(
            "--depth {}: must be 1..={MAX_RAY_DEPTH}",
            opt.depth
        ));
    }
    let chip_costs = (opt.bsp.rule == SplitRule::Chip).then(|| {
        let frac = crate::scene_image::fitted_frac(scene, nm.guard_bits).unwrap_or(9)
            + opt.datapath.bits()
            - 16;
        std::sync::Arc::new(layout::packet_nodes::chip_costs(
            scene,
            opt.datapath,
            nm.normals.fine_on(opt.datapath),
            frac,
        ))
    });
    let copt = CompileOptions {
        bsp: opt.bsp,
        chip_costs,
        layout: Some(crate::scene_image::NodeFormat::BitVectors),
        guard_bits: nm.guard_bits,
        target_extra_frac: opt.datapath.bits() - 16,
        ..CompileOptions::default()
    };
    let image = compile(scene, &copt).map_err(|e| e.to_string())?;
    let mut lay = match opt.traversal {
        Traversal::Paper => layout::build(
            scene,
            &image,
            opt,
            nm.guard_bits,
            nm.normals.fine_on(opt.datapath),
            force_stream,
        )?,
        Traversal::Packet => {
            // The format of the paper's layout of this scene (its tree):
            // the streamed one's where the paper's layout streams.
            let fine = force_stream || {
                let paper = CompileOptions {
                    bsp: resolve_bsp(
                        &Options {
                            traversal: Traversal::Paper,
                            bsp: BspParams {
                                max_depth: 0,
                                rule: SplitRule::Auto,
                                ..opt.bsp
                            },
                            ..*opt
                        },
                        scene.objects.len(),
                    )[0],
                    ..copt
                };
                let paper_opt = Options {
                    traversal: Traversal::Paper,
                    bsp: paper.bsp,
                    ..*opt
                };
                match compile(scene, &paper) {
                    Ok(pi) => layout::build(
                        scene,
                        &pi,
                        &paper_opt,
                        nm.guard_bits,
                        nm.normals.fine_on(opt.datapath),
                        false,
                    )
                    .map_or(true, |l| l.stream.is_some()),
                    Err(_) => true,
                }
            };
            layout::build_packet(
                scene,
                &image,
                opt,
                nm.guard_bits,
                nm.normals.fine_on(opt.datapath),
                force_stream,
                fine,
            )?
        }
    };
    lay.fb[..256].copy_from_slice(&math::table_slots_for(
        nm.table_entries as usize,
        opt.datapath.bits() - 16,
    ));
    let prog = program::program(scene, &lay, opt, nm, tw, th)?;
    let shadows = if shadows::merged(opt, &lay) {
        ShadowPackets::Merged
    } else {
        ShadowPackets::PerLight
    };
    Ok(Firmware {
        source: prog.source,
        fb: lay.fb.clone(),
        datapath: opt.datapath,
        report: image.report.clone(),
        tile_w: tw,
        tile_h: th,
        frac: lay.frac,
        context_words: prog.context_words,
        kernels: prog.kernels,
        layout: lay,
        bsp: opt.bsp,
        shadows,
        child_order: resolved_child_order(opt),
        pieces: LeafPieces {
            second: Some(opt.pieces.second_or_rest()),
            ..opt.pieces
        },
    })
}

/// What the chip does not render as `scene` asks, one [`Warning`] per
/// feature (the count of objects and the first line): Phong exponents over
/// the shading kernel's where they show, and values the scene compiler
/// clamped to its formats (`notes`, from
/// [`Report::notes`]). The scene's own warnings (skipped degenerate
/// objects) are in [`Scene::warnings`].
///
/// [`Warning`]: crate::scene::Warning
pub fn chip_warnings(scene: &Scene, notes: &[String]) -> Vec<crate::scene::Warning> {
    use crate::scene::Warning;
    let mut out = Vec::new();
    let mut add = |feature: &str, hits: Vec<usize>, message: String| {
        if let Some(&line) = hits.first() {
            out.push(Warning {
                feature: feature.into(),
                file: scene.source.clone(),
                line,
                count: hits.len(),
                message,
            });
        }
    };
    let plural = |n: usize, one: &str, many: &str| {
        if n == 1 {
            format!("1 {one}")
        } else {
            format!("{n} {many}")
        }
    };
    // Phong exponents over the shading kernel's: only where Ks > 0 (the
    // SPD writes 100000 for many surfaces without highlights).
    let shiny: Vec<usize> = scene
        .objects
        .iter()
        .filter(|o| {
            let m = &scene.materials[o.material];
            m.ks > 0.0 && m.shine > shading::MAX_SHINE
        })
        .map(|o| o.line)
        .collect();
    let n = shiny.len();
    add(
        "phong-exponent",
        shiny,
        format!(
            "{} a Phong exponent over {}: the chip's highlight is computed with {} (wider where R.V is within a few 1/{} of 1)",
            plural(n, "object has", "objects have"),
            shading::MAX_SHINE,
            shading::MAX_SHINE,
            shading::MAX_SHINE
        ),
    );
    // One warning per distinct note of the scene compiler (the exponent is
    // the tracer's own, above).
    let notes: Vec<&String> = notes
        .iter()
        .filter(|n| !n.starts_with("Phong exponent"))
        .collect();
    let mut seen: Vec<&String> = Vec::new();
    for note in notes.iter().copied() {
        if seen.contains(&note) {
            continue;
        }
        seen.push(note);
        out.push(Warning {
            feature: "clamped".into(),
            file: scene.source.clone(),
            line: 0,
            count: notes.iter().filter(|n| **n == note).count(),
            message: format!("scene compiler: {note}"),
        });
    }
    out
}
