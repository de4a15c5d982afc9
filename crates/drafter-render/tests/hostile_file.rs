//! A baked file that lies about itself loads without allocating what it claims: a `partCount`
//! of four billion with 15 part records gives 15 parts and a notice.

mod common;

use std::path::Path;

use drafter_render::Model;

#[test]
fn a_huge_part_count_is_not_allocated() {
    let imported = drafter_io::import(&common::repo_path("samples/assembly.glb")).expect("sample imports");
    let baked = drafter_bake::bake(&imported.scene, &drafter_bake::BakeConfig::default()).expect("bakes");
    let honest = Model::load_bytes(Path::new("honest.glb"), &baked.written.main).expect("loads");

    let chunks = drafter_format::glb::split(&baked.written.main).expect("glb");
    let mut json: serde_json::Value = serde_json::from_slice(chunks.json).expect("json");
    json["extensions"][drafter_format::EXTENSION]["partCount"] = 4_000_000_000u32.into();
    let lying = drafter_format::glb::write(&serde_json::to_vec(&json).expect("json"), chunks.bin.unwrap_or_default())
        .expect("glb");
    let model = Model::load_bytes(Path::new("lying.glb"), &lying).expect("loads");
    assert_eq!(model.parts.len(), honest.parts.len());
    assert!(model.notices.iter().any(|n| n.contains("partCount 4000000000")), "{:?}", model.notices);
}
