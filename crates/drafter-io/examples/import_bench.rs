//! Import + welded-topology timing on one file: `cargo run --release -p drafter-io --example
//! import_bench -- FILE [RUNS]`. Prints the median and best of RUNS (default 7) for reading the file,
//! parsing it into a scene and building the exact-weld topology of every unique mesh.

use std::time::Instant;

use drafter_core::{Topology, Weld};
use rayon::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = std::path::PathBuf::from(args.next().ok_or("usage: import_bench FILE [RUNS]")?);
    let runs: usize = args.next().map(|r| r.parse()).transpose()?.unwrap_or(7);
    let (mut read, mut parse, mut topo, mut total) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut triangles = 0;
    for _ in 0..runs {
        let t0 = Instant::now();
        let bytes = std::fs::read(&path)?;
        let t1 = Instant::now();
        let imported = drafter_io::import_bytes(&path, &bytes)?;
        let t2 = Instant::now();
        let topologies: Vec<Topology> =
            imported.scene.meshes.par_iter().map(|m| Topology::build(m, Weld::Exact)).collect();
        let t3 = Instant::now();
        triangles = topologies.iter().map(|t| t.faces.len()).sum::<usize>();
        read.push((t1 - t0).as_secs_f64() * 1e3);
        parse.push((t2 - t1).as_secs_f64() * 1e3);
        topo.push((t3 - t2).as_secs_f64() * 1e3);
        total.push((t3 - t0).as_secs_f64() * 1e3);
    }
    let stat = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        (v[v.len() / 2], v[0])
    };
    println!(
        "{} ({} unique triangles, {} threads, {runs} runs)",
        path.display(),
        triangles,
        rayon::current_num_threads()
    );
    for (name, v) in
        [("read file", &mut read), ("parse to scene", &mut parse), ("topology", &mut topo), ("total", &mut total)]
    {
        let (median, best) = stat(v);
        println!("  {name:<15} median {median:8.1} ms   best {best:8.1} ms");
    }
    Ok(())
}
