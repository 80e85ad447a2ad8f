//! The options of `morphosys render` that set the tracer, each declared
//! once ([`RenderOption`]): its flag, which `RenderArgs` takes as clap's
//! `long`; its name, the sweep's knob of it; the render JSON's key of its
//! value; and how a point's [`Options`] and [`Numerics`] spell it on that
//! flag, from which `sweep --plan` writes every point's command line. A
//! test parses each sweep point's line with `render`'s own parser
//! ([`crate::cmd_render::RenderArgs::options`]) and holds the result to
//! the point, so a flag added to one and not the other fails; another
//! holds the render JSON to the keys.

use firmware::bsp::SplitRule;
use firmware::tracer::{Numerics, Options};

/// One render option, declared once: its flag (clap's `long`, which
/// `RenderArgs` takes from here), its name as a sweep knob, the render
/// JSON's key that reports it, and its value for a point.
pub struct RenderOption {
    /// The flag without its `--`.
    pub long: &'static str,
    /// `long` with `_` for `-`: the sweep's knob of it.
    pub name: &'static str,
    /// How the render JSON reports it.
    pub json: Json,
    pub value: fn(&Options, &Numerics) -> String,
}

impl RenderOption {
    /// `--` and the flag.
    pub fn flag(&self) -> String {
        format!("--{}", self.long)
    }

    /// The render JSON's key of its value (its name where no key of its
    /// own reports it, [`Json::Apart`]).
    pub fn key(&self) -> &'static str {
        match self.json {
            Json::Key(k) => k,
            _ => self.name,
        }
    }
}

/// How the render JSON reports an option.
#[derive(Clone, Copy)]
pub enum Json {
    /// Under its name.
    Name,
    /// Under another key (`--split` is `bsp_split`).
    Key(&'static str),
    /// Not under one key of its own (`--size` is `width` and `height`;
    /// `--layout` is in `node_layout`, which says the packet traversal's
    /// own; `--guard-bits` is in the format).
    Apart,
}

/// `auto` for 0, else the number.
fn auto0(d: u32) -> String {
    if d == 0 {
        "auto".into()
    } else {
        d.to_string()
    }
}

pub const SIZE: RenderOption = RenderOption {
    long: "size",
    name: "size",
    json: Json::Apart,
    value: |o, _| format!("{}x{}", o.width, o.height),
};
pub const WAYS: RenderOption = RenderOption {
    long: "ways",
    name: "ways",
    json: Json::Name,
    value: |o, _| o.ways.to_string(),
};
pub const DEPTH: RenderOption = RenderOption {
    long: "depth",
    name: "depth",
    json: Json::Name,
    value: |o, _| o.depth.to_string(),
};
pub const TRAVERSAL: RenderOption = RenderOption {
    long: "traversal",
    name: "traversal",
    json: Json::Name,
    value: |o, _| o.traversal.name().into(),
};
pub const SPLIT: RenderOption = RenderOption {
    long: "split",
    name: "split",
    json: Json::Key("bsp_split"),
    value: |o, _| {
        match o.bsp.rule {
            SplitRule::Median => "median",
            SplitRule::Sah => "sah",
            SplitRule::Chip => "chip",
            SplitRule::Auto => "auto",
        }
        .into()
    },
};
pub const MAX_DEPTH: RenderOption = RenderOption {
    long: "max-depth",
    name: "max_depth",
    json: Json::Key("bsp_depth_limit"),
    value: |o, _| auto0(o.bsp.max_depth),
};
pub const MAX_LEAF: RenderOption = RenderOption {
    long: "max-leaf",
    name: "max_leaf",
    json: Json::Apart,
    value: |o, _| o.bsp.max_leaf.to_string(),
};
pub const COLLAPSE: RenderOption = RenderOption {
    long: "collapse",
    name: "collapse",
    json: Json::Name,
    value: |o, _| o.collapse.to_string(),
};
pub const LEAF_PIECES: RenderOption = RenderOption {
    long: "leaf-pieces",
    name: "leaf_pieces",
    json: Json::Name,
    value: |o, _| o.pieces.to_string(),
};
pub const SHADOW_PACKETS: RenderOption = RenderOption {
    long: "shadow-packets",
    name: "shadow_packets",
    json: Json::Name,
    value: |o, _| o.shadows.to_string(),
};
pub const SUB_EDGES: RenderOption = RenderOption {
    long: "sub-edges",
    name: "sub_edges",
    json: Json::Name,
    value: |o, _| o.sub_edges.to_string(),
};
pub const TEST_CUTS: RenderOption = RenderOption {
    long: "test-cuts",
    name: "test_cuts",
    json: Json::Name,
    value: |o, _| o.test_cuts.to_string(),
};
pub const CHILD_ORDER: RenderOption = RenderOption {
    long: "child-order",
    name: "child_order",
    json: Json::Name,
    value: |o, _| o.child_order.to_string(),
};
pub const LAYOUT: RenderOption = RenderOption {
    long: "layout",
    name: "layout",
    json: Json::Apart,
    value: |o, _| o.layout.name().into(),
};
pub const DATAPATH: RenderOption = RenderOption {
    long: "datapath",
    name: "datapath",
    json: Json::Key("datapath_bits"),
    value: |o, _| o.datapath.bits().to_string(),
};
pub const NEWTON_STEPS: RenderOption = RenderOption {
    long: "newton-steps",
    name: "newton_steps",
    json: Json::Name,
    value: |_, n| n.newton_steps.to_string(),
};
pub const TABLE_ENTRIES: RenderOption = RenderOption {
    long: "table-entries",
    name: "table_entries",
    json: Json::Name,
    value: |_, n| n.table_entries.to_string(),
};
pub const GUARD_BITS: RenderOption = RenderOption {
    long: "guard-bits",
    name: "guard_bits",
    json: Json::Apart,
    value: |_, n| n.guard_bits.to_string(),
};
pub const RAY_OFFSET_LSB: RenderOption = RenderOption {
    long: "ray-offset-lsb",
    name: "ray_offset_lsb",
    json: Json::Apart,
    value: |_, n| n.eps_lsb.to_string(),
};
pub const NORMALS: RenderOption = RenderOption {
    long: "normals",
    name: "normals",
    json: Json::Name,
    value: |_, n| n.normals.name().into(),
};
pub const POSITIONS: RenderOption = RenderOption {
    long: "positions",
    name: "positions",
    json: Json::Name,
    value: |o, _| o.positions.name().into(),
};

/// Every render option that sets the tracer, in the order a planned
/// command line lists them.
pub const RENDER_OPTIONS: &[RenderOption] = &[
    SIZE,
    WAYS,
    DEPTH,
    TRAVERSAL,
    SPLIT,
    MAX_DEPTH,
    MAX_LEAF,
    COLLAPSE,
    LEAF_PIECES,
    SHADOW_PACKETS,
    SUB_EDGES,
    TEST_CUTS,
    CHILD_ORDER,
    LAYOUT,
    DATAPATH,
    NEWTON_STEPS,
    TABLE_ENTRIES,
    GUARD_BITS,
    RAY_OFFSET_LSB,
    NORMALS,
    POSITIONS,
];

/// The flags and values that ask `morphosys render` for `opt` and `nm`.
pub fn argv(opt: &Options, nm: &Numerics) -> Vec<String> {
    RENDER_OPTIONS
        .iter()
        .flat_map(|r| [r.flag(), (r.value)(opt, nm)])
        .collect()
}

/// `morphosys render`'s flags that are not options of the tracer: files,
/// the waveform's window, the timing, the firmware, how to run.
pub const OTHER_FLAGS: &[&str] = &[
    "--out",
    "--json",
    "--hits",
    "--vcd",
    "--trace-from",
    "--trace-cycles",
    "--trace-scope",
    "--emit-asm",
    "--skip-done",
    "--profile",
    "--timing",
    "--firmware",
    "--plain",
];

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[derive(clap::Parser)]
    struct Render {
        #[command(flatten)]
        args: crate::cmd_render::RenderArgs,
    }

