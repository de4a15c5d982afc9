//! `drafter._drafter`, the native module of the `drafter` Python package: thin bindings over
//! drafter-catalog, the crate `drafter bake` runs, so a bake from Python is the CLI's bake byte for
//! byte. Every call releases the GIL while it works; `threads=N` runs it on a pool of its own.
//! The Python-facing API (argument normalisation, docs, type hints) is `drafter/__init__.py`.
//!
//! `draw_file` and `draw_many` are `drafter draw`'s one drawing through the cache and its
//! catalogs (drafter-catalog's `draw`), the options as the JSON of its `DrawSpec`.
//!
//! `bake_many` and `draw_many` run the batch on a thread of its own while the calling thread, the GIL released,
//! looks for Python's signals every [`SIGNAL_POLL`]: a Ctrl-C stops the batch at the next file as
//! the CLI's first Ctrl-C does, and the caller gets the partial report with the
//! `KeyboardInterrupt`. The progress callback takes the GIL only while it runs.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

use drafter_bake::BakeConfig;
use drafter_catalog::batch::{self, Permit};
use drafter_catalog::cache::Cache;
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyOSError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

create_exception!(_drafter, DrafterError, PyException, "A drafter error (the base class).");
create_exception!(_drafter, InputError, DrafterError, "Bad input or options (the CLI's exit code 2).");
create_exception!(_drafter, InternalError, DrafterError, "A bug in drafter (exit code 1): please report it.");

/// `IoError(DrafterError, OSError)`: made at import by calling `type`, since `create_exception!`
/// takes one base class.
static IO_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

fn io_error_type(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    IO_ERROR
        .get_or_try_init(py, || {
            let bases = PyTuple::new(py, [py.get_type::<DrafterError>(), py.get_type::<PyOSError>()])?;
            let namespace = PyDict::new(py);
            namespace.set_item("__doc__", "A file could not be read or written (exit code 3); an OSError.")?;
            namespace.set_item("__module__", "drafter._drafter")?;
            let made = py.get_type::<PyType>().call1(("IoError", bases, namespace))?;
            Ok::<_, PyErr>(made.cast_into::<PyType>()?.unbind())
        })
        .map(|t| t.bind(py))
}

fn io_error(message: String) -> PyErr {
    Python::attach(|py| match io_error_type(py) {
        Ok(t) => PyErr::from_type(t.clone(), (message,)),
        Err(e) => e,
    })
}

fn to_py(e: &drafter_catalog::Error) -> PyErr {
    let message = e.to_string().replace('\n', " ");
    match e.exit_code() {
        drafter_catalog::exit::BAD_INPUT => InputError::new_err(message),
        drafter_catalog::exit::IO_FAILURE => io_error(message),
        _ => InternalError::new_err(message),
    }
}

/// The configuration from TOML text (`config_toml`) or JSON text of the same tables
/// (`config_json`, what a Python dict becomes), each read straight into the one config type and
/// validated as `drafter bake --config` does.
fn config(config_toml: Option<&str>, config_json: Option<&str>) -> PyResult<BakeConfig> {
    match (config_toml, config_json) {
        (Some(toml), _) => drafter_catalog::job::config_from_toml(toml),
        (None, Some(json)) => drafter_catalog::job::config_from_json(json),
        (None, None) => Ok(BakeConfig::default()),
    }
    .map_err(InputError::new_err)
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
/// With `root`, `output` is a path relative to the folder `root` and is confined below it as a
/// batch's outputs are (`drafter_catalog::output::confined`: plain names only, no symbolic link
/// followed, folders created); `drafter.ray`'s tasks bake so.
#[pyfunction]
#[pyo3(signature = (input, output, *, root=None, config_toml=None, config_json=None, cache=None, cache_max=None, threads=None, max_triangles=None))]
#[allow(clippy::too_many_arguments)]
fn bake_file(
    py: Python<'_>,
    input: PathBuf,
    output: PathBuf,
    root: Option<PathBuf>,
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
            let output = match &root {
                Some(root) => match drafter_catalog::output::confined(root, &output) {
                    Ok(path) => path,
                    Err(e) => return refused(&input, &root.join(&output), &e),
                },
                None => {
                    if let Some(folder) = output.parent().filter(|p| !p.as_os_str().is_empty()) {
                        let _ = std::fs::create_dir_all(folder);
                    }
                    output
                }
            };
            let admit = |bytes| Some(Permit::unbounded(bytes));
            let record = batch::bake_file(&input, &output, &config, &limits, cache.as_ref(), &admit);
            // Eviction lists the whole cache: only when a bound was asked for (a caller baking
            // many files passes none and evicts once at the end, as drafter.ray does).
            if let Some(cache) = cache.as_ref().filter(|c| c.max_bytes.is_some()) {
                cache.evict();
            }
            serde_json::to_value(&record)
                .unwrap_or_else(|e| refused(&input, &output, &drafter_catalog::Error::Io(e.to_string())))
        })
    })?;
    Ok(record.to_string())
}

