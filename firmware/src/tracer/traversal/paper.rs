//! The paper's traversal of a resident scene (section VI; Fig. 6's object
//! loop with the paper's mailboxes): TinyRISC walks the BSP depth first,
//! steered by the RCs' status at each node.
//!
//! ```text
//! trace:                               ; one ray pass
//!   PASS += 1 (the mailboxes cleared when it wraps)
//!   NEG[axis] = the rays going down along each axis
//!   node = ROOT
//!   loop:
//!     if no ray awake: return
//!     if node is a leaf:
//!       test_objects(node)             ; every object not tested in this pass
//!       closest hit: the rays whose hit lies in the leaf's cell sleep
//!       any hit: the rays with a hit sleep
//!       node = pop() or return
//!     else classify the awake rays' segments against the split plane:
//!       all below: node = below; all above: node = above
//!       both, every ray crossing the same way: push far, node = near
//!       otherwise (incoherent): test_objects(node); node = pop() or return
//! ```
//!
//! The nodes (FB, [`super::super::NodeLayout`]): Fig. 5's, a head
//! (`N_FLAGS`, `N_SPLIT`, `N_LEFT`, `N_RIGHT`, `N_BOUNDS`) and per type a
//! membership bit vector over all objects of that type (`N_BV_type`); or
//! compact ones, a head (`NC_INNER_LISTS` or `NC_LEAF_LISTS` words) and
//! per type a count and the slot indices of the node's objects.
//!
//! TinyRISC registers: r5 the node, r11, r12 the awake mask, r14 the node
//! stack pointer (`NSTACK`), r1..r4, r6..r10, r13 temporaries.

use super::super::data::{
    AWAKE, MAILBOX, MASK_HI, MODE, NEG, NEG_X, NEG_Y, NEG_Z, NOBJ, NSTACK, PASS, PASSES, PASS_WRAP,
    ROOT, SAVE_LR, TESTS,
};
use super::super::emit::{
    at, deref, Code, K, R0, R1, R10, R11, R12, R13, R14, R15, R2, R3, R4, R5, R6, R7, R8, R9,
};
use super::super::layout::paper_nodes::fields::{
    NC_INNER_LISTS, NC_LEAF_BOUNDS, NC_LEAF_LISTS, N_BOUNDS, N_FLAGS, N_LEFT, N_RIGHT, N_SPLIT,
};
use super::super::layout::FbImage;
use super::super::memory_map::ram;
use super::super::primitives::{kaddr, klen};
use super::super::NodeLayout;
use super::read_awake;
use crate::tracer::kernel_names as names;

/// The paper traversal's kernels, in load order (after the signs).
pub fn kernels() -> Vec<(String, K)> {
    let mut v: Vec<(String, K)> = (0..3u8)
        .map(|a| (names::classify(a), classify(a)))
        .collect();
    v.push((names::CLASSIFY_ABOVE.into(), classify_above()));
    v.push((names::LEAF_CLOSEST.into(), leaf_closest(false)));
    v.push((names::LEAF_ANY.into(), leaf_any()));
    v
}

/// BSP node status: does the segment `[o, o + tbest d]` reach below the
/// split plane (F, read by TinyRISC) and above it (r13 threshold, second
/// kernel [`classify_above`]). Stream: the split position.
pub fn classify(axis: u8) -> K {
    let (o, d) = (1 + axis, 4 + axis);
    let mut k = K::new();
    k.doc(&format!(
        "{}: the segment [o, o + tbest d] against a split plane across {} (stream: its\n\
         position s). Out: F = the segment reaches below s + 1; r10 = its far end, r13 = s - 1\n\
         (for k_classify_above).",
        names::classify(axis),
        ["x", "y", "z"][axis as usize]
    ));
    k.c(format!("ldacc r{o}, <<Q14"))
        .c(format!("mac r8, r7, r{d}, >>Q14"))
        .note("o + tbest d")
        .c(format!("min r9, r{o}, r8"))
        .c(format!("max r10, r{o}, r8"))
        .c("mov r11, fb0")
        .c("add r12, r11, #1")
        .c("sub r13, r11, #1")
        .c("cmp.le r9, r12");
    k
}

