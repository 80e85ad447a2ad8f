//! The whole assembly source of one build: a header naming every number
//! the program uses (formats, the scene's fitted shifts, main memory, the
//! FB image and its records, the RC RAM map), TinyRISC's data and code
//! (the tile loop, [`super::tiles`]; the traversal,
//! [`super::traversal`]), and the RC kernels in context memory.

use super::emit::{define, Code, K};
use super::kernel_names as names;
use super::layout::{FbImage, TypeInfo, STREAM_BANK};
use super::memory_map::{format_lines, ram_lines};
use super::primitives::{self, ChipType, Gen};
use super::{data, mem, shading, shadows, tiles, traversal, Numerics, Options, Traversal};
use crate::scene::Scene;

/// The program of one build.
pub struct Program {
    pub source: String,
    pub context_words: usize,
    pub kernels: Vec<(String, usize)>,
}

/// Output banks of FB set 1 (alternating, so DMA drains one while the next
/// tile is written to the other).
pub const OUT_BANK: [u32; 2] = [0x8000, 0xC000];

/// The program for `lay` (the scene laid out for `opt`).
pub fn program(
    scene: &Scene,
    lay: &FbImage,
    opt: &Options,
    nm: &Numerics,
    tw: u32,
    th: u32,
) -> Result<Program, String> {
    let g = Gen {
        datapath: opt.datapath,
        approx: nm.approx(),
        fine_normals: lay.fine_normals,
        test_cuts: lay.test_cuts,
        published: lay.traversal == Traversal::Paper,
    };
    let merged = shadows::merged(opt, lay);
    let kernels = kernels(lay, opt, nm, &g, merged);
    let mut s = header(scene, lay, opt, nm, tw, th, merged);
    s.push_str(&data(lay, merged.then(|| tile_lanes(tw, th)).as_deref()));
    let mut t = Code::new();
    t.directive(".text");
    tiles::main(&mut t, lay, opt.depth, merged);
    if merged {
        shadows::routine(&mut t, lay);
    }
    if lay.phong_in_runs() {
        shading::phong_runs(&mut t, lay.shines.len());
    }
    match (lay.traversal, lay.stream.is_some()) {
        (Traversal::Packet, _) => traversal::packet::trace(&mut t, lay, opt.child_order),
        (Traversal::Paper, false) => traversal::paper::trace(&mut t, lay),
        (Traversal::Paper, true) => traversal::streamed::trace(&mut t, lay),
    }
    s.push_str(&t.text());
    s.push_str("\n; ==== RC context kernels (context memory) ====\n");
    s.push_str("        .ctx\n        .org CTXBASE\n");
    let mut names = Vec::new();
    let mut words = 0usize;
    for (n, k) in &kernels {
        s.push('\n');
        s.push_str(&k.text_with_cuts(n, lay.cut_runs));
        names.push((n.clone(), k.words(lay.cut_runs)));
        words += k.words(lay.cut_runs);
    }
    s.push_str("ctx_end:\n");
    if words > 8192 {
        return Err(format!(
            "the kernels need {words} context words; the context memory holds 8192"
        ));
    }
    Ok(Program {
        source: s,
        context_words: words,
        kernels: names,
    })
}

/// The RCs of a `tw` x `th` tile in the array's order (row-major).
fn tile_lanes(tw: u32, th: u32) -> Vec<u32> {
    (0..th)
        .flat_map(|r| (0..tw).map(move |c| r * 8 + c))
        .collect()
}