/// The record of a file refused before its bake (an output path that would leave `root`), with
/// the keys of a batch report's failed record.
fn refused(input: &Path, output: &Path, e: &drafter_catalog::Error) -> serde_json::Value {
    serde_json::json!({
        "input": input.display().to_string(),
        "output": output.display().to_string(),
        "status": "failed",
        "cache": "off",
        "ms": 0.0,
        "bytes_in": 0,
        "bytes_out": 0,
        "estimated_peak_bytes": 0,
        "error": e.to_string().replace('\n', " "),
        "exit_code": e.exit_code(),
    })
}

fn open_cache(dir: Option<&Path>, max: Option<u64>) -> PyResult<Option<Cache>> {
    dir.map(|d| Cache::open(d, max).map_err(|e| io_error(format!("{}: cannot open the cache: {e}", d.display()))))
        .transpose()
}

/// How often `bake_many`'s calling thread looks for Python's signals (a Ctrl-C).
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// `bake_many`'s observer: counts the files finished and calls the Python callback, if any, with
/// each one's record as JSON text, with how many have finished and how many the batch holds. The
/// GIL is taken only for the call. A callback that raises stops the batch; its error is kept.
struct Progress<'a> {
    callback: Option<Py<PyAny>>,
    total: AtomicUsize,
    done: AtomicUsize,
    stop: &'a AtomicBool,
    error: Mutex<Option<PyErr>>,
}

impl<'a> Progress<'a> {
    fn new(callback: Option<Py<PyAny>>, stop: &'a AtomicBool) -> Self {
        Progress { callback, total: AtomicUsize::new(0), done: AtomicUsize::new(0), stop, error: Mutex::new(None) }
    }
}

impl batch::Observer for Progress<'_> {
    fn begin(&self, files: usize, _bytes: u64) {
        self.total.store(files, Ordering::SeqCst);
    }

    fn finished(&self, _item: &drafter_catalog::discover::Item, _bytes: u64, record: &batch::Record) {
        // Counted under the lock, so that the calls come in the order of `done`.
        let mut error = self.error.lock().unwrap_or_else(|e| e.into_inner());
        let done = self.done.fetch_add(1, Ordering::SeqCst) + 1;
        let Some(callback) = &self.callback else { return };
        if error.is_some() {
            return;
        }
        let total = self.total.load(Ordering::SeqCst);
        let result = serde_json::to_string(record)
            .map_err(|e| InternalError::new_err(e.to_string()))
            .and_then(|text| Python::attach(|py| callback.call1(py, (text, done, total)).map(drop)));
        if let Err(e) = result {
            *error = Some(e);
            self.stop.store(true, Ordering::SeqCst);
        }
    }
}

/// Bakes many inputs (files, folders, manifests) into `out_dir` as `drafter bake ... -o DIR` does;
/// returns the batch report as JSON text, and the exception that stopped the batch, if one did (a
/// `KeyboardInterrupt` from Ctrl-C, or what `progress` raised): the caller raises it with the
/// report.
#[pyfunction]
#[pyo3(signature = (inputs, out_dir, *, manifests=Vec::new(), config_toml=None, config_json=None, cache=None, cache_max=None, memory=None, jobs=None, max_triangles=None, progress=None))]
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
    progress: Option<Py<PyAny>>,
) -> PyResult<(String, Option<Py<PyAny>>)> {
    // As the CLI's batch: a folder below a named one that cannot be listed is one failed record.
    let found = drafter_catalog::discover::discover_all(&inputs, &manifests, Some(&out_dir))
        .map_err(|e| InputError::new_err(e.to_string()))?;
    let options = batch::Options {
        config: config(config_toml, config_json)?,
        limits: limits(max_triangles),
        cache: open_cache(cache.as_deref(), cache_max)?,
        memory_budget: memory.unwrap_or_else(batch::default_memory_budget),
        workers: jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from)).max(1),
    };
    let stop = AtomicBool::new(false);
    let observer = Progress::new(progress, &stop);
    let summary = run_batch(py, &out_dir, &stop, &observer, options.cache.as_ref(), &|stop, observer| {
        batch::run_discovered(&found, &out_dir, &options, stop, observer)
    });
    finish_batch(py, summary, &observer)
}

