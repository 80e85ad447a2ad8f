//! A leaf of the packet traversal: its objects by type, each broadcast
//! unless every awake ray has tested it (its mailbox); a streamed leaf's
//! records moved in pieces through the leaf cache.

use super::Fields;
use crate::tracer::data::{
    LEAF_FIRST, LEAF_LOAD, LEAF_MISS, LEAF_TAGS, MAILBOX, MASK_HI, PREV_GEN, SBANK, TILE_GEN,
};
use crate::tracer::emit::{
    at, deref, Code, R0, R1, R10, R11, R12, R13, R15, R2, R3, R4, R5, R6, R7, R8, R9,
};
use crate::tracer::layout::packet_nodes::fields::{
    LE_MAILBOX, LE_RECORD, LE_WORDS, MB_PASS, MB_RAYS, MB_SHIFT, PL_LISTS, PS_BLOCK,
    PS_BLOCK_WORDS, PS_FB, PS_LIST, PS_NEXT, PS_OBJECTS,
};
use crate::tracer::layout::packet_nodes::{LEAF_AWAKE, LEAF_EMPTY, LEAF_LATE};
use crate::tracer::layout::{FbImage, TypeInfo};
use crate::tracer::primitives::{
    kaddr, run_first_part, run_rest, run_with_cut_contexts, stream_field,
};

/// The mailbox check of the object whose mailbox address is in r8: on to
/// `{n}_next` when every awake ray (r4, r10) has tested it in this pass
/// (r11), else the mailbox is updated and the object goes to `{n}_go`.
fn mailbox_check(t: &mut Code, n: &str) {
    t.m("MAILBOX_CHECK", n);
}

/// Streamed leaf: once the array is done with the other bank (the tests
/// of the piece before the current one), the DMA of the next piece (r1)
/// into it.
fn next_piece_dma(t: &mut Code, one_slot: bool, why: &str) {
    if one_slot {
        // The cache's one slot is the further pieces' buffer.
        t.sw(R0, at(LEAF_TAGS, R0))
            .c("the cache's slot overwritten");
    }
    t.rcany(R2)
        .c("the array done with the other bank")
        .lw(R2, at(PS_BLOCK, R1))
        .lw(R3, at(PS_BLOCK_WORDS, R1))
        .lw(R8, at(PS_FB, R1))
        .ldfb(R2, R8, R3)
        .c(why);
}

/// The leaf (r5): every object not yet tested by every awake ray in this
/// pass, by type.
pub(super) fn leaf(t: &mut Code, lay: &FbImage, f: &Fields) {
    t.comment("the leaf r5: an object in more than one leaf has a mailbox (the pass that last")
        .comment(
            "tested it and which rays have not); it is broadcast unless every awake ray has tested it",
        );
    if f.streamed {
        streamed_leaf(t, lay);
    } else {
        resident_leaf(t, lay);
    }
}

/// r4, r10: the sleeping rays (for the mailboxes).
fn awake_rays(t: &mut Code) {
    t.rcsl(R4).rcsh(R10).c("r4, r10: the sleeping rays");
}

