//! TinyRISC's main program: start-up, the tile loop and the ray tree of
//! each tile, and the pixels out by DMA. The traversal it calls for every
//! ray pass (`trace`) is in [`super::traversal`]; the RC kernels it
//! broadcasts between passes are in [`super::shading`].
//!
//! ```text
//! _start: FB image and contexts in by DMA; RC RAM tables; lanes
//! tile:   for each tile of the list:
//!           eye rays; shade(level 0)
//!             shade(l): trace (closest hit); post;
//!                       per light: shadow rays, trace (any hit), Phong
//!                         (packet traversal, l > 0: every light's shadow
//!                         rays in merged packets, `shadows`, where chosen)
//!                       if l + 1 < depth: reflected rays, shade(l + 1), pop
//!                         (packet traversal: where some ray reflects)
//!                         (and the refracted rays' subtree, where any)
//!           pixels into an output bank of FB set 1, DMA to main memory
//!           (the other bank drains while the next tile is traced)
//! finish: cycle counter into T_END; halt
//! ```
//!
//! The tile loop keeps its state in memory (`TL_PTR`, `TL_CNT`, `TL_BANK`,
//! `CUR_OUT`), so that `trace` may use r1..r14.

use super::data::{
    CUR_OUT, EYE_PX, EYE_PY, FBIMG, FBWORDS, FB_EYE, FB_POST, MODE, PREV_GEN, TILE, TILELIST,
    TILE_BYTES, TILE_GEN, TILE_OUT, TILE_PX, TILE_PY, TL_BANK, TL_CNT, TL_COUNT, TL_FIRST, TL_PTR,
    T_END, T_START,
};
use super::emit::{at, Code, R0, R1, R2, R3, R4, R5, R6};
use super::kernel_names as names;
use super::layout::FbImage;
use super::primitives::kaddr;

/// `BCAST k`: broadcast a kernel without a stream.
fn cb<'a>(t: &'a mut Code, k: &str) -> &'a mut Code {
    t.m("BCAST", k)
}

/// `BCAST_FB k, stream`: broadcast a kernel with its FB stream.
fn sb<'a>(t: &'a mut Code, k: &str, stream: impl std::fmt::Display) -> &'a mut Code {
    t.m("BCAST_FB", format!("{k}, {stream}"))
}

