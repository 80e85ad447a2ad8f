//! The knob sweep's points: each knob's values on the paper's
//! configuration or the packet traversal's, and each on the default
//! timing, the M1 chip's issue model and every `--timing` file.

use crate::render_options as ro;
use firmware::bsp::{BspParams, SplitRule};
use firmware::tracer::{Datapath, NodeLayout, Numerics, Options, Traversal};
use rtl::tinyrisc::IssueModel;
use rtl::Timing;

/// One point of the knob sweep: the knob it varies and the tracer options.
#[derive(Clone, Debug)]
pub(super) struct Knob {
    pub(super) knob: &'static str,
    pub(super) value: String,
    pub(super) opt: Options,
    pub(super) nm: Numerics,
}

/// One configuration: a knob's point on a chip timing.
#[derive(Clone, Debug)]
pub(super) struct Config {
    pub(super) knob: &'static str,
    pub(super) value: String,
    pub(super) opt: Options,
    pub(super) nm: Numerics,
    /// The chip's timing, and its name in the table ("default", "M1 issue"
    /// or a timing file's name).
    pub(super) timing: Timing,
    pub(super) timing_name: String,
    /// Which `--timing` file it is (its index), if it is one.
    pub(super) timing_file: Option<usize>,
}

impl From<Knob> for Config {
    fn from(k: Knob) -> Config {
        Config {
            knob: k.knob,
            value: k.value,
            opt: k.opt,
            nm: k.nm,
            timing: Timing::default(),
            timing_name: "default".into(),
            timing_file: None,
        }
    }
}

/// The paper's configuration at `width` x `height`: its traversal, its
/// BSP (median split, depth 15, 5 objects per leaf), 64 ways, recursion
/// level 2, the 16-bit chip.
pub(super) fn paper_config(width: u32, height: u32) -> Options {
    Options {
        width,
        height,
        traversal: Traversal::Paper,
        bsp: BspParams::default(),
        ..Options::default()
    }
}

/// The packet traversal with its defaults (its own choice of BSP).
pub(super) fn packet_config(width: u32, height: u32) -> Options {
    Options {
        width,
        height,
        traversal: Traversal::Packet,
        ..Options::default()
    }
}

pub(super) fn knobs(width: u32, height: u32) -> Vec<Knob> {
    let base = paper_config(width, height);
    let nm = Numerics::default();
    let mut v = vec![Knob {
        knob: "paper",
        value: "paper".into(),
        opt: base,
        nm,
    }];
    numerics_knobs(&mut v, base, nm);
    ray_knobs(&mut v, base, nm);
    tree_knobs(&mut v, base, nm);
    packet_knobs(&mut v, width, height, nm);
    chip_knobs(&mut v, base, width, height, nm);
    v
}

/// The RC arithmetic's knobs on the paper's configuration: Newton steps,
/// guard bits, table sizes, normals, the ray offset.
fn numerics_knobs(v: &mut Vec<Knob>, base: Options, nm: Numerics) {
    for newton_steps in [0, 1, 2, 3] {
        v.push(Knob {
            knob: ro::NEWTON_STEPS.name,
            value: newton_steps.to_string(),
            opt: base,
            nm: Numerics { newton_steps, ..nm },
        });
    }
    // More guard bits: a coarser coordinate format (fewer fraction bits).
    for guard_bits in [2, 3, 4] {
        v.push(Knob {
            knob: ro::GUARD_BITS.name,
            value: guard_bits.to_string(),
            opt: base,
            nm: Numerics { guard_bits, ..nm },
        });
    }
    // Reciprocal / square-root table size, with one and two Newton steps.
    for table_entries in firmware::tracer::math::TABLE_SIZES {
        for newton_steps in [1, 2] {
            v.push(Knob {
                knob: ro::TABLE_ENTRIES.name,
                value: format!("{table_entries}/{newton_steps}"),
                opt: base,
                nm: Numerics {
                    table_entries,
                    newton_steps,
                    ..nm
                },
            });
        }
    }
    // The kernels as first written (`--normals coarse`): the paper
    // configuration's point before the fine normals, beside it.
    v.push(Knob {
        knob: ro::NORMALS.name,
        value: "coarse".into(),
        opt: base,
        nm: Numerics {
            normals: firmware::tracer::Normals::Coarse,
            ..nm
        },
    });
    for eps_lsb in [1, 3, 8] {
        v.push(Knob {
            knob: ro::RAY_OFFSET_LSB.name,
            value: eps_lsb.to_string(),
            opt: base,
            nm: Numerics { eps_lsb, ..nm },
        });
    }
}

