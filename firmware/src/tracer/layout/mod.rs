//! The frame-buffer image the tracer reads (FB set 0, word addresses):
//!
//! ```text
//! 0     RSQ table (128) | RCP table (128) | 1.0 | 32767      init stream
//! EYE   px0, py0 (written per tile), from.xyz, (A, B, C) x 3  eye stream
//! POST  background.rgb, (material id, ks) per material
//! TRANSMIT per transmitting material: id, T, 1/ior, ior (refracting scenes)
//! LIGHT per light: [scale shift,] position.xyz
//! SHADE per light, per material: id, then per channel kd c lc, ks lc
//! ROOTBOX the root cell widened (packet traversal)
//! objects, grouped by type, fixed record size per type (one module per
//!     primitive in `primitives/`; polygons padded to the largest fan)
//! BSP nodes: the paper's traversal's (paper_nodes.rs) or the packet
//!     traversal's (packet_nodes/), and the paper's mailboxes
//! ```
//!
//! A scene whose image does not fit FB set 0 gets a streamed layout
//! ([`Stream`]): only the part up to SHADE (and ROOTBOX) stays in the FB
//! (bank 0, plus the split words); nodes, per-leaf blocks of records and
//! mailboxes go to main memory, and bank 1 is the streaming buffer. The
//! program's header names every address and field of this image.

mod costs;
pub mod packet_nodes;
pub mod paper_nodes;
mod streams;

use crate::scene::Scene;
use crate::scene_image::SceneImage;

use super::math::table_slots_for;
pub use super::memory_map::{FB_LIMIT, STREAM_BANK};
pub use super::primitives::record::fb_word_bytes;
pub(crate) use super::primitives::record::W;
use super::primitives::record::{fit_shift_w, Fitter};
pub use super::primitives::ChipType;
use super::primitives::{polygon, Fit, Geometry, Object, RecordError, PRIMITIVES};
use super::shading::phong_exponent;
use super::{NodeLayout, Options, Traversal};
pub use packet_nodes::{PK_INNER, PK_LEAF_HEAD, PK_MAILBOX_BYTES};
pub use paper_nodes::{compact_head, COMPACT_INNER_HEAD, COMPACT_LEAF_HEAD, NODE_HEAD};
use streams::{camera, distinct_materials, lights, post_streams};
pub use streams::{fit_frac, light_shift, light_shift_w};

/// The object types a streamed scene's node records count: one word per
/// type present, between the records' fields (`PS_COUNTS` and
/// `SN_COUNTS`, 28 to 56 bytes).
pub const STREAMED_TYPES: usize = 7;

/// The resident part of a streamed layout (`w` so far) fits FB bank 0,
/// or the error that says by how much it does not.
fn resident_fits(w: &W, err: &dyn Fn(usize, String) -> String) -> Result<(), String> {
    if w.fb.len() > STREAM_BANK {
        return Err(err(
            0,
            format!(
                "the resident part of the streamed layout needs {} FB words; bank 0 holds {STREAM_BANK}",
                w.fb.len()
            ),
        ));
    }
    Ok(())
}

/// A streamed scene's types fit its node records' counts, or the error
/// that names them.
fn streamed_types_fit(
    types: &[TypeInfo],
    err: &dyn Fn(usize, String) -> String,
) -> Result<(), String> {
    if types.len() <= STREAMED_TYPES {
        return Ok(());
    }
    let names: Vec<&str> = types.iter().map(|t| t.ty.name()).collect();
    Err(err(
        0,
        format!(
            "the scene is streamed from main memory, whose node records count at most {STREAMED_TYPES} object types; it has {} ({})",
            types.len(),
            names.join(", ")
        ),
    ))
}

