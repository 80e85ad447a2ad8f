//! The packet traversal's child order: which child of a node the packet
//! visits first (`--child-order`, `docs/tracer.md`, "The child order").
//!
//! Every ray computes its own parts of its interval on both sides of a
//! split plane; the packet visits one child, then (from the stack) the
//! other, the same order for every node split on the same axis during a
//! pass. Where every awake ray goes the same way along an axis, that is
//! their near child first. Where they do not (a *mixed* packet along that
//! axis), the order serves some of the rays and not others, and it
//! matters only for the rays that end early: a ray that finds its hit (a
//! closest-hit pass) or an occluder (an any-hit pass) in the child it
//! visits first drops out of the cells behind it, while a ray that finds
//! nothing walks its whole path whatever the order. The order per axis of
//! a mixed packet is therefore a rule of its own:
//!
//! * **majority**: the near child of most of the awake rays (a popcount
//!   of the two 64-bit masks, [`majority`]);
//! * **down**: the near child of the rays going down along the axis (the
//!   child above the plane first), whatever their number;
//! * **up**: the near child of the rays going up (the child below first).
//!
//! Closest-hit passes (eye, reflected and refracted rays) and any-hit
//! passes (shadow rays) each have their rule per axis. `render`'s `auto`
//! takes `down` or `up` where the view's secondary rays find their hits
//! (and its shadow rays their occluders) mostly going that way
//! ([`ChildOrder::from_hits`], from rays the host's f64 tracer samples),
//! and keeps that order only where the probe of the frame runs it in
//! fewer cycles than `majority`.

use super::super::emit::{at, Code, Name, R0, R1, R11, R12, R13, R2, R3, R4, R5, R6, R8, R9};
use super::super::kernel_names as names;
use super::super::primitives::kaddr;

pub use super::super::options::{AxisOrder, ChildOrder, EndCounts, SIGNIFICANT};

