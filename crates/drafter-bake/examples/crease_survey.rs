//! What the bake's edge classes gain from face borders and crease hysteresis: per model,
//! summed over its meshes (each mesh once, however many instances draw it), the creases with the
//! threshold alone, with hysteresis at a few continuation fractions, the continued edges and the
//! tangent edges the input's faces (glTF primitives) give. Parts are not separated (no part
//! borders), so counts differ slightly from a bake's report.
//!
//! `cargo run --release -p drafter-bake --example crease_survey -- MODEL...`

use drafter_core::Topology;
use drafter_lines::{FaceLabels, LineOptions, classify_edges_labelled};

mod common;

fn main() {
    let config = drafter_bake::BakeConfig::default();
    let base = config.lines.line_options();
    let fractions = [0.9f32, 0.8, 0.7];
    print!("| model | creases, threshold alone |");
    for f in fractions {
        print!(" creases at {f} (continued) |");
    }
    println!(" tangent edges | ms (0.8) |");
    println!("|---|---:|{}---:|---:|", "---:|".repeat(fractions.len()));
    for (path, scene) in common::scenes_from_args() {
        let topologies: Vec<(Topology, Option<Vec<u32>>)> = scene
            .meshes
            .iter()
            .filter(|m| !m.triangles.is_empty())
            .map(|m| (Topology::build(m, config.segment.weld), drafter_bake::input_faces(m)))
            .collect();
        let run = |options: &LineOptions| {
            let start = std::time::Instant::now();
            let (mut crease, mut continued, mut tangent) = (0, 0, 0);
            for (topology, faces) in &topologies {
                let labels = FaceLabels { parts: None, input_faces: faces.as_deref() };
                let lines = classify_edges_labelled(topology, labels, options).expect("labels fit");
                crease += lines.counts.crease;
                continued += lines.counts.continued;
                tangent += lines.counts.tangent;
            }
            (crease, continued, tangent, start.elapsed().as_secs_f64() * 1e3)
        };
        let name = std::path::Path::new(&path).file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or(path);
        let (off, _, _, _) = run(&LineOptions { crease_continue: 1.0, ..base });
        print!("| {name} | {off} |");
        let mut last = (0, 0.0);
        for f in fractions {
            let (crease, continued, tangent, ms) = run(&LineOptions { crease_continue: f, ..base });
            print!(" {crease} ({continued}) |");
            if f == 0.8 {
                last = (tangent, ms);
            }
        }
        println!(" {} | {:.0} |", last.0, last.1);
    }
}