/// Every kernel of the program, in load order (the row-mode group first:
/// it must be 8-aligned); `merged`: with merged shadow packets'.
fn kernels(lay: &FbImage, opt: &Options, nm: &Numerics, g: &Gen, merged: bool) -> Vec<(String, K)> {
    let packet = lay.traversal == Traversal::Packet;
    let mut init = shading::init();
    if packet {
        traversal::packet::init_ram(&mut init);
    }
    let mut v: Vec<(String, K)> = vec![
        (names::ROW_INDEX.into(), shading::rows()),
        (names::INIT.into(), init),
        (names::LANES.into(), shading::lanes()),
        (names::WAKE.into(), shading::wake_restore(packet)),
    ];
    for a in 0..3u8 {
        v.push((names::sign(a), traversal::sign(a)));
    }
    if packet {
        v.extend(traversal::packet::kernels(nm.approx()));
    } else {
        v.extend(traversal::paper::kernels());
    }
    // Smooth triangles: the shading normal and the reflection's fallback.
    let smooth = lay.types.iter().any(|x| x.ty.primitive().smooth());
    let local = lay.fit.local;
    let eye = if super::positions::precise_eye(opt, lay.fine_normals) {
        super::positions::eye(nm.approx(), lay.refract, local)
    } else {
        shading::eye(nm.approx(), lay.refract)
    };
    v.push((names::EYE.into(), eye));
    for (name, level0) in [(names::POST_EYE, true), (names::POST, false)] {
        let mut post = shading::post(level0, lay.materials, smooth, lay.refract, local);
        if packet {
            shading::flag_hit(&mut post);
        }
        v.push((name.into(), post));
    }
    let mut shadow = shading::light_setup(nm.approx(), lay.light_shifted, local);
    if local {
        super::positions::shadow_origins(&mut shadow, lay.light_shifted);
    }
    v.push((names::SHADOW.into(), shadow));
    v.push((
        names::PHONG.into(),
        shading::shade(&lay.shines, lay.phong_in_runs()),
    ));
    for i in 0..4 {
        v.push((names::out(i).into(), shading::out_word(i)));
    }
    v.push((
        names::STORE_ROW.into(),
        shading::store_lane(names::STORE_ROW, super::memory_map::ram::LANE_ROW),
    ));
    v.push((
        names::STORE_COL.into(),
        shading::store_lane(names::STORE_COL, super::memory_map::ram::LANE_COL),
    ));
    for l in 0..opt.depth.saturating_sub(1) {
        let mut reflect = shading::reflect_setup(l, smooth, lay.refract);
        if local {
            super::positions::origins(&mut reflect);
        }
        v.push((names::reflect(l), reflect));
        v.push((names::reflected(l), shading::reflect_pop(l)));
        if lay.refract {
            v.push((
                names::refract_prepare(l),
                shading::refract_prepare(l, lay.transmit_materials, nm.approx()),
            ));
            let mut refract = shading::refract_setup(l);
            if local {
                super::positions::refracted_origins(&mut refract);
            }
            v.push((names::refract(l), refract));
            v.push((names::refracted(l), shading::refract_pop(l)));
        }
    }
    if lay.stream.is_some() && !packet {
        v.extend(traversal::streamed::kernels());
    }
    if merged {
        v.extend(shadows::kernels(lay));
    }
    // Object kernels: the types present, each kernel once.
    for ty in ChipType::LOAD_ORDER {
        if lay.types.iter().any(|x| x.ty == ty) {
            for (n, k) in ty.kernels(g, &lay.fit) {
                if !v.iter().any(|(m, _)| m == n) {
                    v.push((n.to_string(), k));
                }
            }
        }
    }
    v
}

/// A block of header lines under a title.
fn block(s: &mut String, title: &str, lines: impl IntoIterator<Item = String>) {
    s.push_str(&format!("\n; ---- {title} ----\n"));
    for l in lines {
        s.push_str(&l);
        s.push('\n');
    }
}

/// The header: what the program was generated for, and every name it
/// uses.
fn header(
    scene: &Scene,
    lay: &FbImage,
    opt: &Options,
    nm: &Numerics,
    tw: u32,
    th: u32,
    merged: bool,
) -> String {
    let mut s = title(scene, lay, opt, tw, th, merged);
    s.push_str(
        ";\n; Every number the program uses is named below. TinyRISC code (.text) steers the\n\
         ; traversal and broadcasts RC kernels (.ctx) with their FB streams; each routine\n\
         ; and kernel is headed by what it does, its inputs and its outputs.\n",
    );
    let types: Vec<ChipType> = lay.types.iter().map(|t| t.ty).collect();
    let mut f = format_lines(opt.datapath.extra_bits());
    f.extend(nm.approx().header());
    block(
        &mut s,
        "number formats (Qn: the 16-bit chip's n fraction bits on this datapath)",
        f,
    );
    let mut fit = vec![
        define("TILE_W", tw, "the tile: TILE_W x TILE_H rays, one per RC"),
        define("TILE_H", th, ""),
        define(
            "KD",
            lay.kd,
            "eye rays: the pixel steps B, C scaled by 2^KD",
        ),
        define(
            "EPS_LSB",
            nm.eps_lsb,
            "spawned rays start this far off the surface (LSB)",
        ),
    ];
    if lay.traversal == Traversal::Packet {
        fit.push(define(
            "P_TOL",
            traversal::packet::P_TOL,
            "split planes widened by this many LSB",
        ));
    }
    fit.extend(lay.fit.header(&types));
    block(&mut s, "the scene's fit", fit);
    block(&mut s, "main memory (byte addresses)", main_memory(lay));
    block(&mut s, "FB set 0 (word addresses)", fb(lay));
    let rec = record_fields(lay);
    if !rec.is_empty() {
        block(
            &mut s,
            "record fields (FB words from a record's start)",
            rec,
        );
    }
    block(&mut s, "BSP nodes", nodes(lay));
    block(
        &mut s,
        "FB set 1: output banks (word addresses)",
        output_banks(),
    );
    if merged {
        block(
            &mut s,
            "merged shadow packets (FB set 1, words from the tile's output bank)",
            shadows::header(lay),
        );
    }
    block(
        &mut s,
        "RC RAM (word addresses in every RC)",
        ram_lines(opt.depth),
    );
    s.push_str("\n; ---- macros ----\n");
    s.push_str(&tiles::macros(lay).text());
    if lay.traversal == Traversal::Packet {
        s.push('\n');
        s.push_str(&traversal::packet::macros().text());
    }
    s
}

