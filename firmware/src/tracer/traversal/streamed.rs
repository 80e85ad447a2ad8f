//! The paper's traversal of a scene that does not fit FB set 0: nodes,
//! leaf lists and mailboxes in main memory (read by TinyRISC), each
//! leaf's block (bounds and records) moved into FB bank 1 (`SBANK`) by
//! DMA before its objects are broadcast; the split value of a node is
//! written into bank 0 (`SPLIT`) for the classification kernel.
//!
//! ```text
//! trace:
//!   as the resident traversal (paper.rs), but where the rays disagree at a
//!   node both children are visited in a fixed order (the subtree would be
//!   thousands of objects); entering such an unordered subtree against a
//!   ray's direction counts in the ray's UNORD, and inside one the
//!   closest-hit pass does not put rays to sleep at a leaf (a nearer hit
//!   may lie in a cell not visited yet); the shadow pass does (any hit
//!   will do)
//! test_objects(leaf):
//!   if every object's mailbox holds PASS: nothing to do
//!   DMA the leaf's block into SBANK unless it is there (CUR_BLK)
//!   per type, per object not tested in this pass: broadcast its test
//! ```
//!
//! Node record (main memory, `NODE_BYTES`): `SN_FLAGS` (-32768 leaf, else
//! the split axis), `SN_SPLIT`, `SN_LEFT`, `SN_RIGHT` (byte addresses),
//! `SN_BLOCK`, `SN_BLOCK_WORDS`, `SN_LIST`, per type present the leaf's
//! number of objects of that type (`SN_COUNT_type`), their total
//! (`SN_OBJECTS`). A list holds per object the byte address of its
//! mailbox half-word (the number of the pass that last tested it).
//!
//! TinyRISC registers: r5 the node, r11, r12 the awake mask, r14 the node
//! stack pointer (`NSTACK`), `UPTR` the unordered-subtree stack (`USTK`).

use super::super::data::{
    AWAKE, CUR_BLK, MAILBOX, MASK_HI, MODE, NEG, NOBJ, NSTACK, PASS, ROOT, SAVE_LR, SBANK, SPLIT,
    TESTS, UPTR, USTK,
};
use super::super::emit::{
    at, deref, Code, K, R0, R1, R10, R11, R12, R13, R14, R15, R2, R3, R4, R5, R6, R7, R8, R9,
};
use super::super::layout::paper_nodes::fields::{
    SN_BLOCK, SN_BLOCK_WORDS, SN_FLAGS, SN_LEFT, SN_LIST, SN_OBJECTS, SN_RIGHT, SN_SPLIT, U_AXIS,
    U_FRAME, U_NSTACK,
};
use super::super::layout::FbImage;
use super::super::memory_map::ram;
use super::super::primitives::{kaddr, klen};
use super::paper::{leaf_closest, pass_start};
use super::read_awake;
use crate::tracer::kernel_names as names;

/// The kernels the streamed traversal adds, in load order (after the
/// shading kernels).
pub fn kernels() -> Vec<(String, K)> {
    let mut v = vec![
        (names::LEAF_CLOSEST_ORDERED.to_string(), leaf_closest(true)),
        (names::UNORDERED_NONE.into(), unordered_clear()),
    ];
    for a in 0..3u8 {
        v.push((names::unordered_enter(a), unordered_count(a, 1)));
        v.push((names::unordered_leave(a), unordered_count(a, -1)));
    }
    v
}

/// Entering (`delta` 1) or leaving (-1) an unordered subtree visited
/// below-first: rays going down along `axis` count it.
pub fn unordered_count(axis: u8, delta: i32) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{}: {} an unordered subtree split across {} (visited below first): the rays\n\
         going down along that axis count it in UNORD.",
        if delta > 0 {
            names::unordered_enter(axis)
        } else {
            names::unordered_leave(axis)
        },
        if delta > 0 { "entering" } else { "leaving" },
        ["x", "y", "z"][axis as usize]
    ));
    k.c(format!("cmp.lt r{}, #0", 4 + axis))
        .c(format!("ld r8, [r0 + #{}]", ram::UNORD))
        .c(if delta > 0 {
            "(f) add r8, r8, #1"
        } else {
            "(f) sub r8, r8, #1"
        })
        .c(format!("st r8, [#{}]", ram::UNORD));
    k
}

/// No unordered subtree at a pass's start.
pub fn unordered_clear() -> K {
    let mut k = K::new();
    k.doc("k_unordered_none: UNORD = 0 at a pass's start.");
    k.c("sub r8, r8, r8").c(format!("st r8, [#{}]", ram::UNORD));
    k
}

/// `li r1` the kernel `name(axis)` of the axis in r7, then to `go`.
fn kernel_of_axis(t: &mut Code, name: fn(u8) -> String, go: &str) {
    t.li(R1, kaddr(&name(0)))
        .beqz(R7, go)
        .li(R1, kaddr(&name(1)))
        .slti(R3, R7, 2)
        .bnez(R3, go)
        .li(R1, kaddr(&name(2)));
}

