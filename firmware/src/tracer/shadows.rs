//! Merged shadow packets (`--shadow-packets merged`, `docs/tracer.md`,
//! "Merged shadow packets"): from the first reflection level on, the
//! shadow rays of all the lights leave the RCs that spawned them and are
//! packed into as few packets as hold them, each traced once; the answers
//! (blocked or not) go back to the spawning RCs as one bit per ray.
//!
//! The reflected rays of a tile hit few RCs' worth of surfaces facing a
//! light: traced one light at a time, their shadow packets run a quarter
//! full on the SPD's rings, and a packet costs about what its traversal
//! costs, however many rays it carries. The eye rays' level keeps its
//! packet per light (they are full, and rays of several lights in one
//! packet walk more of the tree).
//!
//! ```text
//! shadows (TinyRISC, one level of a tile):
//!   per light l: k_shadow_rays; k_shadow_keep (N.L, R.V into the light's
//!     RAM slot); the lit RCs (rcsl, rcsh) into SC_LIT; the ray's words
//!     out (k_ray_word*, wfb) into the stage: FB set 1, this tile's
//!     output bank (SC_STAGE + l * 512 + w * 64 + RC)
//!   packet: the lit RCs of the lights in turn, up to the tile's ways:
//!     entry n: its RC (SC_LANES[n]) and the ray's words copied from the
//!     stage into the packet stream (SC_PACK, SC_REC words per entry)
//!     k_shadow_clear; k_shadow_load per entry; k_shadow_go; trace (any
//!     hit); k_shadow_seen; rcfl / rcfh: unblocked rays -> SC_VIS
//!   per light l: its SC_VIS as four 16-RC mask words; k_shadow_lit (LIT,
//!     N.L, R.V of the light); k_phong
//! ```
//!
//! Every move is the chip's: the words out by `wfb` (8 cycles for 64), the
//! copies by TinyRISC's `lfb` / `sfb`, one load kernel per ray, the masks
//! back by `sfb` and one kernel per light.

use super::emit::{at, Code, Name, K, R0, R1, R10, R2, R3, R4, R5, R6, R7, R8, R9};
use super::kernel_names as names;
use super::layout::FbImage;
use super::memory_map::ram;
use super::{Options, Traversal};

use super::data::{
    DEBRUIJN, MODE, SC_BITS, SC_FB, SC_L, SC_LANES, SC_LIT, SC_N, SC_RET, SC_SRC, SC_VIS, TL_BANK,
};
pub use super::options::ShadowPackets;

/// A ray's first word in the packet stream: the RC it goes to.
pub const SC_RAY_RC: Name = Name::new("SC_RAY_RC", 0, "  the RC it goes to");

/// The most lights whose rays are merged (their N.L and R.V take two
/// words each of every RC's RAM, `SHADOW_SLOTS`); a scene with more keeps
/// a packet per light.
pub const MAX_LIGHTS: usize = 12;

/// FB set 1, words from the start of the tile's output bank (after the
/// output's `OUT_WORDS`): per light its RAM slot and mask words, the
/// packet stream, the stage.
const SC_PARAM: u32 = 256;
const SC_PACK: u32 = 320;
const SC_STAGE: u32 = 1024;
/// Words of a light's stage (up to 8 ray words of 64 RCs).
const SC_LSTRIDE: u32 = 512;

/// Whether this build merges the shadow rays of its reflection levels.
pub fn merged(opt: &Options, lay: &FbImage) -> bool {
    opt.shadows == ShadowPackets::Merged && applies(opt, lay)
}

/// Whether merging can apply to this build: the packet traversal, a
/// reflection level, 2 to [`MAX_LIGHTS`] lights, and positions in the
/// scene's format (the stage holds no origin remainders,
/// [`super::Positions::Local`]).
pub fn applies(opt: &Options, lay: &FbImage) -> bool {
    lay.traversal == Traversal::Packet
        && !lay.fit.local
        && opt.depth >= 2
        && (2..=MAX_LIGHTS).contains(&lay.lights.len())
}

