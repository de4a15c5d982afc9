//! Scaling of the bake: 4:1 midpoint subdivisions of one model from ~10k to ~2M triangles, each
//! baked with the default config in its own process; per stage, the fitted exponent `b` of
//! `time ≈ a · triangles^b` (least squares on log–log) and the peak memory per triangle.
//!
//! ```text
//! cargo run --release -p drafter-bench --example scaling -- [MODEL] [--max-triangles N] [--repeat N] [--json FILE]
//!     [--first-use-order]
//! ```
//!
//! MODEL defaults to `../shared/models/obj/cad-denoising-set/partLp.obj` (8,530 triangles: 8.5k,
//! 34k, 136k, 546k, 2.18M). Each level runs `--repeat` times (default 3; the fastest time of each
//! stage counts) in a child process (this program with `--level K`) so
//! that its peak resident memory (`VmHWM` in /proc/self/status, Linux) is its own; memory per
//! triangle is reported as the peak over the triangles and as the growth during the bake (peak minus
//! the resident size before it, which holds the subdivided input).
//!
//! `--first-use-order` numbers each level's vertices in the order its triangles first use them (as
//! real meshes come), instead of the subdivision's order, which appends every level's midpoints
//! after the older vertices and so scatters each triangle's corners over the whole array.
//!
//! Midpoint subdivision keeps each input facet flat, so the new interior edges are coplanar: the
//! silhouette candidates grow about 2× per level while triangles grow 4× (printed per level).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use drafter_bake::{BakeConfig, bake};
use drafter_testkit::generate::TriMesh;
use serde_json::{Value, json};

