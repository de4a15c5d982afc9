//! Axis views against the iso view: `cargo run --release -p drafter-draw --example axis_views --
//! FILE...` bakes each file in memory (as `drafter draw` does with an unbaked file), draws it from
//! the front (elevation exactly 0), the top (the steepest elevation the camera accepts) and the
//! default iso view, orthographic, 1000×1000 with hidden lines, and prints per view the visible
//! and hidden length, the visible length drawn twice (lying within half a pixel of another visible
//! stroke, `drafter_draw::doubled_visible_length`), the pieces merged and the drawing's time.

use std::path::Path;

use drafter_draw::{DrawOptions, Hidden};
use drafter_scene::{Model, View};

fn main() {
    let files: Vec<String> = std::env::args().skip(1).collect();
    if files.is_empty() {
        eprintln!("usage: axis_views FILE...");
        std::process::exit(2);
    }
    println!("model\tview\tvisible_px\thidden_px\tdoubled_px\tdoubled_%\tmerged\tms");
    for file in &files {
        let path = Path::new(file);
        let imported = drafter_io::import(path).unwrap_or_else(|e| panic!("{file}: {e}"));
        let baked = drafter_bake::bake(&imported.scene, &drafter_bake::BakeConfig::default())
            .unwrap_or_else(|e| panic!("{file}: bake failed: {e}"));
        let model = Model::load_bytes(&path.with_extension("baked.glb"), &baked.written.main).expect("loads");
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        for (label, view) in [("front", (0.0, 0.0)), ("top", (0.0, 89.99999)), ("iso", (35.0, 25.0))] {
            let options = DrawOptions {
                size: (1000, 1000),
                view: View { azimuth_deg: view.0, elevation_deg: view.1 },
                orthographic: true,
                hidden: Hidden::Dashed,
                ..DrawOptions::default()
            };
            let drawing = drafter_draw::draw(&model, &options);
            let (doubled, visible) = drafter_draw::doubled_visible_length(&drawing, 0.5);
            println!(
                "{name}\t{label}\t{visible:.0}\t{:.0}\t{doubled:.0}\t{:.2}\t{}\t{:.1}",
                drawing.stats.hidden_px,
                100.0 * doubled / visible.max(1e-9),
                drawing.stats.merged,
                drawing.stats.elapsed.as_secs_f64() * 1e3
            );
        }
    }
}
