"""Bake a catalog across a Ray cluster: one Ray task per file (or per ``files_per_task`` files),
each baking with drafter's own threads (``RAYON_NUM_THREADS`` and the pool set to the task's CPUs)
into a shared output folder, through a shared cache folder, with the same per-file records and
report as ``drafter bake DIR -o OUT --report``.

    import ray, drafter.ray
    ray.init(address="auto")                     # a cluster started with `ray start --head` / `--address`
    # run from the shared folder: relative paths are resolved on the driver
    report = drafter.ray.bake_catalog(["catalog"], "baked", cache="drafter-cache")

Every path (inputs, manifests, ``out_dir``, ``cache``, ``report``, a config file) is resolved on
the driver, against its working folder, before any task is sent: the workers' working folder is
``/``. No file is written outside ``out_dir`` and the cache: each task writes its output through
the local batch's confinement (``drafter.bake_file(..., out_dir=...)``). Every write is atomic (a
temporary file renamed into place), so a task that Ray retries after a worker or node is lost
leaves no partial file and bakes the same bytes again; with a cache, a retry of a file already
baked is a hit. A file drafter refuses is a ``"failed"`` record (not retried).
Inputs, outputs and the cache must be on storage every node sees (NFS or another shared folder).
"""

import json as _json
import os as _os
import time as _time
from typing import Any, Iterable, List, Optional, Sequence, Tuple

import drafter

__all__ = ["bake_catalog", "bake_dataset"]


def _bake_chunk(pairs: Sequence[Tuple[str, str]], out_dir: str, options: dict, cpus: int) -> List[dict]:
    """The work of one Ray task: each file through drafter.bake_file on ``cpus`` threads, its
    output a path relative to ``out_dir`` and confined below it as the local batch's are; each
    record also names the node that baked it."""
    import ray

    node = ray.get_runtime_context().get_node_id()
    return [dict(drafter.bake_file(i, o, out_dir=out_dir, threads=cpus, **options), node=node) for i, o in pairs]


def _absolute(path: Any) -> str:
    """``path`` against the driver's working folder (the workers' is ``/``)."""
    return _os.path.abspath(_os.path.expanduser(_os.fspath(path)))


def _options(config, cache, max_triangles) -> dict:
    """The per-file options of the tasks, every path made absolute and a config file read here.
    The cache's size bound is not among them: eviction lists the whole cache, so the driver runs it
    once at the end instead of every task after every file."""
    return {
        "config": drafter._config_value(config),
        "cache": None if cache is None else _absolute(cache),
        "max_triangles": max_triangles,
    }


def bake_catalog(
    inputs: Iterable[Any],
    out_dir: Any,
    *,
    manifests: Iterable[Any] = (),
    config: Any = None,
    cache: Optional[Any] = None,
    cache_max: Optional[int] = None,
    cpus_per_task: int = 1,
    files_per_task: int = 1,
    max_retries: int = 3,
    max_triangles: Optional[int] = None,
    report: Optional[Any] = None,
) -> dict:
    """Bakes ``inputs`` (files and folders, recursively) and ``manifests`` into ``out_dir`` on the
    Ray cluster this process is connected to (``ray.init`` first; a local one is started if not).

    Outputs mirror the inputs' relative paths as in the local batch. Returns the report (and writes
    it to ``report`` as JSON when given): ``files`` (one record per input, in input order),
    ``baked``, ``cached``, ``failed``, ``skipped``, ``wall_ms``, ``tasks``. Large files are
    submitted first. ``max_retries`` covers lost workers and nodes (Ray's task retries).
    """
    import ray

    if not ray.is_initialized():
        ray.init()
    started = _time.perf_counter()
    out_dir = _absolute(out_dir)
    inputs = [_absolute(p) for p in drafter._paths(inputs, "inputs")]
    manifests = [_absolute(p) for p in drafter._paths(manifests, "manifests")]
    options = _options(config, cache, max_triangles)
    _os.makedirs(out_dir, exist_ok=True)
    # (input, output relative to out_dir): the tasks create the outputs' folders, through the
    # same confinement as the local batch (no `..`, no symbolic link inside out_dir followed).
    pairs = drafter.discover(inputs, manifests, skip=out_dir)
    # Largest first, as the local batch orders its files: a big file started last would keep the
    # cluster waiting on one task.
    order = sorted(range(len(pairs)), key=lambda k: (-_size(pairs[k][0]), k))
    chunks = [order[k : k + max(1, files_per_task)] for k in range(0, len(order), max(1, files_per_task))]
    cpus = max(1, int(cpus_per_task))
    task = ray.remote(_bake_chunk).options(
        num_cpus=cpus,
        max_retries=max_retries,
        retry_exceptions=False,
        runtime_env={"env_vars": {"RAYON_NUM_THREADS": str(cpus)}},
    )
    refs = [task.remote([pairs[k] for k in chunk], out_dir, options, cpus) for chunk in chunks]
    records: List[Optional[dict]] = [None] * len(pairs)
    for chunk, ref in zip(chunks, refs):
        try:
            results = ray.get(ref)
        except Exception as e:  # a task that failed past its retries: its files fail, the rest go on
            results = [_lost(pairs[k][0], _os.path.join(out_dir, pairs[k][1]), e) for k in chunk]
        for k, record in zip(chunk, results):
            records[k] = record
    if options["cache"] is not None and cache_max is not None:
        drafter.cache_evict(options["cache"], cache_max)
    summary = _summary(records, started, len(chunks))
    if report is not None:
        _write_atomically(_absolute(report), _json.dumps(summary, indent=2).encode())
    return summary