/// The rays in flight and the recursion depth.
fn ray_knobs(v: &mut Vec<Knob>, base: Options, nm: Numerics) {
    for ways in [4, 8, 16, 32, 64] {
        v.push(Knob {
            knob: ro::WAYS.name,
            value: ways.to_string(),
            opt: Options { ways, ..base },
            nm,
        });
    }
    for depth in [1, 2, 3, 5] {
        v.push(Knob {
            knob: "recursion",
            value: depth.to_string(),
            opt: Options { depth, ..base },
            nm,
        });
    }
}

/// The paper's BSP: its depth limit, leaf size and split rule.
fn tree_knobs(v: &mut Vec<Knob>, base: Options, nm: Numerics) {
    for max_depth in [2, 4, 8, 15] {
        v.push(Knob {
            knob: "bsp_depth",
            value: max_depth.to_string(),
            opt: Options {
                bsp: BspParams {
                    max_depth,
                    ..base.bsp
                },
                ..base
            },
            nm,
        });
    }
    for max_leaf in [1, 2, 5, 10] {
        v.push(Knob {
            knob: "leaf_size",
            value: max_leaf.to_string(),
            opt: Options {
                bsp: BspParams {
                    max_leaf,
                    ..base.bsp
                },
                ..base
            },
            nm,
        });
    }
    v.push(Knob {
        knob: ro::SPLIT.name,
        value: "sah".into(),
        opt: Options {
            bsp: BspParams {
                rule: SplitRule::Sah,
                ..base.bsp
            },
            ..base
        },
        nm,
    });
}