/// A streamed leaf, its block in pieces.
fn streamed_leaf(t: &mut Code, lay: &FbImage) {
    // A leaf's block comes in pieces, alternately into FB bank 1 and
    // the top of bank 0 (`PS_FB`). The first piece's DMA starts at
    // once: the array is idle (a node decision or a pop came before)
    // and the awake rays' read, the mailbox scan and the loads the
    // tests start from run while it moves. Each further piece's
    // DMA starts before the tests of the piece before it are issued,
    // once the array is done with the other bank (the tests of the
    // piece before that), so that it moves while those tests run. A
    // piece is waited for (`dwait`) before its tests; one whose
    // objects every awake ray has tested is left as it moves, unless
    // it goes to bank 0, which the node kernels read (the array reads
    // bank 1 only in a leaf's tests, after that leaf's `dwait`).
    let one_slot = lay
        .stream
        .as_ref()
        .is_some_and(|st| st.slots_at == crate::tracer::layout::STREAM_BANK);
    // Leaves whose first piece is one large record of an object in
    // several leaves (LEAF_LATE) move it only once the mailbox scan
    // finds it untested by some awake ray: r11 says the move is still
    // to come.
    let late = lay.stream.as_ref().is_some_and(|st| st.late_leaves > 0);
    first_piece(t, late);
    let scan = piece_scan(one_slot, late);
    t.comment("while the piece still moves: what its tests start from");
    let count_field = |ti: &TypeInfo| format!("PS_COUNT_{}", ti.ty.name().to_uppercase());
    t.label("leaf_go");
    if late {
        t.bnez(R11, "leaf_late").c("a large first piece to move");
        t.label("leaf_go_moving");
    }
    t.lw(R1, at(PS_NEXT, R5)).lw(R6, at(PS_LIST, R5));
    if let Some(ti) = lay.types.first() {
        t.lw(R9, at(count_field(ti), R5));
    }
    t.label(LEAF_LOAD)
        .dwait()
        .c("the piece is in the FB")
        .beqz(R1, "leaf_tests");
    next_piece_dma(
        t,
        one_slot,
        "the next piece moves while this one's tests run",
    );
    t.label("leaf_tests");
    for (i, ti) in lay.types.iter().enumerate() {
        let n = format!("lo_{}", ti.ty.name());
        let up = ti.ty.name().to_uppercase();
        if i > 0 {
            t.lw(R9, at(count_field(ti), R5));
        }
        t.beqz(R9, format!("{n}_end"));
        let fetch = |t: &mut Code, p: &str| {
            t.lw(R8, deref(R6))
                .addi(R6, R6, 4)
                .beqz(R8, format!("{p}_go"))
                .c("no mailbox");
        };
        let advance = |t: &mut Code| {
            t.addi(R7, R7, format!("{up}_WORDS"));
        };
        type_loop(t, lay, ti, &n, &fetch, &advance);
    }
    t.label("leaf_next_piece")
        .lw(R5, at(PS_NEXT, R5))
        .beqz(R5, "leaf_done")
        .lw(R7, at(PS_FB, R5))
        .c("r7: the piece's first record");
    t.extend(scan);
    if late {
        late_first_piece(t);
    }
}

/// A streamed leaf's first piece: in its slot of the leaf cache, or its
/// DMA started (`late`: leaves whose first piece waits for the scan).
fn first_piece(t: &mut Code, late: bool) {
    t.label("leaf")
        .andi(R1, R6, LEAF_EMPTY)
        .bnez(R1, "leaf_done")
        .c("an empty leaf")
        .andi(R12, R6, LEAF_AWAKE)
        .c("r12 = 0: no mailbox to check");
    if late {
        t.andi(R11, R6, LEAF_LATE)
            .c("r11: a large first piece, moved only if one of its objects is to be tested");
    }
    let hit = if late { "leaf_hit" } else { "leaf_cached" };
    t.comment("the first piece: in its slot of the leaf cache since this tile or the one before")
        .comment("moved or used it there, or its DMA starts");
    t.label(LEAF_FIRST)
        .lw(R1, at(PS_BLOCK, R5))
        .lw(R7, at(PS_FB, R5))
        .c("r7: the piece's first record, through the scan")
        .add(R6, R7, R7)
        .lw(R3, at(format!("{LEAF_TAGS} - 2*SBANK + 4"), R6))
        .lw(R2, at(TILE_GEN, R0))
        .beq(R3, R2, "leaf_this_tile")
        .c("moved or used in this tile")
        .lw(R8, at(PREV_GEN, R0))
        .bne(R3, R8, LEAF_MISS)
        .c("in neither this tile nor the one before (checked first: an older tag never costs more)")
        .lw(R3, at(format!("{LEAF_TAGS} - 2*SBANK"), R6))
        .bne(R1, R3, LEAF_MISS)
        .sw(R2, at(format!("{LEAF_TAGS} - 2*SBANK + 4"), R6))
        .c("a hit on the tile before's block: this tile's now")
        .j(hit);
    t.label("leaf_this_tile")
        .lw(R3, at(format!("{LEAF_TAGS} - 2*SBANK"), R6))
        .beq(R1, R3, hit)
        .c("the slot holds the block: a hit");
    t.label(LEAF_MISS);
    if late {
        t.bnez(R11, "leaf_awake").c("not yet: the scan first");
    }
    t.lw(R3, at(PS_BLOCK_WORDS, R5))
        .ldfb(R1, R7, R3)
        .c("the first piece's DMA starts")
        .sw(R1, at(format!("{LEAF_TAGS} - 2*SBANK"), R6))
        .sw(R2, at(format!("{LEAF_TAGS} - 2*SBANK + 4"), R6))
        .c("r2 = TILE_GEN");
    // A first piece in the cache has no move to hide: its tests start
    // at once, each object's mailbox checked in the type loop (the
    // scan would check the same ones first).
    t.label("leaf_cached")
        .beqz(R12, "leaf_go")
        .c("in its slot: the tests start, no mailbox to check");
    awake_rays(t);
}

