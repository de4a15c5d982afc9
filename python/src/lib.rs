//! `drafter._drafter`, the native module of the `drafter` Python package: thin bindings over
//! drafter-catalog, the crate `drafter bake` runs, so a bake from Python is the CLI's bake byte for
//! byte. Every call releases the GIL while it works; `threads=N` runs it on a pool of its own.
//! The Python-facing API (argument normalisation, docs, type hints) is `drafter/__init__.py`.

use std::path::{Path, PathBuf};

use drafter_bake::BakeConfig;
use drafter_catalog::batch::{self, Permit};
use drafter_catalog::cache::Cache;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(_drafter, DrafterError, PyException, "A drafter error (the base class).");
create_exception!(_drafter, InputError, DrafterError, "Bad input or options (the CLI's exit code 2).");
create_exception!(_drafter, IoError, DrafterError, "A file could not be read or written (exit code 3).");
create_exception!(_drafter, InternalError, DrafterError, "A bug in drafter (exit code 1): please report it.");

fn to_py(e: &drafter_catalog::Error) -> PyErr {
    let message = e.to_string().replace('\n', " ");
    match e.exit_code() {
        drafter_catalog::exit::BAD_INPUT => InputError::new_err(message),
        drafter_catalog::exit::IO_FAILURE => IoError::new_err(message),
        _ => InternalError::new_err(message),
    }
}

/// The configuration from TOML text (`config_toml`) or JSON text of the same tables
/// (`config_json`, what a Python dict becomes).
fn config(config_toml: Option<&str>, config_json: Option<&str>) -> PyResult<BakeConfig> {
    let text = match (config_toml, config_json) {
        (Some(toml), _) => toml.to_owned(),
        (None, Some(json)) => {
            let value: serde_json::Value =
                serde_json::from_str(json).map_err(|e| InputError::new_err(format!("config: {e}")))?;
            toml::to_string(&value).map_err(|e| InputError::new_err(format!("config: {e}")))?
        }
        (None, None) => return Ok(BakeConfig::default()),
    };
    drafter_catalog::job::config_from_toml(&text).map_err(InputError::new_err)
}

/// Runs `work` on `threads` threads of its own (the global pool when `None`).
fn on_threads<T: Send>(threads: Option<usize>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    match threads {
        None => Ok(work()),
        Some(n) if (1..=1024).contains(&n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| InternalError::new_err(format!("thread pool: {e}")))?;
            Ok(pool.install(work))
        }
        Some(n) => Err(InputError::new_err(format!("threads must be between 1 and 1024, not {n}"))),
    }
}

/// The input of `bake` and `inspect`: a file's path and bytes, or bytes named `name` (format
/// detection and provenance; `input` when unnamed).
fn source(
    path: Option<PathBuf>,
    data: Option<Vec<u8>>,
    name: Option<String>,
) -> Result<(PathBuf, Vec<u8>), drafter_catalog::Error> {
    match (path, data) {
        (Some(path), None) => {
            let bytes = drafter_catalog::job::read_input(&path)?;
            Ok((path, bytes))
        }
        (None, Some(data)) => Ok((PathBuf::from(name.unwrap_or_else(|| "input".into())), data)),
        _ => Err(drafter_catalog::Error::Input("give a path or bytes".into())),
    }
}

fn limits(max_triangles: Option<u64>) -> drafter_io::Limits {
    drafter_io::Limits { max_triangles: max_triangles.unwrap_or(drafter_io::DEFAULT_MAX_TRIANGLES) }
}

