use std::path::Path;
use drafter_core::{Topology, Weld, MeshId};
use glam::DVec3;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let scene = drafter_io::import(Path::new(&path)).unwrap().scene;
    let mesh = scene.mesh(MeshId(0));
    let topo = Topology::build(mesh, Weld::default());
    let mut vol = 0.0;
    for &[a,b,c] in &topo.faces { let p = |v: u32| topo.welded_positions[v as usize].as_dvec3(); vol += p(a).dot(p(b).cross(p(c))); }
    println!("signed vol {vol}");
    // manifold-only comps
    let mut parent: Vec<usize> = (0..topo.faces.len()).collect();
    fn find(p: &mut Vec<usize>, mut x: usize) -> usize { while p[x] != x { p[x] = p[p[x]]; x = p[x]; } x }
    for e in 0..topo.edge_count() { let f = topo.faces_of_edge(e); if f.len() == 2 { let a = find(&mut parent, f[0] as usize); let b = find(&mut parent, f[1] as usize); parent[a.max(b)] = a.min(b); } }
    let mut roots = std::collections::BTreeMap::<usize, usize>::new();
    for f in 0..topo.faces.len() { *roots.entry(find(&mut parent, f)).or_default() += 1; }
    println!("manifold-only comps {}: sizes {:?}", roots.len(), roots.values().collect::<Vec<_>>());
    let mut shown = 0;
    for e in 0..topo.edge_count() {
        let faces = topo.faces_of_edge(e);
        if faces.len() < 3 { continue; }
        let [a, b] = topo.edges[e];
        let pa = topo.welded_positions[a as usize].as_dvec3();
        let axis = (topo.welded_positions[b as usize].as_dvec3() - pa).normalize();
        let u = axis.any_orthonormal_vector(); let v = axis.cross(u);
        let mut fan: Vec<(f64, bool, u32, usize, f64)> = faces.iter().map(|&f| {
            let tri = topo.faces[f as usize];
            let k = topo.face_edges[f as usize].iter().position(|&x| x as usize == e).unwrap();
            let c = topo.welded_positions[tri[(k+2)%3] as usize].as_dvec3() - pa;
            let n = (topo.welded_positions[tri[1] as usize].as_dvec3()-topo.welded_positions[tri[0] as usize].as_dvec3()).cross(topo.welded_positions[tri[2] as usize].as_dvec3()-topo.welded_positions[tri[0] as usize].as_dvec3());
            (c.dot(v).atan2(c.dot(u)).to_degrees(), tri[k] == a, f, find(&mut parent, f as usize), n.length())
        }).collect();
        fan.sort_by(|x, y| x.0.total_cmp(&y.0));
        let alt = fan.len() % 2 == 0 && (0..fan.len()).all(|i| fan[i].1 != fan[(i+1)%fan.len()].1);
        if shown < 40 { println!("edge {e} len {:.4} alt {alt}: {:?}", (topo.welded_positions[b as usize].as_dvec3() - pa).length(), fan.iter().map(|x| format!("{:.1}{} f{} c{} A{:.2e}", x.0, if x.1 {"+"} else {"-"}, x.2, x.3, x.4)).collect::<Vec<_>>()); shown += 1; }
        let _ = DVec3::ZERO;
    }
}
