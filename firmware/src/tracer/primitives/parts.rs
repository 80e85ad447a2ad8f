//! Object tests in parts: a [`CutTest`] (the first kernel of a test and
//! its cuts, [`super::super::emit::K::cut`]) run by the broadcast unit's
//! `cut` contexts as one run ([`run_with_cut_contexts`]), or part by part
//! steered by TinyRISC ([`run_first_part`], [`run_rest`]; `--test-cuts
//! tinyrisc`).

use super::super::emit::{cut_label, Code, Reg, R2, R3};
use super::{cylinder, klen, planar, ChipType, Fit};

/// A test whose first kernel has cuts ([`super::super::emit::K::cut`]): the
/// packet traversal runs it in parts ([`run_with_cut_contexts`]).
#[derive(Clone, Copy, Debug)]
pub struct CutTest {
    /// The kernel.
    pub kernel: &'static str,
    /// The record field its stream starts at.
    pub field: &'static str,
    /// Its cuts, in order: name, and what F holds there.
    pub cuts: &'static [(&'static str, &'static str)],
    /// What F holds at its end, where the test goes on with further
    /// kernels that run only if some awake RC has F then (a polygon's
    /// edges and tail).
    pub then: Option<&'static str>,
}

impl ChipType {
    /// The test that runs in parts, for the types that have one
    /// ([`super::ChipPrimitive::cut_test`]).
    pub fn cut_test(self, fit: &Fit) -> Option<CutTest> {
        self.primitive().cut_test(self.sides(), fit)
    }

    /// What a cut test's object runs after its first kernel whatever F,
    /// its record at `rec` ([`super::ChipPrimitive::broadcast_after_cut_test`]).
    pub fn broadcast_after_cut_test(self, t: &mut Code, at: &str, rec: Reg, caps: bool) {
        self.primitive()
            .broadcast_after_cut_test(self.sides(), t, at, rec, caps)
    }
}

/// Broadcast the first part of a test in parts ([`CutTest`] `c`) on the
/// record at `first`: its kernel up to the first cut (`BCAST_UPTO`), or the
/// whole kernel where it has no cut. TinyRISC's work while it runs comes
/// next, then [`run_rest`].
pub fn run_first_part(t: &mut Code, c: &CutTest, first: Reg) {
    let (k, field) = (c.kernel, c.field);
    match c.cuts.first() {
        Some((name, holds)) => {
            let cut = cut_label(k, name);
            t.m("BCAST_UPTO", format!("{k}, {cut}, {first}, {field}"))
                .c(format!("up to F: {holds}"));
        }
        None => {
            t.m("BCAST_REC", format!("{k}, {first}, {field}"));
            if let Some(holds) = c.then {
                t.c(format!("F: {holds}"));
            }
        }
    }
}

/// Whether TinyRISC's parts (`--test-cuts tinyrisc`) end at the cut
/// `name`. The cuts before a test's normal and commit (a cylinder's
/// `height`, a planar test's `inside`) leave 6 to 54 contexts, less than
/// the status read and second issue of a part cost TinyRISC there: only
/// the broadcast unit's `cut` contexts end a run at them.
pub fn tinyrisc_part(name: &str) -> bool {
    name != cylinder::CUTS[3].0 && name != planar::CUTS[1].0
}

/// The rest of a test of type `ty` in parts ([`CutTest`] `c`) after
/// [`run_first_part`], on the record at `rec`: each part after a cut, and
/// then the further kernels (`then`), only where some awake RC has F
/// (`rcany`), else on to `none`. Labels begin with `at`; `fit`: the
/// records' variants. Clobbers r1..r3.
pub fn run_rest(
    t: &mut Code,
    ty: ChipType,
    c: &CutTest,
    fit: &Fit,
    rec: Reg,
    at: &str,
    none: &str,
) {
    let (k, field) = (c.kernel, c.field);
    let run_from = |t: &mut Code, from: &str, to: &str| {
        t.m(
            "BCAST_FROM_ANY",
            format!("{from}, {to}, {rec}, {field}, {none}"),
        );
    };
    let parts: Vec<&(&str, &str)> = c.cuts.iter().filter(|(n, _)| tinyrisc_part(n)).collect();
    let cuts: Vec<String> = parts.iter().map(|(name, _)| cut_label(k, name)).collect();
    for (i, (_, holds)) in parts.iter().enumerate().skip(1) {
        run_from(t, &cuts[i - 1], &cuts[i]);
        t.c(format!("up to F: {holds}"));
    }
    if let Some(last) = cuts.last() {
        run_from(t, last, &format!("{k}_end"));
        t.c("the rest, if some awake ray can still hit it");
        if let Some(holds) = c.then {
            t.c(format!("F: {holds}"));
        }
    }
    if c.then.is_some() {
        t.rcany(R3).beqz(R3, none).c("no awake ray can hit it");
        ty.primitive().broadcast_then(ty.sides(), t, at, rec, fit);
    }
}

/// The record field a cut test's stream starts at ([`CutTest::field`]),
/// `"0"` where that is the record itself: a cylinder's or cone's record
/// without caps (`caps` false) is its body.
pub fn stream_field(ty: ChipType, c: &CutTest, caps: bool) -> &'static str {
    if ty.primitive().disc_caps() && !caps {
        "0"
    } else {
        c.field
    }
}

/// A test in parts ([`CutTest`] `c`) of type `ty` as one run of its
/// kernel, whose `cut` contexts end it where no awake RC has F
/// ([`super::super::emit::K::text_with_cuts`]), on the record at `rec`, its
/// stream from `field` ([`stream_field`]); then the further kernels
/// (`then`) only where some awake RC has F (`rcany`), else on to `none`.
/// `kernel`: a register that holds the kernel's address (a type loop
/// sets it once), else the address is set here. Labels begin with `at`;
/// `fit`: the records' variants. Clobbers r1..r3.
#[allow(clippy::too_many_arguments)]
pub fn run_with_cut_contexts(
    t: &mut Code,
    ty: ChipType,
    c: &CutTest,
    field: &str,
    kernel: Option<Reg>,
    fit: &Fit,
    rec: Reg,
    at: &str,
    none: &str,
) {
    let k = c.kernel;
    match (kernel, field) {
        (None, "0") => {
            t.m("BCAST_AT", format!("{k}, {rec}"));
        }
        (None, _) => {
            t.m("BCAST_REC", format!("{k}, {rec}, {field}"));
        }
        (Some(kr), "0") => {
            t.sbcb(kr, rec, klen(k));
        }
        (Some(kr), _) => {
            t.addi(R2, rec, field).sbcb(kr, R2, klen(k));
        }
    }
    if c.cuts.is_empty() {
        t.c("the test");
    } else {
        t.c("the test; its cuts end the run where no awake ray can still hit it");
    }
    if let Some(holds) = c.then {
        t.rcany(R3).c(format!("F: {holds}"));
        t.beqz(R3, none).c("no awake ray can hit it");
        ty.primitive().broadcast_then(ty.sides(), t, at, rec, fit);
    }
}