/// The header's first lines: the scene, the image, the chip and the
/// traversal the program was generated for, and its `.datapath`.
fn title(scene: &Scene, lay: &FbImage, opt: &Options, tw: u32, th: u32, merged: bool) -> String {
    let mut s = String::new();
    // The scene's name is a file name: its control characters (a line
    // break would start a line of the program) written out.
    let name: String = scene
        .source
        .chars()
        .map(|c| match c.is_control() {
            true => format!("U+{:04X}", c as u32),
            false => c.to_string(),
        })
        .collect();
    s.push_str(&format!(
        "; MorphoSys BSP ray tracer, generated by firmware::tracer for {name}\n"
    ));
    s.push_str(&format!(
        "; {}x{}, {} ways ({}x{} tiles), depth {}, {} datapath, scene format Q{}.{}, {} normals{}\n",
        opt.width,
        opt.height,
        opt.ways,
        tw,
        th,
        opt.depth,
        opt.datapath,
        opt.datapath.bits() - 1 - lay.frac,
        lay.frac,
        if lay.fine_normals { "fine" } else { "coarse" },
        if lay.fit.local {
            ", local positions"
        } else {
            ""
        }
    ));
    s.push_str(&format!(
        "; {} traversal, BSP {} split to depth {}, at most {} objects per leaf{}\n",
        opt.traversal,
        format!("{:?}", opt.bsp.rule).to_lowercase(),
        opt.bsp.max_depth,
        opt.bsp.max_leaf,
        if opt.traversal == Traversal::Packet {
            format!(
                ", collapse {}{}{}",
                opt.collapse,
                if merged {
                    ", merged shadow packets"
                } else {
                    ""
                },
                match (lay.test_cuts, lay.cut_runs) {
                    (true, true) => "",
                    (true, false) => ", object tests in parts steered by TinyRISC",
                    _ => ", whole object tests",
                }
            )
        } else {
            format!(", {} nodes", opt.layout)
        }
    ));
    s.push_str(&format!("        .datapath {}\n", opt.datapath.bits()));
    s
}

/// Each primitive's record fields, for the sides of its types present;
/// its records carry caps or not alike for both.
fn record_fields(lay: &FbImage) -> Vec<String> {
    let mut rec = Vec::new();
    for p in primitives::PRIMITIVES {
        let present: Vec<&TypeInfo> = lay
            .types
            .iter()
            .filter(|ti| ti.ty.primitive().names() == p.names())
            .collect();
        if present.is_empty() {
            continue;
        }
        let sides: Vec<primitives::Sides> = present.iter().map(|ti| ti.ty.sides()).collect();
        let caps = present.iter().any(|ti| ti.caps);
        rec.extend(p.record_header(&lay.fit, &sides, caps));
    }
    rec
}

/// FB set 1's output banks and a bank's words.
fn output_banks() -> Vec<String> {
    vec![
        define(
            "OUT_BANK0",
            OUT_BANK[0],
            "the two output banks, alternating by tile",
        ),
        define("OUT_BANK1", OUT_BANK[1], ""),
        define("OUT_R", 0, "a bank's words: red of RCs 0..63"),
        define("OUT_G", 64, "green"),
        define("OUT_B", 128, "blue"),
        define("OUT_ID", 192, "the eye ray's object id"),
        define("OUT_WORDS", 256, "words a tile's output moves by DMA"),
    ]
}