def bake_dataset(dataset: Any, out_dir: Any, *, column: str = "path", cpus_per_task: int = 1, **kwargs) -> Any:
    """Bakes the files named by ``column`` of a Ray Dataset into ``out_dir`` (their file names under
    it), returning a Dataset of the per-file records (as JSON text in column ``record``). The
    options are ``bake_catalog``'s: ``config``, ``cache``, ``max_triangles`` (bound the cache with
    ``drafter.cache_evict`` once the dataset is consumed). Relative paths in the column are taken
    against the driver's working folder, as every other path."""
    options = _options(kwargs.pop("config", None), kwargs.pop("cache", None), kwargs.pop("max_triangles", None))
    if kwargs:
        raise TypeError(f"unknown options: {sorted(kwargs)}")
    out_dir = _absolute(out_dir)
    _os.makedirs(out_dir, exist_ok=True)
    cpus = max(1, int(cpus_per_task))
    base = _os.getcwd()

    def one(row: dict) -> dict:
        source = _os.path.join(base, _os.path.expanduser(_os.fspath(row[column])))
        output = _os.path.splitext(_os.path.basename(source))[0] + ".glb"
        return {"record": _json.dumps(drafter.bake_file(source, output, out_dir=out_dir, threads=cpus, **options))}

    return dataset.map(one, num_cpus=cpus, runtime_env={"env_vars": {"RAYON_NUM_THREADS": str(cpus)}})


def _size(path: str) -> int:
    try:
        return _os.path.getsize(path)
    except OSError:
        return 0


def _lost(input: str, output: str, error: BaseException) -> dict:
    return {
        "input": input,
        "output": output,
        "status": "failed",
        "cache": "off",
        "ms": 0.0,
        "bytes_in": 0,
        "bytes_out": 0,
        "estimated_peak_bytes": 0,
        "error": f"{input}: the Ray task failed: {type(error).__name__}: {error}".replace("\n", " "),
        "exit_code": 1,
    }


def _summary(records: List[Optional[dict]], started: float, tasks: int) -> dict:
    files = [r for r in records if r is not None]
    count = lambda s: sum(1 for r in files if r["status"] == s)  # noqa: E731
    return {
        "files": files,
        "baked": count("baked"),
        "cached": count("cached"),
        "failed": count("failed"),
        "skipped": count("skipped"),
        "wall_ms": (_time.perf_counter() - started) * 1e3,
        "tasks": tasks,
    }


def _write_atomically(path: str, data: bytes) -> None:
    temp = f"{path}.{_os.getpid()}.tmp"
    with open(temp, "wb") as f:
        f.write(data)
        f.flush()
        _os.fsync(f.fileno())
    _os.replace(temp, path)
