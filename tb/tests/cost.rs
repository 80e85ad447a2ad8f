//! What the silicon costs: the committed synthesis results
//! (rtl/verilog/synth/cost.json) hold together, are what Yosys gives for
//! the Verilog as it is, and reach `morphosys cost` and the sweep.

mod common;
use common::morphosys;
use rtl::rc::Datapath;
use tb::cost::{Synthesis, UNITS};

/// Yosys's CMOS transistor estimate per cell (`stat -tech cmos`), written
/// out here to recount each unit.
fn cmos(cell: &str) -> u64 {
    match cell {
        "$_NOT_" => 2,
        "$_NAND_" | "$_NOR_" => 4,
        "$_AND_" | "$_OR_" | "$_ANDNOT_" | "$_ORNOT_" => 6,
        "$_XOR_" | "$_XNOR_" | "$_MUX_" => 12,
        "$_DFF_P_" => 16,
        c => panic!("a cell type the estimate does not know: {c}"),
    }
}

#[test]
fn the_committed_results_hold_together() {
    let s = Synthesis::committed();
    for dp in [Datapath::W16, Datapath::W32] {
        let w = dp.bits() as u64;
        for (name, _) in UNITS {
            let u = s.unit(name, dp).unwrap_or_else(|| panic!("{name} at {dp}"));
            let cells: u64 = u.cells_by_type.values().sum();
            // the whole RC's count also has the RAM, a black box
            assert_eq!(u.cells, cells + (*name == "rc") as u64, "{name} {dp}");
            let t: u64 = u.cells_by_type.iter().map(|(c, n)| cmos(c) * n).sum();
            assert_eq!(u.transistors, t, "{name} {dp}");
            assert!(u.path_depth > 0);
        }
        // The state synthesized is the ISA's: 16 registers, out, the
        // accumulator (2W) and four flags.
        let rc = s.unit("rc", dp).unwrap();
        assert_eq!(rc.flip_flops, 16 * w + w + 2 * w + 4, "{dp}");
        assert_eq!(s.unit("rc_register_file", dp).unwrap().flip_flops, 16 * w);
        assert_eq!(s.unit("rc_multiplier", dp).unwrap().flip_flops, 2 * w);
        let ic = s.unit("rc_interconnect", dp).unwrap();
        assert_eq!(
            ic.flip_flops, 0,
            "the interconnect is wires and multiplexers"
        );
        assert_eq!(
            s.array_transistors(dp),
            64 * (rc.transistors + 512 * w * 6) + ic.transistors,
            "{dp}"
        );
    }
    // The multiplier (W x W into 2W, its accumulator and output stage)
    // is most of what 16 more bits add to the RC's logic.
    let grow = |n: &str| {
        s.unit(n, Datapath::W32).unwrap().transistors as i64
            - s.unit(n, Datapath::W16).unwrap().transistors as i64
    };
    assert!(
        grow("rc_multiplier") * 2 > grow("rc"),
        "{} of {}",
        grow("rc_multiplier"),
        grow("rc")
    );
    assert_eq!(s.clock_mhz(Datapath::W16), 300.0);
    assert!(s.clock_mhz(Datapath::W32) < 300.0);
}

#[test]
fn cost_prints_the_table_and_writes_json() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) = morphosys(dir.path(), &["cost", "--json", "cost.json"]);
    assert!(ok, "{err}");
    for what in [
        "multiplier + accumulator (rc_multiplier)",
        "array: 64 RCs with RAM, interconnect",
        "clock estimate",
        "not a sign-off",
    ] {
        assert!(out.contains(what), "{what}:\n{out}");
    }
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("cost.json")).unwrap())
            .unwrap();
    let s = Synthesis::committed();
    for (k, dp) in [Datapath::W16, Datapath::W32].iter().enumerate() {
        let w = &j["widths"][k];
        assert_eq!(w["datapath_bits"], dp.bits());
        assert_eq!(w["array_transistors"], s.array_transistors(*dp));
        assert_eq!(w["path_depth"], s.unit("rc", *dp).unwrap().path_depth);
    }
    let ratio = j["rc_area_32_over_16"].as_f64().unwrap();
    assert!(ratio > 1.5 && ratio < 4.0, "{ratio}");
    // --out needs --synthesize
    let (ok, _, err) = morphosys(dir.path(), &["cost", "--out", "x.json"]);
    assert!(!ok && err.contains("--synthesize"), "{err}");
    assert!(!dir.path().join("x.json").exists());
}

#[test]
#[ignore = "needs Yosys (Debian package yosys); .ci/run installs it and runs the ignored tests"]
fn the_committed_synthesis_is_what_yosys_gives() {
    let s = tb::cost::synthesize(&tb::testbench::cosim::verilog_dir()).unwrap();
    let c = Synthesis::committed();
    assert_eq!(
        s.tool, c.tool,
        "regenerate with `morphosys cost --synthesize` with this Yosys"
    );
    for u in &s.units {
        let dp = Datapath::from_bits(u.datapath_bits).unwrap();
        assert_eq!(
            Some(u),
            c.unit(&u.unit, dp),
            "{} at {dp}: run `morphosys cost --synthesize`",
            u.unit
        );
    }
    assert_eq!(s.units.len(), c.units.len());
}
