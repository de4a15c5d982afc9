//! Brute force vs hierarchies, per view, in the same process (Gooch et al. 1999, Table 1 style).
//!
//! ```text
//! cargo run --release -p drafter-lines --example silhouette_bench -- [FILE ...] [--views N]
//!     [--sphere SEGMENTS] [--no-sphere] [--seed S]
//! ```
//!
//! Without files it measures a generated UV sphere of ≥ 100k faces. For every model: candidates,
//! brute-force ns/view on one thread (and M candidates/s), hierarchy ns/view, speedup, mean
//! silhouette count and the number of views whose sets differ, for random orthographic directions
//! and for random eyes outside the bounding box; then what the [`SilhouetteIndex`] chose and the
//! Gauss-map per-level histogram (Table 2 style). Timing warm and cold as in
//! [`drafter_lines::measure`]; `drafter bench silhouettes` measures any model the same way.

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::*;
use drafter_core::{PartId, Topology, Weld};
use drafter_lines::measure::{Warmth, time_per_view};
use drafter_lines::*;
use glam::Vec3;

struct Args {
    files: Vec<String>,
    views: usize,
    sphere: Option<u32>,
    seed: u64,
    calibrate: bool,
    /// Options of the measured hierarchies (defaults unless overridden on the command line).
    options: SilhouetteOptions,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        files: Vec::new(),
        views: 1000,
        sphere: Some(320),
        seed: 1,
        calibrate: false,
        options: SilhouetteOptions::default(),
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--views" => args.views = value("--views")?.parse().map_err(|e| format!("--views: {e}"))?,
            "--sphere" => args.sphere = Some(value("--sphere")?.parse().map_err(|e| format!("--sphere: {e}"))?),
            "--no-sphere" => args.sphere = None,
            "--calibrate" => args.calibrate = true,
            "--overlap" => {
                let factor = value("--overlap")?.parse().map_err(|e| format!("--overlap: {e}"))?;
                args.options.gauss.bins = Bins::Overlapping { factor };
            }
            "--strict-bins" => args.options.gauss.bins = Bins::Strict,
            "--depth" => {
                args.options.gauss.max_depth = Some(value("--depth")?.parse().map_err(|e| format!("--depth: {e}"))?)
            }
            "--no-prune" => {
                args.options.gauss.prune = false;
                args.options.bvh.prune = false;
            }
            "--leaf" => args.options.bvh.leaf_size = value("--leaf")?.parse().map_err(|e| format!("--leaf: {e}"))?,
            "--normal-level" => {
                let v = value("--normal-level")?;
                args.options.bvh.normal_split = match v.as_str() {
                    "off" => NormalSplit::Off,
                    "auto" => NormalSplit::Auto,
                    l => NormalSplit::Level(l.parse().map_err(|e| format!("--normal-level: {e}"))?),
                };
            }
            // Cost-model overrides (ns), to see how the pruning's choices move query times.
            "--bvh-block" => {
                args.options.cost.bvh_block_ns =
                    value("--bvh-block")?.parse().map_err(|e| format!("--bvh-block: {e}"))?
            }
            "--bvh-range" => {
                args.options.cost.bvh_range_ns =
                    value("--bvh-range")?.parse().map_err(|e| format!("--bvh-range: {e}"))?
            }
            "--seed" => args.seed = value("--seed")?.parse().map_err(|e| format!("--seed: {e}"))?,
            "-h" | "--help" => {
                return Err(
                    "usage: silhouette_bench [FILE ...] [--views N] [--sphere SEGMENTS] [--no-sphere] [--seed S] \
                     [--calibrate] [--overlap F | --strict-bins] [--depth D] [--no-prune] [--leaf N] \
                     [--normal-level off|auto|L] [--bvh-block NS] [--bvh-range NS]"
                        .into(),
                );
            }
            _ => args.files.push(a),
        }
    }
    Ok(args)
}

struct Row {
    mode: &'static str,
    brute_ns: f64,
    brute_cold_ns: f64,
    hierarchy_cold_ns: f64,
    brute_parallel_ns: f64,
    hierarchy_ns: f64,
    mean_silhouettes: f64,
    mismatches: usize,
    counts: QueryCounts,
}

