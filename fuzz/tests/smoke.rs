//! The CI's bounded campaign: a fixed seed and 300 cases per target (2,400 in all), seeds up to
//! 64 KB, so that it finishes in well under a minute in a debug build (12 s on the 2-core VM).
//! Every target must run all its cases, accept some and reject some (a mutator that never breaks a
//! seed, or a target whose seeds never import, tests nothing), and nothing may panic, fail
//! internally, pass the time budget or the memory budget.

use std::path::Path;

use drafter_fuzz::Target;
use drafter_fuzz::campaign::{self, Options};

const CASES_PER_TARGET: u64 = 300;

#[test]
fn a_bounded_campaign_finds_nothing() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let corpus = drafter_fuzz::seeds::corpus(&repo, 64 * 1024).expect("seeds");
    // The default campaign (one thread, every target, 20 s and 1 GiB per case) at a fixed seed and
    // number of cases.
    let options =
        Options { seed: 0x5eed, cases_per_target: Some(CASES_PER_TARGET), duration: None, ..Options::default() };
    let report = campaign::run(&corpus, &options);
    eprint!("{}", report.table());
    for target in Target::ALL {
        let stats = &report.stats[&target];
        assert_eq!(stats.cases, CASES_PER_TARGET, "{}", target.name());
        assert!(stats.accepted > 0, "{}: no case was accepted", target.name());
        assert!(stats.rejected > 0, "{}: no case was rejected", target.name());
    }
    let findings: Vec<String> = report
        .findings
        .iter()
        .map(|f| format!("{} {} case {}: {}", f.target.name(), f.kind.name(), f.case, f.message))
        .collect();
    assert!(findings.is_empty(), "findings:\n{}", findings.join("\n"));
}

#[test]
fn cases_are_deterministic() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let corpus = drafter_fuzz::seeds::corpus(&repo, 64 * 1024).expect("seeds");
    for target in Target::ALL {
        let seeds = corpus.of(target).len() as u64;
        for n in [0, seeds, seeds + 1, seeds + 50] {
            let a = campaign::case_bytes(&corpus, target, 7, n);
            assert_eq!(a, campaign::case_bytes(&corpus, target, 7, n), "{} case {n}", target.name());
        }
        // Mutated cases differ from their seeds, and from the same case under another seed.
        let n = seeds + 3;
        assert_ne!(campaign::case_bytes(&corpus, target, 7, n), campaign::case_bytes(&corpus, target, 8, n));
    }
}
