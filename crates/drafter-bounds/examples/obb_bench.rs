//! Oriented-box benchmark: time per part and volume relative to `optimal`, per method.
//!
//! ```text
//! cargo run --release -p drafter-bounds --example obb_bench                 # generated CAD-like parts
//! cargo run --release -p drafter-bounds --example obb_bench -- --count 220 --seed 7
//! cargo run --release -p drafter-bounds --example obb_bench -- --points a.xyz b.xyz   # your parts
//! cargo run --release -p drafter-bounds --example obb_bench -- --stress     # big hulls, 800k points
//! ```
//! A `.xyz` file holds one part: one point per line, `x y z` separated by spaces or commas (other lines
//! are skipped). Figures only, no assertions; ratios are taken within the same run.

#[path = "../tests/common/shapes.rs"]
mod shapes;

use std::time::Instant;

use drafter_bounds::{Coverage, HullDimension, ObbMethod, ObbOptions, oriented_box_with_stats};
use glam::DVec3;

/// Results of one method over all parts.
#[derive(Default)]
struct Row {
    seconds: Vec<f64>,
    ratios: Vec<(f64, String)>,
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| args.iter().position(|a| a == flag).and_then(|i| args.get(i + 1)).cloned();
    let parts: Vec<(String, Vec<DVec3>)> = if let Some(i) = args.iter().position(|a| a == "--points") {
        args[i + 1..]
            .iter()
            .take_while(|a| !a.starts_with("--"))
            .filter_map(|path| match std::fs::read_to_string(path) {
                Ok(text) => Some((path.clone(), parse_xyz(&text))),
                Err(e) => {
                    eprintln!("skipping {path}: {e}");
                    None
                }
            })
            .collect()
    } else if args.iter().any(|a| a == "--stress") {
        stress_parts()
    } else {
        let count: usize = value("--count").and_then(|v| v.parse().ok()).unwrap_or(110);
        let seed: u64 = value("--seed").and_then(|v| v.parse().ok()).unwrap_or(1);
        (0..count).map(|i| shapes::cad_like(seed, i)).map(|s| (s.name, s.points)).collect()
    };
    run(&parts);
}

fn parse_xyz(text: &str) -> Vec<DVec3> {
    text.lines()
        .filter_map(|line| {
            let v: Vec<f64> =
                line.split([' ', ',', '\t']).filter(|s| !s.is_empty()).filter_map(|s| s.parse().ok()).collect();
            (v.len() >= 3).then(|| DVec3::new(v[0], v[1], v[2]))
        })
        .collect()
}

fn stress_parts() -> Vec<(String, Vec<DVec3>)> {
    let mut rng = shapes::rng(99);
    let mut out = Vec::new();
    // About 2000 hull faces: 1000 points on an ellipsoid.
    out.push(("ellipsoid_1000pts".to_owned(), shapes::ellipsoid(&mut rng, 1000, DVec3::new(1.0, 2.0, 3.0))));
    out.push(("ellipsoid_3000pts".to_owned(), shapes::ellipsoid(&mut rng, 3000, DVec3::new(1.0, 2.0, 3.0))));
    out.push(("cylinder_512seg".to_owned(), shapes::cylinder(1.0, 3.0, 512, 50)));
    // A big mesh: 800k points inside a noisy box-like scan.
    let mut big = shapes::noisy_cloud(&mut rng, 800_000, DVec3::new(1.0, 0.6, 0.3));
    let rot = glam::DMat3::from_quat(rng.rotation());
    for p in &mut big {
        *p = rot * *p;
    }
    out.push(("gaussian_800k".to_owned(), big));
    let fine: Vec<DVec3> = shapes::cylinder(1.0, 3.0, 1024, 780).into_iter().map(|p| rot * p).collect();
    out.push(("cylinder_800k".to_owned(), fine));
    out
}