fn measure(
    views: &[View],
    brute: &BruteForce,
    hierarchy: impl Fn(View, &mut EdgeSet),
    counted: impl Fn(View, &mut EdgeSet) -> QueryCounts,
    mode: &'static str,
) -> Row {
    let mut a = EdgeSet::default();
    let mut b = EdgeSet::default();
    let mut mismatches = 0;
    let mut total = 0usize;
    let mut counts = QueryCounts::default();
    for &v in views {
        brute.query_serial(v, &mut a);
        let c = counted(v, &mut b);
        counts += c;
        total += a.count();
        mismatches += usize::from(a != b);
    }
    let warm = time_per_view(views.len(), 3, Warmth::Warm, |k, v| match k {
        0 => brute.query_serial(views[v], &mut a),
        1 => brute.query(views[v], &mut a),
        _ => hierarchy(views[v], &mut b),
    });
    let (brute_ns, brute_parallel_ns, hierarchy_ns) = (warm[0], warm[1], warm[2]);
    let cold = time_per_view(views.len(), 2, Warmth::Cold, |k, v| match k {
        0 => brute.query_serial(views[v], &mut a),
        _ => hierarchy(views[v], &mut b),
    });
    let (brute_cold_ns, hierarchy_cold_ns) = (cold[0], cold[1]);
    let n = views.len().max(1);
    counts.nodes_entered /= n;
    counts.bounds_tested /= n;
    counts.ranges /= n;
    counts.blocks_tested /= n;
    counts.arcs_tested /= n;
    Row {
        mode,
        brute_ns,
        brute_cold_ns,
        hierarchy_cold_ns,
        brute_parallel_ns,
        hierarchy_ns,
        mean_silhouettes: total as f64 / n as f64,
        mismatches,
        counts,
    }
}

