//! Oriented boxes of every part of ../shared/models (parts as `drafter bake` cuts them): the default
//! box contains every vertex of its part, and rotating a part by a random rotation gives the same box
//! volume within 0.1%.

use drafter_testkit::models::shared_models;

use drafter_bounds::{ObbOptions, oriented_box};
use drafter_core::PartId;
use drafter_segment::{SegmentOptions, segment};
use glam::{DQuat, DVec3};

/// A seeded uniform random rotation.
fn rotation(seed: u64) -> DQuat {
    drafter_testkit::Rng::new(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1).rotation()
}

#[test]
fn every_part_box_contains_its_points_and_survives_rotation() {
    let files = drafter_testkit::models::input_files(&shared_models(), drafter_io::has_input_extension);
    assert!(files.len() >= 40, "only {} models", files.len());
    let options = ObbOptions::default();
    let (mut parts_checked, mut rotated_checked) = (0, 0);
    let mut failures = Vec::new();
    for file in &files {
        let scene = drafter_io::import(file).expect("imports").scene;
        let (parts, _) = segment(&scene, &SegmentOptions::default());
        for p in 0..parts.len() {
            let points = drafter_bake::part_points(&scene, &parts, PartId::from(p));
            let obb = oriented_box(&points, &options).expect("box");
            let eps = 1e-9 * (obb.half_extents.max_element() + obb.center.abs().max_element()).max(1e-30);
            if let Some(q) = points.iter().find(|&&q| !obb.contains(q, eps)) {
                failures.push(format!("{}: part {p}: point {q:?} outside its box", file.display()));
            }
            parts_checked += 1;
            // Rotation: every 5th part (time), non-flat parts only.
            if p % 5 != 0 || obb.volume <= 1e-9 * (2.0 * obb.half_extents.max_element()).powi(3) {
                continue;
            }
            let centre = points.iter().copied().sum::<DVec3>() / points.len() as f64;
            let r = rotation(parts_checked as u64);
            let turned: Vec<DVec3> = points.iter().map(|&q| centre + r * (q - centre)).collect();
            let again = oriented_box(&turned, &options).expect("box");
            let change = (again.volume / obb.volume - 1.0).abs();
            if change > 1e-3 {
                failures.push(format!(
                    "{}: part {p}: volume {} → {} after rotation ({:.3}%)",
                    file.display(),
                    obb.volume,
                    again.volume,
                    100.0 * change
                ));
            }
            rotated_checked += 1;
        }
    }
    assert!(parts_checked > 600, "only {parts_checked} parts");
    assert!(rotated_checked > 100, "only {rotated_checked} rotated parts");
    assert!(failures.is_empty(), "{} of {parts_checked} parts failed:\n{}", failures.len(), failures.join("\n"));
}