/// The words of a ray in the stage: r1..r7, and with two-sided objects the
/// object it leaves (`ORIG_OBJ`).
fn ray_words(lay: &FbImage) -> u32 {
    if lay.refract {
        8
    } else {
        7
    }
}

/// The names of the header: FB set 1 offsets and the record's length.
pub fn header(lay: &FbImage) -> Vec<String> {
    use super::emit::define;
    vec![
        define(
            "SC_PARAM",
            SC_PARAM,
            "merged shadows, in the tile's output bank: per light 5 words (RAM slot, 4 mask words)",
        ),
        define(
            "SC_PACK",
            SC_PACK,
            "the packet stream: per ray its RC, then its words",
        ),
        define(
            "SC_REC",
            ray_words(lay) + 1,
            "words of a ray in the packet stream:",
        ),
        SC_RAY_RC.define(),
        define("SC_RAY_W", 1, "  its words, r1..r7[, ORIG_OBJ]"),
        define(
            "SC_STAGE",
            SC_STAGE,
            "the stage: light l's ray word w of RC i at SC_STAGE + l*512 + w*64 + i",
        ),
        define("LIGHTS", lay.lights.len(), "the scene's lights"),
        define("SL_NL", 0, "a light's slot in SHADOW_SLOTS: N.L"),
        define("SL_RV", 1, "  R.V"),
    ]
}

/// TinyRISC's data.
pub fn data(t: &mut Code, lay: &FbImage, lanes: &[u32]) {
    let l = lay.lights.len();
    use super::data::{
        DEBRUIJN, SC_BITS, SC_FB, SC_L, SC_LANES, SC_LIT, SC_N, SC_RET, SC_SRC, SC_VIS,
    };
    for v in [SC_RET, SC_FB, SC_L, SC_BITS, SC_N] {
        t.raw(v.line());
    }
    t.raw(SC_LIT.line_with(&format!(".space {}", 8 * l)));
    t.raw(SC_VIS.line_with(&format!(".space {}", 8 * l)));
    t.raw(SC_SRC.line());
    let list: Vec<String> = lanes.iter().map(|x| x.to_string()).collect();
    t.raw(SC_LANES.line_with(&format!(".byte {}", list.join(", "))));
    t.raw(DEBRUIJN.line());
    t.raw(format!(
        "{:<16}.byte 31, 27, 13, 23, 21, 19, 16, 7, 26, 12, 18, 6, 11, 5, 10, 9",
        ""
    ));
    t.raw(format!("{:<16}.align 4", ""));
}

/// The RC kernels, in load order.
pub fn kernels(lay: &FbImage) -> Vec<(String, K)> {
    let w = ray_words(lay);
    let mut v = vec![
        (names::LANE_ID.to_string(), lane_id()),
        (names::SHADOW_KEEP.to_string(), keep()),
    ];
    for i in 0..w {
        v.push((names::ray_word(i), ray_word(i)));
    }
    if lay.refract {
        v.push((names::SHADOW_SAVE.into(), save_orig()));
    }
    v.push((names::SHADOW_CLEAR.into(), clear()));
    v.push((names::SHADOW_LOAD.into(), load(lay.refract)));
    v.push((names::SHADOW_GO.into(), go()));
    v.push((names::SHADOW_SEEN.into(), seen()));
    v.push((names::SHADOW_LIT.into(), lit(lay.refract)));
    v
}

/// `LANE_ID` = the RC's number, row * 8 + column (once, at start-up).
fn lane_id() -> K {
    let mut k = K::new();
    k.doc("k_lane_id: LANE_ID = the RC's number in the array, row * 8 + column (rcfl / rcfh bit order).");
    k.c(format!("ld r8, [r0 + #{}]", ram::LANE_ROW))
        .c("sll r8, r8, #3")
        .c(format!("ld r9, [r0 + #{}]", ram::LANE_COL))
        .c("add r8, r8, r9")
        .c(format!("st r8, [#{}]", ram::LANE_ID));
    k
}