/// The macros of the main program and the traversals: broadcasts of a
/// kernel (its context address and length from its labels), a level's
/// shading and one light's shadow pass.
pub fn macros(lay: &FbImage) -> Code {
    let mut t = Code::new();
    let body = |f: &dyn Fn(&mut Code)| {
        let mut b = Code::new();
        f(&mut b);
        b
    };
    let packet = lay.traversal == super::Traversal::Packet;
    // A kernel's context address into r1: one `addi` from r0 in the packet
    // traversal (the address fits its immediate), the paper's `li` (two
    // instructions for a label defined further on) in the paper's, whose
    // cycle counts are published.
    let kernel_address = move |b: &mut Code, k: &str| {
        if packet {
            b.addi(R1, R0, kaddr(k));
        } else {
            b.li(R1, kaddr(k));
        }
    };
    t.define_macro(
        "BCAST",
        "k",
        "BCAST k: broadcast kernel k to the array (its contexts, no FB stream). Clobbers r1.",
        body(&|b| {
            kernel_address(b, "\\k");
            b.cbcast(R1, "(\\k\\()_end - \\k) / 4");
        }),
    );
    t.define_macro(
        "BCAST_FB",
        "k, fb",
        "BCAST_FB k, fb: broadcast kernel k with the FB words from address fb as its stream.\n\
         Clobbers r1, r2.",
        body(&|b| {
            kernel_address(b, "\\k");
            b.li(R2, "\\fb").sbcb(R1, R2, "(\\k\\()_end - \\k) / 4");
        }),
    );
    t.define_macro(
        "BCAST_AT",
        "k, ra",
        "BCAST_AT k, ra: broadcast kernel k with the FB words from the address in ra as its\n\
         stream. Clobbers r1.",
        body(&|b| {
            kernel_address(b, "\\k");
            b.line("sbcb r1, \\ra, (\\k\\()_end - \\k) / 4");
        }),
    );
    t.define_macro(
        "BCAST_REC",
        "k, ra, field",
        "BCAST_REC k, ra, field: broadcast kernel k with the FB words from `field` of the\n\
         record (or node) at ra as its stream. Clobbers r1, r2.",
        body(&|b| {
            kernel_address(b, "\\k");
            b.line("addi r2, \\ra, \\field")
                .sbcb(R1, R2, "(\\k\\()_end - \\k) / 4");
        }),
    );
    if lay.traversal == super::Traversal::Packet {
        t.define_macro(
            "BCAST_UPTO",
            "k, cut, ra, field",
            "BCAST_UPTO k, cut, ra, field: broadcast kernel k's contexts up to its cut `cut`,\n\
             with the FB words from `field` of the record at ra as their stream. Clobbers r1, r2.",
            body(&|b| {
                kernel_address(b, "\\k");
                b.line("addi r2, \\ra, \\field")
                    .sbcb(R1, R2, "(\\cut - \\k) / 4");
            }),
        );
        t.define_macro(
            "BCAST_FROM_ANY",
            "cut, end, ra, field, none",
            "BCAST_FROM_ANY cut, end, ra, field, none: once the array is done, if some awake RC\n\
             has F, broadcast a kernel's contexts from its cut `cut` up to label `end`, the\n\
             stream going on from `field` of the record at ra past the words read before the\n\
             cut (`cut_fb`); else on to `none`. The run's operands are set before the status\n\
             read, while the array may still be busy. Clobbers r1, r2, r3.",
            body(&|b| {
                kernel_address(b, "\\cut");
                b.line("addi r2, \\ra, \\field + \\cut\\()_fb")
                    .rcany(R3)
                    .line("beqz r3, \\none")
                    .sbcb(R1, R2, "(\\end - \\cut) / 4");
            }),
        );
    }
    shading_macros(&mut t, lay);
    t
}

/// The macros of a level's shading: one light's shadow pass, and a
/// level's trace, shading state and shadow passes.
fn shading_macros(t: &mut Code, lay: &FbImage) {
    let body = |f: &dyn Fn(&mut Code)| {
        let mut b = Code::new();
        f(&mut b);
        b
    };
    t.define_macro(
        "SHADOW_PASS",
        "light, shade",
        "SHADOW_PASS light, shade: shadow rays from the hits towards the light of stream\n\
         `light`, traced (any hit), then its Phong terms (stream `shade`) where it is visible.",
        body(&|b| {
            b.m("BCAST_FB", format!("{}, \\light", names::SHADOW))
                .li(R1, 1)
                .sw(R1, at(MODE, R0))
                .c("any hit")
                .jal("trace")
                .m("BCAST", names::WAKE);
            super::shading::broadcast_phong(b, lay.phong_in_runs(), "\\shade");
        }),
    );
    let packet = lay.traversal == super::Traversal::Packet;
    t.define_macro(
        "SHADE_LEVEL",
        "post",
        &format!(
            "SHADE_LEVEL post: the rays of a level traced (closest hit), the hits' shading state\n\
             (kernel `post`: k_post_eye for the eye rays, k_post after), then every light's\n\
             shadow pass ({} light{}){}.",
            lay.lights.len(),
            if lay.lights.len() == 1 { "" } else { "s" },
            if packet {
                ", where some ray of the level hit (post leaves F = a hit)"
            } else {
                ""
            }
        ),
        body(&|b| {
            b.sw(R0, at(MODE, R0))
                .c("closest hit")
                .jal("trace")
                .m("BCAST", names::WAKE)
                .m("BCAST_FB", "\\post, FB_POST");
            if packet {
                // (The paper's traversal keeps its published cycles.)
                b.rcany(R1)
                    .beqz(R1, "no_hit\\@")
                    .c("no ray hit: no shadow pass");
            }
            for i in 0..lay.lights.len() {
                b.m("SHADOW_PASS", format!("FB_LIGHT{i}, FB_SHADE{i}"));
            }
            if packet {
                b.label("no_hit\\@");
            }
        }),
    );
}