fn bench(mesh: &TestMesh, parts: Option<&[PartId]>, args: &Args) {
    let t = Instant::now();
    let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
    let weld_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let lines = match classify_edges(&topology, parts, &LineOptions::default()) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("{}: {e}", mesh.name);
            return;
        }
    };
    let classify_s = t.elapsed().as_secs_f64();
    let n = lines.candidates.len();
    let t = Instant::now();
    let chosen = SilhouetteIndex::build(&lines, &args.options);
    let index_s = t.elapsed().as_secs_f64();
    // Force both hierarchies so that their speed is measured even where they are not stored.
    let forced = SilhouetteOptions { min_candidates: 0, min_speedup: 0.0, ..args.options };
    let t = Instant::now();
    let measured = SilhouetteIndex::build(&lines, &forced);
    let forced_s = t.elapsed().as_secs_f64();
    let (Some(gauss), Some(bvh)) = (measured.gauss_map(), measured.cone_bvh()) else {
        eprintln!("{}: no hierarchy could be built", mesh.name);
        return;
    };
    let brute = measured.brute_force();

    let mut rng = Rng::new(args.seed);
    let (lo, hi) = bounds(&mesh.positions);
    let ortho: Vec<View> = (0..args.views).map(|_| View::Orthographic { direction: rng.direction_f32() }).collect();
    let persp: Vec<View> = (0..args.views).map(|_| View::Perspective { eye: eye_outside(&mut rng, lo, hi) }).collect();
    let direction = |v: View| match v {
        View::Orthographic { direction } => direction,
        View::Perspective { .. } => Vec3::ZERO,
    };
    let eye = |v: View| match v {
        View::Perspective { eye } => eye,
        View::Orthographic { .. } => Vec3::ZERO,
    };
    let rows = [
        measure(
            &ortho,
            brute,
            |v, out| gauss.query(direction(v), out),
            |v, out| gauss.query_counted(direction(v), out),
            "ortho",
        ),
        measure(&persp, brute, |v, out| bvh.query(eye(v), out), |v, out| bvh.query_counted(eye(v), out), "persp"),
    ];

    println!(
        "\n## {} — {} faces, {} edges, {} candidates ({} crease, {} boundary, {} border, {} non-manifold, {} coplanar, {} degenerate)",
        mesh.name,
        mesh.triangles.len(),
        topology.edges.len(),
        n,
        lines.counts.crease,
        lines.counts.boundary,
        lines.counts.part_border,
        lines.counts.non_manifold,
        lines.counts.coplanar,
        lines.counts.degenerate,
    );
    println!(
        "build: weld {weld_s:.3} s, classify {classify_s:.3} s, index {index_s:.3} s (both hierarchies forced: {forced_s:.3} s)"
    );
    println!(
        "| mode  | brute ns/view | M cand/s (1 core) | brute ns/view (all cores) | hierarchy ns/view | speedup | cold: brute / hierarchy ns, speedup | mean silhouettes | mismatches | entered / bounds / ranges / blocks / arcs per view |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for r in &rows {
        println!(
            "| {} | {:.0} | {:.0} | {:.0} | {:.0} | {:.2}× | {:.0} / {:.0}, {:.2}× | {:.1} | {} / {} | {} / {} / {} / {} / {} |",
            r.mode,
            r.brute_ns,
            n as f64 / r.brute_ns * 1e3,
            r.brute_parallel_ns,
            r.hierarchy_ns,
            r.brute_ns / r.hierarchy_ns,
            r.brute_cold_ns,
            r.hierarchy_cold_ns,
            r.brute_cold_ns / r.hierarchy_cold_ns,
            r.mean_silhouettes,
            r.mismatches,
            args.views,
            r.counts.nodes_entered,
            r.counts.bounds_tested,
            r.counts.ranges,
            r.counts.blocks_tested,
            r.counts.arcs_tested,
        );
    }
    println!(
        "Gauss map: {} nodes, predicted {:.0} ns/view; cone BVH: {} nodes ({} leaves), predicted {:.0} ns/view",
        gauss.node_count(),
        gauss.predicted_ns_per_query(),
        bvh.node_count(),
        bvh.leaf_count(),
        bvh.predicted_ns_per_query()
    );
    println!("chosen: orthographic {:?}", chosen.orthographic_choice());
    println!("chosen: perspective  {:?}", chosen.perspective_choice());
    let stored = gauss.histogram();
    if let Some(assigned) = gauss.assigned_histogram() {
        println!("Gauss-map levels (arcs assigned by overlapping bins | stored after pruning):");
        println!("  root: {:>8} | {:>8}", assigned.root.arcs, stored.root.arcs);
        for (k, l) in assigned.levels.iter().enumerate() {
            let s = stored.levels.get(k).copied().unwrap_or_default();
            println!("  {k:>4}: {:>8} | {:>8}   ({} | {} nodes)", l.arcs, s.arcs, l.nodes, s.nodes);
        }
    }
}

/// One timed query: its operation counts and nanoseconds.
type Sample = (QueryCounts, f64);

/// Times (warm, as the main table) every view of several unpruned hierarchies of different depths (so that the counts vary
/// independently) and collects samples for a least-squares fit of the cost model.
fn calibration_samples(mesh: &TestMesh, args: &Args, gauss: &mut Vec<Sample>, bvh: &mut Vec<Sample>) {
    let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
    let Ok(lines) = classify_edges(&topology, None, &LineOptions::default()) else { return };
    let cost = CostModel::default();
    let mut rng = Rng::new(args.seed);
    let (lo, hi) = bounds(&mesh.positions);
    let mut out = EdgeSet::default();
    let views = args.views.min(300);
    for depth in [2u8, 4, 5, 6, 7] {
        let g_options = GaussMapOptions { max_depth: Some(depth), prune: depth == 7, ..Default::default() };
        let options = SilhouetteOptions {
            min_candidates: 0,
            min_speedup: 0.0,
            perspective: false,
            gauss: g_options,
            cost,
            ..Default::default()
        };
        let index = SilhouetteIndex::build(&lines, &options);
        let Some(g) = index.gauss_map() else { continue };
        for _ in 0..views {
            let d = rng.direction_f32();
            let mut best = f64::INFINITY;
            let mut counts = QueryCounts::default();
            for _ in 0..3 {
                let t = Instant::now();
                g.query(d, &mut out);
                best = best.min(t.elapsed().as_nanos() as f64);
                counts = g.query_counted(d, &mut out);
            }
            gauss.push((counts, best));
        }
    }
    for leaf_size in [4u32, 16, 64] {
        let options = ConeBvhOptions { leaf_size, prune: leaf_size == 16, ..Default::default() };
        let b = ConeBvh::build(&lines.candidate_normals, &lines.candidate_points, &options, &cost);
        for _ in 0..views {
            let e = eye_outside(&mut rng, lo, hi);
            let mut best = f64::INFINITY;
            let mut counts = QueryCounts::default();
            for _ in 0..3 {
                let t = Instant::now();
                b.query(e, &mut out);
                best = best.min(t.elapsed().as_nanos() as f64);
                counts = b.query_counted(e, &mut out);
            }
            bvh.push((counts, best));
        }
    }
}