/// One type present in the scene.
#[derive(Clone, Debug)]
pub struct TypeInfo {
    pub ty: ChipType,
    /// Scene object indices, in slot order.
    pub objects: Vec<usize>,
    pub first: usize,
    pub size: usize,
    /// Offset of the type's bit vector in a Fig. 5 node.
    pub bv_offset: usize,
    pub bv_words: usize,
    pub mailbox: usize,
    /// Polygons: edges per record (the largest polygon's non-horizontal
    /// edges in its projection).
    pub fan: usize,
    /// Cylinders and cones: the records carry caps (a flag and two discs,
    /// [`records_carry_caps`]).
    pub caps: bool,
}

/// The laid-out image and everything the generator needs to know of it.
#[derive(Clone, Debug)]
pub struct FbImage {
    /// FB words as values: 16-bit on the 16-bit chip; on the 32-bit chip
    /// numeric words use the whole word and the others (flags, addresses,
    /// bit vectors, counts) are the 16-bit words sign-extended.
    pub fb: Vec<i32>,
    pub frac: u32,
    pub eye: usize,
    pub post: usize,
    /// FB address of the refraction table (`id, T, 1/ior, ior` per
    /// transmitting material) and its entries; `refract`: the scene has
    /// refracting objects (the ray tree branches).
    pub transmit: usize,
    pub transmit_materials: usize,
    pub refract: bool,
    pub lights: Vec<usize>,
    pub shades: Vec<usize>,
    pub types: Vec<TypeInfo>,
    pub root: usize,
    /// Words (32-bit words when streamed) of a node; 0 for compact nodes,
    /// whose size varies.
    pub node_words: usize,
    /// The node format of the resident layout (the option; the streamed
    /// layout has per-leaf lists whichever it is).
    pub node_layout: NodeLayout,
    /// The traversal the nodes are laid out for.
    pub traversal: Traversal,
    /// Packet traversal: object tests run in parts at their kernels' cuts
    /// ([`super::TestCuts`]).
    pub test_cuts: bool,
    /// ... and the kernels hold a `cut` context at each, where the
    /// broadcast unit ends the run (`on`); else TinyRISC runs the parts.
    pub cut_runs: bool,
    /// Packet traversal: FB address of the root cell widened by
    /// [`packet_nodes::P_TOL`] (6 words: per axis min, max).
    pub root_box: usize,
    /// Packet traversal: the tree it walks is a single leaf.
    pub root_leaf: bool,
    /// Packet traversal: the expected array cycles of a packet's walk from
    /// the root, by the surface-area cost model of [`super::Collapse::Auto`]
    /// (0 for the paper's traversal).
    pub expected_cost: f64,
    /// FB words the resident image needs with this node format (tables to
    /// mailboxes), whether or not it fits and was used.
    pub resident_words: usize,
    /// Of those, the BSP nodes.
    pub resident_node_words: usize,
    pub mailbox: usize,
    pub objects: usize,
    pub materials: usize,
    /// Phong exponents: integer part and fraction (see [`phong_exponent`]).
    pub shines: Vec<(u32, f64)>,
    /// Scale shift of the eye rays' pixel steps.
    pub kd: u32,
    /// The kernels' scale shifts and record variants.
    pub fit: Fit,
    /// Fine normals ([`super::Normals`], resolved for the datapath).
    pub fine_normals: bool,
    /// Light records carry a scale shift (some light is too far for
    /// `light - P` to fit the format, [`light_shift`]).
    pub light_shifted: bool,
    /// The streamed layout (scenes that do not fit FB set 0), or `None`
    /// when the whole scene is resident in the FB.
    pub stream: Option<Stream>,
}

impl FbImage {
    /// Whether `k_phong` runs a material at a time
    /// ([`super::shading::phong_in_runs`]).
    pub fn phong_in_runs(&self) -> bool {
        super::shading::phong_in_runs(self.cut_runs, self.shines.len())
    }
}

/// Words at the start of a streamed leaf block: the cell bounds.
pub const BLOCK_HEAD: usize = 6;
/// Bytes of a node record in main memory (streamed layout).
pub const NODE_BYTES: usize = 64;