/// After `k_shadow_rays` (stream, FB set 1: the light's RAM slot): the lit
/// RCs keep the light's N.L and R.V in its slot.
fn keep() -> K {
    let mut k = K::new();
    k.doc(
        "k_shadow_keep: the lit RCs keep this light's N.L and R.V (stream, FB set 1: the light's\n\
         slot in SHADOW_SLOTS).",
    );
    k.c("mov r15, fb1")
        .c(format!("ld r8, [r0 + #{}]", ram::SH_NL))
        .c("st r8, [r15]")
        .c("add r15, r15, #1")
        .c(format!("ld r8, [r0 + #{}]", ram::SH_RV))
        .c("st r8, [r15]");
    k
}

/// Word `i` of the RC's shadow ray into `out` (for `wfb`): r1..r7, then
/// `ORIG_OBJ`.
fn ray_word(i: u32) -> K {
    let mut k = K::new();
    let what = [
        "origin x",
        "origin y",
        "origin z",
        "direction x",
        "direction y",
        "direction z",
        "tbest",
        "the object it leaves",
    ];
    k.doc(&format!(
        "{}: the shadow ray's {} into the output register (for wfb).",
        names::ray_word(i),
        what[i as usize]
    ));
    if i < 7 {
        k.c(format!("mov out, r{}", i + 1));
    } else {
        k.c(format!("ld out, [r0 + #{}]", ram::ORIG_OBJ));
    }
    k
}

/// Before a packet's loads: no RC has a ray yet.
fn clear() -> K {
    let mut k = K::new();
    k.doc("k_shadow_clear: before a merged packet's loads: no RC holds a ray (SHADOW_LOADED = 0).");
    k.c(format!("st r0, [#{}]", ram::SHADOW_LOADED));
    k
}

/// One ray of the packet (stream, FB set 1: the RC it goes to, its words):
/// that RC takes it, `PASS_T0` = its `tbest`.
fn load(refract: bool) -> K {
    let mut k = K::new();
    k.doc(
        "k_shadow_load: one ray of a merged packet (stream, FB set 1: its RC, then r1..r7[, ORIG_OBJ]):\n\
         that RC takes it; PASS_T0 = its tbest, SHADOW_LOADED = 1.",
    );
    k.c(format!("ld r8, [r0 + #{}]", ram::LANE_ID))
        .c("cmp.eq fb1, r8")
        .note("F: this RC's ray");
    for r in 1..=7 {
        k.c(format!("(f) mov r{r}, fb1"));
    }
    if refract {
        k.c(format!("(f) st fb1, [#{}]", ram::ORIG_OBJ));
    }
    k.c(format!("(f) st r7, [#{}]", ram::PASS_T0))
        .c("(f) movb r9, #1")
        .c(format!("(f) st r9, [#{}]", ram::SHADOW_LOADED));
    k
}

/// The RCs with no ray in the packet sleep.
fn go() -> K {
    let mut k = K::new();
    k.doc("k_shadow_go: the RCs with no ray in the merged packet sleep for its pass.");
    k.c(format!("ld r8, [r0 + #{}]", ram::SHADOW_LOADED))
        .c("cmp.eq r8, #0")
        .c("(f) sleep");
    k
}

/// After the pass: F = the RC's ray is unblocked (no hit before `tbest`).
fn seen() -> K {
    let mut k = K::new();
    k.doc("k_shadow_seen: after a merged packet's pass, F = the RC's ray met nothing before the light.");
    k.c(format!("ld r8, [r0 + #{}]", ram::PASS_T0))
        .c("cmp.ge r7, r8");
    k
}