fn run(parts: &[(String, Vec<DVec3>)]) {
    let methods = [ObbMethod::Aabb, ObbMethod::Pca, ObbMethod::Hull, ObbMethod::Default, ObbMethod::Optimal];
    let mut rows: Vec<Row> = methods.iter().map(|_| Row::default()).collect();
    let mut over_budget = 0;
    let mut flat = 0;
    let mut hull_sizes = Vec::new();
    for (name, points) in parts {
        let mut volumes = Vec::new();
        let mut solid = true;
        for (m, method) in methods.iter().enumerate() {
            let options = ObbOptions::with_method(*method);
            // Repeat small parts so that the timer sees at least ~2 ms.
            let mut reps = 0;
            let start = Instant::now();
            let mut result = None;
            while reps == 0 || (start.elapsed().as_secs_f64() < 2e-3 && reps < 1000) {
                result = Some(oriented_box_with_stats(points, &options));
                reps += 1;
            }
            let seconds = start.elapsed().as_secs_f64() / reps as f64;
            match result {
                Some(Ok((obb, stats))) => {
                    volumes.push(obb.volume);
                    rows[m].seconds.push(seconds);
                    if *method == ObbMethod::Optimal {
                        solid = stats.hull_dimension == Some(HullDimension::Solid);
                        hull_sizes.push(stats.hull_vertices);
                        if stats.edge_search == Coverage::OverBudget || stats.face_search == Coverage::OverBudget {
                            over_budget += 1;
                        }
                    }
                }
                Some(Err(e)) => {
                    eprintln!("{name}: {method}: {e}");
                    volumes.push(f64::NAN);
                }
                None => volumes.push(f64::NAN),
            }
        }
        let optimal = volumes[methods.len() - 1];
        if !solid {
            flat += 1; // flat, linear or point-like: volumes are ~0, ratios meaningless
        }
        for (m, v) in volumes.iter().enumerate() {
            if solid && optimal > 0.0 && v.is_finite() {
                rows[m].ratios.push((v / optimal, name.clone()));
            }
        }
        if parts.len() <= 12 {
            // Per part: volume / optimal and milliseconds, for each method.
            let cells: Vec<String> = volumes
                .iter()
                .zip(&rows)
                .map(|(v, row)| {
                    format!("{:>7.4} {:>8.2}ms", v / optimal, 1e3 * row.seconds.last().copied().unwrap_or(0.0))
                })
                .collect();
            println!(
                "{name:<18} {:>7} pts hull {:>5}  {}",
                points.len(),
                hull_sizes.last().copied().unwrap_or(0),
                cells.join(" ")
            );
        }
    }
    println!();
    println!(
        "{} parts ({flat} flat or degenerate, left out of the ratios); Optimal over budget on {over_budget}",
        parts.len()
    );
    if !hull_sizes.is_empty() {
        hull_sizes.sort_unstable();
        println!(
            "hull vertices: median {}, max {}",
            hull_sizes[hull_sizes.len() / 2],
            hull_sizes[hull_sizes.len() - 1]
        );
    }
    println!(
        "{:<8} {:>14} {:>14} {:>12} {:>12}  worst part",
        "method", "mean ms/part", "max ms/part", "mean ratio", "worst ratio"
    );
    for (m, method) in methods.iter().enumerate() {
        let row = &rows[m];
        if row.seconds.is_empty() {
            continue;
        }
        let mean_ms = 1e3 * row.seconds.iter().sum::<f64>() / row.seconds.len() as f64;
        let max_ms = 1e3 * row.seconds.iter().cloned().fold(0.0, f64::max);
        let mean_ratio = row.ratios.iter().map(|r| r.0).sum::<f64>() / row.ratios.len().max(1) as f64;
        let worst = row
            .ratios
            .iter()
            .cloned()
            .fold((f64::NAN, String::new()), |a, b| if a.0.is_nan() || b.0 > a.0 { b } else { a });
        println!(
            "{:<8} {:>14.3} {:>14.3} {:>12.6} {:>12.6}  {}",
            method.name(),
            mean_ms,
            max_ms,
            mean_ratio,
            worst.0,
            worst.1
        );
    }
}