/// Bakes a file (`path`) or bytes (`data`, named `name` for format detection and provenance) into
/// GLB bytes.
#[pyfunction]
#[pyo3(signature = (*, path=None, data=None, name=None, config_toml=None, config_json=None, threads=None, max_triangles=None))]
#[allow(clippy::too_many_arguments)]
fn bake(
    py: Python<'_>,
    path: Option<PathBuf>,
    data: Option<Vec<u8>>,
    name: Option<String>,
    config_toml: Option<&str>,
    config_json: Option<&str>,
    threads: Option<usize>,
    max_triangles: Option<u64>,
) -> PyResult<Py<pyo3::types::PyBytes>> {
    let config = config(config_toml, config_json)?;
    let limits = limits(max_triangles);
    let main = py.detach(|| {
        on_threads(threads, || {
            let (path, bytes) = source(path, data, name)?;
            drafter_catalog::bake_bytes(&path, bytes, &config, &limits, &mut |_| {}).map(|b| b.written.main)
        })
    })?;
    let main = main.map_err(|e| to_py(&e))?;
    Ok(pyo3::types::PyBytes::new(py, &main).unbind())
}

/// Bakes `input` into `output` (.glb or .gltf) atomically, through the cache when given; returns
/// the file's record (JSON text, the batch report's per-file entry). A failure is in the record.
#[pyfunction]
#[pyo3(signature = (input, output, *, config_toml=None, config_json=None, cache=None, cache_max=None, threads=None, max_triangles=None))]
#[allow(clippy::too_many_arguments)]
fn bake_file(
    py: Python<'_>,
    input: PathBuf,
    output: PathBuf,
    config_toml: Option<&str>,
    config_json: Option<&str>,
    cache: Option<PathBuf>,
    cache_max: Option<u64>,
    threads: Option<usize>,
    max_triangles: Option<u64>,
) -> PyResult<String> {
    let config = config(config_toml, config_json)?;
    let limits = limits(max_triangles);
    let cache = open_cache(cache.as_deref(), cache_max)?;
    let record = py.detach(|| {
        on_threads(threads, || {
            if let Some(folder) = output.parent().filter(|p| !p.as_os_str().is_empty()) {
                let _ = std::fs::create_dir_all(folder);
            }
            let admit = |bytes| Some(Permit::unbounded(bytes));
            let record = batch::bake_file(&input, &output, &config, &limits, cache.as_ref(), &admit);
            // Eviction lists the whole cache: only when a bound was asked for (a caller baking
            // many files passes none and evicts once at the end, as drafter.ray does).
            if let Some(cache) = cache.as_ref().filter(|c| c.max_bytes.is_some()) {
                cache.evict();
            }
            record
        })
    })?;
    serde_json::to_string(&record).map_err(|e| InternalError::new_err(e.to_string()))
}

fn open_cache(dir: Option<&Path>, max: Option<u64>) -> PyResult<Option<Cache>> {
    dir.map(|d| {
        Cache::open(d, max).map_err(|e| IoError::new_err(format!("{}: cannot open the cache: {e}", d.display())))
    })
    .transpose()
}

/// Bakes many inputs (files, folders, manifests) into `out_dir` as `drafter bake ... -o DIR` does;
/// returns the batch report as JSON text.
#[pyfunction]
#[pyo3(signature = (inputs, out_dir, *, manifests=Vec::new(), config_toml=None, config_json=None, cache=None, cache_max=None, memory=None, jobs=None, max_triangles=None))]
#[allow(clippy::too_many_arguments)]
fn bake_many(
    py: Python<'_>,
    inputs: Vec<PathBuf>,
    out_dir: PathBuf,
    manifests: Vec<PathBuf>,
    config_toml: Option<&str>,
    config_json: Option<&str>,
    cache: Option<PathBuf>,
    cache_max: Option<u64>,
    memory: Option<u64>,
    jobs: Option<usize>,
    max_triangles: Option<u64>,
) -> PyResult<String> {
    let items = discover(inputs, manifests, Some(out_dir.clone()))?;
    let options = batch::Options {
        config: config(config_toml, config_json)?,
        limits: limits(max_triangles),
        cache: open_cache(cache.as_deref(), cache_max)?,
        memory_budget: memory.unwrap_or_else(batch::default_memory_budget),
        workers: jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from)).max(1),
    };
    let items: Vec<_> = items
        .into_iter()
        .map(|(input, relative_output)| drafter_catalog::discover::Item { input, relative_output })
        .collect();
    let summary = py.detach(|| {
        std::fs::create_dir_all(&out_dir)
            .map_err(|e| drafter_catalog::Error::Io(format!("{}: cannot create: {e}", out_dir.display())))?;
        let summary = batch::run(&items, &out_dir, &options, &|| false, &batch::Quiet);
        if let Some(cache) = &options.cache {
            cache.evict();
        }
        Ok(summary)
    });
    let summary = summary.map_err(|e: drafter_catalog::Error| to_py(&e))?;
    serde_json::to_string(&summary).map_err(|e| InternalError::new_err(e.to_string()))
}

