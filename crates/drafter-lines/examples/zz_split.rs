#[path = "../tests/common/mod.rs"]
mod common;
use drafter_core::{Topology, Weld};
use drafter_lines::*;
use std::time::Instant;
fn main() {
    let f = std::env::args().nth(1).unwrap();
    let which = std::env::args().nth(2).unwrap_or("gauss".into());
    let (mesh, _) = common::load_model(std::path::Path::new(&f)).unwrap();
    let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
    let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
    let o = SilhouetteOptions::default();
    for _ in 0..7 {
        let t = Instant::now();
        if which == "gauss" {
            let g = GaussMapHierarchy::build(&lines.candidate_normals, &o.gauss, &o.cost);
            println!("gauss {:.3} s ({} nodes)", t.elapsed().as_secs_f64(), g.node_count());
        } else if which == "bvh" {
            let b = ConeBvh::build(&lines.candidate_normals, &lines.candidate_points, &o.bvh, &o.cost);
            println!("bvh {:.3} s ({} nodes)", t.elapsed().as_secs_f64(), b.node_count());
        } else {
            let i = SilhouetteIndex::build(&lines, &o);
            println!("index {:.3} s", t.elapsed().as_secs_f64());
            drop(i);
        }
    }
}