/// The pass's start: `k_pass_start`, then per axis the order of the
/// children (`NK`, `NF`, `NS`); no ray awake: `trace_done`. The
/// directions' signs (`k_sign_*`, F = going down) are read into `NEG_*`
/// before the pass starts, with the awake rays, so that TinyRISC decides
/// the orders while `k_pass_start` runs; the rays the pass start puts to
/// sleep (those that miss the root cell) are known only after it, so the
/// orders are decided again when there were any (the same orders as from
/// the awake rays after the start). Where the awake rays do not all go
/// the same way along an axis, `order`'s rule for the pass's kind (r13's
/// sign: any hit) decides. `left`, `right`: the node's child fields.
pub fn pass_start(t: &mut Code, order: ChildOrder, left: Name, right: Name) {
    let (closest, any) = order.rules();
    // Each axis's masks stay in registers until the pass start is issued.
    let masks = [(R3, R4), (R5, R6), (R8, R9)];
    for (a, &(lo, hi)) in masks.iter().enumerate() {
        t.m("BCAST", names::sign(a as u8))
            .rcfl(lo)
            .rcfh(hi)
            .c(format!("the rays going down along {}", ["x", "y", "z"][a]));
    }
    t.rcsl(R11)
        .rcsh(R12)
        .c("r11, r12: the rays asleep before the pass starts");
    t.m("BCAST_FB", format!("{}, ROOTBOX", names::PASS_START))
        .c("intervals in the root cell, 1/d; while they are computed: the orders");
    for (&(lo, hi), axis) in masks.iter().zip(["X", "Y", "Z"]) {
        t.sw(lo, at(format!("NEG_{axis}"), R0))
            .sw(hi, at(format!("NEG_{axis}+MASK_HI"), R0));
    }
    t.label("order_pass")
        .nor(R11, R11, R0)
        .nor(R12, R12, R0)
        .c("r11, r12: the awake rays")
        .or(R1, R11, R12)
        .beqz(R1, "trace_done")
        .c("no ray awake");
    for (a, axis) in ["X", "Y", "Z"].into_iter().enumerate() {
        let lo = axis.to_lowercase();
        let done = format!("order_{lo}");
        t.lw(R1, at(format!("NEG_{axis}"), R0))
            .lw(R2, at(format!("NEG_{axis}+MASK_HI"), R0))
            .and(R1, R1, R11)
            .and(R2, R2, R12)
            .c(format!("r1, r2: the awake rays going down along {lo}"))
            .li(R8, 0)
            .or(R3, R1, R2)
            .beqz(R3, &done)
            .c("none")
            .li(R8, 1)
            .bne(R1, R11, format!("order_{lo}_some"))
            .beq(R2, R12, &done)
            .c("all");
        t.label(format!("order_{lo}_some"));
        let (c, n) = (closest[a], any[a]);
        if c != n {
            let any_label = format!("order_{lo}_any");
            t.blt(R13, R0, &any_label).c("an any-hit pass");
            mixed(t, c, "closest hit");
            t.j(&done);
            t.label(any_label);
            mixed(t, n, "any hit");
        } else {
            mixed(t, c, "");
        }
        t.label(&done)
            .addi(R1, R0, kaddr(&names::node(a as u8, false)))
            .li(R2, left)
            .li(R3, right)
            .beqz(R8, format!("order_{lo}_set"))
            .addi(R1, R0, kaddr(&names::node(a as u8, true)))
            .li(R2, right)
            .li(R3, left)
            .c("r8 = 1: above first");
        t.label(format!("order_{lo}_set"))
            .sw(R1, at(format!("NK+AXIS_{axis}"), R0))
            .sw(R2, at(format!("NF+AXIS_{axis}"), R0))
            .sw(R3, at(format!("NS+AXIS_{axis}"), R0))
            .c("node kernel, first and second child");
    }
    t.rcsl(R1)
        .rcsh(R2)
        .c("the rays asleep once the pass has started")
        .nor(R11, R11, R0)
        .nor(R12, R12, R0)
        .bne(R1, R11, "order_again")
        .beq(R2, R12, "order_done");
    t.label("order_again")
        .mv(R11, R1)
        .mv(R12, R2)
        .j("order_pass")
        .c("some ray missed the root cell: the orders from the awake rays left");
    t.label("order_done");
}

/// A mixed packet's order along one axis into r8 (1: above first), by
/// `rule`; r8 = 1 on entry. `kind`: the pass's kind, for the comment.
fn mixed(t: &mut Code, rule: AxisOrder, kind: &str) {
    let of = if kind.is_empty() {
        String::new()
    } else {
        format!(" ({kind})")
    };
    match rule {
        AxisOrder::Majority => {
            t.jal("majority").c(format!("some{of}: r8 = most go down"));
        }
        AxisOrder::Down => {
            t.comment(format!("some{of}: the rays going down first (r8 = 1)"));
        }
        AxisOrder::Up => {
            t.li(R8, 0).c(format!("some{of}: the rays going up first"));
        }
    }
}

/// `majority`: r8 = 1 when more of the awake rays (r11, r12) go down
/// (r1, r2: those of them whose direction component is negative) than
/// not: `awake < 2 down`. Both counts are SWAR population counts of the
/// 64-bit masks, the halves summed at 4-bit fields (at most 8 each).
pub fn majority(t: &mut Code) {
    t.doc(
        "majority: r8 = 1 if more of the awake RCs (r11, r12) are in r1, r2 than not.\n\
         Clobbers r1..r6, r9.",
    );
    t.label("majority")
        .li(R5, "0x55555555")
        .li(R6, "0x33333333");
    // pairs: x - ((x >> 1) & 0x55..)
    for (x, src) in [(R1, R1), (R2, R2), (R3, R11), (R4, R12)] {
        t.srli(R9, src, 1).and(R9, R9, R5).sub(x, src, R9);
    }
    t.c("2-bit counts");
    for x in [R1, R2, R3, R4] {
        t.and(R9, x, R6).srli(x, x, 2).and(x, x, R6).add(x, x, R9);
    }
    t.c("4-bit counts")
        .add(R1, R1, R2)
        .add(R3, R3, R4)
        .c("the halves summed: down in r1, awake in r3")
        .li(R5, "0x0f0f0f0f")
        .li(R6, "0x01010101");
    // Bytes: both nibbles masked before the sum (up to 16, five bits).
    for x in [R1, R3] {
        t.srli(R9, x, 4)
            .and(R9, R9, R5)
            .and(x, x, R5)
            .add(x, x, R9)
            .mul(x, x, R6)
            .srli(x, x, 24);
    }
    t.c("the byte counts summed")
        .slli(R1, R1, 1)
        .slt(R8, R3, R1)
        .c("awake < 2 down: fewer go up than down")
        .ret();
}