/// The main program: `_start`, the tile loop, `finish`; `merged`: the
/// reflection levels' shadow rays go through [`super::shadows`].
pub fn main(t: &mut Code, lay: &FbImage, depth: u32, merged: bool) {
    t.doc(
        "_start: the FB image and the contexts in by DMA, every RC's RAM tables and lane words,\n\
         then the tile loop; T_START, T_END: the cycle counter around it.",
    );
    t.label("_start")
        .li(R1, FBIMG)
        .li(R2, 0)
        .li(R3, FBWORDS)
        .ldfb(R1, R2, R3)
        .c("the FB image into FB set 0")
        .dwait()
        .li(R1, "CTXBASE")
        .li(R2, 0)
        .li(R3, "(ctx_end - CTXBASE) / 4")
        .ldctxt(R1, R2, R3)
        .c("the kernels into context memory")
        .dwait();
    sb(t, names::INIT, "0").c("RSQ, RCP, C_ONE, C_INF from the FB");
    t.li(R1, kaddr(names::ROW_INDEX))
        .cbcr(R1, R0, 1)
        .c("row i: r8 = i");
    cb(t, names::STORE_ROW);
    t.li(R1, kaddr(names::ROW_INDEX))
        .cbcc(R1, R0, 1)
        .c("column j: r8 = j");
    cb(t, names::STORE_COL);
    cb(t, names::LANES).c("the RCs outside the tile sleep");
    if merged {
        cb(t, names::LANE_ID).c("every RC's number, for merged shadow packets");
    }
    t.rcany(R1)
        .c("the array done")
        .rdcyc(R1)
        .sw(R1, at(T_START, R0))
        .li(R1, TILELIST)
        .lw(R2, at(TL_COUNT, R1))
        .addi(R1, R1, TL_FIRST)
        .sw(R1, at(TL_PTR, R0))
        .sw(R2, at(TL_CNT, R0));
    t.doc(
        "tile: one tile of the list (TL_PTR: its entry, TL_CNT: tiles left): eye rays, the ray\n\
         tree, the pixels out.",
    );
    t.label(TILE)
        .lw(R2, at(TL_CNT, R0))
        .beqz(R2, "finish")
        .lw(R1, at(TL_PTR, R0))
        .lw(R3, at(TILE_PX, R1))
        .lw(R4, at(TILE_PY, R1))
        .lw(R5, at(TILE_OUT, R1))
        .sw(R5, at(CUR_OUT, R0));
    if lay.traversal == super::Traversal::Packet && lay.stream.is_some() {
        t.lw(R2, at(TILE_GEN, R0))
            .sw(R2, at(PREV_GEN, R0))
            .slli(R6, R4, 12)
            .or(R6, R6, R3)
            .sw(R6, at(TILE_GEN, R0))
            .c("the leaf cache holds the leaves of this tile and of the one before");
    }
    t.li(R6, FB_EYE)
        .sfb(R3, at(EYE_PX, R6))
        .sfb(R4, at(EYE_PY, R6))
        .c("the tile's corner into the eye stream");
    sb(t, names::EYE, FB_EYE).c("eye rays");
    let mut skips = 0;
    tree(t, lay, 0, depth.max(1), merged, &mut skips);
    output(t);
    t.label("finish")
        .dwait()
        .rdcyc(R1)
        .sw(R1, at(T_END, R0))
        .halt();
}

