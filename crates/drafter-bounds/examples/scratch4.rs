use drafter_bounds::*;
use glam::DVec3;
fn main() {
    let m: ObbMethod = std::env::var("METHOD").unwrap_or("optimal".into()).parse().unwrap();
    for path in std::env::args().skip(1) {
        let text = std::fs::read_to_string(&path).unwrap();
        let pts: Vec<DVec3> = text.lines().filter_map(|l| { let v: Vec<f64> = l.split(' ').filter_map(|s| s.parse().ok()).collect(); (v.len()==3).then(|| DVec3::new(v[0],v[1],v[2])) }).collect();
        let (o, st) = oriented_box_with_stats(&pts, &ObbOptions::with_method(m)).unwrap();
        println!("{} {:.9e} {:?}", path, o.volume, st);
    }
}