/// The packet traversal's choices, each forced (its defaults probe them).
fn packet_knobs(v: &mut Vec<Knob>, width: u32, height: u32, nm: Numerics) {
    // The packet traversal's trees, each forced (its default probes all
    // three and keeps the fastest).
    for rule in [SplitRule::Median, SplitRule::Sah, SplitRule::Chip] {
        let packet = packet_config(width, height);
        v.push(Knob {
            knob: "packet_split",
            value: format!("{rule:?}").to_lowercase(),
            opt: Options {
                bsp: BspParams { rule, ..packet.bsp },
                ..packet
            },
            nm,
        });
    }
    // A streamed scene's leaf pieces (resident scenes have none): whole
    // leaves (one piece unless a leaf exceeds the bank), smaller pieces,
    // and each of `auto`'s two second pieces forced.
    for pieces in [
        firmware::tracer::LeafPieces::two(
            firmware::tracer::LeafPieces::MAX,
            firmware::tracer::LeafPieces::MAX,
        ),
        firmware::tracer::LeafPieces::two(32, 128),
        firmware::tracer::LeafPieces::two(64, 256),
        firmware::tracer::LeafPieces {
            first: 64,
            second: Some(128),
            rest: 256,
        },
    ] {
        let packet = packet_config(width, height);
        v.push(Knob {
            knob: ro::LEAF_PIECES.name,
            value: pieces.to_string(),
            opt: Options { pieces, ..packet },
            nm,
        });
    }
    // The reflection levels' shadow rays, each packing forced (the
    // default probes both and keeps the faster).
    for shadows in [
        firmware::tracer::ShadowPackets::PerLight,
        firmware::tracer::ShadowPackets::Merged,
    ] {
        let packet = packet_config(width, height);
        v.push(Knob {
            knob: ro::SHADOW_PACKETS.name,
            value: shadows.to_string(),
            opt: Options { shadows, ..packet },
            nm,
        });
    }
    // Banded polygons' sub-edges in the records a leaf's pieces move
    // (the default keeps them apart and moves a packet's bands).
    let packet = packet_config(width, height);
    v.push(Knob {
        knob: ro::SUB_EDGES.name,
        value: firmware::tracer::SubEdges::InRecords.to_string(),
        opt: Options {
            sub_edges: firmware::tracer::SubEdges::InRecords,
            ..packet
        },
        nm,
    });
    // The child order of mixed packets by the majority alone (the
    // default serves the ways the view's rays end, where the probe runs
    // that faster).
    let packet = packet_config(width, height);
    v.push(Knob {
        knob: ro::CHILD_ORDER.name,
        value: firmware::tracer::ChildOrder::MAJORITY.to_string(),
        opt: Options {
            child_order: firmware::tracer::ChildOrder::MAJORITY,
            ..packet
        },
        nm,
    });
    // Object tests in parts steered by TinyRISC, and whole (the default
    // runs them in parts, ended by the broadcast unit at their cuts).
    let packet = packet_config(width, height);
    for test_cuts in [
        firmware::tracer::TestCuts::Tinyrisc,
        firmware::tracer::TestCuts::Off,
    ] {
        v.push(Knob {
            knob: ro::TEST_CUTS.name,
            value: test_cuts.to_string(),
            opt: Options {
                test_cuts,
                ..packet
            },
            nm,
        });
    }
}

/// The chip: the datapath, the traversal, the node layout.
fn chip_knobs(v: &mut Vec<Knob>, base: Options, width: u32, height: u32, nm: Numerics) {
    for datapath in [Datapath::W16, Datapath::W32] {
        v.push(Knob {
            knob: ro::DATAPATH.name,
            value: datapath.bits().to_string(),
            opt: Options { datapath, ..base },
            nm,
        });
    }
    v.push(Knob {
        knob: ro::TRAVERSAL.name,
        value: Traversal::Packet.name().into(),
        opt: packet_config(width, height),
        nm,
    });
    v.push(Knob {
        knob: ro::LAYOUT.name,
        value: NodeLayout::Compact.name().into(),
        opt: Options {
            layout: NodeLayout::Compact,
            ..base
        },
        nm,
    });
}

/// The knob sweep's configurations: every knob on the default timing,
/// the broadcast knob (the paper's configuration and the packet traversal
/// with the M1 chip's issue model) and, per timing file, both again.
pub(super) fn configs(width: u32, height: u32, files: &[(String, Timing)]) -> Vec<Config> {
    let mut v: Vec<Config> = knobs(width, height).into_iter().map(Config::from).collect();
    let nm = Numerics::default();
    let both = [paper_config(width, height), packet_config(width, height)];
    let m1 = Timing {
        risc: rtl::tinyrisc::RiscTiming {
            issue: rtl::tinyrisc::IssueModel::Instruction,
            ..Timing::default().risc
        },
        ..Timing::default()
    };
    for opt in both {
        v.push(Config {
            timing: m1,
            timing_name: "M1 issue".into(),
            ..Config::from(Knob {
                knob: "broadcast",
                value: IssueModel::Instruction.name().into(),
                opt,
                nm,
            })
        });
    }
    for (i, (name, t)) in files.iter().enumerate() {
        for opt in both {
            v.push(Config {
                timing: *t,
                timing_name: name.clone(),
                timing_file: Some(i),
                ..Config::from(Knob {
                    knob: "timing",
                    value: name.clone(),
                    opt,
                    nm,
                })
            });
        }
    }
    v
}