/// The streamed layout: the scene lives in main memory and TinyRISC moves
/// each leaf's block (cell bounds, then the records of its objects grouped
/// by type) into FB bank 1 by DMA when the traversal reaches it (the node
/// records: `traversal/streamed.rs`, `traversal/packet/`).
#[derive(Clone, Debug)]
pub struct Stream {
    /// Main-memory byte address of [`Stream::image`].
    pub base: u32,
    pub image: Vec<u8>,
    pub root: u32,
    pub mailbox: u32,
    /// FB word (bank 0) the split value of the node being classified is
    /// written to.
    pub split_slot: usize,
    pub nodes: usize,
    pub largest_block: usize,
    /// Packet traversal: leaf pieces beyond one per leaf (a leaf's records
    /// are moved in pieces, [`super::LeafPieces`]).
    pub extra_pieces: usize,
    /// Packet traversal: leaves whose first piece is moved only once an
    /// object in it is to be tested
    /// ([`packet_nodes::LEAF_LATE`]).
    pub late_leaves: usize,
    /// Packet traversal: the leaf cache, slots of FB bank 1 that keep
    /// leaves' first pieces for the rest of the tile (`docs/tracer.md`,
    /// "Leaves and pieces"): their number (1 with no room beside the
    /// further pieces' buffer, then the slot is that buffer), words each
    /// and the FB address of the first.
    pub cache_slots: usize,
    pub slot_words: usize,
    pub slots_at: usize,
    /// Packet traversal: where the banded polygons' sub-edges are
    /// ([`super::primitives::polygon::Form::Apart`]), if the scene has any.
    pub fans: Option<FansApart>,
}

/// The banded polygons' sub-edges in main memory and the FB buffer a
/// packet's bands of them are moved into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FansApart {
    /// Main-memory byte address of the first (`FANS`).
    pub at: u32,
    /// FB address of the buffer (`FAN_BUF`, the top of bank 1).
    pub buf: usize,
    /// Words of the buffer: the most sub-edge words of a polygon.
    pub words: usize,
    /// log2 of an FB word's bytes (`FB_WORD_SHIFT`).
    pub word_shift: u32,
}

/// Lay out the scene.
pub fn build(
    scene: &Scene,
    image: &SceneImage,
    opt: &Options,
    guard_bits: u32,
    fine_normals: bool,
    force_stream: bool,
) -> Result<FbImage, String> {
    if !force_stream {
        let lay = build_as(
            scene,
            image,
            opt,
            guard_bits,
            fine_normals,
            false,
            false,
            polygon::Form::Plain,
        )?;
        if lay.stream.is_none() {
            return Ok(lay);
        }
    }
    // A streamed scene has thousands of objects, many of them a few LSB
    // small: it is laid out again in the finest format with one guard bit
    // (differences of two points of the scene still fit), the compiler's
    // rule, and sphere records carry the unrounded radius's reciprocal.
    build_as(
        scene,
        image,
        opt,
        guard_bits.min(1),
        fine_normals,
        true,
        true,
        polygon::Form::Plain,
    )
}

