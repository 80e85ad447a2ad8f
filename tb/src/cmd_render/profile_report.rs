//! `render --profile`'s report of a frame's profile: its cycles by cause,
//! the packet traversal's cost model against it, the JSON and the table.

use serde_json::json;

use crate::profile::{Causes, Profile};

/// The profile's cycles by cause for this render's statistics.
pub(crate) fn causes(p: &Profile, chip: &crate::render::ChipRender) -> Causes {
    let tests: Vec<String> = firmware::tracer::primitives::all_test_kernels()
        .into_iter()
        .map(String::from)
        .collect();
    p.causes(&tests, chip.simd_efficiency(), chip.array_idle_on_dma())
}

/// The packet traversal's cost model ([`firmware::tracer::layout::packet_nodes`]:
/// a node visit, a leaf's loop, TinyRISC's share of an object test)
/// against this frame's profile; `None` where the frame does not show it
/// (a leaf's loop: resident scenes do not count their leaves).
#[derive(Clone, Copy, Debug)]
pub(crate) struct CostCheck {
    pub node_visit: Option<f64>,
    pub leaf_loop: Option<f64>,
    pub object_risc: Option<f64>,
}

impl CostCheck {
    pub(crate) fn of(
        p: &Profile,
        causes: &Causes,
        chip: &crate::render::ChipRender,
    ) -> Option<CostCheck> {
        use firmware::tracer::traversal::packet::cost_items as ci;
        if chip.firmware.layout.traversal != firmware::tracer::Traversal::Packet {
            return None;
        }
        let per = |c: u64, n: f64| (n > 0.0).then(|| c as f64 / n);
        let node_len = chip
            .firmware
            .kernels
            .iter()
            .find(|(n, _)| n.starts_with(ci::NODE_KERNEL_PREFIX))
            .map_or(0, |k| k.1);
        let node_cycles: u64 = p
            .kernels
            .iter()
            .filter(|(n, _)| n.starts_with(ci::NODE_KERNEL_PREFIX))
            .map(|x| x.1)
            .sum();
        let node_other: u64 = p
            .kernels
            .iter()
            .filter(|(n, _)| ci::NODE_KERNELS.contains(&n.as_str()))
            .map(|x| x.1)
            .sum();
        let control = |f: &dyn Fn(&str) -> bool| -> u64 {
            p.control.iter().filter(|(n, _)| f(n)).map(|x| x.1).sum()
        };
        let node_control = control(&|n| ci::NODE_LABELS.contains(&n));
        let leaf_control = control(&|n| ci::is_leaf_label(n)).saturating_sub(causes.dma_wait);
        let leaves = chip.leaf_cache.map_or(0, |c| c.hits + c.misses);
        Some(CostCheck {
            node_visit: per(
                node_cycles + node_other + node_control,
                node_cycles as f64 / node_len.max(1) as f64,
            ),
            leaf_loop: per(leaf_control, leaves as f64),
            object_risc: per(
                control(&|n| ci::is_object_label(n)),
                chip.object_tests() as f64,
            ),
        })
    }
}

pub(crate) fn profile_json(p: &Profile, causes: &Causes) -> serde_json::Value {
    let rows = |v: &[(String, u64)]| {
        v.iter()
            .map(|(n, c)| json!({"name": n, "cycles": c}))
            .collect::<Vec<_>>()
    };
    json!({
        "cycles": p.cycles,
        "kernels": rows(&p.kernels),
        "control": rows(&p.control),
        "causes": causes,
    })
}

pub(crate) fn print_profile(p: &Profile, causes: &Causes, check: Option<CostCheck>) {
    let pct = |c: u64| 100.0 * c as f64 / p.cycles.max(1) as f64;
    let busy: u64 = p.kernels.iter().map(|x| x.1).sum();
    println!(
        "profile                  the tile loop: {} cycles; array busy {:.1}%, idle {:.1}%",
        p.cycles,
        pct(busy),
        pct(p.cycles - busy)
    );
    println!("  cycles by cause               cycles      share");
    for (n, c) in [
        ("object tests needed", causes.tests_needed),
        ("divergence waste", causes.divergence_waste),
        ("traversal, shading", causes.traversal_and_shading),
        ("DMA wait", causes.dma_wait),
        ("control idle", causes.control_idle),
    ] {
        println!("  {n:<24} {c:>12} {:>9.1}%", pct(c));
    }
    if let Some(c) = check {
        use firmware::tracer::layout::packet_nodes as pn;
        println!("  cost model (chip split)     measured      model");
        let show = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.1}"));
        for (n, m, model) in [
            ("node visit", c.node_visit, pn::PK_NODE_COST),
            ("leaf loop", c.leaf_loop, pn::PK_LEAF_COST),
            ("TinyRISC per test", c.object_risc, pn::PK_OBJECT_RISC),
        ] {
            println!("  {n:<24} {:>12} {model:>10.1}", show(m));
        }
    }
    println!("  array busy in kernel          cycles      share");
    for (n, c) in p.kernels.iter().take(14) {
        println!("  {n:<24} {c:>12} {:>9.1}%", pct(*c));
    }
    println!("  array idle, TinyRISC at       cycles      share");
    for (n, c) in p.control.iter().take(14) {
        println!("  {n:<24} {c:>12} {:>9.1}%", pct(*c));
    }
}
