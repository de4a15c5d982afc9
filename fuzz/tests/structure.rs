//! An `images` entry with neither `uri` nor `bufferView` made the gltf crate panic
//! (gltf-1.4.1 `src/image.rs:128`, "called `Option::unwrap()` on a `None` value"), and the smoke
//! run did not reach it: no glTF or GLB seed had an image (the samples have none; the baked files,
//! which do, are the `baked` target's, whose readers do not use the gltf crate), and the mutators
//! changed values, not the shape of the document.
//!
//! This test holds the fuzzer to reaching that class from the shipped seeds within the smoke run's
//! budget (`tests/smoke.rs`: seed 0x5eed, 300 cases per target, seeds up to 64 KB), and the importer
//! to refusing it as input: some case has an image without a source; every such case is refused or
//! accepted, never a panic; at least one is refused for that image, naming it, and is accepted once
//! the image is given a source. That last case is one an earlier importer took as far as
//! asking every image's source (the file is otherwise good and no earlier image names a file, which
//! would have stopped the question), where the gltf crate panics on it (drafter-io's
//! `what_the_gltf_crate_unwraps_is_refused_by_its_place` shows the panic).

use std::path::Path;

use drafter_fuzz::campaign::{self, case_bytes};
use drafter_fuzz::{Outcome, Target, run_case};
use serde_json::Value;

/// The smoke run's budget and seed (`tests/smoke.rs`).
const SMOKE_CASES_PER_TARGET: u64 = 300;
const SMOKE_SEED: u64 = 0x5eed;

const PNG_URI: &str = "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8DwHwAFBQIAX8jx0gAAAABJRU5ErkJggg==";

/// The JSON of a case and, for a GLB, its BIN chunk.
fn split(target: Target, bytes: &[u8]) -> Option<(Value, Option<Vec<u8>>)> {
    match target {
        Target::Gltf => Some((serde_json::from_slice(bytes).ok()?, None)),
        _ => {
            let chunks = drafter_format::glb::split(bytes).ok()?;
            Some((serde_json::from_slice(chunks.json).ok()?, Some(chunks.bin.unwrap_or_default().to_vec())))
        }
    }
}

fn join(doc: &Value, bin: Option<&[u8]>) -> Vec<u8> {
    let json = serde_json::to_vec(doc).expect("json");
    match bin {
        None => json,
        Some(bin) => drafter_format::glb::write(&json, bin).expect("glb"),
    }
}

fn names_a_file(image: &Value) -> bool {
    image.get("uri").and_then(Value::as_str).is_some_and(|u| !u.starts_with("data:"))
}

#[test]
fn the_structural_mutators_reach_an_image_without_a_source_within_the_smoke_budget() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let corpus = drafter_fuzz::seeds::corpus(&repo, 64 * 1024).expect("seeds");
    campaign::quiet_panics();
    let dir = std::env::temp_dir().join(format!("drafter-structure-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch");

    let mut reached = Vec::new();
    let mut proofs = Vec::new();
    let mut findings = Vec::new();
    for target in [Target::Gltf, Target::Glb] {
        let seeds = corpus.of(target).len() as u64;
        assert!(
            corpus.of(target).iter().any(|s| split(target, &s.bytes).is_some_and(|(d, _)| d["images"].is_array())),
            "{}: no seed has images",
            target.name()
        );
        for n in seeds..SMOKE_CASES_PER_TARGET {
            let bytes = case_bytes(&corpus, target, SMOKE_SEED, n);
            let Some((doc, bin)) = split(target, &bytes) else { continue };
            let Some(images) = doc["images"].as_array() else { continue };
            let Some(k) =
                images.iter().position(|i| i.is_object() && i.get("uri").is_none() && i.get("bufferView").is_none())
            else {
                continue;
            };
            let outcome = run_case(target, &bytes, &dir);
            if outcome.is_finding() {
                findings.push(format!("{} case {n}: {outcome:?}", target.name()));
            }
            reached.push(format!("{} case {n}: /images/{k}, {outcome:?}", target.name()));
            let named = matches!(&outcome, Outcome::Rejected(m) if m.contains(&format!("/images/{k}: an image needs a uri or a bufferView")));
            if !named || images[..k].iter().any(names_a_file) {
                continue;
            }
            let mut repaired = doc.clone();
            repaired["images"][k]["uri"] = PNG_URI.into();
            if run_case(target, &join(&repaired, bin.as_deref()), &dir) == Outcome::Accepted {
                proofs.push(format!("{} case {n}", target.name()));
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    // The quiet hook would swallow the messages of the assertions below.
    drop(std::panic::take_hook());
    assert!(findings.is_empty(), "cases that panic or fail internally:\n{}", findings.join("\n"));
    eprintln!("cases with an image without a source:\n{}", reached.join("\n"));
    eprintln!("refused for that image alone: {}", proofs.join(", "));
    assert!(!reached.is_empty(), "no case of the smoke budget has an image without uri and bufferView");
    assert!(!proofs.is_empty(), "no case is refused for its image alone:\n{}", reached.join("\n"));
}

/// Each structural edit does what it says on a document that has what it needs, and leaves a
/// document without it alone.
#[test]
fn structural_edits_change_the_shape() {
    let doc: Value = serde_json::json!({
        "asset": {"version": "2.0"},
        "images": [{"uri": "a.png"}, {"bufferView": 0, "mimeType": "image/png"}],
        "bufferViews": [{"buffer": 0, "byteLength": 4}],
        "buffers": [{"byteLength": 4, "uri": "data:application/octet-stream;base64,AAAAAA=="}],
        "textures": [{"source": 1}]
    });
    let mut seen_empty_image = false;
    let mut seen_sourceless = false;
    let mut seen_changed = 0;
    for seed in 0..2000 {
        let mut rng = drafter_fuzz::Rng::new(seed);
        let mut edited = doc.clone();
        drafter_fuzz::mutate::mutate_structure(&mut edited, &mut rng);
        seen_changed += usize::from(edited != doc);
        if let Some(images) = edited["images"].as_array() {
            seen_empty_image |= images.iter().any(|i| i.as_object().is_some_and(serde_json::Map::is_empty));
            seen_sourceless |=
                images.iter().any(|i| i.is_object() && i.get("uri").is_none() && i.get("bufferView").is_none());
        }
    }
    assert!(seen_empty_image && seen_sourceless, "empty {seen_empty_image}, sourceless {seen_sourceless}");
    assert!(seen_changed > 1800, "only {seen_changed} of 2000 edits changed the document");
    let mut scalar = serde_json::json!(7);
    drafter_fuzz::mutate::mutate_structure(&mut scalar, &mut drafter_fuzz::Rng::new(1));
}