/// Lay out the scene for the packet traversal. `fine`: the format of the
/// streamed layout (one guard bit, unrounded sphere radii), which the
/// paper's layout takes for scenes it streams; the packet traversal's
/// nodes are much smaller, so it keeps resident many scenes the paper's
/// layout streams, but its format follows the paper's decision (the same
/// numbers, hence the same hits up to ties). Streamed when it does not fit
/// FB set 0 or with `force_stream`.
pub fn build_packet(
    scene: &Scene,
    image: &SceneImage,
    opt: &Options,
    guard_bits: u32,
    fine_normals: bool,
    force_stream: bool,
    fine: bool,
) -> Result<FbImage, String> {
    let g = if fine { guard_bits.min(1) } else { guard_bits };
    // Polygons of many edges get banded records (`polygon::Form`): in the
    // record where the scene is resident, apart from it in main memory
    // where it is streamed and a record would be over
    // `polygon::APART_FROM` words (so that a leaf's piece moves the record
    // without its sub-edges). Where no banded layout can be built, the
    // plain one is, whose error stands if it fails too. (Only a scene
    // with a polygon of that many vertices can have banded records.)
    let may_band = scene
        .objects
        .iter()
        .filter_map(|o| o.shape.as_polygon())
        .any(|p| p.v.len() >= polygon::BANDED_FROM);
    let build = |form| build_as(scene, image, opt, g, fine_normals, fine, force_stream, form);
    let large = |lay: &FbImage| {
        lay.types.iter().any(|t| {
            matches!(t.ty, ChipType::Polygon | ChipType::GlassPolygon)
                && polygon::keeps_apart(t.size)
        })
    };
    match build(polygon::Form::Banded) {
        Ok(lay)
            if lay.stream.is_some()
                && lay.fit.polygon_form.banded()
                && large(&lay)
                && opt.sub_edges == super::SubEdges::Apart =>
        {
            Ok(build(polygon::Form::Apart).unwrap_or(lay))
        }
        Err(_) if may_band && opt.sub_edges == super::SubEdges::Apart => {
            build(polygon::Form::Apart).or_else(|_| build(polygon::Form::Plain))
        }
        Err(_) if may_band => build(polygon::Form::Plain),
        r => r,
    }
}

/// `file:line: m`, or `file: m` without a line.
fn located(file: &str, line: usize, m: String) -> String {
    if line > 0 {
        format!("{file}:{line}: {m}")
    } else {
        format!("{file}: {m}")
    }
}

/// The most distinct materials and lights a layout holds.
fn check_counts(materials: usize, lights: usize) -> Result<(), String> {
    if materials > 1000 || lights > 64 {
        return Err("more than 1000 distinct materials or 64 lights".into());
    }
    Ok(())
}

/// Packet traversal: the root cell widened by the traversal's tolerance
/// (the stream of its pass-start kernel), resident in either layout;
/// returns where it is.
fn root_box(w: &mut W, image: &SceneImage) -> usize {
    let at = w.fb.len();
    let b = image.bsp.nodes[0].bounds;
    let tol = packet_nodes::P_TOL as f64;
    for a in 0..3 {
        w.push((b.min.axis(a) * w.s).floor() - tol);
        w.push((b.max.axis(a) * w.s).ceil() + tol);
    }
    at
}

