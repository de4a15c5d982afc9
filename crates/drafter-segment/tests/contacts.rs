//! Parts that touch (clamped, pressed, stacked) recovered from one merged, unwelded
//! mesh. The generated family is `drafter_testkit::assemblies`; the real assemblies are every glTF
//! assembly of ../shared/models flattened into one triangle soup (the true part of a triangle is
//! its instance). The bar: at least 99% of triangles in a part that matches one original
//! part (`assemblies::accuracy`), and the right part count. Figures are printed; run with
//! `--nocapture` to see them.
//!
//! Cases known to miss the bar are listed with the reason, and the tests check that they still
//! miss it, so that a fix has to take them off the list (a gap is visible, never skipped).

mod common;

use std::path::PathBuf;

use drafter_core::{PartId, Scene};
use drafter_segment::{Parts, SegmentMode, SegmentOptions, segment};
use drafter_testkit::assemblies::{Accuracy, accuracy, contact_assemblies, flatten, flatten_solids};

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

/// Generated assemblies that miss the bar in `components` mode, and why (`auto` meets it on all).
const GENERATED_GAPS: [(&str, &str); 1] = [(
    "pin-in-hole/cracked",
    "the crack runs all the way around the pin: two open pieces that share no edge; only `auto` glues \
     them across the crack (crate docs, Cracks)",
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
            let gap = mode == SegmentMode::Components && GENERATED_GAPS.iter().any(|g| g.0 == a.name);
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

/// Merged glTF assemblies that miss the bar against their solids
/// ([`drafter_testkit::assemblies::flatten_solids`]: an instance whose mesh holds several separate
/// closed bodies counts as that many parts), and why. Against their instances all but
/// RodAssembly miss it, since a mesh with a bearing and its balls, or four bolts, cannot be told
/// from four parts by geometry; the figures are printed.
const GLTF_GAPS: [(&str, &str); 4] = [
    (
        "2CylinderEngine/2CylinderEngine.gltf",
        "open pieces of one part whose seams lie up to 1e-5 of the diagonal apart: 94.1% glued at the \
         default 1e-7, 96.8% at 1e-6, 100% at 1e-5; ReciprocatingSaw rules out both (crate docs, Cracks)",
    ),
    (
        "Buggy/Buggy.gltf",
        "hundreds of open pieces that share no vertex with their part and seal against it, if at all, \
         only at 1e-4 of the diagonal",
    ),
    (
        "FM1Satellite/FM1_satellite.glb",
        "open pieces that float 3e-4 to 2e-3 of the diagonal off their part's solid (labels, pins): \
         nothing in the geometry ties them to it",
    ),
    (
        "ReciprocatingSaw/ReciprocatingSaw.gltf",
        "open pieces of one node that neither share a vertex nor seal each other at the default \
         tolerance (96.8%); from 1e-6 up, open bodies of different nodes whose rims seal each other \
         into one closed surface, as a cracked part's pieces do, are glued across nodes",
    ),
];

#[test]
fn merged_gltf_assemblies_come_back_as_their_parts() {
    let dir = PathBuf::from(common::MODELS).join("gltf");
    assert!(dir.is_dir(), "{} is missing: ../shared/models must sit next to the repository", dir.display());
    let mut failed = Vec::new();
    for name in GLTF_ASSEMBLIES {
        let scene = load(&format!("gltf/{name}"));
        let (merged, truth) = flatten(&scene);
        let (solids, several) = flatten_solids(&scene);
        let (parts, notes) = run(&merged, SegmentMode::Auto);
        let by_instance = accuracy(&parts, &truth);
        let acc = accuracy(&parts, &solids);
        let pure = purity(&parts, &truth);
        line(name, SegmentMode::Auto, truth.len(), &by_instance, &notes);
        println!(
            "{:38} against solids ({several} instances hold several): {:.3}% matched, {} parts of {}; \
             {:.3}% of triangles in parts that are ≥ 99% one instance",
            "",
            acc.matched * 100.0,
            acc.parts,
            acc.truth_parts,
            pure * 100.0
        );
        // Never a part across two instances, whatever the bar says.
        if pure < 0.99 {
            failed.push(format!("{name}: {:.3}% pure", pure * 100.0));
        }
        let gap = GLTF_GAPS.iter().any(|g| g.0 == name);
        if acc.passes() == gap {
            failed.push(format!("{name}: {acc:?} against solids, listed as a gap: {gap}"));
        }
    }
    assert!(failed.is_empty(), "below the bar (or a listed gap that now passes): {failed:#?}");
}