/// One light's answers (stream, FB set 1: its RAM slot, then four mask
/// words, RCs 0..15, 16..31, ...): `LIT` = the RC's bit, N.L and R.V from
/// the slot, and `r7 >= PASS_T0` for `k_phong`; with two-sided objects the
/// RC's own `ORIG_OBJ` back.
fn lit(refract: bool) -> K {
    let mut k = K::new();
    k.doc(
        "k_shadow_lit: one light's answers (stream, FB set 1: its slot, then 4 mask words of 16 RCs):\n\
         LIT = this RC's bit (lit and unblocked), SH_NL and SH_RV from the slot; r7 = PASS_T0 = 0,\n\
         so that k_phong shades where LIT.",
    );
    k.c("mov r15, fb1")
        .c("mov r10, fb1")
        .c("mov r11, fb1")
        .c("mov r12, fb1")
        .c("mov r13, fb1")
        .c(format!("ld r8, [r0 + #{}]", ram::LANE_ID))
        .c("srl r9, r8, #4")
        .note("its mask word")
        .c("and r8, r8, #15")
        .note("its bit");
    for (i, r) in [(1, 11), (2, 12), (3, 13)] {
        k.c(format!("cmp.eq r9, #{i}"))
            .c(format!("(f) mov r10, r{r}"));
    }
    k.c("srl r10, r10, r8")
        .c("and r10, r10, #1")
        .c(format!("st r10, [#{}]", ram::LIT))
        .c("ld r8, [r15 + #SL_NL]")
        .c(format!("st r8, [#{}]", ram::SH_NL))
        .c("ld r8, [r15 + #SL_RV]")
        .c(format!("st r8, [#{}]", ram::SH_RV))
        .c("movb r7, #0")
        .c(format!("st r7, [#{}]", ram::PASS_T0));
    if refract {
        k.c(format!("ld r8, [r0 + #{}]", ram::SHADOW_ORIG))
            .c(format!("st r8, [#{}]", ram::ORIG_OBJ));
    }
    k
}

/// Before the stage is written (refraction scenes): every RC keeps its
/// own `ORIG_OBJ` in `SHADOW_ORIG`.
fn save_orig() -> K {
    let mut k = K::new();
    k.doc("k_shadow_save: every RC keeps the object its rays leave (ORIG_OBJ) while merged packets load others'.");
    k.c(format!("ld r8, [r0 + #{}]", ram::ORIG_OBJ))
        .c(format!("st r8, [#{}]", ram::SHADOW_ORIG));
    k
}

/// `BCAST k`.
fn cb(t: &mut Code, k: &str) {
    t.m("BCAST", k);
}

/// The `shadows` routine: one level's shadow rays of every light, merged
/// into packets, traced, and the lights' Phong terms (called after the
/// level's `k_post`; r15 the return address; clobbers r1..r15).
pub fn routine(t: &mut Code, lay: &FbImage) {
    let nl = lay.lights.len() as u32;
    let w = ray_words(lay);
    stage(t, lay, nl, w);
    pack(t, w);
    trace_packet(t);
    shade(t, lay, nl);
    t.lw(super::emit::R15, at(SC_RET, R0)).line("jr r15");
}

/// Each light's rays, its lit RCs and the rays' `w` words into the stage.
fn stage(t: &mut Code, lay: &FbImage, nl: u32, w: u32) {
    t.doc(
        "shadows: a reflection level's shadow rays of every light, merged into full packets (see\n\
         the module's text in firmware/src/tracer/shadows.rs); then every light's Phong terms.",
    );
    t.label("shadows")
        .sw(super::emit::R15, at(SC_RET, R0))
        .lw(R5, at(TL_BANK, R0))
        .li(R4, "OUT_BANK0")
        .beqz(R5, "sc_bank")
        .li(R4, "OUT_BANK1");
    t.label("sc_bank").sw(R4, at(SC_FB, R0));
    if lay.refract {
        cb(t, names::SHADOW_SAVE);
    }
    for l in 0..nl {
        t.comment(format!(
            "light {l}: its rays, the lit RCs, the rays' words into the stage"
        ));
        t.li(R3, format!("SHADOW_SLOTS + {}", 2 * l))
            .sfb(R3, at(format!("SC_PARAM + {}", 5 * l), R4));
        t.m("BCAST_FB", format!("{}, FB_LIGHT{l}", names::SHADOW));
        t.addi(R3, R4, format!("SC_PARAM + {}", 5 * l));
        t.m("BCAST_AT", format!("{}, r3", names::SHADOW_KEEP));
        t.rcsl(R1)
            .rcsh(R2)
            .nor(R1, R1, R0)
            .nor(R2, R2, R0)
            .c("the lit RCs: awake")
            .sw(R1, at(format!("SC_LIT + {}", 8 * l), R0))
            .sw(R2, at(format!("SC_LIT + {}", 8 * l + 4), R0))
            .sw(R0, at(format!("SC_VIS + {}", 8 * l), R0))
            .sw(R0, at(format!("SC_VIS + {}", 8 * l + 4), R0));
        for i in 0..w {
            cb(t, &names::ray_word(i));
            t.wfb(R4, format!("SC_STAGE + {}", l * SC_LSTRIDE + i * 64));
        }
        cb(t, names::WAKE);
    }
}