/// One level's shading ([`macros`]' `SHADE_LEVEL`); `merged`: a
/// reflection level's shadow rays in merged packets (`jal shadows`).
fn shade_level(t: &mut Code, level: u32, merged: bool, skips: &mut u32) {
    if merged && level > 0 {
        t.sw(R0, at(MODE, R0))
            .c(format!("level {level}: trace (closest hit)"))
            .jal("trace");
        cb(t, names::WAKE);
        sb(t, names::POST, FB_POST);
        *skips += 1;
        let skip = format!("no_hit{}", *skips);
        t.rcany(R1).beqz(R1, &skip).c("no ray hit: no shadow pass");
        t.jal("shadows").c("every light's shadow rays, merged");
        t.label(&skip);
        return;
    }
    t.m(
        "SHADE_LEVEL",
        if level == 0 {
            names::POST_EYE
        } else {
            names::POST
        },
    )
    .c(format!("level {level}: trace, shade, every light"));
}

/// The ray tree, depth first: a level's shading, then its reflected ray's
/// subtree and, where the scene refracts, its refracted ray's (each
/// skipped when no ray of the tile reflects or refracts there; with the
/// paper's traversal the reflected rays' subtree is always traced).
fn tree(t: &mut Code, lay: &FbImage, level: u32, levels: u32, merged: bool, skips: &mut u32) {
    shade_level(t, level, merged, skips);
    if level + 1 >= levels {
        return;
    }
    if lay.refract {
        sb(t, &names::refract_prepare(level), "FB_TRANSMIT")
            .c(format!("level {level}'s refracted rays, for later"));
    }
    cb(t, &names::reflect(level)).c(format!("level {level}'s reflected rays"));
    if lay.traversal == super::Traversal::Packet {
        // (The paper's traversal keeps its published cycles: it traces
        // the level whether or not a ray reflects.)
        *skips += 1;
        let skip = format!("no_reflection{}", *skips);
        t.rcany(R1).beqz(R1, &skip).c("none in the tile");
        tree(t, lay, level + 1, levels, merged, skips);
        t.label(&skip);
        cb(t, names::WAKE);
    } else {
        tree(t, lay, level + 1, levels, merged, skips);
    }
    cb(t, &names::reflected(level)).c("their colour added");
    if lay.refract {
        *skips += 1;
        let skip = format!("no_refraction{}", *skips);
        cb(t, &names::refract(level)).c(format!("level {level}'s refracted rays"));
        t.rcany(R1).beqz(R1, &skip).c("none in the tile");
        tree(t, lay, level + 1, levels, merged, skips);
        t.label(&skip);
        cb(t, names::WAKE);
        cb(t, &names::refracted(level)).c("their colour added");
    }
}

/// Four words per lane through the FB (an output bank of FB set 1), then
/// DMA to the tile's place in main memory; the next tile.
fn output(t: &mut Code) {
    t.comment("the pixels: R, G, B, object id per RC into an output bank, then DMA out")
        .lw(R5, at(TL_BANK, R0))
        .li(R4, "OUT_BANK0")
        .beqz(R5, "out_bank")
        .li(R4, "OUT_BANK1");
    t.label("out_bank").dwait().c("the bank's last DMA done");
    for (i, w) in ["OUT_R", "OUT_G", "OUT_B", "OUT_ID"]
        .into_iter()
        .enumerate()
    {
        t.m("BCAST", names::out(i as u32)).wfb(R4, w);
    }
    t.lw(R3, at(CUR_OUT, R0))
        .stfb(R3, R4, "OUT_WORDS")
        .c("DMA to main memory")
        .lw(R5, at(TL_BANK, R0))
        .xori(R5, R5, 1)
        .sw(R5, at(TL_BANK, R0))
        .c("the other bank next")
        .lw(R1, at(TL_PTR, R0))
        .addi(R1, R1, TILE_BYTES)
        .sw(R1, at(TL_PTR, R0))
        .lw(R2, at(TL_CNT, R0))
        .addi(R2, R2, -1)
        .sw(R2, at(TL_CNT, R0))
        .j(TILE);
}
