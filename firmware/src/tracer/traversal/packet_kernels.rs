//! The packet traversal's RC kernels ([`super::packet`]): a pass's start
//! (each ray's interval in the root cell), an inner node (each ray's
//! interval cut at the split plane, which children it reaches), the
//! stack's push and pop, the leaf's test of which rays are awake.

use super::super::emit::K;
use super::super::math::Approx;
use super::super::memory_map::ram;
use crate::tracer::kernel_names as names;
/// Newton-Raphson steps of the traversal's direction reciprocals: the
/// intervals' widening assumes a relative error under 2^-14, which one
/// step reaches from the 128-entry table (0.4% before the step, 1.5e-5
/// after) and two from any smaller one.
fn p_newton(nr: Approx) -> u32 {
    if nr.table_entries >= 128 {
        1
    } else {
        2
    }
}

/// The packet traversal's kernels, in load order (after the signs).
pub fn kernels(nr: Approx) -> Vec<(String, K)> {
    let mut v = vec![(names::PASS_START.to_string(), pass_start(nr))];
    for a in 0..3u8 {
        v.push((names::node(a, false), node(a, false)));
        v.push((names::node(a, true), node(a, true)));
    }
    v.push((names::SECOND_TOO.into(), second()));
    v.push((names::FIRST_OR_SLEEP.into(), sleep_first()));
    v.push((names::TAKE_SECOND.into(), take()));
    v.push((names::PUSH_SECOND.into(), push()));
    v.push((names::POP_NODE.into(), pop()));
    v.push((names::DONE_WITH_HIT.into(), leaf_any()));
    v
}

/// Appended to the init kernel: no ray alive, every interval slot empty.
pub fn init_ram(k: &mut K) {
    k.c(format!("st r0, [#{}]", ram::P_ALIVE))
        .note("no ray alive")
        .c("movb r8, #-1");
    k.rept(ram::P_SLOTS, "d", |k| {
        k.c(format!("st r8, [#{}+2*d+SLOT_TMAX]", ram::P_SLOT));
    });
}

/// `t(x)` for the operand `x` (a register or `fb0`) into `out`:
/// `out = ((x - o) << zr) * rr >> 14`.
fn distance(k: &mut K, out: u8, x: &str, o: u8, zr: u8, rr: u8) {
    k.c(format!("sub r{out}, {x}, r{o}"))
        .c(format!("asl r{out}, r{out}, r{zr}"))
        .c(format!("mul r{out}, r{out}, r{rr}, >>Q14"));
}

/// Start of a packet pass (stream: the root box widened by `P_TOL`, per
/// axis min then max). Every awake ray takes part (`P_ALIVE` = 1); per
/// axis the direction's reciprocal (`P_Z`, `P_R`) and `dt` (`P_DT`) are
/// computed, and the interval (r8, r9) is `[0, tbest]` clipped to the root
/// box; a ray that misses the box is not alive and sleeps.
pub fn pass_start(nr: Approx) -> K {
    let mut k = K::new();
    k.doc(
        "k_pass_start: a pass starts (stream: the root cell widened by P_TOL, per axis min, max).\n\
         Out: P_ALIVE = 1, per axis P_Z, P_R (1/d = R >> z) and P_DT (P_TOL / |d|); the interval\n\
         (r8, r9) = [0, tbest] clipped to the root cell; the rays that miss it sleep, not alive.",
    );
    k.c("movb r8, #1").c(format!("st r8, [#{}]", ram::P_ALIVE));
    k.c(format!("ld r9, [r0 + #{}]", ram::C_ONE))
        .c("sub r9, r9, #1")
        .c(format!("ld r15, [r0 + #{}]", ram::C_ONE));
    for a in 0..3u32 {
        let d = 4 + a;
        k.comment(&format!("1 / d{}", ["x", "y", "z"][a as usize]));
        k.c(format!("abs r8, r{d}"))
            .c("max r8, r8, #1")
            .c("min r8, r8, r9")
            .c("clz r10, r8")
            .c("sub r10, r10, #1")
            .c("sll r11, r8, r10")
            .note("|d| normalised")
            .c("srl r12, r11, #RCP_SHIFT")
            .c("and r12, r12, #RCP_MASK")
            .c(format!("ld r12, [r12 + #{}]", ram::RCP));
        for _ in 0..p_newton(nr) {
            k.c("mul r14, r11, r12, >>Q15")
                .c("sub r14, r14, r15")
                .c("ldacc r12, <<Q14")
                .c("msu r12, r12, r14, >>Q14");
        }
        k.c("sub r10, r10, #1")
            .c(format!("st r10, [#{}]", ram::P_Z + a))
            .c("movb r13, #P_TOL")
            .c("asl r13, r13, r10")
            .c("mul r13, r13, r12, >>Q14")
            .c(format!("st r13, [#{}]", ram::P_DT + a))
            .c(format!("cmp.lt r{d}, #0"))
            .c("(f) neg r12, r12")
            .c(format!("st r12, [#{}]", ram::P_R + a));
    }
    k.comment("root interval");
    k.c("movb r8, #0").c("mov r9, r7");
    for a in 0..3u32 {
        k.c(format!("ld r12, [r0 + #{}]", ram::P_Z + a))
            .c(format!("ld r13, [r0 + #{}]", ram::P_R + a));
        distance(&mut k, 10, "fb0", 1 + a as u8, 12, 13);
        distance(&mut k, 11, "fb0", 1 + a as u8, 12, 13);
        k.c("min r14, r10, r11")
            .c("max r10, r10, r11")
            .c("max r8, r8, r14")
            .c("min r9, r9, r10");
    }
    k.c("cmp.lt r8, r9")
        .note("F: the ray meets the root cell")
        .c("movb r10, #0")
        .c(format!("(!f) st r10, [#{}]", ram::P_ALIVE))
        .c("(!f) sleep");
    k
}

