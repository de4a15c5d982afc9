use std::path::Path;
use drafter_core::{Mesh, Scene, SourceFormat, Instance, MeshId, Topology, Weld, InstanceId};
use drafter_segment::*;
use glam::{DMat4, Vec3};

fn merged(scene: &Scene) -> (Scene, Vec<u32>) {
    let mut mesh = Mesh::default();
    let mut origin = Vec::new();
    for (i, inst) in scene.instances.iter().enumerate() {
        let m = scene.mesh(inst.mesh);
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(m.positions.iter().map(|p| inst.world_from_object.transform_point3(p.as_dvec3()).as_vec3()));
        for t in &m.triangles {
            let t = t.map(|v| v + base);
            mesh.triangles.push(if inst.flips_winding() { [t[0], t[2], t[1]] } else { t });
            origin.push(i as u32);
        }
    }
    let mut s = Scene::new(SourceFormat::Stl);
    s.meshes.push(mesh);
    s.instances.push(Instance { name: "merged".into(), mesh: MeshId(0), node: None, world_from_object: DMat4::IDENTITY });
    (s, origin)
}

fn main() {
    let path = std::env::args().nth(1).unwrap();
    let imported = drafter_io::import(Path::new(&path)).unwrap();
    let scene = imported.scene;
    let (s, origin) = if scene.instances.len() > 1 { merged(&scene) } else { let n = scene.mesh(MeshId(0)).triangle_count(); (scene.clone(), vec![0; n]) };
    let mesh = &s.meshes[0];
    let topo = Topology::build(mesh, Weld::default());
    println!("instances {} tris {} vcomp {} nm {} bd {}", scene.instances.len(), mesh.triangles.len(), topo.component_count, topo.nonmanifold_edge_count(), topo.boundary_edge_count());
    let t0 = std::time::Instant::now();
    let env = |k: &str, d: f64| std::env::var(k).ok().and_then(|v| v.parse().ok()).unwrap_or(d);
    let mode = if std::env::var("MODE").is_ok_and(|m| m == "auto") { SegmentMode::Auto } else { SegmentMode::Components };
    let (parts, diags) = segment(&s, &SegmentOptions { mode, merge_triangle_fraction: env("TF", DEFAULT_MERGE_TRIANGLE_FRACTION), merge_diagonal_fraction: env("DF", DEFAULT_MERGE_DIAGONAL_FRACTION), touch_fraction: env("TOUCH", DEFAULT_TOUCH_FRACTION), ..Default::default() });
    println!("components {} in {:?} {:?}", parts.len(), t0.elapsed(), diags);
    let diag = mesh.bounds().diagonal();
    let mut open = vec![false; parts.len()];
    for e in 0..topo.edge_count() { if topo.edge_valence(e) == 1 { let f = topo.faces_of_edge(e)[0]; open[parts.part_of(InstanceId(0), f).index()] = true; } }
    let ninst = scene.instances.len();
    let mut rows = Vec::new();
    let mut impure_tris = 0; let mut pure99 = 0u32;
    for (pi, p) in parts.parts.iter().enumerate() {
        let mut hist = std::collections::BTreeMap::<u32, u32>::new();
        let mut b = drafter_core::Aabb::EMPTY;
        let mut area = 0.0;
        for t in parts.triangles_of(drafter_core::PartId(pi as u32)) {
            *hist.entry(origin[t as usize]).or_default() += 1;
            let [a, bb, c] = mesh.triangles[t as usize].map(|v| mesh.positions[v as usize]);
            for v in [a, bb, c] { b.extend(v.as_dvec3()); }
            area += 0.5 * (bb - a).cross(c - a).length() as f64;
        }
        let (&dom, &cnt) = hist.iter().max_by_key(|(_, c)| **c).unwrap();
        impure_tris += p.triangles - cnt; if (cnt as f64) >= 0.99 * p.triangles as f64 { pure99 += p.triangles; }
        // boundary edges within part
        rows.push((p.triangles, b.diagonal() / diag, area, dom, cnt, hist.len(), pi));
    }
    // instance -> number of components
    let mut per_inst = vec![0u32; ninst];
    for r in &rows { per_inst[r.3 as usize] += 1; }
    let split = per_inst.iter().filter(|&&c| c > 1).count();
    println!("impure tris {impure_tris} ({:.3}%) pure99 {:.2}% parts {} inst {ninst}; instances split into >1 comps: {split}; instances with no dominant comp: {}", impure_tris as f64 / mesh.triangles.len() as f64 * 100.0, pure99 as f64 / mesh.triangles.len() as f64 * 100.0, parts.len(), per_inst.iter().filter(|&&c| c == 0).count());
    // primary = largest comp of its instance
    let mut best = vec![(0u32, usize::MAX); ninst];
    for (i, r) in rows.iter().enumerate() { if r.4 > best[r.3 as usize].0 { best[r.3 as usize] = (r.4, i); } }
    let total = mesh.triangles.len() as f64; let (mut po, mut so) = (0, 0);
    let mut prim: Vec<(f64, f64)> = Vec::new(); let mut sec: Vec<(f64, f64)> = Vec::new();
    for (i, r) in rows.iter().enumerate() { let v = (r.0 as f64 / total, r.1); if best[r.3 as usize].1 == i { if open[r.6] { po += 1 } } else if open[r.6] { so += 1 } if best[r.3 as usize].1 == i { prim.push(v) } else { sec.push(v) } }
    let q = |v: &mut Vec<(f64, f64)>| { let mut a: Vec<f64> = v.iter().map(|x| x.0).collect(); let mut d: Vec<f64> = v.iter().map(|x| x.1).collect(); a.sort_by(f64::total_cmp); d.sort_by(f64::total_cmp); let n = a.len(); if n == 0 { return String::new(); } let pick = |x: &Vec<f64>| [0, n/20, n/4, n/2, 3*n/4, n-1].iter().map(|&i| format!("{:.1e}", x[i])).collect::<Vec<_>>().join(" "); format!("n={n} tris-frac[min 5% 25% 50% 75% max]: {} | diag-frac: {}", pick(&a), pick(&d)) };
    println!("open primary {po} open secondary {so}");
    println!("primary   {}", q(&mut prim));
    println!("secondary {}", q(&mut sec));
    rows.sort_by(|a, b| a.0.cmp(&b.0));
    let verbose = std::env::args().nth(2).is_some();
    for r in rows.iter().take(if verbose { 10000 } else { 40 }) {
        println!("open {} tris {:6} diag {:.4} area {:.3e} inst {:3} ({} of {} tris; inst has {} comps, inst tris {}) mixed {}", open[r.6], r.0, r.1, r.2, r.3, r.4, r.0, per_inst[r.3 as usize], origin.iter().filter(|&&o| o == r.3).count(), r.5);
    }
    let _ = (Vec3::ZERO, InstanceId(0));
}

#[allow(dead_code)]
pub fn dummy() {}