/// The streamed `trace`, its `clear_mailbox` and `test_objects`.
pub fn trace(t: &mut Code, lay: &FbImage) {
    t.doc(
        "trace: one ray pass, the paper's traversal of a streamed scene. In: the rays in r1..r7\n\
         of every RC, MODE (0: closest hit, 1: any hit). Out: the hits in HIT_*, r7.\n\
         Clobbers r1..r14.",
    );
    pass_start(t);
    t.jal("read_awake")
        .li(R9, USTK)
        .sw(R9, at(UPTR, R0))
        .m("BCAST", names::UNORDERED_NONE)
        .li(R14, NSTACK)
        .li(R5, ROOT);
    t.label("visit_node")
        .lw(R11, at(AWAKE, R0))
        .lw(R12, at(format!("{AWAKE}+{MASK_HI}"), R0))
        .or(R1, R11, R12)
        .beqz(R1, "trace_done")
        .c("no ray awake")
        .lw(R6, at(SN_FLAGS, R5))
        .blt(R6, R0, "leaf")
        .lw(R1, at(SN_SPLIT, R5))
        .sfb(R1, at(SPLIT, R0))
        .c("the split for the kernel's stream")
        .andi(R7, R6, 3);
    kernel_of_axis(t, names::classify, "classify");
    t.label("classify")
        .li(R2, SPLIT)
        .sbcb(R1, R2, klen(&names::classify(0)))
        .rcfl(R1)
        .rcfh(R2)
        .c("r1, r2: the rays reaching below")
        .li(R8, kaddr(names::CLASSIFY_ABOVE))
        .cbcast(R8, 1)
        .rcfl(R3)
        .rcfh(R4)
        .c("r3, r4: the rays reaching above")
        .and(R1, R1, R11)
        .and(R2, R2, R12)
        .and(R3, R3, R11)
        .and(R4, R4, R12)
        .or(R9, R3, R4)
        .bnez(R9, "some_above")
        .or(R9, R1, R2)
        .beqz(R9, "pop_node")
        .lw(R5, at(SN_LEFT, R5))
        .c("all below")
        .j("visit_node");
    t.label("some_above")
        .or(R9, R1, R2)
        .bnez(R9, "both_sides")
        .lw(R5, at(SN_RIGHT, R5))
        .c("all above")
        .j("visit_node");
    both_sides(t);
    leaf_and_pop(t);
    clear_mailbox(t);
    test_objects(t, lay);
    read_awake(t);
}

/// `both_sides`: rays reach both children: the near child first where
/// every awake ray goes one way along the axis, else the subtree
/// unordered (its rays count it, its end and axis on the stack).
fn both_sides(t: &mut Code) {
    t.label("both_sides")
        .slli(R9, R7, 3)
        .lw(R10, at(NEG, R9))
        .lw(R13, at(format!("{NEG}+{MASK_HI}"), R9))
        .and(R10, R10, R11)
        .and(R13, R13, R12)
        .or(R9, R10, R13)
        .beqz(R9, "positive_first")
        .bne(R10, R11, "mixed")
        .bne(R13, R12, "mixed")
        .lw(R9, at(SN_LEFT, R5))
        .sw(R9, deref(R14))
        .addi(R14, R14, 4)
        .c("push below")
        .lw(R5, at(SN_RIGHT, R5))
        .c("all going down: above first")
        .j("visit_node");
    t.label("mixed")
        .lw(R9, at(UPTR, R0))
        .sw(R14, at(U_NSTACK, R9))
        .sw(R7, at(U_AXIS, R9))
        .addi(R9, R9, U_FRAME)
        .sw(R9, at(UPTR, R0))
        .c("an unordered subtree: where it ends, its axis");
    kernel_of_axis(t, names::unordered_enter, "mixed_count");
    t.label("mixed_count")
        .cbcast(R1, klen(&names::unordered_enter(0)))
        .c("the rays going down count it");
    t.label("positive_first")
        .lw(R9, at(SN_RIGHT, R5))
        .sw(R9, deref(R14))
        .addi(R14, R14, 4)
        .c("push above")
        .lw(R5, at(SN_LEFT, R5))
        .c("visit below first")
        .j("visit_node");
}