#[allow(clippy::too_many_arguments)]
fn build_as(
    scene: &Scene,
    image: &SceneImage,
    opt: &Options,
    guard_bits: u32,
    fine_normals: bool,
    fine: bool,
    streamed: bool,
    form: polygon::Form,
) -> Result<FbImage, String> {
    // `Form::Apart` streams the scene; `Form::Plain`: no banded records.
    let bands = form != polygon::Form::Plain;
    let streamed = streamed || form == polygon::Form::Apart;
    // The 32-bit chip: every format gets `xb` more fraction bits.
    let xb = opt.datapath.extra_bits();
    let frac = fit_frac(scene, image.report.frac_bits, guard_bits) + xb;
    let s = (frac as f64).exp2();
    let err = |line: usize, m: String| located(&scene.source, line, m);

    let (by, slot) = by_type(scene);
    // Materials: identical ones are one (an NFF file repeats its `f` line
    // for every object: SPD rings, 841 lines, 7 materials); the kernels
    // shade per distinct material.
    let (mat_of, mats) = distinct_materials(scene);
    check_counts(mats.len(), scene.lights.len()).map_err(|m| err(0, m))?;

    let packet = opt.traversal == Traversal::Packet;
    let (geo, fan, mut fit) = fit_scene(scene, s, frac, opt, fine_normals, packet && bands);
    let test_cuts = packet && opt.test_cuts.in_parts();
    fit.cyl_bound = test_cuts;
    // A streamed layout keeps the banded polygons' sub-edges in main
    // memory, once each, and moves a packet's bands of them.
    if fit.polygon_form.banded() {
        fit.polygon_form = form;
    }
    let mut w = init_stream(s, frac, xb);
    let eye_kd = camera(&mut w, scene, opt, fine_normals);
    let (eye, kd) = eye_kd.map_err(|m| err(scene.lines.camera, m))?;

    let refract = ChipType::ALL
        .iter()
        .any(|c| c.refracts() && !by[*c as usize].is_empty());
    let (post, transmit, transmit_materials) = post_streams(&mut w, scene, &mats, refract);
    let (lights, shades, light_shifted) =
        lights(&mut w, scene, &mats, frac, xb, packet).map_err(|m| err(0, m))?;
    let shines: Vec<(u32, f64)> = mats.iter().map(|m| phong_exponent(m, packet)).collect();

    let root_box = if packet { root_box(&mut w, image) } else { 0 };

    let records_start = w.fb.len();
    let (types, bv_offset, mailbox_slots) = records(
        &mut w,
        scene,
        &by,
        &geo,
        &fit,
        fan,
        &mat_of,
        fine,
        opt.traversal,
        &err,
    )?;
    let nodes = &image.bsp.nodes;
    let fin = Finish {
        frac,
        eye,
        post,
        lights,
        shades,
        objects: scene.objects.len(),
        materials: mats.len(),
        transmit,
        transmit_materials,
        refract,
        shines,
        kd,
        fit,
        light_shifted,
        node_layout: opt.layout,
        traversal: opt.traversal,
        test_cuts,
        cut_runs: opt.traversal == Traversal::Packet && opt.test_cuts.cut_contexts(),
        root_box,
        collapse: opt.collapse,
        pieces: opt.pieces,
        cost: if packet {
            costs::object_costs(scene, s, &fit)
        } else {
            Vec::new()
        },
    };
    if packet {
        return packet_nodes::packet_nodes(
            w,
            fin,
            types,
            nodes,
            &slot,
            records_start,
            streamed,
            &err,
        );
    }
    paper_nodes::paper_nodes(
        w,
        fin,
        types,
        nodes,
        &slot,
        records_start,
        streamed,
        opt.layout,
        bv_offset,
        mailbox_slots,
        &err,
    )
}

/// The FB image's writer with the init stream written: the tables'
/// slots, one and the largest word.
fn init_stream(s: f64, frac: u32, xb: u32) -> W {
    let mut w = W::new(s, frac, xb);
    w.fb.extend(table_slots_for(128, xb));
    w.push(w.one());
    w.push(w.max());
    w
}

/// What every node format's [`FbImage`] shares (the part laid out before
/// the BSP nodes).
pub(super) struct Finish {
    frac: u32,
    eye: usize,
    post: usize,
    transmit: usize,
    transmit_materials: usize,
    refract: bool,
    lights: Vec<usize>,
    shades: Vec<usize>,
    objects: usize,
    materials: usize,
    shines: Vec<(u32, f64)>,
    kd: u32,
    fit: Fit,
    light_shifted: bool,
    node_layout: NodeLayout,
    traversal: Traversal,
    test_cuts: bool,
    cut_runs: bool,
    root_box: usize,
    collapse: super::Collapse,
    pieces: super::LeafPieces,
    /// Per scene object, the array cycles of its test (kernel contexts and
    /// the TinyRISC loop around them).
    cost: Vec<f64>,
}

impl Finish {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn layout(
        self,
        fb: Vec<i32>,
        types: Vec<TypeInfo>,
        root: usize,
        node_words: usize,
        resident_words: usize,
        resident_node_words: usize,
        mailbox: usize,
        stream: Option<Stream>,
    ) -> FbImage {
        FbImage {
            fb,
            frac: self.frac,
            eye: self.eye,
            post: self.post,
            transmit: self.transmit,
            transmit_materials: self.transmit_materials,
            refract: self.refract,
            lights: self.lights,
            shades: self.shades,
            types,
            root,
            node_words,
            node_layout: self.node_layout,
            traversal: self.traversal,
            test_cuts: self.test_cuts,
            cut_runs: self.cut_runs,
            root_box: self.root_box,
            root_leaf: false,
            expected_cost: 0.0,
            resident_words,
            resident_node_words,
            mailbox,
            objects: self.objects,
            materials: self.materials,
            shines: self.shines,
            kd: self.kd,
            fit: self.fit,
            fine_normals: self.fit.fine_normals,
            light_shifted: self.light_shifted,
            stream,
        }
    }
}

