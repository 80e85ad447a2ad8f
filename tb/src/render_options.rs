//! The options of `morphosys render` that set the tracer, as one table:
//! each one's flag and how a point's [`Options`] and [`Numerics`] spell
//! it on that flag. `sweep --plan` writes every point's command line from
//! it, and a test parses each sweep point's line with `render`'s own
//! parser ([`crate::cmd_render::RenderArgs::options`]) and holds the
//! result to the point, so a flag added to one and not the other fails.

use firmware::bsp::SplitRule;
use firmware::tracer::{Numerics, Options};

/// One render option: its flag and its value for a point.
pub struct RenderOption {
    pub flag: &'static str,
    pub value: fn(&Options, &Numerics) -> String,
}

/// `auto` for 0, else the number.
fn auto0(d: u32) -> String {
    if d == 0 {
        "auto".into()
    } else {
        d.to_string()
    }
}

/// Every render option that sets the tracer, in the order a planned
/// command line lists them.
pub const RENDER_OPTIONS: &[RenderOption] = &[
    RenderOption {
        flag: "--size",
        value: |o, _| format!("{}x{}", o.width, o.height),
    },
    RenderOption {
        flag: "--ways",
        value: |o, _| o.ways.to_string(),
    },
    RenderOption {
        flag: "--depth",
        value: |o, _| o.depth.to_string(),
    },
    RenderOption {
        flag: "--traversal",
        value: |o, _| o.traversal.name().into(),
    },
    RenderOption {
        flag: "--split",
        value: |o, _| {
            match o.bsp.rule {
                SplitRule::Median => "median",
                SplitRule::Sah => "sah",
                SplitRule::Chip => "chip",
                SplitRule::Auto => "auto",
            }
            .into()
        },
    },
    RenderOption {
        flag: "--max-depth",
        value: |o, _| auto0(o.bsp.max_depth),
    },
    RenderOption {
        flag: "--max-leaf",
        value: |o, _| o.bsp.max_leaf.to_string(),
    },
    RenderOption {
        flag: "--collapse",
        value: |o, _| o.collapse.to_string(),
    },
    RenderOption {
        flag: "--leaf-pieces",
        value: |o, _| o.pieces.to_string(),
    },
    RenderOption {
        flag: "--shadow-packets",
        value: |o, _| o.shadows.to_string(),
    },
    RenderOption {
        flag: "--sub-edges",
        value: |o, _| o.sub_edges.to_string(),
    },
    RenderOption {
        flag: "--test-cuts",
        value: |o, _| o.test_cuts.to_string(),
    },
    RenderOption {
        flag: "--child-order",
        value: |o, _| o.child_order.to_string(),
    },
    RenderOption {
        flag: "--layout",
        value: |o, _| o.layout.name().into(),
    },
    RenderOption {
        flag: "--datapath",
        value: |o, _| o.datapath.bits().to_string(),
    },
    RenderOption {
        flag: "--newton-steps",
        value: |_, n| n.newton_steps.to_string(),
    },
    RenderOption {
        flag: "--table-entries",
        value: |_, n| n.table_entries.to_string(),
    },
    RenderOption {
        flag: "--guard-bits",
        value: |_, n| n.guard_bits.to_string(),
    },
    RenderOption {
        flag: "--ray-offset-lsb",
        value: |_, n| n.eps_lsb.to_string(),
    },
    RenderOption {
        flag: "--normals",
        value: |_, n| n.normals.name().into(),
    },
];

/// The flags and values that ask `morphosys render` for `opt` and `nm`.
pub fn argv(opt: &Options, nm: &Numerics) -> Vec<String> {
    RENDER_OPTIONS
        .iter()
        .flat_map(|r| [r.flag.to_string(), (r.value)(opt, nm)])
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
                RENDER_OPTIONS.iter().any(|r| r.flag == f) || OTHER_FLAGS.contains(&f.as_str());
            assert!(
                known,
                "render's {f} is neither a tracer option of the table nor another flag"
            );
        }
        for r in RENDER_OPTIONS {
            assert!(
                flags.iter().any(|f| f == r.flag),
                "{} is not a flag of render",
                r.flag
            );
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