/// `leaf`: its objects tested, the rays with a hit in the cell asleep
/// (closest hit) or done (any hit); `pop_node`: the stack's next node,
/// leaving an unordered subtree where it ends.
fn leaf_and_pop(t: &mut Code) {
    t.label("leaf")
        .lw(R1, at(SN_BLOCK_WORDS, R5))
        .beqz(R1, "pop_node")
        .c("an empty leaf")
        .jal("test_objects")
        .beqz(R4, "pop_node")
        .c("nothing tested")
        .lw(R1, at(MODE, R0))
        .bnez(R1, "leaf_any_hit")
        .m("BCAST_AT", format!("{}, r4", names::LEAF_CLOSEST_ORDERED))
        .c("the rays with a hit in the cell sleep")
        .j("leaf_done");
    t.label("leaf_any_hit").m("BCAST", names::LEAF_ANY);
    t.label("leaf_done").jal("read_awake");
    t.label("pop_node")
        .lw(R9, at(UPTR, R0))
        .li(R8, USTK)
        .beq(R9, R8, "pop_stack")
        .lw(R10, at(format!("{U_NSTACK}-{U_FRAME}"), R9))
        .bne(R10, R14, "pop_stack")
        .c("leaving an unordered subtree?")
        .lw(R7, at(format!("{U_AXIS}-{U_FRAME}"), R9))
        .addi(R9, R9, "-U_FRAME")
        .sw(R9, at(UPTR, R0));
    kernel_of_axis(t, names::unordered_leave, "pop_count");
    t.label("pop_count")
        .cbcast(R1, klen(&names::unordered_enter(0)));
    t.label("pop_stack")
        .li(R9, NSTACK)
        .beq(R14, R9, "trace_done")
        .addi(R14, R14, -4)
        .lw(R5, deref(R14))
        .j("visit_node");
    t.label("trace_done").lw(R15, at(SAVE_LR, R0)).ret();
}

/// `clear_mailbox`: every mailbox to 0.
fn clear_mailbox(t: &mut Code) {
    t.doc(
        "clear_mailbox: every mailbox (main memory, a half-word per object) to 0. Clobbers r2, r3.",
    );
    t.label("clear_mailbox")
        .li(R2, MAILBOX)
        .li(R3, NOBJ)
        .beqz(R3, "clear_mailbox_done");
    t.label("clear_mailbox_loop")
        .sh(R0, deref(R2))
        .addi(R2, R2, 2)
        .addi(R3, R3, -1)
        .bnez(R3, "clear_mailbox_loop");
    t.label("clear_mailbox_done").ret();
}

/// `test_objects` of a streamed leaf.
fn test_objects(t: &mut Code, lay: &FbImage) {
    t.doc(
        "test_objects: the leaf r5's objects not yet tested in this pass, type by type, from its\n\
         block in SBANK (moved there by DMA unless it is the last one loaded, CUR_BLK).\n\
         Out: r4 = the block's bounds in the FB (0: nothing tested). Clobbers r1..r3, r6..r9, r13.",
    );
    t.label("test_objects")
        .lw(R9, at(SN_OBJECTS, R5))
        .lw(R6, at(SN_LIST, R5))
        .lw(R13, at(PASS, R0));
    t.label("to_scan")
        .lw(R2, deref(R6))
        .addi(R6, R6, 4)
        .lhu(R1, deref(R2))
        .bne(R1, R13, "to_need")
        .c("one not tested yet")
        .addi(R9, R9, -1)
        .bnez(R9, "to_scan")
        .li(R4, 0)
        .ret();
    t.label("to_need")
        .li(R4, SBANK)
        .lw(R1, at(SN_BLOCK, R5))
        .lw(R3, at(SN_BLOCK_WORDS, R5))
        .lw(R2, at(CUR_BLK, R0))
        .beq(R1, R2, "to_have")
        .rcany(R2)
        .c("the array done with the bank")
        .li(R2, SBANK)
        .ldfb(R1, R2, R3)
        .dwait()
        .sw(R1, at(CUR_BLK, R0));
    t.label("to_have")
        .lw(R6, at(SN_LIST, R5))
        .lw(R13, at(PASS, R0))
        .li(R7, "SBANK + BLOCK_HEAD")
        .c("r7: the first record");
    for ti in &lay.types {
        let n = format!("to_{}", ti.ty.name());
        let up = ti.ty.name().to_uppercase();
        t.lw(R9, at(format!("SN_COUNT_{up}"), R5))
            .beqz(R9, format!("{n}_end"));
        t.label(format!("{n}_obj"))
            .lw(R2, deref(R6))
            .addi(R6, R6, 4)
            .lhu(R1, deref(R2))
            .beq(R1, R13, format!("{n}_next"))
            .c("tested in this pass")
            .sh(R13, deref(R2))
            .lw(R1, at(TESTS, R0))
            .addi(R1, R1, 1)
            .sw(R1, at(TESTS, R0));
        ti.ty.broadcast(t, &n, &lay.fit, ti.caps);
        t.label(format!("{n}_next"))
            .addi(R7, R7, format!("{up}_WORDS"))
            .addi(R9, R9, -1)
            .bnez(R9, format!("{n}_obj"));
        t.label(format!("{n}_end"));
    }
    t.ret();
}
