//! The fuzzers at a CI-sized count, and the regression corpus: every kept
//! input must be accepted or rejected with a located error, never panic.
//! (`morphosys fuzz --count 1000000` is the full run; see the README.)

use tb::fuzz::{check, corpus_dir, run, ALL};

#[test]
fn every_target_survives_mutated_and_random_inputs() {
    for t in ALL {
        let rep = run(t, 3000, 0xC1, |_| {});
        assert_eq!(rep.inputs, 3000);
        assert!(
            rep.findings.is_empty(),
            "{}: {} findings, first: {}",
            t.name(),
            rep.findings.len(),
            rep.findings[0].what
        );
        // The mutations are not all rejected: the fuzzer reaches past the parser.
        assert!(
            rep.accepted > 30,
            "{}: only {} accepted",
            t.name(),
            rep.accepted
        );
        assert!(
            rep.rejected > 300,
            "{}: only {} rejected",
            t.name(),
            rep.rejected
        );
    }
}

#[test]
fn regression_corpus() {
    let mut n = 0;
    for t in ALL {
        let dir = corpus_dir(t);
        let mut paths: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .collect();
        paths.sort();
        for p in paths {
            let input = std::fs::read(&p).unwrap();
            let r = std::panic::catch_unwind(|| check(t, &input));
            match r {
                Ok(Ok(_)) => {}
                Ok(Err(what)) => panic!("{}: {what}", p.display()),
                Err(_) => panic!("{}: panicked", p.display()),
            }
            n += 1;
        }
    }
    assert!(n >= 10, "corpus has {n} inputs");
}

/// The seeds are embedded (run outside the source tree
/// the fuzzer used to find no seeds and fuzz nothing, silently): every
/// conformance program is among them, and `morphosys fuzz` run from an
/// empty folder accepts some inputs of every target.
#[test]
fn seeds_are_embedded_and_complete() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/conformance");
    let mut on_disk: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".s"))
        .collect();
    on_disk.sort();
    let embedded: Vec<String> = tb::fuzz::CONFORMANCE
        .iter()
        .map(|(n, _)| n.to_string())
        .collect();
    assert_eq!(
        embedded, on_disk,
        "tb/src/fuzz.rs CONFORMANCE must list firmware/conformance/*.s"
    );
    let tmp = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_morphosys"))
        .current_dir(tmp.path())
        .args(["fuzz", "--count", "300"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    for t in ALL {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{}:", t.name())))
            .unwrap_or_else(|| panic!("no line for {}: {text}", t.name()));
        assert!(!line.contains(" 0 accepted"), "{line}");
    }
}

/// The structure-aware generator reaches what mutations of the seeds do
/// not: expressions thousands deep, absurd counts and
/// files of megabytes; and every such input is handled (no finding).
#[test]
fn structured_inputs_reach_deep_nesting_absurd_counts_and_large_files() {
    let mut g = tb::fuzz::Rng::new(7);
    let mut deep = false;
    let mut absurd = false;
    let mut large = false;
    let mut huge_image = false;
    for _ in 0..300 {
        for t in ALL {
            let input = tb::fuzz::structured::input(t, &mut g);
            let text = String::from_utf8_lossy(&input);
            deep |= t == tb::fuzz::Target::Asm
                && (text.contains(&"(".repeat(1000)) || text.contains(&"-".repeat(1000)));
            absurd |= t == tb::fuzz::Target::Nff && text.contains("p 1000000000");
            large |= input.len() > 1 << 20;
            huge_image |=
                t == tb::fuzz::Target::Image && input.len() >= 16 && input[12..16] == [0xff; 4];
            let r = std::panic::catch_unwind(|| check(t, &input));
            assert!(
                matches!(r, Ok(Ok(_))),
                "{}: {:?}",
                t.name(),
                r.map(|x| x.err())
            );
        }
        if deep && absurd && large && huge_image {
            return;
        }
    }
    panic!(
        "not reached: deep {deep}, absurd {absurd}, large {large}, huge image count {huge_image}"
    );
}