/// The geometry every record is written from, and the kernels' scale
/// shifts fitted to it (`opt`: the datapath, whose extra bits every
/// format gets, and the positions; `s`: LSBs per unit of the scene format
/// `frac`). Also the polygons' largest fan
/// ([`polygon_fan`]; `bands`: banded records where they pay).
fn fit_scene(
    scene: &Scene,
    s: f64,
    frac: u32,
    opt: &Options,
    fine_normals: bool,
    bands: bool,
) -> (Vec<Geometry>, usize, Fit) {
    let xb = opt.datapath.extra_bits();
    let local = opt.positions == super::Positions::Local;
    let fitter = Fitter { x: xb };
    let mut geo: Vec<Geometry> = Vec::with_capacity(scene.objects.len());
    let poly_k = local.then(|| {
        let polys = scene.objects.iter().filter_map(|o| o.shape.as_polygon());
        polygon::fine_k(polys.map(|p| &p.v[..]), s)
    });
    let (fan, polygon_bands) = polygon_fan(scene, s, bands, poly_k);
    for o in &scene.objects {
        geo.push(
            ChipType::of_object(&o.shape, false)
                .primitive()
                .geometry(&o.shape, s),
        );
    }
    let mut m = [0.0f64; 3];
    for g in &geo {
        for p in g.planars() {
            let k = p.kind.kt_index();
            m[k] = m[k].max(p.dual_max((14 + xb) as i32 - frac as i32));
        }
    }
    let kt = m.map(|m| fitter.shift(m, 24 + xb));
    let mut fit = Fit {
        kt,
        fine_normals,
        local,
        poly_k: poly_k.unwrap_or(0),
        polygon_form: if polygon_bands {
            polygon::Form::Banded
        } else {
            polygon::Form::Plain
        },
        ..Fit::default()
    };
    for p in PRIMITIVES {
        p.fit(scene, &geo, s, &fitter, &mut fit);
    }
    if local {
        use super::primitives::triangle_local as tl;
        let framed = |o: &crate::scene::Object, g: &Geometry| {
            let p = *g.planars().first()?;
            let c = match o.shape.as_triangle() {
                Some(t) if t.normals.is_none() => tl::centre(&p, Some(&t.v)),
                Some(_) => return None,
                None if o.shape.as_rectangle().is_some() || o.shape.as_disc().is_some() => {
                    tl::centre(&p, None)
                }
                None => return None,
            };
            Some((c, p))
        };
        // Rectangles and discs in frames where every one fits a frame and
        // most are small enough for a frame finer than the fine planar
        // kernel's edges ([`tl::frames_pay`]).
        let extents: Vec<f64> = scene
            .objects
            .iter()
            .zip(&geo)
            .filter(|(o, _)| o.shape.as_triangle().is_none())
            .filter_map(|(o, g)| framed(o, g).map(|((_, r), _)| r))
            .collect();
        fit.planar_frames = tl::frames_pay(&extents, s);
        let shapes = scene.objects.iter().zip(&geo).filter_map(|(o, g)| {
            framed(o, g).filter(|_| o.shape.as_triangle().is_some() || fit.planar_frames)
        });
        fit.kt_local = tl::fit_kt(shapes, s, &fitter);
    }
    (geo, fan, fit)
}