#[cfg(test)]
mod tests {
    use super::*;
    use AxisOrder::{Down as D, Majority as M, Up as U};

    #[test]
    fn orders_parse_and_print_back() {
        for (s, closest, any, shown) in [
            ("majority", [M; 3], [M; 3], "majority"),
            ("mmm", [M; 3], [M; 3], "majority"),
            ("mmm,mmm", [M; 3], [M; 3], "majority"),
            ("uud", [U, U, D], [M; 3], "uud,mmm"),
            ("uud,dmu", [U, U, D], [D, M, U], "uud,dmu"),
            ("mmm,ddd", [M; 3], [D; 3], "mmm,ddd"),
        ] {
            let o: ChildOrder = s.parse().unwrap();
            assert_eq!(o, ChildOrder::Fixed { closest, any }, "{s}");
            assert_eq!(o.to_string(), shown, "{s}");
            assert_eq!(shown.parse::<ChildOrder>().unwrap(), o, "{shown}");
        }
        assert_eq!("auto".parse::<ChildOrder>().unwrap(), ChildOrder::Auto);
        assert_eq!(ChildOrder::Auto.to_string(), "auto");
        assert_eq!(ChildOrder::Auto.rules(), ([M; 3], [M; 3]));
    }

    #[test]
    fn bad_orders_are_refused_with_the_value() {
        for s in [
            "",
            "uu",
            "uuuu",
            "uux",
            "UUD",
            "uud,",
            "uud,mm",
            ",uud",
            "uud,mmm,mmm",
            "up",
        ] {
            let e = s.parse::<ChildOrder>().unwrap_err();
            assert!(e.contains(&format!("'{s}'")), "{s}: {e}");
        }
    }

    #[test]
    fn the_rays_that_end_choose_only_where_they_lean_clearly() {
        let all: EndCounts = [[1000, 1000]; 3];
        // 100 rays that end: 3 standard deviations are 30.
        let order = |ended: EndCounts, all: EndCounts| {
            ChildOrder::from_hits((&ended, &all), (&[[0, 0]; 3], &all)).rules()
        };
        assert_eq!(order([[66, 34], [34, 66], [50, 50]], all).0, [D, U, M]);
        // 64:36 and 35:65 are 2.8 and 3.0 standard deviations: not clear.
        assert_eq!(order([[64, 36], [35, 65], [0, 0]], all).0, [M; 3]);
        // An axis along which every ray went the same way: its packets
        // agree, the rule never applies.
        assert_eq!(
            order(
                [[900, 0], [0, 900], [900, 0]],
                [[1000, 0], [0, 1000], [1000, 0]]
            )
            .0,
            [M; 3]
        );
        // Any-hit passes take the blocked shadow rays.
        let o = ChildOrder::from_hits(
            (&[[0, 0]; 3], &all),
            (&[[10, 300], [300, 10], [5, 5]], &all),
        );
        assert_eq!(o.rules(), ([M; 3], [U, D, M]));
        assert_eq!(
            o.describe(),
            "closest hit: majority; any hit: x up, y down, z majority"
        );
    }
}