/// Inner node on `axis` (stream: the split). Each awake ray cuts its
/// interval (r8, r9; `r9 <= tbest`: the pass start and every pop clip it,
/// and no hit is found between two inner nodes) at the plane into the part
/// below and the part above (each reaching `P_TOL` LSB past the plane);
/// `first_above` names the child the packet visits first. The first
/// child's interval becomes the current one (r8, r9), the second's is left
/// in r11, r14 for [`second`], [`push`] and [`take`]; rays that reach
/// neither child sleep; F = reaches the first child.
pub fn node(axis: u8, first_above: bool) -> K {
    let (o, d) = (1 + axis, 4 + axis);
    let a = axis as u32;
    let mut k = K::new();
    k.doc(&format!(
        "{}: an inner node split across {}, the child {} the plane first (stream: the\n\
         split s). Each awake ray's interval (r8, r9) cut at t(s) widened by P_TOL: the first\n\
         child's into r8, r9, the second's into r11, r14; the rays reaching neither sleep.\n\
         Out: F = reaches the first child.",
        names::node(axis, first_above),
        ["x", "y", "z"][axis as usize],
        if first_above { "above" } else { "below" }
    ));
    k.c(format!("ld r12, [r0 + #{}]", ram::P_Z + a))
        .c(format!("ld r13, [r0 + #{}]", ram::P_R + a));
    distance(&mut k, 10, "fb0", o, 12, 13);
    k.note("t(s)");
    k.c(format!("ld r12, [r0 + #{}]", ram::P_DT + a))
        .c("subs r11, r10, r12")
        .c("adds r10, r10, r12")
        .comment("near = [tmin, min(hi, t + dt)], far = [max(tmin, t - dt), hi]")
        .c("min r12, r9, r10")
        .c("max r13, r8, r11")
        .c(if first_above {
            format!("cmp.lt r{d}, #0")
        } else {
            format!("cmp.ge r{d}, #0")
        })
        .c("sel r14, r9, r12")
        .c("sel r9, r12, r9")
        .c("sel r11, r13, r8")
        .c("sel r8, r8, r13")
        .c("cmp.lt r11, r14")
        .c("(!f) cmp.lt r8, r9")
        .c("(!f) sleep")
        .note("neither child")
        .c("cmp.lt r8, r9");
    k
}

/// After [`node`], when every awake ray reaches the first child: F =
/// reaches the second too.
pub fn second() -> K {
    let mut k = K::new();
    k.doc("k_second_too: after a node kernel, F = the ray reaches the second child too.");
    k.c("cmp.lt r11, r14");
    k
}

/// After [`node`], when the packet visits both children: the rays that
/// do not reach the first sleep until the second is popped.
pub fn sleep_first() -> K {
    let mut k = K::new();
    k.doc("k_first_or_sleep: the rays that do not reach the first child sleep until the second is popped.");
    k.c("(!f) sleep");
    k
}

/// After [`node`], the second child is pushed (stream: the node's slot
/// address): every awake ray stores its interval for it.
pub fn push() -> K {
    let mut k = K::new();
    k.doc("k_push_second: the second child pushed: every awake ray's interval for it into its slot\n(stream: the slot's RAM address).");
    k.c("mov r15, fb0")
        .c("st r14, [r15]")
        .note("SLOT_TMAX")
        .c("add r15, r15, #1")
        .c("st r11, [r15]")
        .note("SLOT_TMIN");
    k
}

/// After [`node`], the packet visits the second child only (every awake
/// ray reaches it): its interval becomes the current one.
pub fn take() -> K {
    let mut k = K::new();
    k.doc("k_take_second: only the second child is visited: its interval becomes the current one.");
    k.c("mov r8, r11").c("mov r9, r14");
    k
}

/// A popped node (stream: the slot its parent pushed it with): every RC
/// wakes, takes its interval from the slot and clears the slot; the rays
/// that are not alive in this pass, or whose interval is empty or lies
/// beyond their hit, sleep again (F = awake).
pub fn pop() -> K {
    let mut k = K::new();
    k.doc(
        "k_pop_node: a popped node (stream: its slot's RAM address): every RC wakes and takes its\n\
         interval from the slot, emptied; the rays not alive, or whose interval is empty or\n\
         beyond their hit, sleep again. Out: F = awake.",
    );
    k.c("wake")
        .c("mov r15, fb0")
        .c("ld r9, [r15 + #SLOT_TMAX]")
        .c("ld r8, [r15 + #SLOT_TMIN]")
        .c("movb r10, #-1")
        .c("st r10, [r15]")
        .note("empty")
        .c("min r9, r9, r7")
        .c(format!("ld r11, [r0 + #{}]", ram::P_ALIVE))
        .c("cmp.ne r11, #0")
        .c("(f) cmp.lt r8, r9")
        .c("(!f) sleep");
    k
}

/// Any-hit (shadow) pass, after a leaf: a ray that found a hit is done for
/// the pass.
pub fn leaf_any() -> K {
    let mut k = K::new();
    k.doc(
        "k_done_with_hit: after a leaf, any-hit pass: the rays with a hit are done (not alive) and sleep.",
    );
    k.c(format!("ld r8, [r0 + #{}]", ram::PASS_T0))
        .c("cmp.lt r7, r8")
        .c("movb r9, #0")
        .c(format!("(f) st r9, [#{}]", ram::P_ALIVE))
        .c("(f) sleep");
    k
}