/// The polygon records' room: the most edges of a polygon of the scene
/// (at `s` LSB per unit), or where the records are banded (`bands`: the
/// packet traversal's, a polygon of [`polygon::BANDED_FROM`] edges or
/// more) the most sub-edges; and whether they are banded.
pub(crate) fn polygon_fan(scene: &Scene, s: f64, bands: bool, fine: Option<u32>) -> (usize, bool) {
    let edges: Vec<Vec<[i64; 5]>> = scene
        .objects
        .iter()
        .filter_map(|o| o.shape.as_polygon())
        .map(|p| polygon::edges_as(&p.v, s, fine).1)
        .collect();
    let banded = bands && edges.iter().any(|e| e.len() >= polygon::BANDED_FROM);
    let fan = edges
        .iter()
        .map(|e| {
            if banded {
                polygon::band_edges(e)
            } else {
                e.len()
            }
        })
        .max()
        .unwrap_or(0);
    (fan, banded)
}

/// The object records, grouped by type in test order, with what the
/// nodes and kernels need to know of each type. `unrounded`: sphere
/// records with the unrounded radius's reciprocal (the streamed format).
#[allow(clippy::too_many_arguments)]
fn records(
    w: &mut W,
    scene: &Scene,
    by: &[Vec<usize>],
    geo: &[Geometry],
    fit: &Fit,
    fan: usize,
    mat_of: &[usize],
    unrounded: bool,
    traversal: Traversal,
    err: &dyn Fn(usize, String) -> String,
) -> Result<(Vec<TypeInfo>, usize, usize), String> {
    let mut types = Vec::new();
    let mut bv_offset = NODE_HEAD;
    let mut mailbox_slots = 0;
    for t in ChipType::ALL {
        let objs = &by[t as usize];
        if objs.is_empty() {
            continue;
        }
        let caps = records_carry_caps(scene, t, traversal);
        let size = t.record_words(fit, fan, caps);
        let first = w.fb.len();
        for &i in objs {
            let o = &scene.objects[i];
            let mat = mat_of[o.material];
            let start = w.fb.len();
            let record = Object {
                shape: &o.shape,
                geometry: &geo[i],
                fit,
                sides: t.sides(),
                caps,
                size,
                unrounded,
                id: i,
                mat,
            };
            t.primitive().write(w, &record).map_err(|e| match e {
                RecordError::Object(m) => err(o.line, m),
                RecordError::Scene(m) => err(0, m),
            })?;
            debug_assert_eq!(w.fb.len() - start, size, "{t:?}");
            if w.fb.len() - start != size {
                return Err(format!(
                    "internal: {} record of {} words, expected {size}",
                    t.name(),
                    w.fb.len() - start
                ));
            }
        }
        let bv_words = objs.len().div_ceil(16);
        types.push(TypeInfo {
            ty: t,
            objects: objs.clone(),
            first,
            size,
            bv_offset,
            bv_words,
            mailbox: mailbox_slots,
            fan,
            caps,
        });
        bv_offset += bv_words;
        mailbox_slots += objs.len();
    }

    Ok((types, bv_offset, mailbox_slots))
}

/// Whether the records of type `t` carry caps (a flag and two discs):
/// a cylinder's or cone's under the paper's traversal always (its records
/// as published), under the packet traversal where some cylinder (cone)
/// of the scene, opaque or glass, has caps; other types never.
pub(crate) fn records_carry_caps(scene: &Scene, t: ChipType, traversal: Traversal) -> bool {
    let p = t.primitive();
    p.disc_caps()
        && (traversal == Traversal::Paper
            || scene
                .objects
                .iter()
                .any(|o| p.is_of(&o.shape) && o.shape.capped()))
}

/// The scene's objects by chip type (indexed by `ChipType as usize`, in
/// scene order), and per object its (type, slot among its type).
#[allow(clippy::type_complexity)]
fn by_type(scene: &Scene) -> (Vec<Vec<usize>>, Vec<(usize, usize)>) {
    let mut by: Vec<Vec<usize>> = vec![Vec::new(); ChipType::ALL.len()];
    let mut slot = vec![(0usize, 0usize); scene.objects.len()];
    for (i, o) in scene.objects.iter().enumerate() {
        let t = ChipType::of_object(&o.shape, scene.materials[o.material].t > 0.0);
        let ti = t as usize;
        slot[i] = (ti, by[ti].len());
        by[ti].push(i);
    }
    (by, slot)
}