/// A batch to run: given its stop request and its observer, it returns the report.
type BatchRun<'a> = dyn Fn(&(dyn Fn() -> bool + Sync), &dyn batch::Observer) -> batch::Summary + Sync + 'a;

/// Runs `batch` on a thread of its own while the calling thread, the GIL released, looks for
/// Python's signals: a Ctrl-C sets `stop` as the CLI's first Ctrl-C does. Returns the summary and
/// the `KeyboardInterrupt`, if one came; the cache is kept within its bound afterwards.
fn run_batch(
    py: Python<'_>,
    out_dir: &Path,
    stop: &AtomicBool,
    observer: &Progress<'_>,
    cache: Option<&Cache>,
    batch: &BatchRun<'_>,
) -> Result<(batch::Summary, Option<PyErr>), drafter_catalog::Error> {
    py.detach(|| {
        std::fs::create_dir_all(out_dir)
            .map_err(|e| drafter_catalog::Error::Io(format!("{}: cannot create: {e}", out_dir.display())))?;
        let caller = std::thread::current();
        let (summary, interrupt) = std::thread::scope(|scope| {
            let worker = scope.spawn(|| {
                let summary = batch(&|| stop.load(Ordering::SeqCst), observer);
                caller.unpark();
                summary
            });
            // The signal handlers of Python run on the main thread only when it asks
            // (`PyErr_CheckSignals`); a worker's own check would never see them.
            let mut interrupt = None;
            while !worker.is_finished() {
                std::thread::park_timeout(SIGNAL_POLL);
                if interrupt.is_none()
                    && let Err(e) = Python::attach(|py| py.check_signals())
                {
                    stop.store(true, Ordering::SeqCst);
                    interrupt = Some(e);
                }
            }
            let summary = worker.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            (summary, interrupt)
        });
        if let Some(cache) = cache {
            cache.evict();
        }
        Ok((summary, interrupt))
    })
}

/// The report as JSON text and the exception that stopped the batch, if one did (a
/// `KeyboardInterrupt`, or what the progress callback raised).
fn finish_batch(
    py: Python<'_>,
    outcome: Result<(batch::Summary, Option<PyErr>), drafter_catalog::Error>,
    observer: &Progress<'_>,
) -> PyResult<(String, Option<Py<PyAny>>)> {
    let (summary, interrupt) = outcome.map_err(|e| to_py(&e))?;
    let report = serde_json::to_string(&summary).map_err(|e| InternalError::new_err(e.to_string()))?;
    let error = interrupt.or_else(|| observer.error.lock().unwrap_or_else(|e| e.into_inner()).take());
    Ok((report, error.map(|e| e.into_value(py).into_any())))
}

/// A drawing's options from the JSON of `drafter_catalog::draw::DrawSpec` (the defaults when
/// `None`), checked for `input`.
fn draw_spec(spec_json: Option<&str>) -> PyResult<drafter_catalog::draw::DrawSpec> {
    spec_json
        .map(|json| serde_json::from_str(json).map_err(|e| InputError::new_err(format!("drawing options: {e}"))))
        .transpose()
        .map(Option::unwrap_or_default)
}

/// Draws `input` into `output` (.svg, .pdf or .dxf) atomically, through the cache when given, as
/// `drafter draw INPUT -o OUTPUT [--cache DIR]` does with the options of `spec_json`; returns the
/// file's record (JSON text). A failure is in the record.
#[pyfunction]
#[pyo3(signature = (input, output, *, spec_json=None, cache=None, cache_max=None, threads=None, max_triangles=None))]
#[allow(clippy::too_many_arguments)]
fn draw_file(
    py: Python<'_>,
    input: PathBuf,
    output: PathBuf,
    spec_json: Option<&str>,
    cache: Option<PathBuf>,
    cache_max: Option<u64>,
    threads: Option<usize>,
    max_triangles: Option<u64>,
) -> PyResult<String> {
    let spec = draw_spec(spec_json)?;
    let limits = limits(max_triangles);
    let cache = open_cache(cache.as_deref(), cache_max)?;
    let record = py.detach(|| {
        on_threads(threads, || {
            let Some(format) = drafter_catalog::draw::Format::of_path(&output) else {
                let why = format!("{}: output must end in .svg, .pdf or .dxf", output.display());
                return refused(&input, &output, &drafter_catalog::Error::Input(why));
            };
            let resolved = match spec.resolve(&input) {
                Ok(resolved) => resolved,
                Err(e) => return refused(&input, &output, &e),
            };
            if let Some(folder) = output.parent().filter(|p| !p.as_os_str().is_empty()) {
                let _ = std::fs::create_dir_all(folder);
            }
            let admit = |bytes| Some(Permit::unbounded(bytes));
            let outputs = [(format, output.clone())];
            let record = drafter_catalog::draw::draw_file(&input, &outputs, &resolved, &limits, cache.as_ref(), &admit);
            if let Some(cache) = cache.as_ref().filter(|c| c.max_bytes.is_some()) {
                cache.evict();
            }
            serde_json::to_value(&record)
                .unwrap_or_else(|e| refused(&input, &output, &drafter_catalog::Error::Io(e.to_string())))
        })
    })?;
    Ok(record.to_string())
}