    /// Every flag of `morphosys render` is in the table or among the
    /// others, and every flag of the table is one of `render`'s.
    #[test]
    fn the_table_names_every_render_option() {
        let cmd = Render::command();
        let flags: Vec<String> = cmd
            .get_arguments()
            .filter_map(|a| a.get_long())
            .map(|l| format!("--{l}"))
            .collect();
        for f in &flags {
            let known =
                RENDER_OPTIONS.iter().any(|r| &r.flag() == f) || OTHER_FLAGS.contains(&f.as_str());
            assert!(
                known,
                "render's {f} is neither a tracer option of the table nor another flag"
            );
        }
        for r in RENDER_OPTIONS {
            assert!(
                flags.iter().any(|f| *f == r.flag()),
                "{} is not a flag of render",
                r.flag()
            );
            assert_eq!(r.name, r.long.replace('-', "_"), "{}", r.long);
        }
    }

    /// A command line written from the table asks `render` for the very
    /// options it was written from (every field, by `Debug`), on every
    /// point of the knob sweep.
    #[test]
    fn every_sweep_point_parses_back_to_itself() {
        use clap::Parser;
        let timing = rtl::Timing::default();
        let points = crate::cmd_sweep::knob_points(64, 48);
        assert!(points.len() > 30);
        for (opt, nm) in points {
            let line = std::iter::once("render".to_string())
                .chain(["scene.nff".to_string()])
                .chain(argv(&opt, &nm));
            let r = Render::try_parse_from(line).unwrap_or_else(|e| panic!("{e}"));
            let (got, got_nm) = r.args.options(&timing);
            let want = Options {
                datapath: rtl::rc::Datapath::W16,
                test_cuts: opt.test_cuts.for_issue(timing.risc.issue),
                ..opt
            };
            assert_eq!(format!("{got:?}"), format!("{want:?}"));
            assert_eq!(got_nm, nm);
            assert_eq!(
                r.args.datapath,
                crate::cli::DatapathChoice::Fixed(opt.datapath)
            );
        }
    }
}