fn status_kib(field: &str) -> Option<f64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with(field))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// One level in this process: subdivide `level` times, bake, print one JSON line.
fn child(model: &Path, level: u32, first_use_order: bool) -> Result<(), Box<dyn std::error::Error>> {
    let scene = drafter_io::import(model)?.scene;
    let mut mesh = TriMesh::default();
    for inst in &scene.instances {
        let m = scene.mesh(inst.mesh);
        let base = mesh.positions.len() as u32;
        let placed = TriMesh { positions: m.positions.clone(), triangles: m.triangles.clone() }
            .transformed(&inst.world_from_object);
        mesh.positions.extend(placed.positions);
        mesh.triangles.extend(placed.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    for _ in 0..level {
        mesh = mesh.subdivided();
    }
    if first_use_order {
        renumber_by_first_use(&mut mesh);
    }
    let scene = mesh.to_scene("subdivided");
    drop(mesh);
    let before_kib = status_kib("VmRSS:").unwrap_or(0.0);
    let start = Instant::now();
    let baked = bake(&scene, &BakeConfig::default())?;
    let total_ms = start.elapsed().as_secs_f64() * 1e3;
    let peak_kib = status_kib("VmHWM:").unwrap_or(0.0);
    let stages: serde_json::Map<String, Value> =
        baked.report.stages.iter().map(|s| (s.name.to_owned(), json!(s.ms))).collect();
    let candidates = baked.report.lines.as_ref().map_or(0, |l| l.silhouette_candidates);
    println!(
        "{}",
        json!({
            "level": level,
            "triangles": baked.report.triangles,
            "candidates": candidates,
            "total_ms": total_ms,
            "stages": stages,
            "output_bytes": baked.report.output_bytes,
            "rss_before_kib": before_kib,
            "peak_kib": peak_kib,
        })
    );
    Ok(())
}

/// Numbers the vertices in the order the triangles first use them, as exporters and scanners
/// write meshes (and as meshoptimizer's vertex-fetch optimisation leaves them). Midpoint
/// subdivision appends every level's midpoints after all older vertices, so a triangle's corners
/// lie far apart in the vertex array, further at every level, and the topology's walk and the
/// normals' fans miss the cache more (docs/bench.md#scaling).
fn renumber_by_first_use(mesh: &mut TriMesh) {
    let mut new_of = vec![u32::MAX; mesh.positions.len()];
    let mut positions = Vec::with_capacity(mesh.positions.len());
    for t in &mut mesh.triangles {
        for v in t.iter_mut() {
            if new_of[*v as usize] == u32::MAX {
                new_of[*v as usize] = positions.len() as u32;
                positions.push(mesh.positions[*v as usize]);
            }
            *v = new_of[*v as usize];
        }
    }
    mesh.positions = positions;
}

/// Least-squares slope of ln y over ln x.
fn exponent(points: &[(f64, f64)]) -> f64 {
    let pts: Vec<(f64, f64)> =
        points.iter().filter(|(x, y)| *x > 0.0 && *y > 0.0).map(|(x, y)| (x.ln(), y.ln())).collect();
    let n = pts.len() as f64;
    if n < 2.0 {
        return f64::NAN;
    }
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    sxy / sxx
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flag = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    let first_use_order = args.iter().any(|a| a == "--first-use-order");
    let model = PathBuf::from(
        args.first()
            .filter(|a| !a.starts_with("--"))
            .cloned()
            .unwrap_or_else(|| "../shared/models/obj/cad-denoising-set/partLp.obj".into()),
    );
    if let Some(level) = flag("--level") {
        // The heap policy of `drafter bake` (one arena, freed memory reused), so that a level's time
        // and peak are the command's.
        drafter_bake::heap::keep_freed_memory();
        return child(&model, level.parse()?, first_use_order);
    }
    let max_triangles: usize = flag("--max-triangles").map_or(Ok(2_200_000), |v| v.parse())?;
    let repeat: usize = flag("--repeat").map_or(Ok(3), |v| v.parse())?;
    let base = drafter_io::import(&model)?.scene.instanced_triangle_count();
    if base == 0 {
        return Err(format!("{}: no triangles", model.display()).into());
    }
    let levels: Vec<u32> = (0..12).take_while(|&k| base.saturating_mul(1 << (2 * k)) <= max_triangles).collect();
    let exe = std::env::current_exe()?;
    let mut rows = Vec::new();
    println!("{}: {base} triangles, levels {levels:?}", model.display());
    println!(
        "{:>10} {:>10} {:>9}  stages (ms)  peak MB  bytes/triangle (peak, growth)",
        "triangles", "candidates", "total ms"
    );
    for level in levels {
        // `repeat` fresh processes per level; per stage the fastest run counts (shared machine),
        // memory from the first (it does not depend on load).
        let mut row: Option<Value> = None;
        for _ in 0..repeat {
            let mut command = Command::new(&exe);
            command.arg(&model).arg("--level").arg(level.to_string());
            if first_use_order {
                command.arg("--first-use-order");
            }
            let out = command.output()?;
            if !out.status.success() {
                return Err(format!("level {level} failed: {}", String::from_utf8_lossy(&out.stderr)).into());
            }
            let run: Value = serde_json::from_slice(&out.stdout)?;
            row = Some(match row.take() {
                None => run,
                Some(mut best) => {
                    if let (Some(b), Some(r)) = (best["stages"].as_object_mut(), run["stages"].as_object()) {
                        for (name, ms) in r {
                            let (x, y) =
                                (b[name].as_f64().unwrap_or(f64::INFINITY), ms.as_f64().unwrap_or(f64::INFINITY));
                            b.insert(name.clone(), json!(x.min(y)));
                        }
                    }
                    let total = best["total_ms"]
                        .as_f64()
                        .unwrap_or(f64::INFINITY)
                        .min(run["total_ms"].as_f64().unwrap_or(f64::INFINITY));
                    best["total_ms"] = json!(total);
                    best
                }
            });
        }
        let row = row.ok_or("no run")?;
        let t = row["triangles"].as_f64().unwrap_or(0.0);
        let peak = row["peak_kib"].as_f64().unwrap_or(0.0) * 1024.0;
        let growth = peak - row["rss_before_kib"].as_f64().unwrap_or(0.0) * 1024.0;
        let stages: Vec<String> = row["stages"]
            .as_object()
            .map(|m| m.iter().map(|(k, v)| format!("{k} {:.0}", v.as_f64().unwrap_or(0.0))).collect())
            .unwrap_or_default();
        println!(
            "{:>10} {:>10} {:>9.0}  {}  {:.0}  {:.0}, {:.0}",
            t,
            row["candidates"],
            row["total_ms"].as_f64().unwrap_or(0.0),
            stages.join(", "),
            peak / 1e6,
            peak / t,
            growth / t
        );
        rows.push(row);
    }
    // Exponents per stage and in total.
    let mut names: Vec<String> =
        rows.first().and_then(|r| r["stages"].as_object()).map(|m| m.keys().cloned().collect()).unwrap_or_default();
    names.push("total".into());
    // Fitted over every level, and over the levels of at least 100k triangles (past the sizes
    // whose working set still fits in cache).
    let mut exponents = serde_json::Map::new();
    let mut exponents_large = serde_json::Map::new();
    let series = |name: &str, min_triangles: f64| -> Vec<(f64, f64)> {
        rows.iter()
            .map(|r| {
                let y = if name == "total" { r["total_ms"].as_f64() } else { r["stages"][name].as_f64() };
                (r["triangles"].as_f64().unwrap_or(0.0), y.unwrap_or(0.0))
            })
            .filter(|p| p.0 >= min_triangles)
            .collect()
    };
    for name in &names {
        exponents.insert(name.clone(), json!(exponent(&series(name, 0.0))));
        exponents_large.insert(name.clone(), json!(exponent(&series(name, 1e5))));
    }
    let candidates: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r["triangles"].as_f64().unwrap_or(0.0), r["candidates"].as_f64().unwrap_or(0.0)))
        .collect();
    println!("fitted exponent of time vs triangles (least squares, log-log): all levels, levels >= 100k");
    for name in &names {
        let b = exponents[name].as_f64().unwrap_or(f64::NAN);
        let l = exponents_large[name].as_f64().unwrap_or(f64::NAN);
        println!("  {name:<10} {b:.3}  {l:.3}{}", if b > 1.15 || l > 1.15 { "  (> 1.15)" } else { "" });
    }
    println!("  candidates vs triangles: {:.3}", exponent(&candidates));
    if let Some(path) = flag("--json") {
        std::fs::write(
            path,
            serde_json::to_string_pretty(&json!({
                "model": model.display().to_string(),
                "levels": rows,
                "exponents": exponents,
                "exponents_from_100k": exponents_large,
            }))?,
        )?;
    }
    Ok(())
}
