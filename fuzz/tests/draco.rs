//! The smoke run (`tests/smoke.rs`: seed 0x5eed, 300 cases per target) mutates the Draco seed
//! (fuzz/seeds/draco-cylinder.glb) as a GLB and as a .gltf, so every `cargo test` feeds
//! mutated Draco streams to the importer: a seed the campaign never picked would test nothing.

use std::path::Path;

use drafter_fuzz::Target;
use drafter_fuzz::campaign::case_bytes;

const SMOKE_SEED: u64 = 0x5eed;
const SMOKE_CASES_PER_TARGET: u64 = 300;

#[test]
fn the_smoke_run_mutates_the_draco_seed() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let corpus = drafter_fuzz::seeds::corpus(&repo, 64 * 1024).expect("seeds");
    let name = b"KHR_draco_mesh_compression";
    for target in [Target::Glb, Target::Gltf] {
        let seeds = corpus.of(target);
        assert!(seeds.iter().any(|s| s.name.contains("draco-cylinder")), "{}: no Draco seed", target.name());
        let mutated = (seeds.len() as u64..SMOKE_CASES_PER_TARGET)
            .map(|n| case_bytes(&corpus, target, SMOKE_SEED, n))
            .filter(|bytes| bytes.windows(name.len()).any(|w| w == name))
            .count();
        assert!(mutated >= 5, "{}: only {mutated} mutated cases carry a Draco stream", target.name());
    }
}
