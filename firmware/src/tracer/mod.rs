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

pub mod data;
pub mod emit;
pub mod kernel_names;
pub mod layout;
pub mod math;
pub mod memory_map;
pub mod positions;
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
pub mod options;
pub use options::{
    AxisOrder, ChildOrder, Collapse, LeafPieces, NodeLayout, Normals, Numerics, Options, Positions,
    ShadowPackets, SubEdges, TestCuts, Traversal,
};

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
        layout::fb_word_bytes(&self.fb, self.datapath.extra_bits())
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
/// that over the distance the reflected ray travels, which on SPD balls
/// on the 16-bit chip costs dB that show (`--normals coarse` renders
/// without the move).
/// The scene's images are the same in exact arithmetic (objects, eye and
/// lights move together). Where the move would change the format (an
/// extent within an LSB of a format's limit), the unmoved build is kept.
/// Scenes without curved objects (spheres, cylinders, cones) are not
/// moved: a plane's normal does not turn with the ray, and the move would
/// only round every vertex afresh (and may change the median tree's
/// shape). Nor are scenes with local positions whose curved objects are
/// all opaque and tested in frames of their own: their eye rays start at
/// the eye with its remainder ([`positions::eye`]), and the move would
/// round the lights and the planes afresh (with transmitting ones, whose
/// refracted rays start at the rounded hit point, the move measures
/// better: SPD mount-2 at 128x128, depth 5, 38.88 against 37.54 dB).
fn build_as(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    force_stream: bool,
) -> Result<Firmware, String> {
    let local = opt.positions == Positions::Local;
    let curved = scene.objects.iter().any(|o| {
        o.shape.surface().curved()
            && !(local
                && scene.materials[o.material].t <= 0.0
                && crate::scene_image::local_frame(scene, &o.shape).is_some())
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
        .map(|c| layout::fit_frac(scene, c, nm.guard_bits) + opt.datapath.extra_bits());
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
    let (tw, th) = checked(opt, nm)?;
    let chip_costs = (opt.bsp.rule == SplitRule::Chip).then(|| {
        let frac = crate::scene_image::fitted_frac(scene, nm.guard_bits).unwrap_or(9)
            + opt.datapath.extra_bits();
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
        // The chip's records are finer than the compiler's format where
        // lights set its span (`layout::fit_frac`): features are checked
        // at the records' precision.
        target_extra_frac: opt.datapath.extra_bits()
            + crate::scene_image::fitted_frac(scene, nm.guard_bits)
                .map_or(0, |c| layout::fit_frac(scene, c, nm.guard_bits) - c),
        local_frames: opt.positions == Positions::Local,
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
            let fine = force_stream || paper_layout_streams(scene, opt, nm, &copt);
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
        opt.datapath.extra_bits(),
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

/// The options' and numerics' ranges (what the library is given, whoever
/// calls it); the tile of `opt.ways` rays.
fn checked(opt: &Options, nm: &Numerics) -> Result<(u32, u32), String> {
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
    if opt.positions == Positions::Local {
        if opt.datapath != rtl::rc::Datapath::W16 {
            return Err("--positions local: the 16-bit chip's (the 32-bit chip's formats carry 16 more fraction bits)".into());
        }
        if opt.traversal != Traversal::Packet {
            return Err("--positions local: the packet traversal's (the paper's traversal keeps the paper's number handling)".into());
        }
    }
    let tile = tile_shape(opt.ways)
        .ok_or_else(|| format!("--ways {}: must be 4, 8, 16, 32 or 64", opt.ways))?;
    if opt.depth == 0 || opt.depth > MAX_RAY_DEPTH {
        return Err(format!(
            "--depth {}: must be 1..={MAX_RAY_DEPTH}",
            opt.depth
        ));
    }
    Ok(tile)
}

/// Whether the paper's layout of this scene (its tree) streams: the packet
/// traversal takes the format of the streamed layout where it does.
fn paper_layout_streams(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    copt: &CompileOptions,
) -> bool {
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
        ..copt.clone()
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
