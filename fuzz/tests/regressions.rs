//! Replays every file under the repository's `tests/regressions/<target>/` through its target and
//! checks the outcome `tests/regressions/outcomes.txt` documents for it: `accepted` (imports and
//! bakes, or reads and loads), or `rejected` with a typed input error whose message contains the
//! given words (what the CLI reports as exit 2, one line). A panic or an internal error fails, and so
//! does a file the list does not name or a name without a file, and one that raises the process's
//! peak RSS by more than [`PEAK_GROWTH_LIMIT`] (Linux; the blow-ups it once found took gigabytes).

use std::collections::BTreeMap;
use std::path::Path;

use drafter_fuzz::campaign::{reset_peak, rss_bytes};
use drafter_fuzz::{Outcome, Target};

/// Every regression file is small; none may need more than this (64 MiB) beyond what the process
/// held before it.
const PEAK_GROWTH_LIMIT: u64 = 64 << 20;

#[test]
fn every_regression_file_ends_as_documented() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/regressions");
    let listing = std::fs::read_to_string(root.join("outcomes.txt")).expect("tests/regressions/outcomes.txt");
    let mut expected: BTreeMap<String, (String, String)> = BTreeMap::new();
    for line in listing.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
        let (file, rest) = line.split_once(char::is_whitespace).unwrap_or_else(|| panic!("bad line: {line}"));
        let rest = rest.trim_start();
        let (outcome, needle) = rest.split_once(char::is_whitespace).unwrap_or((rest, ""));
        let needle = needle.trim().to_owned();
        assert!(matches!(outcome, "accepted" | "rejected"), "{file}: outcome must be accepted or rejected");
        assert!(expected.insert(file.to_owned(), (outcome.to_owned(), needle)).is_none(), "{file} listed twice");
    }

    let dir = std::env::temp_dir().join(format!("drafter-regressions-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch");
    drafter_fuzz::campaign::quiet_panics();
    let mut replayed = 0;
    let mut failures = Vec::new();
    let mut folders: Vec<_> =
        std::fs::read_dir(&root).expect("tests/regressions").flatten().map(|e| e.path()).collect();
    folders.sort();
    for folder in folders.iter().filter(|p| p.is_dir()) {
        let name = folder.file_name().unwrap_or_default().to_string_lossy().into_owned();
        let target = Target::from_name(&name).unwrap_or_else(|| panic!("tests/regressions/{name}: not a target"));
        let mut files: Vec<_> = std::fs::read_dir(folder).expect("folder").flatten().map(|e| e.path()).collect();
        files.sort();
        for file in files {
            let key = format!("{name}/{}", file.file_name().unwrap_or_default().to_string_lossy());
            let Some((outcome, needle)) = expected.remove(&key) else {
                failures.push(format!("{key}: not listed in outcomes.txt"));
                continue;
            };
            let bytes = std::fs::read(&file).expect("read");
            reset_peak();
            let before = rss_bytes("VmRSS");
            let got = drafter_fuzz::run_case(target, &bytes, &dir);
            let growth = rss_bytes("VmHWM").saturating_sub(before);
            replayed += 1;
            if growth > PEAK_GROWTH_LIMIT {
                failures.push(format!("{key}: peak RSS grew by {} MiB", growth >> 20));
            }
            let ok = match (&got, outcome.as_str()) {
                (Outcome::Accepted, "accepted") => true,
                (Outcome::Rejected(message), "rejected") => message.to_lowercase().contains(&needle.to_lowercase()),
                _ => false,
            };
            if !ok {
                failures.push(format!("{key}: expected {outcome} {needle:?}, got {got:?}"));
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    failures.extend(expected.keys().map(|k| format!("{k}: listed but missing")));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(replayed > 0, "no regression file replayed");
}
