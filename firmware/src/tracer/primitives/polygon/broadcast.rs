//! TinyRISC's broadcast of a polygon's test: its head, then its edges
//! (plain records) or the bands its rays' points lie in (banded records).

use super::super::super::emit::{Code, Reg, R0, R1, R2, R3, R7};
use super::super::{kaddr, klen, Sides};
use super::{
    head_name, tail_name, Form, ABOVE, BAND_EDGE, BAND_EDGE_WORDS, BELOW, EDGE,
    POLY_BAND_EDGE_WORDS, POLY_BAND_FAN, POLY_BOUNDS, POLY_EDGES, POLY_EDGE_WORDS, POLY_FAN,
    POLY_FANS_AT, POLY_HEAD, POLY_NB, POLY_STARTS, POLY_TAIL,
};

/// Broadcast a polygon's test (record at r7): the head, one edge run per
/// edge, the tail. Labels begin with `at`.
pub fn broadcast(t: &mut Code, at: &str, sides: Sides, form: Form) {
    t.m(
        "BCAST_REC",
        format!("{}, r7, {POLY_HEAD}", head_name(sides)),
    )
    .c("the plane");
    broadcast_edges(t, at, sides, R7, form);
}

/// After the head (record at `rec`): one edge run per edge, the tail;
/// a banded record's sub-edges of the bands that hold a point (clobbers
/// r1..r3; r8, r12, r13 kept in `BAND_SAVE`).
pub fn broadcast_edges(t: &mut Code, at: &str, sides: Sides, rec: Reg, form: Form) {
    if form.banded() {
        broadcast_bands(t, at, sides, rec, form == Form::Apart);
        return;
    }
    t.lfb(R3, super::super::super::emit::at(POLY_EDGES, rec))
        .c("edges")
        .addi(R2, rec, POLY_FAN)
        .li(R1, kaddr(EDGE));
    t.label(format!("{at}_fan"))
        .beqz(R3, format!("{at}_tail"))
        .sbcb(R1, R2, klen(EDGE))
        .c("one edge of the crossing test")
        .addi(R2, R2, POLY_EDGE_WORDS)
        .addi(R3, R3, -1)
        .j(format!("{at}_fan"));
    t.label(format!("{at}_tail"))
        .m("BCAST_AT", format!("{}, r2", tail_name(sides)))
        .c("commit where the parity is odd");
}

/// A banded record's sub-edges (record at `rec`): the lowest band that
/// holds a point of an awake ray with a valid plane hit (r1), by
/// bisection on "some such point lies below `Y_b+1`", the highest (r1
/// again) on "some lies at or above `Y_b`", then the sub-edges between
/// them and the tail. A point outside every band straddles no sub-edge,
/// so whichever bands its search ends at, its parity is even there.
/// `apart`: the sub-edges are moved by DMA from main memory into
/// `FAN_BUF` first.
fn broadcast_bands(t: &mut Code, at: &str, sides: Sides, rec: Reg, apart: bool) {
    use super::super::super::emit::{at as field, R12, R13, R8};
    let save = |k: usize| format!("BAND_SAVE+{}", 4 * k);
    t.sw(R8, field(save(0), R0))
        .sw(R12, field(save(1), R0))
        .sw(R13, field(save(2), R0))
        .c("r8, r12, r13 kept")
        .lfb(R3, field(POLY_NB, rec))
        .addi(R3, R3, -1)
        .li(R1, 0)
        .c("r1, r3: the bands the lowest can be");
    t.label(format!("{at}_blo"))
        .bge(R1, R3, format!("{at}_blo_end"))
        .add(R8, R1, R3)
        .srli(R8, R8, 1)
        .add(R12, rec, R8)
        .addi(R12, R12, format!("{POLY_BOUNDS}+1"))
        .addi(R2, R0, kaddr(BELOW))
        .sbcb(R2, R12, klen(BELOW))
        .c("some point below Y_mid+1?")
        .rcany(R2)
        .beqz(R2, format!("{at}_blo_up"))
        .mv(R3, R8)
        .j(format!("{at}_blo"));
    t.label(format!("{at}_blo_up"))
        .addi(R1, R8, 1)
        .j(format!("{at}_blo"));
    t.label(format!("{at}_blo_end"))
        .add(R12, rec, R1)
        .lfb(R13, field(POLY_STARTS, R12))
        .c("r13: the lowest band's first sub-edge")
        .lfb(R3, field(POLY_NB, rec))
        .addi(R3, R3, -1)
        .c("r1, r3: the bands the highest can be");
    t.label(format!("{at}_bhi"))
        .bge(R1, R3, format!("{at}_bhi_end"))
        .add(R8, R1, R3)
        .addi(R8, R8, 1)
        .srli(R8, R8, 1)
        .add(R12, rec, R8)
        .addi(R12, R12, POLY_BOUNDS)
        .addi(R2, R0, kaddr(ABOVE))
        .sbcb(R2, R12, klen(ABOVE))
        .c("some point at or above Y_mid?")
        .rcany(R2)
        .beqz(R2, format!("{at}_bhi_down"))
        .mv(R1, R8)
        .j(format!("{at}_bhi"));
    t.label(format!("{at}_bhi_down"))
        .addi(R3, R8, -1)
        .j(format!("{at}_bhi"));
    t.label(format!("{at}_bhi_end"))
        .add(R12, rec, R1)
        .lfb(R3, field(format!("{POLY_STARTS}+1"), R12))
        .sub(R3, R3, R13)
        .c("r3: words of the sub-edges to run");
    if apart {
        t.beqz(R3, format!("{at}_tail"))
            .rcany(R2)
            .c("the array done with the bank (no probe runs before a record of one band)")
            .lfb(R2, field(POLY_FANS_AT, rec))
            .slli(R2, R2, "FAN_UNIT_SHIFT")
            .slli(R13, R13, "FB_WORD_SHIFT")
            .add(R2, R2, R13)
            .li(R1, "FANS")
            .add(R2, R2, R1)
            .c("r2: the lowest band's first sub-edge in main memory")
            .li(R1, "FAN_BUF")
            .ldfb(R2, R1, R3)
            .c("the bands' sub-edges into FAN_BUF");
        t.label(format!("{at}_fan_wait"))
            .dwait()
            .mv(R2, R1)
            .addi(R1, R0, kaddr(BAND_EDGE));
    } else {
        t.add(R2, rec, R13)
            .addi(R2, R2, POLY_BAND_FAN)
            .addi(R1, R0, kaddr(BAND_EDGE));
    }
    t.label(format!("{at}_fan"))
        .beqz(R3, format!("{at}_tail"))
        .sbcb(R1, R2, klen(BAND_EDGE))
        .c("one sub-edge of the crossing test")
        .addi(R2, R2, POLY_BAND_EDGE_WORDS)
        .addi(R3, R3, -(BAND_EDGE_WORDS as i64))
        .j(format!("{at}_fan"));
    t.label(format!("{at}_tail"))
        .lfb(R2, field(POLY_TAIL, rec))
        .add(R2, R2, rec)
        .m("BCAST_AT", format!("{}, r2", tail_name(sides)))
        .c("commit where the parity is odd")
        .lw(R8, field(save(0), R0))
        .lw(R12, field(save(1), R0))
        .lw(R13, field(save(2), R0));
}
