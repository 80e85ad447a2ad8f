//! Masked packet traversal (`--traversal packet`, the default), resident
//! or streamed: each ray keeps its parametric interval `[tmin, tmax]`
//! inside the cell being visited (r8, r9 of its RC); a child is visited
//! only by the rays whose interval reaches it (the others sleep), near
//! child first, the far child pushed with every ray's interval for it; a
//! ray whose hit lies before a popped cell drops out.
//!
//! ```text
//! trace:
//!   PASS += 1; per axis k_sign: which rays go down (F masks read)
//!   k_pass_start: every awake ray alive, its interval [0, tbest]
//!     clipped to the root cell, 1/d per axis; while it runs, per axis:
//!     the child order (the awake rays' near child where they agree; the
//!     rule of `super::child_order` where they do not), decided again if
//!     the start put a ray to sleep
//!     (NK: the node kernel, NF/NS: the first and second child's field)
//!   node = ROOT
//!   loop:
//!     if node is a leaf:
//!       every object not yet tested by every awake ray (its mailbox) is
//!       broadcast; any-hit pass: the rays with a hit are done
//!     else:
//!       node kernel: each awake ray splits its interval at the plane;
//!       rcst says which children some awake ray reaches:
//!         none: pop; the second only: its intervals, node = second
//!         some the first: push second, the others sleep, node = first
//!         all the first: push second if some ray reaches it, node = first
//!       (the next node's kernel is issued before its children are read)
//!     pop: node = the stack's top; every RC wakes, takes its interval for
//!       it; the rays not alive, or whose interval is empty or beyond
//!       their hit, sleep again; a node no ray needs is popped too
//! ```
//!
//! The distance to a split plane at `x` along axis `a` is `t(x) = (x -
//! o_a) / d_a`, from the reciprocal of the direction computed once per
//! pass ([`super::packet_kernels::pass_start`]): `|D|` (Q1.14, clamped to [1, 2^14 - 1]) is
//! normalised by `z = clz(|D|) - 1` into [2^14, 2^15), `R = ±2^29 / (|D|
//! << z)` (table and Newton-Raphson steps, the sign of `d_a`), and `t(x) =
//! ((x - o_a) << (z - 1)) * R >> 14`. The shift saturates exactly when `t`
//! does (`|R| >= 2^14`), so a saturated `t` lies beyond every segment.
//! Every plane is widened by `P_TOL` LSB on both sides: a ray meets the
//! cell below for `t` up to `t(s) + dt` and the cell above from `t(s) -
//! dt` on, `dt = P_TOL / |d_a|`, more than the error of `t` (2.5 LSB at the
//! end of the range), so an interval never misses a cell its ray meets.
//! The far child's intervals are pushed into RC RAM, one slot per BSP
//! depth (`P_SLOT`), only when TinyRISC pushes the child; a pop reads and
//! clears the slot in every RC.
//!
//! Nodes (resident, FB): inner `PN_FLAGS (the axis), PN_PARENT_SLOT, PN_SPLIT,
//! PN_SLOT, PN_LEFT, PN_RIGHT`; leaf `PL_FLAGS, PL_PARENT_SLOT,
//! PL_OBJECTS, PL_SHARED`, then per type present a count and per object
//! its record's FB address and its mailbox index (-1: in one leaf only, no
//! mailbox). Streamed (main memory, `NODE_BYTES`): the same with byte
//! addresses (`PS_*`); a leaf's records are moved by DMA in pieces
//! (chained by `PS_NEXT`, [`super::super::LeafPieces`]) that alternate
//! between FB bank 1 and the top of bank 0 (`PS_FB`), each piece after the
//! first moving while the piece before it is tested.
//! Mailboxes (main memory, `MB_BYTES` each): the pass that last tested
//! the object (`MB_PASS`, the pass's stamp) and the rays that have not
//! tested it in that pass (`MB_RAYS`: the rays asleep at each of its
//! tests, a mask in the sense of the sleep mask `rcsl`/`rcsh` reads, so
//! that no mask is inverted).
//!
//! TinyRISC registers: r5 the node, r6 its flags (the split axis times 4,
//! negative for a leaf), r7 `SPLIT` (streamed: the FB word a node
//! kernel's split is written to), r13 the pass's stamp
//! (`PASS | MODE << 31`: negative for any hit), r14 the
//! node stack's depth in bytes (0: empty; its entries at `NSTACK`).
//! The traversal keeps no statistics of its own: the simulator counts the
//! object tests (the runs of the test kernels) and the leaf cache's hits
//! and misses (the issues at `leaf_first` and `leaf_miss`).

mod leaf;