/// The files a batch of `inputs` and `manifests` holds: (input, output path relative to the output
/// folder) pairs, `skip` never entered.
#[pyfunction]
#[pyo3(signature = (inputs, manifests=Vec::new(), skip=None))]
fn discover(inputs: Vec<PathBuf>, manifests: Vec<PathBuf>, skip: Option<PathBuf>) -> PyResult<Vec<(PathBuf, PathBuf)>> {
    let items = drafter_catalog::discover::discover(&inputs, &manifests, skip.as_deref())
        .map_err(|e| InputError::new_err(e.to_string()))?;
    Ok(items.into_iter().map(|i| (i.input, i.relative_output)).collect())
}

/// What `drafter inspect --json` prints, as JSON text.
#[pyfunction]
#[pyo3(signature = (*, path=None, data=None, name=None, max_triangles=None))]
fn inspect(
    py: Python<'_>,
    path: Option<PathBuf>,
    data: Option<Vec<u8>>,
    name: Option<String>,
    max_triangles: Option<u64>,
) -> PyResult<String> {
    let limits = limits(max_triangles);
    let report = py.detach(|| {
        let (path, bytes) = source(path, data, name)?;
        drafter_catalog::inspect::inspect_bytes(&path, &bytes, &limits, drafter_core::Weld::default())
    });
    let report = report.map_err(|e| to_py(&e))?;
    serde_json::to_string(&report).map_err(|e| InternalError::new_err(e.to_string()))
}

/// Cache upkeep: `stats` (JSON text), `evict` to a size, `clear`.
#[pyfunction]
#[pyo3(signature = (dir, action, size=None))]
fn cache(py: Python<'_>, dir: PathBuf, action: &str, size: Option<u64>) -> PyResult<String> {
    let cache = Cache::open(&dir, size).map_err(|e| IoError::new_err(format!("{}: {e}", dir.display())))?;
    py.detach(|| match action {
        "stats" => serde_json::to_string(&cache.stats()).map_err(|e| InternalError::new_err(e.to_string())),
        "evict" => serde_json::to_string(&cache.evict()).map_err(|e| InternalError::new_err(e.to_string())),
        "clear" => {
            cache.clear().map(|n| n.to_string()).map_err(|e| IoError::new_err(format!("{}: {e}", dir.display())))
        }
        other => Err(InputError::new_err(format!("unknown cache action {other:?}"))),
    })
}

#[pymodule]
fn _drafter(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(bake, m)?)?;
    m.add_function(wrap_pyfunction!(bake_file, m)?)?;
    m.add_function(wrap_pyfunction!(bake_many, m)?)?;
    m.add_function(wrap_pyfunction!(discover, m)?)?;
    m.add_function(wrap_pyfunction!(inspect, m)?)?;
    m.add_function(wrap_pyfunction!(cache, m)?)?;
    m.add("DrafterError", m.py().get_type::<DrafterError>())?;
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add("IoError", m.py().get_type::<IoError>())?;
    m.add("InternalError", m.py().get_type::<InternalError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("BUILD_ID", drafter_catalog::cache::BUILD_ID)?;
    Ok(())
}