/// The further pieces' scan, placed after the type loops: a first piece's
/// way falls into `leaf_go`, a further piece's from `leaf_next_piece` into
/// `leaf_piece`.
fn piece_scan(one_slot: bool, late: bool) -> Code {
    let mut scan = Code::new();
    scan.label("leaf_piece")
        .lw(R6, at(PS_LIST, R5))
        .c("r5: a piece whose DMA has started")
        .lw(R9, at(PS_OBJECTS, R5));
    scan.comment("while the piece moves: is there an object some awake ray has not tested?");
    scan.label("leaf_scan")
        .lw(R8, deref(R6))
        .addi(R6, R6, 4)
        .beqz(R8, "leaf_go")
        .c("no mailbox: to be tested")
        .lw(R1, at(MB_PASS, R8))
        .bne(R1, R13, "leaf_go")
        .lw(R2, at(MB_RAYS, R8))
        .or(R2, R2, R4)
        .bne(R2, R4, "leaf_go")
        .c("an awake ray has not tested it")
        .lw(R3, at(format!("{MB_RAYS}+{MASK_HI}"), R8))
        .or(R3, R3, R10)
        .bne(R3, R10, "leaf_go")
        .addi(R9, R9, -1)
        .bnez(R9, "leaf_scan");
    scan.comment("every object of the piece tested by every awake ray");
    scan.label("leaf_skip")
        .lw(R1, at(PS_NEXT, R5))
        .bnez(R1, "leaf_skip_next")
        .andi(R1, R7, SBANK)
        .bnez(R1, "leaf_done")
        .c("a piece in bank 1 may move on: the array reads it only after a leaf's dwait")
        .dwait()
        .c("a piece in bank 0: in before a node kernel reads the bank")
        .j("leaf_done");
    scan.label("leaf_skip_next");
    if late {
        scan.li(R11, 0)
            .c("a late first piece skipped: the next moves as usual");
    }
    next_piece_dma(&mut scan, one_slot, "the next piece's DMA starts");
    scan.j("leaf_next_piece");
    if late {
        scan.comment(
            "while a late first piece waits for the scan: the awake rays, for the mailboxes",
        );
        scan.label("leaf_awake")
            .beqz(R12, "leaf_piece")
            .c("no mailbox to check");
        awake_rays(&mut scan);
        scan.j("leaf_piece");
    }
    scan
}

/// A large first piece some awake ray has not tested: its DMA starts, the
/// slot takes it; a hit needs no move.
fn late_first_piece(t: &mut Code) {
    t.comment(
        "a large first piece some awake ray has not tested: its DMA starts, the slot takes it",
    );
    t.label("leaf_late")
        .li(R11, 0)
        .lw(R1, at(PS_BLOCK, R5))
        .lw(R3, at(PS_BLOCK_WORDS, R5))
        .ldfb(R1, R7, R3)
        .add(R6, R7, R7)
        .lw(R2, at(TILE_GEN, R0))
        .sw(R1, at(format!("{LEAF_TAGS} - 2*SBANK"), R6))
        .sw(R2, at(format!("{LEAF_TAGS} - 2*SBANK + 4"), R6))
        .j("leaf_go_moving");
    t.label("leaf_hit")
        .li(R11, 0)
        .c("in its slot: nothing to move")
        .j("leaf_cached");
}

/// A resident leaf: its lists of objects by type in the FB.
fn resident_leaf(t: &mut Code, lay: &FbImage) {
    t.label("leaf")
        .andi(R1, R6, LEAF_EMPTY)
        .bnez(R1, "leaf_done")
        .c("an empty leaf")
        .andi(R1, R6, LEAF_AWAKE)
        .beqz(R1, "leaf_objects")
        .c("no mailbox to check");
    awake_rays(t);
    t.label("leaf_objects")
        .li(R12, MAILBOX)
        .addi(R6, R5, PL_LISTS);
    for ti in &lay.types {
        let n = format!("lo_{}", ti.ty.name());
        t.lfb(R9, deref(R6))
            .addi(R6, R6, 1)
            .beqz(R9, format!("{n}_end"))
            .c(format!("{} in the leaf", ti.ty.plural()));
        let fetch = |t: &mut Code, p: &str| {
            t.lfb(R7, at(LE_RECORD, R6))
                .lfb(R8, at(LE_MAILBOX, R6))
                .addi(R6, R6, LE_WORDS)
                .blt(R8, R0, format!("{p}_go"))
                .c("no mailbox")
                .slli(R8, R8, MB_SHIFT)
                .add(R8, R8, R12)
                .c("r8: its mailbox");
        };
        type_loop(t, lay, ti, &n, &fetch, &|_| {});
    }
}

