//! Issue 17: parts that touch (clamped, pressed, stacked) recovered from one merged, unwelded
//! mesh. The generated family is `drafter_bench::assemblies`; the real assemblies are every glTF
//! assembly of ../shared/models flattened into one triangle soup (the true part of a triangle is
//! its instance). The bar: at least 99% of triangles in a part that matches one original
//! part (`assemblies::accuracy`), and the right part count. Figures are printed; run with
//! `--nocapture` to see them.
//!
//! Cases known to miss the bar are listed with the reason, and the tests check that they still
//! miss it, so that a fix has to take them off the list (a gap is visible, never skipped).

mod common;

use std::path::PathBuf;

use drafter_bench::assemblies::{Accuracy, accuracy, contact_assemblies, flatten};
use drafter_core::{PartId, Scene};
use drafter_segment::{Parts, SegmentMode, SegmentOptions, segment};

use common::load;

fn run(scene: &Scene, mode: SegmentMode) -> (Parts, String) {
    let (parts, diagnostics) = segment(scene, &SegmentOptions { mode, ..Default::default() });
    let notes: Vec<String> = diagnostics.iter().map(|d| format!("{:?} ×{}", d.kind, d.count)).collect();
    (parts, notes.join(", "))
}

/// Fraction of triangles in parts that are at least 99% one original part (regions and parts
/// never cross a contact).
fn purity(parts: &Parts, truth: &[u32]) -> f64 {
    let mut pure = 0;
    for p in 0..parts.len() {
        let mut from: Vec<u32> = parts.triangles_of(PartId::from(p)).map(|t| truth[t as usize]).collect();
        from.sort_unstable();
        let best = from.chunk_by(|a, b| a == b).map(<[u32]>::len).max().unwrap_or(0);
        if best * 100 >= from.len() * 99 {
            pure += from.len();
        }
    }
    pure as f64 / truth.len().max(1) as f64
}

fn line(name: &str, mode: SegmentMode, triangles: usize, acc: &Accuracy, notes: &str) {
    println!(
        "{name:38} {:10} {triangles:7} triangles: {:7.3}% matched, {} parts of {} {notes}",
        mode.name(),
        acc.matched * 100.0,
        acc.parts,
        acc.truth_parts
    );
}

/// Generated assemblies that miss the bar, and why.
const GENERATED_GAPS: [(&str, &str); 1] = [(
    "pin-in-hole/cracked",
    "the crack runs all the way around the pin: two open pieces that share no edge (crate docs, Limits)",
)];

#[test]
fn generated_contact_assemblies_come_back_as_their_parts() {
    let mut failed = Vec::new();
    for a in contact_assemblies() {
        let (scene, truth) = a.merged();
        for mode in [SegmentMode::Auto, SegmentMode::Components] {
            let (parts, notes) = run(&scene, mode);
            let acc = accuracy(&parts, &truth);
            line(&a.name, mode, truth.len(), &acc, &notes);
            let gap = GENERATED_GAPS.iter().any(|g| g.0 == a.name);
            if acc.passes() == gap {
                failed.push(format!("{} ({mode}): {acc:?}, listed as a gap: {gap}", a.name));
            }
        }
        // Regions cut parts further at creases, but never across a contact.
        let (regions, notes) = run(&scene, SegmentMode::Regions);
        let pure = purity(&regions, &truth);
        println!(
            "{:38} regions    {} regions, {:.3}% of triangles in one-part regions {notes}",
            a.name,
            regions.len(),
            pure * 100.0
        );
        if pure < 0.99 {
            failed.push(format!("{} (regions): {:.3}% pure", a.name, pure * 100.0));
        }
    }
    assert!(failed.is_empty(), "below the bar (or a listed gap that now passes): {failed:#?}");
}

/// The glTF assemblies of ../shared/models (relative to `gltf/`).
const GLTF_ASSEMBLIES: [&str; 7] = [
    "2CylinderEngine/2CylinderEngine.gltf",
    "Buggy/Buggy.gltf",
    "CycloidalDrive/cycloidal.glb",
    "FM1Satellite/FM1_satellite.glb",
    "GearboxAssy/GearboxAssy.gltf",
    "ReciprocatingSaw/ReciprocatingSaw.gltf",
    "RodAssembly/rod.glb",
];

/// Merged glTF assemblies that miss the bar. In each, some instances' meshes are not one
/// solid: several separate closed solids (a bearing's balls, four bolts in one mesh) or open
/// pieces that share no edge (faces whose tessellations do not weld). Segmenting each instance's
/// mesh on its own gives as many parts; nothing in the geometry says they are one part.
const GLTF_GAPS: [&str; 6] = [
    "2CylinderEngine/2CylinderEngine.gltf",
    "Buggy/Buggy.gltf",
    "CycloidalDrive/cycloidal.glb",
    "FM1Satellite/FM1_satellite.glb",
    "GearboxAssy/GearboxAssy.gltf",
    "ReciprocatingSaw/ReciprocatingSaw.gltf",
];

#[test]
fn merged_gltf_assemblies_come_back_as_their_parts() {
    let dir = PathBuf::from(common::MODELS).join("gltf");
    assert!(dir.is_dir(), "{} is missing: ../shared/models must sit next to the repository", dir.display());
    let mut failed = Vec::new();
    for name in GLTF_ASSEMBLIES {
        let scene = load(&format!("gltf/{name}"));
        let (merged, truth) = flatten(&scene);
        let (parts, notes) = run(&merged, SegmentMode::Auto);
        let acc = accuracy(&parts, &truth);
        let pure = purity(&parts, &truth);
        line(name, SegmentMode::Auto, truth.len(), &acc, &notes);
        println!("{:38} {:.3}% of triangles in parts that are ≥ 99% one instance", "", pure * 100.0);
        // Never a part across two instances, whatever the bar says.
        if pure < 0.99 {
            failed.push(format!("{name}: {:.3}% pure", pure * 100.0));
        }
        if acc.passes() == GLTF_GAPS.contains(&name) {
            failed.push(format!("{name}: {acc:?}, listed as a gap: {}", GLTF_GAPS.contains(&name)));
        }
    }
    assert!(failed.is_empty(), "below the bar (or a listed gap that now passes): {failed:#?}");
}