/// After [`classify`]: F = the segment reaches above the plane.
pub fn classify_above() -> K {
    let mut k = K::new();
    k.doc("k_classify_above: after k_clsN, F = the segment reaches above the plane.");
    k.c("cmp.ge r10, r13");
    k
}

/// At a leaf, closest-hit pass: RCs whose hit lies inside the leaf's cell
/// (bounds streamed, widened by 2 LSB) sleep. `ordered` (the streamed
/// traversal): only rays not inside an unordered subtree visited against
/// their direction (`UNORD` = 0).
pub fn leaf_closest(ordered: bool) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{}: after a leaf's objects, closest-hit pass: the rays whose hit lies in the leaf's cell\n\
         (stream: min.xyz, max.xyz) are done and sleep{}.",
        if ordered { names::LEAF_CLOSEST_ORDERED } else { names::LEAF_CLOSEST },
        if ordered {
            ", unless inside an unordered subtree (UNORD > 0)"
        } else {
            ""
        }
    ));
    if ordered {
        k.c(format!("ld r12, [r0 + #{}]", ram::UNORD));
    }
    k.c(format!("ld r8, [r0 + #{}]", ram::PASS_T0))
        .c("cmp.lt r7, r8")
        .note("F: a hit in this pass");
    if ordered {
        k.c("(f) cmp.eq r12, #0");
    }
    for (i, (o, d)) in [(1, 4), (2, 5), (3, 6)].into_iter().enumerate() {
        k.c(format!("ldacc r{o}, <<Q14"))
            .c(format!("mac r{}, r7, r{d}, >>Q14", 9 + i));
    }
    k.note("the hit point");
    for x in [9, 10, 11] {
        k.c(format!("(f) cmp.le fb0, r{x}"));
    }
    for x in [9, 10, 11] {
        k.c(format!("(f) cmp.ge fb0, r{x}"));
    }
    k.note("F: inside the cell").c("(f) sleep");
    k
}

/// At a leaf, any-hit (shadow) pass: RCs that found any hit sleep.
pub fn leaf_any() -> K {
    let mut k = K::new();
    k.doc(
        "k_leaf_any: after a leaf's objects, any-hit pass: the rays with a hit are done and sleep.",
    );
    k.c(format!("ld r8, [r0 + #{}]", ram::PASS_T0))
        .c("cmp.lt r7, r8")
        .c("(f) sleep");
    k
}

/// The start of every paper `trace`: the pass's number and the signs.
pub fn pass_start(t: &mut Code) {
    t.label("trace")
        .sw(R15, at(SAVE_LR, R0))
        .lw(R1, at(PASSES, R0))
        .addi(R1, R1, 1)
        .sw(R1, at(PASSES, R0))
        .c("ray passes, for the statistics")
        .lw(R1, at(PASS, R0))
        .addi(R1, R1, 1)
        .li(R2, PASS_WRAP)
        .blt(R1, R2, "trace_numbered")
        .jal("clear_mailbox")
        .c("the mailboxes hold 16-bit pass numbers")
        .li(R1, 1);
    t.label("trace_numbered").sw(R1, at(PASS, R0));
    for (a, name) in [NEG_X, NEG_Y, NEG_Z].into_iter().enumerate() {
        t.m("BCAST", names::sign(a as u8))
            .rcfl(R2)
            .rcfh(R3)
            .sw(R2, at(name, R0))
            .sw(R3, at(format!("{name}+MASK_HI"), R0))
            .c("the rays going down along this axis");
    }
}