fn main_memory(lay: &FbImage) -> Vec<String> {
    use super::data::{
        AXIS_X, AXIS_Y, AXIS_Z, MASK_HI, TILE_BYTES, TILE_OUT, TILE_PX, TILE_PY, TL_COUNT, TL_FIRST,
    };
    vec![
        define(
            "CTXBASE",
            format!("0x{:x}", mem::CTX_BASE),
            "the kernels (loaded into context memory)",
        ),
        define(
            data::FBIMG.0,
            format!("0x{:x}", mem::FB_IMAGE),
            "the FB image, loaded by the host",
        ),
        define(data::FBWORDS.0, lay.fb.len(), "its words"),
        define(
            data::TILELIST.0,
            format!("0x{:x}", mem::TILE_LIST),
            "the tile list, written by the host:",
        ),
        TL_COUNT.define(),
        TL_FIRST.define(),
        TILE_PX.define(),
        TILE_PY.define(),
        TILE_OUT.define(),
        TILE_BYTES.define(),
        MASK_HI.define(),
        AXIS_X.define(),
        AXIS_Y.define(),
        AXIS_Z.define(),
    ]
}

fn fb(lay: &FbImage) -> Vec<String> {
    use super::data::{EYE_PX, EYE_PY};
    let mut v = vec![
        define(
            data::FB_EYE.0,
            lay.eye,
            "eye stream: px0, py0, eye.xyz, (A, B, C) per axis",
        ),
        EYE_PX.define(),
        EYE_PY.define(),
        define(
            data::FB_POST.0,
            lay.post,
            "post-pass stream: background, (material, Ks) per material",
        ),
    ];
    if lay.refract {
        v.push(define(
            "FB_TRANSMIT",
            lay.transmit,
            "refraction stream: (material, T, 1/ior, ior) per transmitting material",
        ));
    }
    for (i, l) in lay.lights.iter().enumerate() {
        v.push(define(
            &format!("FB_LIGHT{i}"),
            l,
            if i == 0 {
                "light streams: the position (a scale shift first where far)"
            } else {
                ""
            },
        ));
    }
    for (i, l) in lay.shades.iter().enumerate() {
        v.push(define(
            &format!("FB_SHADE{i}"),
            l,
            if i == 0 {
                "shading streams: per material its Phong terms for the light"
            } else {
                ""
            },
        ));
    }
    if lay.traversal == Traversal::Packet {
        v.push(define(
            data::ROOTBOX.0,
            lay.root_box,
            "the root cell widened by P_TOL: per axis min, max",
        ));
    }
    let resident = lay.stream.is_none();
    v.extend(type_lines(lay));
    if resident {
        v.push(define(data::ROOT.0, lay.root, "the BSP root node"));
    } else {
        v.push(define(
            data::ROOT.0,
            lay.root,
            "the BSP root node (main memory)",
        ));
    }
    v.push(define(
        data::MAILBOX.0,
        lay.mailbox,
        if resident && lay.traversal == Traversal::Paper {
            "the mailboxes: per object the pass that last tested it"
        } else {
            "the mailboxes (main memory)"
        },
    ));
    v.push(define(data::NOBJ.0, lay.objects, "objects in the scene"));
    if lay.traversal == Traversal::Paper {
        v.push(define(
            data::PASS_WRAP.0,
            "0x7fff",
            "pass numbers wrap here (16-bit mailboxes)",
        ));
    }
    if let Some(st) = &lay.stream {
        v.extend(stream_lines(lay, st));
    }
    v
}

/// Per type present: its records' words (and, resident, where they are
/// and the paper's mailboxes).
fn type_lines(lay: &FbImage) -> Vec<String> {
    let mut v = Vec::new();
    let resident = lay.stream.is_none();
    for t in &lay.types {
        let up = t.ty.name().to_uppercase();
        let name = t.ty.name().replace('_', " ");
        if resident {
            v.push(define(
                &format!("FB_{up}"),
                t.first,
                &format!("the {name} records"),
            ));
        }
        v.push(define(&format!("{up}_WORDS"), t.size, "  words of one"));
        if resident && lay.traversal == Traversal::Paper {
            v.push(define(&format!("MB_{up}"), t.mailbox, "  their mailboxes"));
        }
    }
    v
}