/// Draws many inputs (files, folders, manifests) into `out_dir` in each of `formats` as `drafter
/// draw INPUTS... -o DIR --format ...` does; returns the report as JSON text and the exception that
/// stopped the catalog, if one did, as `bake_many`.
#[pyfunction]
#[pyo3(signature = (inputs, out_dir, *, manifests=Vec::new(), formats=Vec::new(), spec_json=None, cache=None, cache_max=None, memory=None, jobs=None, max_triangles=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn draw_many(
    py: Python<'_>,
    inputs: Vec<PathBuf>,
    out_dir: PathBuf,
    manifests: Vec<PathBuf>,
    formats: Vec<String>,
    spec_json: Option<&str>,
    cache: Option<PathBuf>,
    cache_max: Option<u64>,
    memory: Option<u64>,
    jobs: Option<usize>,
    max_triangles: Option<u64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(String, Option<Py<PyAny>>)> {
    let spec = draw_spec(spec_json)?;
    // The options checked once, before any file, as the CLI does.
    spec.resolve(inputs.first().map_or(Path::new(""), PathBuf::as_path)).map_err(|e| to_py(&e))?;
    let formats = match formats.is_empty() {
        true => vec![drafter_catalog::draw::Format::Svg],
        false => drafter_catalog::draw::Format::parse_list(&formats.join(",")).map_err(InputError::new_err)?,
    };
    let found = drafter_catalog::discover::discover_all(&inputs, &manifests, Some(&out_dir))
        .map_err(|e| InputError::new_err(e.to_string()))?;
    let options = drafter_catalog::draw::Options {
        spec,
        formats,
        limits: limits(max_triangles),
        cache: open_cache(cache.as_deref(), cache_max)?,
        scheduling: batch::Scheduling {
            memory_budget: memory.unwrap_or_else(batch::default_memory_budget),
            workers: jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from)).max(1),
        },
    };
    let stop = AtomicBool::new(false);
    let observer = Progress::new(progress, &stop);
    let summary = run_batch(py, &out_dir, &stop, &observer, options.cache.as_ref(), &|stop, observer| {
        drafter_catalog::draw::run(&found, &out_dir, &options, stop, observer)
    });
    finish_batch(py, summary, &observer)
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
    // As `drafter cache`: a folder that is not a cache is refused, not created.
    if !dir.join("entries").is_dir() {
        return Err(InputError::new_err(format!("{}: is not a drafter cache (no entries/ folder)", dir.display())));
    }
    let cache = Cache::open(&dir, size).map_err(|e| io_error(format!("{}: {e}", dir.display())))?;
    py.detach(|| match action {
        "stats" => serde_json::to_string(&cache.stats()).map_err(|e| InternalError::new_err(e.to_string())),
        "evict" => serde_json::to_string(&cache.evict()).map_err(|e| InternalError::new_err(e.to_string())),
        "clear" => cache.clear().map(|n| n.to_string()).map_err(|e| io_error(format!("{}: {e}", dir.display()))),
        other => Err(InputError::new_err(format!("unknown cache action {other:?}"))),
    })
}

#[pymodule]
fn _drafter(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(bake, m)?)?;
    m.add_function(wrap_pyfunction!(bake_file, m)?)?;
    m.add_function(wrap_pyfunction!(bake_many, m)?)?;
    m.add_function(wrap_pyfunction!(draw_file, m)?)?;
    m.add_function(wrap_pyfunction!(draw_many, m)?)?;
    m.add_function(wrap_pyfunction!(discover, m)?)?;
    m.add_function(wrap_pyfunction!(inspect, m)?)?;
    m.add_function(wrap_pyfunction!(cache, m)?)?;
    m.add("DrafterError", m.py().get_type::<DrafterError>())?;
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add("IoError", io_error_type(m.py())?)?;
    m.add("InternalError", m.py().get_type::<InternalError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("BUILD_ID", drafter_catalog::cache::BUILD_ID)?;
    Ok(())
}
