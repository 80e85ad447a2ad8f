//! The RC in Verilog (rtl/verilog/) against the Rust RC, cycle for cycle
//! under Verilator, on both datapath widths: the RC testbench's stream and
//! a million random context cycles each; and the Verilog 8x8 array with
//! its interconnect against the Rust array.

use std::path::{Path, PathBuf};

use rtl::rc::Datapath;
use tb::testbench::cosim::{self, array_stream, random_stream, testbench_stream, Top, SEED};

fn build_dir() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("verilator")
}

#[test]
#[ignore = "needs Verilator (Debian package verilator); .ci/run installs it and runs the ignored tests"]
fn the_verilog_rc_is_the_rust_rc_cycle_for_cycle() {
    let tb = testbench_stream();
    assert_eq!(tb.len(), 7_697, "the RC testbench's stream");
    for dp in [Datapath::W16, Datapath::W32] {
        let program = cosim::build(Top::Rc, dp, &cosim::verilog_dir(), &build_dir()).unwrap();
        let r = cosim::run(dp, &program, &tb).unwrap();
        assert!(
            r.mismatch.is_none(),
            "{dp} RC, testbench stream: {}",
            r.mismatch.unwrap()
        );
        assert_eq!(r.cycles, 7_697);
        let n = 1_000_000;
        let r = cosim::run(dp, &program, &random_stream(dp, n, SEED)).unwrap();
        assert!(
            r.mismatch.is_none(),
            "{dp} RC, random: {}",
            r.mismatch.unwrap()
        );
        eprintln!("{dp} RC: {r:?}");
        // The stream reaches what it is meant to: most contexts execute,
        // and faults, illegal words and RAM writes are all compared often.
        assert_eq!(r.cycles, n as u64);
        assert!(r.executed > n as u64 / 2, "{r:?}");
        assert!(
            r.faults > 1_000 && r.illegal > 1_000 && r.ram_writes > 1_000,
            "{r:?}"
        );
    }
}

/// The 8x8 array with its interconnect, in SIMD, row and column mode.
#[test]
#[ignore = "needs Verilator (Debian package verilator); .ci/run installs it and runs the ignored tests"]
fn the_verilog_array_is_the_rust_array_cycle_for_cycle() {
    for dp in [Datapath::W16, Datapath::W32] {
        let program = cosim::build(Top::Array, dp, &cosim::verilog_dir(), &build_dir()).unwrap();
        let n = 20_000;
        let r = cosim::run_array(dp, &program, &array_stream(dp, n, SEED, false)).unwrap();
        assert!(r.mismatch.is_none(), "{dp} array: {}", r.mismatch.unwrap());
        eprintln!("{dp} array: {r:?}");
        assert_eq!(r.cycles, n as u64);
        // most RCs execute most cycles
        assert!(r.executed > 64 * n as u64 / 3, "{r:?}");
    }
}

/// A Verilog RC that rounds wrongly (the multiplier's output stage drops
/// its rounding bit where the accumulator is odd) is caught, and the
/// report names the cycle, the context and both states.
#[test]
#[ignore = "needs Verilator (Debian package verilator); .ci/run installs it and runs the ignored tests"]
fn a_difference_names_the_cycle_the_context_and_both_states() {
    let src = cosim::verilog_dir();
    let tmp = tempfile::tempdir().unwrap();
    for f in Top::Rc.files().iter().chain(&["rc_isa.vh", "cosim/bits.h"]) {
        let to = tmp.path().join(f);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(src.join(f), to).unwrap();
    }
    let m = tmp.path().join("rc_multiplier.v");
    let text = std::fs::read_to_string(&m).unwrap();
    let round = "x[s1[$clog2(A)-1:0]]";
    assert!(text.contains(round), "the rounding bit of rc_multiplier.v");
    std::fs::write(&m, text.replace(round, "(x[s1[$clog2(A)-1:0]] & ~x[0])")).unwrap();
    let program = cosim::build(
        Top::Rc,
        Datapath::W16,
        tmp.path(),
        &tmp.path().join("build"),
    );
    let r = cosim::run(Datapath::W16, &program.unwrap(), &testbench_stream()).unwrap();
    let m = r.mismatch.expect("the wrong rounding is found");
    eprintln!("{m}");
    assert!(
        m.starts_with(&format!("first difference at cycle {}:", r.cycles - 1)),
        "{m}"
    );
    assert!(
        m.contains("`mac r3, r1, r2, >>31`") || m.contains("`mul r3, r1, r2, >>"),
        "{m}"
    );
    assert!(
        m.contains("\n  Verilog: out ") && m.contains("\n  Rust:    out "),
        "{m}"
    );
}