use super::super::emit::{
    at, deref, Code, Name, Reg, R0, R1, R10, R11, R13, R14, R15, R2, R3, R4, R5, R6, R7, R8, R9,
};
use super::super::layout::FbImage;
use super::super::primitives::{kaddr, klen};
use leaf::leaf;

use super::child_order::{self, ChildOrder};
use crate::tracer::kernel_names as names;

use super::super::data::{
    LEAF_FIRST, MASK_HI, MODE, NF, NK, NS, NSTACK, PASS, PASSES, ROOT, SAVE_LR, SPLIT,
};
use super::super::layout::packet_nodes::fields::{
    MB_PASS, MB_RAYS, PN_FLAGS, PN_LEFT, PN_PARENT_SLOT, PN_RIGHT, PN_SLOT, PN_SPLIT, PS_FLAGS,
    PS_LEFT, PS_RIGHT, PS_SPLIT,
};
pub use super::super::layout::packet_nodes::P_TOL;
pub use super::packet_kernels::{init_ram, kernels};

/// The packet traversal's code by the items of its cost model
/// ([`crate::tracer::layout::packet_nodes::chip_costs`]), for `render
/// --profile`'s check of the model against a frame: a node visit (the
/// TinyRISC labels and kernels of a decision, a push and a pop), a leaf's
/// loop (the labels of the leaf loop, streamed) and TinyRISC's share of
/// an object test (the labels of the per-type loops).
pub mod cost_items {
    /// TinyRISC labels of a node visit.
    pub const NODE_LABELS: &[&str] = &[
        "inner_node",
        "all_first",
        "visit_first",
        "some_first",
        "pop_node",
    ];
    /// Kernels of a node visit besides the node kernels (`k_node_*`).
    pub const NODE_KERNELS: &[&str] = &[
        "k_pop_node",
        "k_push_second",
        "k_take_second",
        "k_second_too",
        "k_first_or_sleep",
    ];
    /// The prefix of the node kernels, one run per node visit.
    pub const NODE_KERNEL_PREFIX: &str = "k_node_";
    /// A TinyRISC label of the leaf loop (the DMA waits in it aside),
    /// with the waits for a polygon's sub-edges (`lo_*_fan_wait`, DMA
    /// waits the profile's DMA cause counts, set aside with the others).
    pub fn is_leaf_label(l: &str) -> bool {
        l.starts_with("leaf")
            || (l.starts_with("lo_") && (l.ends_with("_end") || l.ends_with("_fan_wait")))
    }
    /// A TinyRISC label of an object test (its type's loop).
    pub fn is_object_label(l: &str) -> bool {
        l.starts_with("lo_") && !is_leaf_label(l)
    }
}

/// The node fields the traversal reads, resident (FB words) or streamed
/// (bytes of a node record in main memory).
struct Fields {
    streamed: bool,
}

impl Fields {
    fn n(&self, resident: Name, streamed: Name) -> Name {
        if self.streamed {
            streamed
        } else {
            resident
        }
    }
    /// Load a node's word: `lfb` (resident) or `lw` (streamed).
    fn load(&self, t: &mut Code, rt: Reg, m: super::super::emit::Mem) {
        if self.streamed {
            t.lw(rt, m);
        } else {
            t.lfb(rt, m);
        }
    }
}