/// The tests of one type's objects in a leaf (or piece): r9 objects, the
/// list at r6. `fetch` takes the next object (its record in r7, its
/// mailbox in r8, on to `{p}_go` when it has none); `advance` moves r7
/// past an object, tested or not. Each object not yet tested by every
/// awake ray is broadcast. A test that runs in parts
/// ([`ChipType::cut_test`]) is held in r15 while its first part runs, and
/// TinyRISC finds the next object to test meanwhile, so that a test
/// stopped at a cut costs the array only the `rcany` and the next issue.
fn type_loop(
    t: &mut Code,
    lay: &FbImage,
    ti: &TypeInfo,
    n: &str,
    fetch: &dyn Fn(&mut Code, &str),
    advance: &dyn Fn(&mut Code),
) {
    let (ty, caps) = (ti.ty, ti.caps);
    // Each object's mailbox check, then its test issued as written by
    // `test` (given the label of the next object's turn), then the next.
    let one_run_each = |t: &mut Code, test: &dyn Fn(&mut Code, &str)| {
        let next = format!("{n}_next");
        t.label(format!("{n}_obj"));
        fetch(t, n);
        mailbox_check(t, n);
        test(t, &next);
        t.label(&next);
        advance(t);
        t.addi(R9, R9, -1).bnez(R9, format!("{n}_obj"));
        t.label(format!("{n}_end"));
    };
    let Some(cut) = ty.cut_test(&lay.fit).filter(|_| lay.test_cuts) else {
        one_run_each(t, &|t, _| ty.broadcast(t, n, &lay.fit, caps));
        return;
    };
    if lay.cut_runs {
        // One run per test, ended by the broadcast unit at a cut where no
        // awake ray can still hit the object: TinyRISC finds the next
        // object while it runs (the broadcast queue holds its run). Where
        // the test is one run (no further kernels), the kernel's address
        // is set once for the type's objects (r15).
        let field = stream_field(ty, &cut, caps);
        let kernel = cut.then.is_none().then_some(R15);
        if kernel.is_some() {
            t.addi(R15, R0, kaddr(cut.kernel))
                .c("r15: the test's kernel, for every object of the type");
        }
        one_run_each(t, &|t, next| {
            let mut after = Code::new();
            ty.broadcast_after_cut_test(&mut after, n, R7, caps);
            let done = format!("{n}_done");
            let none = if after.is_empty() { next } else { &done };
            run_with_cut_contexts(t, ty, &cut, field, kernel, &lay.fit, R7, n, none);
            if !after.is_empty() {
                t.label(&done).extend(after);
            }
        });
        return;
    }
    // The test's first part, then the next object to test found while it
    // runs; the rest of the test (its parts after the cuts, where some
    // awake ray can still hit it) comes in two copies, one that goes on to
    // the next object's test and one for the leaf's last object of the
    // type, so that a part not run jumps straight on.
    let ahead = format!("{n}_ahead");
    let (test, last, end) = (format!("{n}_test"), format!("{n}_last"), format!("{n}_end"));
    // What runs after the parts whatever F (a cylinder's or cone's caps).
    let after = |at: &str| {
        let mut c = Code::new();
        ty.broadcast_after_cut_test(&mut c, at, R15, caps);
        c
    };
    // The rest, on to `next` where a part does not run.
    let rest = |t: &mut Code, at: &str, next: &str| {
        let after = after(at);
        let done = format!("{at}_done");
        let none = if after.is_empty() { next } else { &done };
        run_rest(t, ty, &cut, &lay.fit, R15, at, none);
        if !after.is_empty() {
            t.label(&done).extend(after);
        }
    };
    t.label(format!("{n}_obj"));
    fetch(t, n);
    mailbox_check(t, n);
    t.label(&test);
    run_first_part(t, &cut, R7);
    t.mv(R15, R7)
        .c("r15: the object under test")
        .comment("while its first part runs: the next object to test (r9 = 0: none)");
    advance(t);
    t.addi(R9, R9, -1).beqz(R9, &last);
    t.label(format!("{ahead}_obj"));
    fetch(t, &ahead);
    mailbox_check(t, &ahead);
    t.label(format!("{n}_parts"));
    rest(t, n, &test);
    t.j(&test);
    t.label(format!("{ahead}_next"));
    advance(t);
    t.addi(R9, R9, -1).bnez(R9, format!("{ahead}_obj"));
    t.comment("the last object's rest");
    t.label(&last);
    rest(t, &last, &end);
    t.j(&end);
    t.label(format!("{n}_next"));
    advance(t);
    t.addi(R9, R9, -1).bnez(R9, format!("{n}_obj"));
    t.label(&end);
}
