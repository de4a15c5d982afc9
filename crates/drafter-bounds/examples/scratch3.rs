use std::time::Instant;
use drafter_bounds::*;
use glam::DVec3;
fn main() {
    let budget: u64 = std::env::var("BUDGET").ok().and_then(|v| v.parse().ok()).unwrap_or(DEFAULT_OPTIMAL_EDGE_BUDGET);
    let mut rows = Vec::new();
    for path in std::env::args().skip(1) {
        let text = std::fs::read_to_string(&path).unwrap();
        let pts: Vec<DVec3> = text.lines().filter_map(|l| { let v: Vec<f64> = l.split(' ').filter_map(|s| s.parse().ok()).collect(); (v.len()==3).then(|| DVec3::new(v[0],v[1],v[2])) }).collect();
        let t = Instant::now();
        let (o, st) = oriented_box_with_stats(&pts, &ObbOptions { optimal_edge_budget: budget, ..ObbOptions::with_method(ObbMethod::Optimal) }).unwrap();
        let to = t.elapsed().as_secs_f64()*1e3;
        let t = Instant::now();
        let d = oriented_box(&pts, &ObbOptions::with_method(ObbMethod::Default)).unwrap();
        let td = t.elapsed().as_secs_f64()*1e3;
        let nb = oriented_box(&pts, &ObbOptions { optimal_edge_budget: 0, ..ObbOptions::with_method(ObbMethod::Optimal) }).unwrap();
        rows.push((to, path.rsplit('/').next().unwrap().to_string(), pts.len(), st, d.volume / o.volume, td, nb.volume / o.volume));
    }
    rows.sort_by(|a, b| b.0.total_cmp(&a.0));
    for r in rows.iter().take(25) {
        println!("{:<40} n={:>7} hv={:>5} tris={:>5} normals={:>5} triples={:>8} {:?} opt {:.1} ms  def {:.2} ms def/opt {:.6} noedge/opt {:.6}", r.1, r.2, r.3.hull_vertices, r.3.hull_triangles, r.3.normals_tried, r.3.edge_triples, r.3.edge_search, r.0, r.5, r.4, r.6);
    }
    let n = rows.len() as f64;
    println!("parts {} mean opt {:.1} ms, mean def {:.2} ms, def/opt mean {:.5} worst {:.5}; noedge/opt mean {:.7} worst {:.6}", rows.len(), rows.iter().map(|r| r.0).sum::<f64>()/n, rows.iter().map(|r| r.5).sum::<f64>()/n, rows.iter().map(|r| r.4).sum::<f64>()/n, rows.iter().map(|r| r.4).fold(0.0, f64::max), rows.iter().map(|r| r.6).sum::<f64>()/n, rows.iter().map(|r| r.6).fold(0.0, f64::max));
    let below: Vec<_> = rows.iter().filter(|r| r.4 < 1.0 - 1e-9 || r.6 < 1.0 - 1e-9).map(|r| (&r.1, r.4, r.6)).collect();
    println!("parts where default or no-edge beat optimal: {:?}", below);
}