/// `sc_packet`: the next packet of entries from the lit RCs of the lights
/// in turn, each ray's `w` words copied into the packet stream.
fn pack(t: &mut Code, w: u32) {
    t.lw(R6, at(SC_LIT, R0))
        .lw(R7, at(format!("{SC_LIT} + 4"), R0))
        .sw(R0, at(SC_L, R0))
        .sw(R6, at(SC_BITS, R0))
        .sw(R7, at(format!("{SC_BITS} + 4"), R0));
    t.doc(
        "sc_packet: the next packet: entries from the lit RCs of the lights in turn (r5 the light,\n\
         r6, r7 its RCs not packed yet), each ray's words copied from the stage into the packet\n\
         stream (r9), up to the tile's ways (r10 entries).",
    );
    t.label("sc_packet")
        .lw(R4, at(SC_FB, R0))
        .lw(R5, at(SC_L, R0))
        .lw(R6, at(SC_BITS, R0))
        .lw(R7, at(format!("{SC_BITS} + 4"), R0))
        .addi(R9, R4, "SC_PACK")
        .li(R10, 0);
    t.label("sc_fill")
        .slti(R1, R10, "TILE_W * TILE_H")
        .beqz(R1, "sc_full")
        .c("the packet is full");
    t.label("sc_next")
        .bnez(R6, "sc_low")
        .bnez(R7, "sc_high")
        .addi(R5, R5, 1)
        .c("the light's rays are packed: the next light")
        .slti(R1, R5, "LIGHTS")
        .beqz(R1, "sc_full")
        .slli(R1, R5, 3)
        .lw(R6, at(SC_LIT, R1))
        .lw(R7, at(format!("{SC_LIT} + 4"), R1))
        .j("sc_next");
    t.label("sc_low")
        .sub(R1, R0, R6)
        .and(R1, R1, R6)
        .c("the lowest lit RC's bit")
        .xor(R6, R6, R1)
        .li(R2, 0)
        .j("sc_index");
    t.label("sc_high")
        .sub(R1, R0, R7)
        .and(R1, R1, R7)
        .xor(R7, R7, R1)
        .li(R2, 32);
    t.label("sc_index")
        .li(R3, "0x077CB531")
        .mul(R1, R1, R3)
        .srli(R1, R1, 27)
        .lbu(R1, at(DEBRUIJN, R1))
        .add(R2, R2, R1)
        .c("r2: the RC that spawned the ray")
        .lbu(R1, at(SC_LANES, R10))
        .sfb(R1, at(SC_RAY_RC, R9))
        .c("the RC it goes to")
        .slli(R3, R5, 9)
        .add(R3, R3, R2)
        .add(R3, R3, R4)
        .c("r3 + SC_STAGE: the ray's first word, light * 512 + RC");
    for i in 0..w {
        t.lfb(R1, at(format!("SC_STAGE + {}", i * 64), R3))
            .sfb(R1, at(format!("SC_RAY_W + {i}"), R9));
    }
    t.slli(R1, R5, 6)
        .add(R1, R1, R2)
        .slli(R3, R10, 2)
        .sw(R1, at(SC_SRC, R3))
        .addi(R9, R9, "SC_REC")
        .addi(R10, R10, 1)
        .j("sc_fill");
}

