use drafter_bounds::*;
use glam::DVec3;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let pts: Vec<DVec3> = text.lines().filter_map(|l| { let v: Vec<f64> = l.split(' ').filter_map(|s| s.parse().ok()).collect(); (v.len()==3).then(|| DVec3::new(v[0],v[1],v[2])) }).collect();
    for m in ObbMethod::ALL {
        let (o, st) = oriented_box_with_stats(&pts, &ObbOptions::with_method(m)).unwrap();
        println!("{m:<8} vol {:.9e} half {:?} axes {:?}\n   {:?}", o.volume, o.half_extents, o.axes, st);
    }
    let hull = convex_hull(&pts, &HullOptions::default()).unwrap();
    println!("hull {:?} {} verts {} tris", hull.dimension, hull.vertices.len(), hull.triangles.len());
    println!("v0 {:?}", hull.vertices[0]);
    for t in &hull.triangles { if t.contains(&0) { println!("tri {:?} {:?}", t, t.map(|i| hull.vertices[i as usize])); } }
}
#[allow(dead_code)]
fn dump() {}
