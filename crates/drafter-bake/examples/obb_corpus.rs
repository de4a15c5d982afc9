//! Oriented boxes over every part of a model folder: each method's time per part and its volume
//! relative to the best box found (`optimal`), plus a containment check of every box.
//!
//! `cargo run --release -p drafter-bake --example obb_corpus -- [MODELS_DIR] [--dump DIR] [--json FILE]`
//!
//! MODELS_DIR defaults to `../shared/models`. `--dump DIR` writes each part's world-space points
//! (little-endian f64 xyz) and `index.json` for the peer comparison in `bench/peers/obb_trimesh.py`.
//! Single-threaded, so times per part are comparable with single-threaded peers.

use std::path::PathBuf;
use std::time::Instant;

use drafter_bounds::{ObbMethod, ObbOptions, oriented_box};
use drafter_core::PartId;
use drafter_segment::{SegmentOptions, segment};
use serde::Serialize;

#[derive(Serialize)]
struct PartRow {
    model: String,
    part: String,
    points: usize,
    /// Diagonal of the points' axis-aligned box.
    diagonal: f64,
    /// (method, milliseconds, volume), cheapest method first.
    methods: Vec<(String, f64, f64)>,
    dump: Option<String>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flag = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).map(PathBuf::from);
    let dump = flag("--dump");
    let json = flag("--json");
    let dir =
        args.first().filter(|a| !a.starts_with("--")).map_or_else(|| PathBuf::from("../shared/models"), PathBuf::from);
    let files = drafter_testkit::models::input_files(&dir, drafter_io::has_input_extension);
    if files.is_empty() {
        return Err(format!("no models under {}", dir.display()).into());
    }
    if let Some(d) = &dump {
        std::fs::create_dir_all(d)?;
    }
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let mut rows = Vec::new();
    let mut not_contained = 0usize;
    for (fi, file) in files.iter().enumerate() {
        let name = file.strip_prefix(&dir).unwrap_or(file).display().to_string();
        let imported = drafter_io::import(file)?;
        let (parts, _) = segment(&imported.scene, &SegmentOptions::default());
        for p in 0..parts.len() {
            let points = drafter_bake::part_points(&imported.scene, &parts, PartId::from(p));
            let mut methods = Vec::new();
            for method in ObbMethod::ALL {
                let start = Instant::now();
                let obb = pool.install(|| oriented_box(&points, &ObbOptions::with_method(method)))?;
                let ms = start.elapsed().as_secs_f64() * 1e3;
                let scale = obb.half_extents.max_element().max(1e-30);
                not_contained += points.iter().filter(|&&q| !obb.contains(q, 1e-9 * scale)).count().min(1);
                methods.push((method.name().to_owned(), ms, obb.volume));
            }
            let dumped = dump.as_ref().map(|d| -> std::io::Result<String> {
                let file_name = format!("{fi:02}_{p:04}.bin");
                let bytes: Vec<u8> = points.iter().flat_map(|q| q.to_array()).flat_map(f64::to_le_bytes).collect();
                std::fs::write(d.join(&file_name), bytes)?;
                Ok(file_name)
            });
            let aabb = drafter_bounds::aabb(&points);
            rows.push(PartRow {
                model: name.clone(),
                part: parts.parts[p].name.clone(),
                points: points.len(),
                diagonal: aabb.diagonal(),
                methods,
                dump: dumped.transpose()?,
            });
        }
        eprintln!("{name}: {} parts", parts.len());
    }
    // Summary: volume relative to optimal (the best box found), and time per part. Flat parts (the
    // best box's volume under 1e-9 of the diagonal cubed) have no meaningful ratio and are counted apart.
    let flat = |r: &PartRow| r.methods[4].2 <= 1e-9 * r.diagonal.powi(3);
    let solid: Vec<&PartRow> = rows.iter().filter(|r| !flat(r)).collect();
    println!(
        "{} parts in {} models ({} flat, excluded from ratios); boxes not containing all their part's points: {not_contained}",
        rows.len(),
        files.len(),
        rows.len() - solid.len()
    );
    println!(
        "{:<8} {:>14} {:>12} {:>12} {:>12}",
        "method", "ms/part mean", "vol/opt mean", "vol/opt max", "parts > opt"
    );
    for (k, method) in ObbMethod::ALL.iter().enumerate() {
        let mut ratios = Vec::new();
        let mut ms = 0.0;
        let mut worse = 0;
        for r in &rows {
            ms += r.methods[k].1;
        }
        for r in &solid {
            let ratio = r.methods[k].2 / r.methods[4].2;
            worse += usize::from(ratio > 1.0 + 1e-9);
            ratios.push(ratio);
        }
        let mean = ratios.iter().sum::<f64>() / ratios.len().max(1) as f64;
        let max = ratios.iter().copied().fold(0.0, f64::max);
        println!("{:<8} {:>14.3} {:>12.4} {:>12.4} {:>12}", method.name(), ms / rows.len() as f64, mean, max, worse);
    }
    if let Some(path) = json.or_else(|| dump.as_ref().map(|d| d.join("index.json"))) {
        std::fs::write(path, serde_json::to_vec_pretty(&rows)?)?;
    }
    Ok(())
}