/// A streamed scene's FB words: the split being classified, the node
/// stack's slots, the leaf blocks' bank, the banded polygons' sub-edges.
fn stream_lines(lay: &FbImage, st: &super::layout::Stream) -> Vec<String> {
    let mut v = Vec::new();
    v.push(define(
        data::SPLIT.0,
        st.split_slot,
        "the split of the node being classified",
    ));
    if lay.traversal == Traversal::Packet {
        v.push(define(
            "SLOTS",
            "SPLIT + 1",
            "per node stack entry (every 4th word) its RAM slot",
        ));
    }
    v.push(define(
        data::SBANK.0,
        format!("0x{STREAM_BANK:x}"),
        "FB bank 1: the leaf blocks, by DMA",
    ));
    if let Some(f) = &st.fans {
        v.push(define(
            "FANS",
            format!("0x{:x}", f.at),
            "the banded polygons' sub-edges (main memory)",
        ));
        v.push(define(
            "FAN_UNIT_SHIFT",
            primitives::polygon::FAN_UNIT.trailing_zeros(),
            "  POLY_FANS_AT counts units of this many bytes (log2)",
        ));
        v.push(define(
            "FB_WORD_SHIFT",
            f.word_shift,
            "  an FB word's bytes in main memory (log2)",
        ));
        v.push(define(
            "FAN_BUF",
            format!("0x{:x}", f.buf),
            "FB: a polygon's bands of sub-edges, by DMA (the top of bank 1)",
        ));
    }
    if lay.traversal == Traversal::Paper {
        v.push(define(
            "BLOCK_HEAD",
            super::layout::BLOCK_HEAD,
            "a block's cell bounds before its records",
        ));
    }
    v
}

fn nodes(lay: &FbImage) -> Vec<String> {
    use super::layout::{packet_nodes, paper_nodes};
    let types: Vec<&str> = lay.types.iter().map(|t| t.ty.name()).collect();
    match (lay.traversal, lay.stream.is_some()) {
        (Traversal::Paper, false) => paper_nodes::header(lay.node_layout, &lay.types),
        (Traversal::Paper, true) => paper_nodes::streamed_header(&types),
        (Traversal::Packet, streamed) => packet_nodes::header(streamed, &types),
    }
}

/// TinyRISC's data.
fn data(lay: &FbImage, merged_lanes: Option<&[u32]>) -> String {
    use super::data::{
        Var, AWAKE, BAND_SAVE, CUR_BLK, CUR_OUT, LEAF_TAGS, MODE, NEG, NEG_X, NEG_Y, NEG_Z, NF, NK,
        NS, NSTACK, PASS, PASSES, PREV_GEN, SAVE_LR, TESTS, TILE_GEN, TL_BANK, TL_CNT, TL_PTR,
        T_END, T_START, UPTR, USTK,
    };
    let mut v = vec![PASS, MODE, SAVE_LR];
    if lay.fit.polygon_form.banded() {
        v.push(BAND_SAVE);
    }
    v.push(AWAKE);
    let mut lines: Vec<String> = v.iter().map(Var::line).collect();
    lines.push(format!("{NEG}:"));
    let mut v = vec![NEG_X, NEG_Y, NEG_Z, T_START, T_END];
    if lay.traversal == Traversal::Paper {
        // (The packet traversal's tests are counted by the simulator.)
        v.push(TESTS);
    }
    v.extend([PASSES, TL_PTR, TL_CNT, TL_BANK, CUR_OUT, NSTACK]);
    match (lay.traversal, lay.stream.is_some()) {
        (Traversal::Packet, true) => v.extend([NK, NF, NS, TILE_GEN, PREV_GEN, LEAF_TAGS]),
        (Traversal::Packet, false) => v.extend([NK, NF, NS]),
        (Traversal::Paper, true) => v.extend([UPTR, USTK, CUR_BLK]),
        (Traversal::Paper, false) => {}
    }
    lines.extend(v.iter().map(Var::line));
    let mut t = Code::new();
    t.raw("\n; ==== TinyRISC data ====").directive(".data");
    for l in lines {
        t.raw(l);
    }
    if let Some(lanes) = merged_lanes {
        shadows::data(&mut t, lay, lanes);
    }
    t.text()
}
