//! The editing session's ways out, on the baked sample assembly: a save rewrites only
//! the edited part records of the file (the binary chunk and every other JSON byte unchanged) and
//! reloads to the same parameters; the exported overrides, re-baked from the source model, give
//! the same part records as the saved file.

// The renderer's test helpers (a renderer that must exist, the baked sample), one copy for both crates.
#[path = "../../drafter-render/tests/common/mod.rs"]
mod common;

use std::path::Path;

use drafter_app::edit::{Adjust, Editor, ScreenView, Tool};
use drafter_format::PartRecord;
use drafter_render::camera::Camera;
use drafter_render::{Model, View};
use glam::DVec2;

const SIZE: (u32, u32) = (1024, 768);

fn bake(config: &drafter_bake::BakeConfig) -> Vec<u8> {
    let path = common::repo_path("samples/assembly.glb");
    let imported = drafter_io::import(&path).expect("sample imports");
    drafter_bake::bake(&imported.scene, config).expect("sample bakes").written.main
}

fn records(bytes: &[u8]) -> Vec<PartRecord> {
    let baked = drafter_format::read(bytes, &|_| None).expect("reads");
    baked.parts().into_iter().cloned().collect()
}

fn screen(model: &Model) -> ScreenView {
    let aspect = SIZE.0 as f32 / SIZE.1 as f32;
    let camera = Camera::fit(&model.fit_points, View::default(), aspect, false, 30.0);
    ScreenView::new(camera.clip_from_render(), model.origin, SIZE)
}

/// Two parts selected, an anchor dragged, q raised, the second part set to metal and flat grey.
fn edit(bytes: &[u8]) -> Editor {
    let model = Model::load_bytes(Path::new("sample.baked.glb"), bytes).expect("loads");
    let view = screen(&model);
    let mut editor = Editor::new(model.parts.iter().map(|p| p.record.clone()).collect());
    editor.selection.click(Some(3));
    editor.selection.toggle(6);
    assert!(editor.begin(Tool::Anchor, DVec2::new(500.0, 400.0)));
    assert_eq!(editor.drag_to(&view, DVec2::new(540.0, 380.0)), vec![3, 6]);
    assert!(editor.end());
    assert_eq!(editor.adjust(Adjust::Q(4)), vec![3, 6]);
    editor.selection.click(Some(6));
    editor.selection.click(Some(6));
    editor.selection.toggle(3);
    assert_eq!(editor.selection.parts, vec![6]);
    editor.adjust(Adjust::NextFlat);
    editor.adjust(Adjust::NextFlat);
    for _ in 0..6 {
        editor.adjust(Adjust::NextStyle);
    }
    assert_eq!(editor.unsaved(), vec![3, 6]);
    editor
}

#[test]
fn a_save_changes_only_the_edited_records_and_reloads_to_the_same_parameters() {
    let original = bake(&drafter_bake::BakeConfig::default());
    let editor = edit(&original);
    let edited: Vec<PartRecord> = editor.records().cloned().collect();
    let saved = drafter_format::replace_part_records(&original, &edited).expect("saves");
    assert_eq!(records(&saved), edited, "the saved file reads back to the edited records");
    let six = &edited[6];
    assert_eq!((six.flat, six.style.map(|s| s.name())), (Some(0.25), Some("metal")));

    // Byte for byte: the BIN chunk is the same, and the JSON is the old one with the two records'
    // text swapped.
    let (old_json, old_bin) = drafter_format::split_container(&original).unwrap();
    let (new_json, new_bin) = drafter_format::split_container(&saved).unwrap();
    assert_eq!(old_bin, new_bin);
    let before = records(&original);
    let text = |r: &PartRecord| serde_json::to_string(&serde_json::to_value(r).unwrap()).unwrap();
    let mut expected = String::from_utf8(old_json.to_vec()).unwrap().trim_end().to_owned();
    for id in [3, 6] {
        assert_eq!(expected.matches(&text(&before[id])).count(), 1);
        expected = expected.replace(&text(&before[id]), &text(&edited[id]));
    }
    assert_eq!(std::str::from_utf8(new_json).unwrap().trim_end(), expected);

    // Saving the same records again changes nothing; a record of another file is refused.
    assert_eq!(drafter_format::replace_part_records(&saved, &edited).unwrap(), saved);
    let mut stranger = edited[0].clone();
    stranger.id = 999;
    assert!(drafter_format::replace_part_records(&saved, &[stranger]).is_err());
    let mut bad = edited[1].clone();
    bad.gradient.q = 0.0;
    assert!(drafter_format::replace_part_records(&saved, &[bad]).is_err(), "q out of range");

    // The viewer loads the saved file with the new parameters on the GPU side too.
    let model = Model::load_bytes(Path::new("sample.baked.glb"), &saved).unwrap();
    assert_eq!(model.parts[6].gpu.flat, 0.25);
    assert_eq!(model.parts[3].gpu.gradient[0], edited[3].gradient.q as f32);
}

#[test]
fn exported_overrides_rebake_to_the_saved_records() {
    let original = bake(&drafter_bake::BakeConfig::default());
    let editor = edit(&original);
    let toml = editor.overrides_toml("sample.baked.glb").expect("edits to export");
    assert_eq!(toml.matches("[[part]]").count(), 2, "{toml}");
    let config = drafter_bake::BakeConfig::from_toml(&toml).unwrap_or_else(|e| panic!("{e}\n{toml}"));
    config.validate().unwrap_or_else(|e| panic!("{e}\n{toml}"));
    let rebaked = bake(&config);
    let edited: Vec<PartRecord> = editor.records().cloned().collect();
    assert_eq!(records(&rebaked), edited, "{toml}");
}

/// An edit reaches the next frame through the part table alone: the frame drawn after
/// `update_parts` equals a frame of the edited model uploaded from scratch, and differs from the
/// frame before only on the edited parts' pixels.
#[test]
fn an_edit_reaches_the_next_frame_through_the_part_table_alone() {
    let original = bake(&drafter_bake::BakeConfig::default());
    let options = drafter_render::RenderOptions { size: (320, 240), ..Default::default() };
    let mut model = Model::load_bytes(Path::new("sample.baked.glb"), &original).unwrap();
    // The base plate's gradient (q) and the right bracket's tone: both large in the default view.
    let mut editor = Editor::new(model.parts.iter().map(|p| p.record.clone()).collect());
    editor.selection.click(Some(0));
    editor.adjust(Adjust::Q(3));
    editor.selection.click(Some(1));
    editor.adjust(Adjust::NextFlat);
    assert_eq!(editor.unsaved(), vec![0, 1]);

    let mut renderer = common::renderer();
    renderer.set_model(&model).unwrap();
    let before = renderer.render(&options).unwrap();
    let ids = renderer.part_map().unwrap().unwrap().ids;
    for id in editor.unsaved() {
        assert!(model.set_part_record(editor.record(id).unwrap()));
    }
    renderer.update_parts(&model).unwrap();
    let after = renderer.render(&options).unwrap();

    let mut fresh = common::renderer();
    fresh.set_model(&model).unwrap();
    assert_eq!(fresh.render(&options).unwrap().rgba, after.rgba, "update_parts draws what a full upload draws");

    let edited = editor.unsaved();
    let mut changed = 0;
    for (k, (a, b)) in before.rgba.chunks_exact(4).zip(after.rgba.chunks_exact(4)).enumerate() {
        if a != b {
            changed += 1;
            assert!(ids[k].is_some_and(|id| edited.contains(&id)), "pixel {k} of part {:?} changed", ids[k]);
        }
    }
    assert!(changed > 20, "{changed} pixels changed");
}
