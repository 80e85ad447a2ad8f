//! The packet traversal's cost model: what a packet's node visit, leaf
//! and object test cost in array cycles ([`PK_NODE_COST`],
//! [`PK_LEAF_COST`], [`object_costs`]), which the chip-cost BSP
//! ([`chip_costs`], `--split chip`) and the subtrees walked as one leaf
//! ([`super::super::Collapse::Auto`]) weigh.

use super::super::primitives::{of_shape, polygon, Fit, Gen, TestCost, PRIMITIVES};
use super::STREAM_BANK;
use crate::scene::Scene;
/// Array cycles a packet spends on an inner node (its kernel and
/// TinyRISC's decision), for [`super::super::Collapse::Auto`]: set above
/// what `render --profile` measures (its "cost model" rows print both),
/// since a value nearer the measurement walks more nodes and costs the
/// SPD scenes cycles (`docs/tracer.md`, "The tree it walks").
pub const PK_NODE_COST: f64 = 60.0;

/// Per scene object, the array cycles a packet's test of it costs: the
/// contexts of its kernel up to the first cut, [`PART_ON`] of the rest
/// (caps and polygon edges included: they run only where the plane or the
/// line is met), and [`PK_OBJECT_RISC`] cycles of TinyRISC's loop that the
/// array does not hide. Priced as tests in parts whether or not they run
/// so (`--test-cuts`), so the tree is the same either way; the kernels as
/// with the default numerics.
pub(super) fn object_costs(scene: &Scene, s: f64, fit: &Fit) -> Vec<f64> {
    // The kernels of tests in parts, whatever the render's `--test-cuts`.
    let fit = &Fit {
        cyl_bound: true,
        ..*fit
    };
    let g = Gen {
        datapath: rtl::rc::Datapath::W16,
        approx: super::super::math::Approx::default(),
        fine_normals: fit.fine_normals,
        test_cuts: true,
        published: false,
    };
    let costs: Vec<TestCost> = PRIMITIVES.iter().map(|p| p.test_cost(&g, fit)).collect();
    scene
        .objects
        .iter()
        .map(|o| {
            let p = of_shape(&o.shape);
            let c = PRIMITIVES
                .iter()
                .zip(&costs)
                .find(|(q, _)| q.names() == p.names())
                .map_or(TestCost::default(), |(_, c)| *c);
            let runs = p.cost_runs(&o.shape, s);
            c.first as f64 + PART_ON * (c.rest + c.each * runs) as f64 + PK_OBJECT_RISC
        })
        .collect()
}

/// The share of an object test's contexts after its first cut that a
/// packet runs, for the cost model: `render --test-cuts on` against `off`
/// with `--profile` on the SPD scenes at their default sizes, 128x128,
/// runs 0.21 (cones, tree) to 0.71 (rectangles, rings) of the kernels'
/// contexts, first parts included (`docs/tracer.md`, "The tree it
/// walks").
const PART_ON: f64 = 0.3;

/// TinyRISC cycles per object test that the array waits for (the mailbox
/// check and the issue; the test's cuts end its run without TinyRISC):
/// set above what `render --profile` measures on the SPD scenes (the
/// `lo_*` rows over the object tests), where the frames are fastest
/// (`docs/tracer.md`, "The tree it walks").
pub const PK_OBJECT_RISC: f64 = 12.0;

/// Array cycles a packet spends on a leaf besides its objects: TinyRISC's
/// leaf loop (the block's check, its DMA's issue, the list's scan, the
/// pieces' turns), for [`crate::bsp::SplitRule::Chip`]; the DMA's set-up
/// is added. 48 to 86 on the SPD scenes at 128x128 but for shells' few
/// large leaves (`render --profile`: the `leaf*`, `lo_*_end` and `lo_*_fan_wait` rows,
/// less the DMA wait, over the leaves reached). Larger values measure a
/// little faster (a leaf also costs its decision and its pieces' waits,
/// which the model prices per object), so the model takes the largest
/// within a factor of two of the cheapest loop measured (balls-4, 41).
pub const PK_LEAF_COST: f64 = 80.0;

/// The costs a [`crate::bsp::SplitRule::Chip`] tree of `scene` weighs
/// (the packet traversal's, as [`object_costs`] and [`PK_NODE_COST`]),
/// before the scene's format is fitted: per object its test and its
/// record's move by DMA (words times the FB word's bytes over the DMA's
/// bytes per cycle), a leaf's block within FB bank 1.
pub fn chip_costs(
    scene: &Scene,
    datapath: rtl::rc::Datapath,
    fine_normals: bool,
    frac: u32,
) -> crate::bsp::ChipCosts {
    use super::super::primitives::ChipType;
    let s = (frac as f64).exp2();
    // (Scenes a chip-cost tree serves are mostly streamed: where banded
    // records would be over `polygon::APART_FROM` words, a record moves
    // without its sub-edges, as `build_packet` lays them out.)
    let (fan, polygon_bands) = super::polygon_fan(scene, s, true, None);
    let polygon_form = match polygon_bands {
        false => polygon::Form::Plain,
        true if polygon::keeps_apart(polygon::words(fan, polygon::Form::Banded)) => {
            polygon::Form::Apart
        }
        true => polygon::Form::Banded,
    };
    let fit = Fit {
        fine_normals,
        polygon_form,
        ..Fit::default()
    };
    let dma = rtl::dma::DmaTiming::default();
    let word_cycles = (datapath.bits() / 8) as f64 / dma.bytes_per_cycle.max(1) as f64;
    let tests = object_costs(scene, s, &fit);
    // Whether each chip type's records carry caps, decided once per type
    // (indexed by `ChipType as usize`).
    let mut caps = [false; ChipType::ALL.len()];
    for t in ChipType::ALL {
        caps[t as usize] = super::records_carry_caps(scene, t, crate::tracer::Traversal::Packet);
    }
    let words: Vec<usize> = scene
        .objects
        .iter()
        .map(|o| {
            let transmits = scene.materials[o.material].t > 0.0;
            let t = ChipType::of_object(&o.shape, transmits);
            let fan = t.primitive().fan(&o.shape, s, fit.polygon_form.banded());
            t.record_words(&fit, fan, caps[t as usize])
        })
        .collect();
    crate::bsp::ChipCosts {
        node: PK_NODE_COST,
        leaf: PK_LEAF_COST + dma.setup_cycles as f64,
        object: tests
            .iter()
            .zip(&words)
            .map(|(t, &w)| t + w as f64 * word_cycles)
            .collect(),
        words,
        leaf_words: super::FB_LIMIT - STREAM_BANK - super::BLOCK_HEAD,
    }
}