/// The paper's `trace` for a resident scene, its `test_objects` (Fig. 6)
/// and helpers.
pub fn trace(t: &mut Code, lay: &FbImage) {
    let compact = lay.node_layout == NodeLayout::Compact;
    t.doc(&format!(
        "trace: one ray pass, the paper's traversal. In: the rays in r1..r7 of every RC, MODE\n\
         (0: closest hit, 1: any hit). Out: the hits in HIT_*, r7. Clobbers r1..r14.\n\
         Nodes: {}.",
        if compact {
            "compact (head, per type a count and slot indices)"
        } else {
            "Fig. 5 (head, per type a membership bit vector)"
        }
    ));
    pass_start(t);
    t.jal("read_awake").li(R14, NSTACK).li(R5, ROOT);
    t.label("visit_node")
        .lw(R11, at(AWAKE, R0))
        .lw(R12, at(format!("{AWAKE}+{MASK_HI}"), R0))
        .or(R1, R11, R12)
        .beqz(R1, "trace_done")
        .c("no ray awake")
        .lfb(R6, at(N_FLAGS, R5))
        .blt(R6, R0, "leaf")
        .andi(R7, R6, 3)
        .c("the split's axis")
        .li(R1, kaddr(&names::classify(0)))
        .li(R2, kaddr(&names::classify(1)))
        .beqz(R7, "classify")
        .li(R1, kaddr(&names::classify(1)))
        .li(R2, kaddr(&names::classify(2)))
        .slti(R3, R7, 2)
        .bnez(R3, "classify")
        .li(R1, kaddr(&names::classify(2)));
    t.label("classify")
        .addi(R2, R5, N_SPLIT)
        .sbcb(R1, R2, klen(&names::classify(0)))
        .c("the segments against the plane")
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
        .lfb(R5, at(N_LEFT, R5))
        .c("all below")
        .j("visit_node");
    t.label("some_above")
        .or(R9, R1, R2)
        .bnez(R9, "both_sides")
        .lfb(R5, at(N_RIGHT, R5))
        .c("all above")
        .j("visit_node");
    both_sides(t);
    t.label("incoherent");
    if compact {
        t.addi(R6, R5, NC_INNER_LISTS);
    }
    t.jal("test_objects")
        .c("every object under the node")
        .j("pop_node");
    t.label("leaf");
    if compact {
        t.addi(R6, R5, NC_LEAF_LISTS);
    }
    t.jal("test_objects")
        .lw(R1, at(MODE, R0))
        .bnez(R1, "leaf_any_hit")
        .m(
            "BCAST_REC",
            format!(
                "{}, r5, {}",
                names::LEAF_CLOSEST,
                if compact { NC_LEAF_BOUNDS } else { N_BOUNDS }
            ),
        )
        .c("the rays with a hit in the cell sleep")
        .j("leaf_done");
    t.label("leaf_any_hit")
        .m("BCAST", names::LEAF_ANY)
        .c("the rays with a hit sleep");
    t.label("leaf_done").jal("read_awake");
    t.label("pop_node")
        .li(R9, NSTACK)
        .beq(R14, R9, "trace_done")
        .addi(R14, R14, -4)
        .lw(R5, deref(R14))
        .j("visit_node");
    t.label("trace_done").lw(R15, at(SAVE_LR, R0)).ret();
    read_awake(t);
    clear_mailbox(t);
    test_objects(t, lay, compact);
}

/// `both_sides`: rays reach both children: every ray crossing the plane
/// the same way, the near child first (the far one pushed); otherwise
/// `incoherent`.
fn both_sides(t: &mut Code) {
    t.label("both_sides")
        .bne(R1, R3, "incoherent")
        .bne(R2, R4, "incoherent")
        .c("every ray crosses the plane:")
        .slli(R9, R7, 3)
        .lw(R10, at(NEG, R9))
        .lw(R13, at(format!("{NEG}+{MASK_HI}"), R9))
        .and(R10, R10, R11)
        .and(R13, R13, R12)
        .or(R9, R10, R13)
        .beqz(R9, "positive_first")
        .c("all in the same direction?")
        .bne(R10, R11, "incoherent")
        .bne(R13, R12, "incoherent")
        .lfb(R9, at(N_LEFT, R5))
        .sw(R9, deref(R14))
        .addi(R14, R14, 4)
        .c("push below")
        .lfb(R5, at(N_RIGHT, R5))
        .c("visit above first")
        .j("visit_node");
    t.label("positive_first")
        .lfb(R9, at(N_RIGHT, R5))
        .sw(R9, deref(R14))
        .addi(R14, R14, 4)
        .c("push above")
        .lfb(R5, at(N_LEFT, R5))
        .c("visit below first")
        .j("visit_node");
}

/// `clear_mailbox`: every object's mailbox (FB) to 0.
fn clear_mailbox(t: &mut Code) {
    t.doc("clear_mailbox: every mailbox (FB, one word per object) to 0. Clobbers r2, r3.");
    t.label("clear_mailbox")
        .li(R2, MAILBOX)
        .li(R3, NOBJ)
        .beqz(R3, "clear_mailbox_done");
    t.label("clear_mailbox_loop")
        .sfb(R0, deref(R2))
        .addi(R2, R2, 1)
        .addi(R3, R3, -1)
        .bnez(R3, "clear_mailbox_loop");
    t.label("clear_mailbox_done").ret();
}

