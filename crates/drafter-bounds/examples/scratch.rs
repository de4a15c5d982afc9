#[path = "../tests/common/shapes.rs"]
mod shapes;
use std::time::Instant;
use drafter_bounds::*;
fn main() {
    let mut worst: f64 = 1.0; let mut sum = 0.0; let mut n = 0;
    let (mut t_full, mut t_nob) = (0.0, 0.0);
    for seed in 1..4 { for i in 0..110 {
        let s = shapes::cad_like(seed, i);
        let t = Instant::now();
        let o = oriented_box(&s.points, &ObbOptions::with_method(ObbMethod::Optimal)).unwrap();
        t_full += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let nb = oriented_box(&s.points, &ObbOptions { optimal_edge_budget: 0, ..ObbOptions::with_method(ObbMethod::Optimal) }).unwrap();
        t_nob += t.elapsed().as_secs_f64();
        let r = nb.volume / o.volume;
        if r > 1.0 + 1e-9 || r < 1.0 - 1e-9 { println!("{:<20} nobudget/full = {:.9}", s.name, r); }
        worst = worst.max(r); sum += r; n += 1;
    }}
    println!("mean {:.6} worst {:.6}  time full {:.1}s no-edges {:.1}s", sum / n as f64, worst, t_full, t_nob);
}