/// The packet `trace`, its leaf loop and `majority`; `order`: the child
/// order of mixed packets.
pub fn trace(t: &mut Code, lay: &FbImage, order: ChildOrder) {
    let streamed = lay.stream.is_some();
    let f = Fields { streamed };
    let flags = f.n(PN_FLAGS, PS_FLAGS);
    t.doc(&format!(
        "trace: one ray pass, the packet traversal of a {} scene. In: the rays in r1..r7 of\n\
         every RC, MODE (0: closest hit, 1: any hit). Out: the hits in HIT_*, r7.\n\
         Clobbers r1..r15 (r15 kept in SAVE_LR).",
        if streamed { "streamed" } else { "resident" }
    ));
    pass_stamp(t);
    if lay.root_leaf {
        root_leaf(t, &f);
    }
    child_order::pass_start(t, order, f.n(PN_LEFT, PS_LEFT), f.n(PN_RIGHT, PS_RIGHT));
    t.li(R14, 0).c("the node stack: empty").li(R5, ROOT);
    if streamed {
        t.li(R7, SPLIT).c("r7 = SPLIT throughout the walk");
    }
    f.load(t, R6, at(flags, R5));
    dispatch_full(t, &f);
    // Placed before `inner_node`, which the first child's dispatch falls
    // into: the commonest way from one node visit to the next takes no
    // jump.
    t.label("all_first")
        .m("BCAST", names::SECOND_TOO)
        .rcany(R4)
        .beqz(R4, "visit_first")
        .c("no ray reaches the second");
    push_second(t, &f);
    t.label("visit_first");
    dispatch_first(t, &f, false);
    t.comment("r5 = a node whose kernel runs: read its children, issue the first's kernel");
    t.label("inner_node").lw(R8, at(NF, R6)).add(R8, R8, R5);
    f.load(t, R9, deref(R8));
    t.c("r9 = the first child");
    t.lw(R10, at(NS, R6)).add(R10, R10, R5);
    f.load(t, R10, deref(R10));
    t.c("r10 = the second child");
    f.load(t, R6, at(flags, R9));
    t.andi(R3, R6, 12)
        .lw(R11, at(NK, R3))
        .c("r11 = its kernel, if inner");
    if streamed {
        t.lw(R15, at(PS_SPLIT, R9)).c("r15 = its split");
    }
    // The cases by how often they come (SPD scenes: all about 45%, none
    // 30%, some 25%), the commonest ways the shortest.
    t.rcst(R4)
        .c("the awake rays reaching the first child: none, some, all")
        .beqz(R4, "none_first")
        .addi(R1, R4, -3)
        .beqz(R1, "all_first")
        .addi(R1, R4, -1)
        .bnez(R1, "pop_node")
        .c("no ray awake (rcall without rcany)");
    t.label("some_first");
    push_second(t, &f);
    t.m("BCAST", names::FIRST_OR_SLEEP)
        .c("the rays not reaching the first sleep");
    dispatch_first(t, &f, true);
    t.label("none_first")
        .m("BCAST", names::TAKE_SECOND)
        .c("none: the second child only")
        .mv(R5, R10);
    f.load(t, R6, at(flags, R5));
    dispatch_full(t, &f);
    leaf(t, lay, &f);
    t.label("leaf_done")
        .bge(R13, R0, "pop_node")
        .c("closest hit")
        .m("BCAST", names::DONE_WITH_HIT)
        .c("any hit: the rays with a hit are done");
    pop_node(t, &f);
    t.label("trace_done").lw(R15, at(SAVE_LR, R0)).ret();
    child_order::majority(t);
}

/// `trace`'s start: the pass counted, r13 the pass's stamp.
fn pass_stamp(t: &mut Code) {
    t.label("trace")
        .sw(R15, at(SAVE_LR, R0))
        .lw(R1, at(PASSES, R0))
        .addi(R1, R1, 1)
        .sw(R1, at(PASSES, R0))
        .c("ray passes, for the statistics")
        .lw(R1, at(PASS, R0))
        .addi(R1, R1, 1)
        .sw(R1, at(PASS, R0))
        .lw(R13, at(MODE, R0))
        .slli(R13, R13, 31)
        .or(R13, R13, R1)
        .c("r13: the pass's stamp, PASS | MODE << 31 (negative: any hit)");
}

/// The whole tree one leaf: its objects are tested by the awake rays,
/// nothing to walk. (`k_sign_x` runs only to mark the pass's start for
/// the simulator's count of the rays traced: its RCs are the pass's.)
fn root_leaf(t: &mut Code, f: &Fields) {
    t.comment("the tree is one leaf: its objects, tested by the awake rays")
        .m("BCAST", names::sign(0))
        .li(R14, 0)
        .li(R5, ROOT)
        .rcsl(R4)
        .rcsh(R10)
        .c("r4, r10: the sleeping rays")
        .and(R1, R4, R10)
        .nor(R1, R1, R0)
        .beqz(R1, "trace_done")
        .c("every ray asleep")
        .j(if f.streamed {
            LEAF_FIRST.0
        } else {
            "leaf_objects"
        });
}

/// `pop_node`: the node stack's top, its rays' intervals restored, its
/// kernel issued where some ray needs it (a leaf's objects otherwise).
fn pop_node(t: &mut Code, f: &Fields) {
    let streamed = f.streamed;
    t.label("pop_node")
        .beqz(R14, "trace_done")
        .c("the node stack empty")
        .addi(R14, R14, -4)
        .lw(R5, at(NSTACK, R14))
        .addi(R1, R0, kaddr(names::POP_NODE));
    if streamed {
        t.addi(R2, R14, "SLOTS").c("its slot: the stack entry's");
    } else {
        t.addi(R2, R5, PN_PARENT_SLOT);
    }
    t.sbcb(R1, R2, klen(names::POP_NODE))
        .c("the rays take their intervals for it");
    t.comment("while they do: its kernel and split, if inner");
    f.load(t, R6, at(f.n(PN_FLAGS, PS_FLAGS), R5));
    t.andi(R3, R6, 12).lw(R11, at(NK, R3));
    if streamed {
        t.li(R7, SPLIT).c("the leaf's code may have used r7");
    }
    let split = split_word(t, f, None);
    t.rcany(R4)
        .beqz(R4, "pop_node")
        .c("no ray needs it")
        .blt(R6, R0, "leaf")
        .sbcb(R11, split, klen(&names::node(0, false)))
        .c("its node kernel")
        .j("inner_node");
}