/// `test_objects`: Fig. 6, per type present.
fn test_objects(t: &mut Code, lay: &FbImage, compact: bool) {
    t.doc(&format!(
        "test_objects: every object of the node (r5{}) not yet tested in this pass (its mailbox\n\
         holds PASS) is broadcast with its type's kernels, type by type (object test reordering).\n\
         Clobbers r1..r4, r6..r10, r12, r13; counts TESTS.",
        if compact { "; r6 = its lists" } else { "" }
    ));
    t.label("test_objects").lw(R13, at(PASS, R0));
    for ti in &lay.types {
        let n = format!("to_{}", ti.ty.name());
        let up = ti.ty.name().to_uppercase();
        if compact {
            // Per type: the count, then that many slot indices k;
            // mailbox = MB + k, record = first + k size.
            t.comment(format!("{}: a count, then slot indices", ti.ty.plural()))
                .lfb(R9, deref(R6))
                .addi(R6, R6, 1)
                .beqz(R9, format!("{n}_end"))
                .li(R8, format!("MB_{up}"))
                .li(R10, format!("{up}_WORDS"))
                .li(R12, format!("FB_{up}"));
            t.label(format!("{n}_obj"))
                .lfb(R1, deref(R6))
                .addi(R6, R6, 1)
                .add(R2, R8, R1)
                .lfb(R3, deref(R2))
                .beq(R3, R13, format!("{n}_next"))
                .c("tested in this pass")
                .sfb(R13, deref(R2))
                .mul(R7, R1, R10)
                .add(R7, R7, R12)
                .c("r7 = its record");
        } else {
            t.comment(format!(
                "{}: the node's bit vector, 16 objects a word",
                ti.ty.plural()
            ))
            .addi(R6, R5, format!("N_BV_{up}"))
            .li(R7, format!("FB_{up}"))
            .li(R8, format!("MB_{up}"))
            .li(R9, format!("BV_WORDS_{up}"));
            t.label(format!("{n}_word"))
                .lfb(R10, deref(R6))
                .addi(R6, R6, 1)
                .slli(R10, R10, 16)
                .li(R4, 16);
            t.label(format!("{n}_obj"))
                .beqz(R10, format!("{n}_skip"))
                .c("no more in this word")
                .bge(R10, R0, format!("{n}_next"))
                .c("bit clear: not under the node")
                .lfb(R1, deref(R8))
                .beq(R1, R13, format!("{n}_next"))
                .c("tested in this pass")
                .sfb(R13, deref(R8));
        }
        t.lw(R1, at(TESTS, R0))
            .addi(R1, R1, 1)
            .sw(R1, at(TESTS, R0));
        ti.ty.broadcast(t, &n, &lay.fit, ti.caps);
        if compact {
            t.label(format!("{n}_next"))
                .addi(R9, R9, -1)
                .bnez(R9, format!("{n}_obj"));
            t.label(format!("{n}_end"));
            continue;
        }
        t.label(format!("{n}_next"))
            .addi(R7, R7, format!("{up}_WORDS"))
            .addi(R8, R8, 1)
            .slli(R10, R10, 1)
            .addi(R4, R4, -1)
            .bnez(R4, format!("{n}_obj"))
            .j(format!("{n}_end"));
        t.label(format!("{n}_skip"))
            .li(R1, format!("{up}_WORDS"))
            .mul(R1, R1, R4)
            .add(R7, R7, R1)
            .add(R8, R8, R4)
            .c("past the word's other objects");
        t.label(format!("{n}_end"))
            .addi(R9, R9, -1)
            .bnez(R9, format!("{n}_word"));
    }
    t.ret();
}

#[cfg(test)]
mod tests {
    /// The traversal kernels read their streams: a split, a cell's bounds.
    #[test]
    fn node_kernels_read_their_streams() {
        assert_eq!(super::classify(2).fb_reads, 1);
        assert_eq!(super::leaf_closest(false).fb_reads, 6);
        assert_eq!(super::leaf_closest(true).fb_reads, 6);
    }
}
