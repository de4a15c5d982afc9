//! What a cache hit costs against hashing its input: for every supported file below the folders
//! given, the time of `cache::key_of` (reading the input and hashing it with its external files and
//! the configuration), of a hit whose output is up to date (`batch::bake_file`: key, receipt, two
//! `stat`s) and of a hit that writes the output (it was removed: the entry is read, checked and
//! written), after one bake that fills the cache. Medians of 5 runs each.
//!
//! `cargo run --release -p drafter-catalog --example hit_cost -- ../shared/models`

use std::path::PathBuf;
use std::time::Instant;

use drafter_catalog::batch::{self, Permit};
use drafter_catalog::cache::{self, Cache};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let roots: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    let items = drafter_catalog::discover::discover(&roots, &[], None).expect("inputs");
    let scratch = std::env::temp_dir().join(format!("drafter-hit-cost-{}", std::process::id()));
    let cache = Cache::open(&scratch.join("cache"), None).expect("cache");
    let config = drafter_bake::BakeConfig::default();
    let limits = drafter_io::Limits::default();
    let admit = |bytes| Some(Permit::unbounded(bytes));
    let (mut hash_total, mut hit_total, mut served_total, mut bytes_total) = (0.0, 0.0, 0.0, 0u64);
    println!("{:>10} {:>9} {:>9} {:>6} {:>9}  file", "bytes in", "hash ms", "hit ms", "ratio", "served ms");
    for item in &items {
        let output = scratch.join("out").join(&item.relative_output);
        std::fs::create_dir_all(output.parent().unwrap_or(&scratch)).expect("folder");
        let first = batch::bake_file(&item.input, &output, &config, &limits, Some(&cache), &admit);
        if first.status != batch::Status::Baked {
            continue;
        }
        let hash = median(
            (0..5)
                .map(|_| {
                    let t = Instant::now();
                    let mut c = config.clone();
                    c.container = drafter_format::Container::Glb;
                    let bytes = std::fs::read(&item.input).expect("input");
                    std::hint::black_box(cache::key_of(&item.input, &bytes, &c));
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect(),
        );
        let hit = |remove: bool| {
            median(
                (0..5)
                    .map(|_| {
                        if remove {
                            std::fs::remove_file(&output).expect("output");
                        }
                        let t = Instant::now();
                        let r = batch::bake_file(&item.input, &output, &config, &limits, Some(&cache), &admit);
                        assert_eq!((r.status, r.up_to_date), (batch::Status::Cached, !remove));
                        t.elapsed().as_secs_f64() * 1e3
                    })
                    .collect(),
            )
        };
        let (current, served) = (hit(false), hit(true));
        hash_total += hash;
        hit_total += current;
        served_total += served;
        bytes_total += first.bytes_in;
        println!(
            "{:>10} {hash:>9.3} {current:>9.3} {:>6.2} {served:>9.3}  {}",
            first.bytes_in,
            current / hash,
            item.input.display()
        );
    }
    println!(
        "all: {bytes_total} bytes in; hashing {hash_total:.1} ms; hits with the output up to date {hit_total:.1} ms \
         ({:.2}x the hashing); hits that write the output {served_total:.1} ms",
        hit_total / hash_total
    );
    let _ = std::fs::remove_dir_all(&scratch);
}