/// Non-negative-ish least squares by normal equations: time ≈ entered·a + bounds·b + ranges·c + blocks·d.
fn fit(samples: &[Sample]) -> [f64; 4] {
    let row =
        |c: &QueryCounts| [c.nodes_entered as f64, c.bounds_tested as f64, c.ranges as f64, c.blocks_tested as f64];
    let mut m = [[0f64; 5]; 4];
    for (c, t) in samples {
        let x = row(c);
        for i in 0..4 {
            for j in 0..4 {
                m[i][j] += x[i] * x[j];
            }
            m[i][4] += x[i] * t;
        }
    }
    // Gaussian elimination with partial pivoting.
    for col in 0..4 {
        let pivot = (col..4).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs())).unwrap_or(col);
        m.swap(col, pivot);
        let p = m[col][col];
        if p.abs() < 1e-12 {
            continue;
        }
        let pivot_row = m[col];
        for (r, row) in m.iter_mut().enumerate() {
            if r != col {
                let f = row[col] / p;
                for (x, &y) in row.iter_mut().zip(&pivot_row).skip(col) {
                    *x -= f * y;
                }
            }
        }
    }
    [0, 1, 2, 3].map(|i| if m[i][i].abs() < 1e-12 { 0.0 } else { m[i][4] / m[i][i] })
}

fn main() {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    println!("silhouette_bench: {} views per mode, one thread unless noted", args.views);
    if args.calibrate {
        let (mut gauss, mut bvh) = (Vec::new(), Vec::new());
        let mut meshes = Vec::new();
        if let Some(segments) = args.sphere {
            meshes.push(uv_sphere(segments, segments / 2));
        }
        for file in &args.files {
            match load_model(std::path::Path::new(file)) {
                Ok((mesh, _)) => meshes.push(mesh),
                Err(e) => eprintln!("{file}: {e}"),
            }
        }
        for mesh in &meshes {
            let (mut g, mut b) = (Vec::new(), Vec::new());
            calibration_samples(mesh, &args, &mut g, &mut b);
            let [a, bb, c, d] = fit(&g);
            println!("  {}: Gauss enter {a:.1}, cap {bb:.1}, range {c:.1}, block {d:.1}", mesh.name);
            let [a, bb, c, d] = fit(&b);
            println!("  {}: BVH enter {a:.1}, test {bb:.1}, range {c:.1}, block {d:.1}", mesh.name);
            gauss.extend(g);
            bvh.extend(b);
        }
        let [a, b, c, d] = fit(&gauss);
        println!(
            "Gauss map ({} samples): enter {a:.2} ns, cap test {b:.2} ns, range {c:.2} ns, block {d:.2} ns",
            gauss.len()
        );
        let [a, b, c, d] = fit(&bvh);
        println!(
            "cone BVH ({} samples): enter {a:.2} ns, box+cone test {b:.2} ns, range {c:.2} ns, block {d:.2} ns",
            bvh.len()
        );
        return;
    }
    if let Some(segments) = args.sphere {
        let mut sphere = uv_sphere(segments, segments / 2);
        sphere.name = format!("UV sphere {segments}×{}", segments / 2);
        bench(&sphere, None, &args);
    }
    for file in &args.files {
        match load_model(std::path::Path::new(file)) {
            Ok((mesh, parts)) => {
                let multi = parts.iter().any(|&p| p != parts[0]);
                bench(&mesh, multi.then_some(parts.as_slice()), &args);
            }
            Err(e) => eprintln!("{file}: {e}"),
        }
    }
}