/// r5 = a node, r6 = its flags: a leaf, or its kernel issued (the split
/// streamed), then `inner_node`.
fn dispatch_full(t: &mut Code, f: &Fields) {
    t.blt(R6, R0, "leaf").lw(R1, at(NK, R6));
    let split = split_word(t, f, None);
    t.sbcb(R1, split, klen(&names::node(0, false)))
        .c("its node kernel")
        .j("inner_node");
}

/// The FB address of the split of the node r5 for its kernel: streamed,
/// `SPLIT` (in r7 throughout the walk), where the split (`held` in a
/// register, else loaded into r2) is written; resident, the node's own
/// word (into r2).
fn split_word(t: &mut Code, f: &Fields, held: Option<Reg>) -> Reg {
    if f.streamed {
        let split = held.unwrap_or_else(|| {
            t.lw(R2, at(PS_SPLIT, R5));
            R2
        });
        t.sfb(split, at(SPLIT, R0));
        R7
    } else {
        t.addi(R2, R5, PN_SPLIT);
        R2
    }
}

/// Visit the first child (r9, flags r6, kernel r11, axis r3 read by
/// `inner_node`): a leaf, or its kernel issued at once; then `inner_node`
/// (a jump unless it follows).
fn dispatch_first(t: &mut Code, f: &Fields, jump: bool) {
    t.mv(R5, R9).blt(R6, R0, "leaf");
    let split = split_word(t, f, Some(R15));
    t.sbcb(R11, split, klen(&names::node(0, false)))
        .c("the first child's node kernel");
    if jump {
        t.j("inner_node");
    }
}

/// Push the second child (r10) of the node r5 with every awake ray's
/// interval for it (the push kernel streams the slot's RAM address: a
/// streamed node's, its stack entry's in `SLOTS`; a resident node's, its
/// own word).
fn push_second(t: &mut Code, f: &Fields) {
    if f.streamed {
        t.addi(R2, R14, "SLOTS").c("its slot: the stack entry's");
    } else {
        t.addi(R2, R5, PN_SLOT).c("its slot: the node's");
    }
    t.m("BCAST_AT", format!("{}, r2", names::PUSH_SECOND))
        .c("the rays' intervals for the second child")
        .sw(R10, at(NSTACK, R14))
        .addi(R14, R14, 4)
        .c("push it");
}

/// The packet traversal's macro: the mailbox check of a leaf's object.
pub fn macros() -> Code {
    let mut t = Code::new();
    let mut b = Code::new();
    b.lw(R1, at(MB_PASS, R8))
        .line("bne r1, r13, \\p\\()_fresh")
        .c("not tested in this pass yet")
        .lw(R2, at(MB_RAYS, R8))
        .lw(R3, at(format!("{MB_RAYS}+{MASK_HI}"), R8))
        .or(R1, R2, R4)
        .line("bne r1, r4, \\p\\()_upd")
        .c("an awake ray has not tested it")
        .or(R1, R3, R10)
        .line("beq r1, r10, \\p\\()_next")
        .c("every awake ray has tested it");
    b.label("\\p\\()_upd")
        .and(R2, R2, R4)
        .and(R3, R3, R10)
        .sw(R2, at(MB_RAYS, R8))
        .sw(R3, at(format!("{MB_RAYS}+{MASK_HI}"), R8))
        .line("j \\p\\()_go");
    b.label("\\p\\()_fresh")
        .sw(R13, at(MB_PASS, R8))
        .sw(R4, at(MB_RAYS, R8))
        .sw(R10, at(format!("{MB_RAYS}+{MASK_HI}"), R8));
    b.label("\\p\\()_go");
    t.define_macro(
        "MAILBOX_CHECK",
        "p",
        "MAILBOX_CHECK p: the mailbox at r8 of the object at hand. Where every awake ray (the\n\
         sleeping ones in r4, r10) has tested it in this pass (r13), on to `p_next`; else\n\
         the mailbox takes the pass and the rays still to test it, and on to `p_go`.\n\
         Clobbers r1..r3.",
        b,
    );
    t
}
