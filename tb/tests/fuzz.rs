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