/// `sc_full`: the packet's rays into their RCs, one any-hit pass, the
/// unblocked ones into `SC_VIS`.
fn trace_packet(t: &mut Code) {
    t.doc("sc_full: the packet's rays into their RCs, one pass (any hit), the unblocked ones into SC_VIS.");
    t.label("sc_full")
        .beqz(R10, "sc_shade")
        .sw(R5, at(SC_L, R0))
        .sw(R6, at(SC_BITS, R0))
        .sw(R7, at(format!("{SC_BITS} + 4"), R0))
        .sw(R10, at(SC_N, R0));
    cb(t, names::SHADOW_CLEAR);
    t.addi(R3, R4, "SC_PACK");
    t.label("sc_load");
    t.m("BCAST_AT", format!("{}, r3", names::SHADOW_LOAD));
    t.addi(R3, R3, "SC_REC")
        .addi(R10, R10, -1)
        .bnez(R10, "sc_load");
    cb(t, names::SHADOW_GO);
    t.li(R1, 1).sw(R1, at(MODE, R0)).c("any hit").jal("trace");
    cb(t, names::WAKE);
    cb(t, names::SHADOW_SEEN);
    t.rcfl(R8)
        .rcfh(R9)
        .c("F: unblocked")
        .lw(R10, at(SC_N, R0))
        .li(R3, 0);
    t.label("sc_result")
        .lbu(R4, at(SC_LANES, R3))
        .slti(R5, R4, 32)
        .beqz(R5, "sc_result_high")
        .srl(R5, R8, R4)
        .j("sc_result_bit");
    t.label("sc_result_high").addi(R5, R4, -32).srl(R5, R9, R5);
    t.label("sc_result_bit")
        .andi(R5, R5, 1)
        .beqz(R5, "sc_result_next")
        .slli(R5, R3, 2)
        .lw(R5, at(SC_SRC, R5))
        .srli(R6, R5, 5)
        .slli(R6, R6, 2)
        .c("the light's SC_VIS word of the RC")
        .andi(R5, R5, 31)
        .li(R7, 1)
        .sll(R7, R7, R5)
        .lw(R5, at(SC_VIS, R6))
        .or(R5, R5, R7)
        .sw(R5, at(SC_VIS, R6));
    t.label("sc_result_next")
        .addi(R3, R3, 1)
        .bne(R3, R10, "sc_result")
        .j("sc_packet");
}

/// `sc_shade`: per light, its answers back to the RCs that spawned the
/// rays, and its Phong terms.
fn shade(t: &mut Code, lay: &FbImage, nl: u32) {
    t.doc("sc_shade: per light, its answers back to the RCs that spawned the rays, and its Phong terms.");
    t.label("sc_shade");
    for l in 0..nl {
        t.lw(R1, at(format!("SC_VIS + {}", 8 * l), R0))
            .lw(R2, at(format!("SC_VIS + {}", 8 * l + 4), R0))
            .andi(R3, R1, "0xffff")
            .sfb(R3, at(format!("SC_PARAM + {}", 5 * l + 1), R4))
            .srli(R3, R1, 16)
            .sfb(R3, at(format!("SC_PARAM + {}", 5 * l + 2), R4))
            .andi(R3, R2, "0xffff")
            .sfb(R3, at(format!("SC_PARAM + {}", 5 * l + 3), R4))
            .srli(R3, R2, 16)
            .sfb(R3, at(format!("SC_PARAM + {}", 5 * l + 4), R4))
            .addi(R3, R4, format!("SC_PARAM + {}", 5 * l));
        t.m("BCAST_AT", format!("{}, r3", names::SHADOW_LIT));
        super::shading::broadcast_phong(t, lay.phong_in_runs(), &format!("FB_SHADE{l}"));
    }
}
