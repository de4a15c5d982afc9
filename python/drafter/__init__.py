"""drafter: bake CAD assemblies and meshes into glTF assets for technical illustration.

The same bake as the ``drafter`` command line, byte for byte (both run the Rust crate
drafter-catalog). Every call releases the GIL while it works, so Python threads bake in parallel.

    import drafter
    glb = drafter.bake("gearbox.gltf")                       # bytes of the baked .glb
    glb = drafter.bake(stl_bytes, name="part.stl", config={"gradient": {"q": 12}})
    info = drafter.inspect(glb)                              # what ``drafter inspect --json`` prints
    record = drafter.bake_file("a.obj", "out/a.glb", cache="~/.cache/drafter")
    report = drafter.bake_many(["models/"], "baked/", cache="/shared/drafter-cache")

Errors raise :class:`InputError` (bad input or options: the CLI's exit code 2), :class:`IoError`
(a file could not be read or written: 3) or :class:`InternalError` (a bug: 1), all subclasses of
:class:`DrafterError`. ``bake_file`` and ``bake_many`` report a failed file in their records instead.

``drafter.ray`` bakes catalogs across a Ray cluster.
"""

from __future__ import annotations

import json
import os
from typing import Any, Iterable, List, Mapping, Optional, Tuple, Union

from . import _drafter
from ._drafter import BUILD_ID, DrafterError, InputError, InternalError, IoError, __version__

__all__ = [
    "BUILD_ID",
    "DrafterError",
    "InputError",
    "InternalError",
    "IoError",
    "__version__",
    "bake",
    "bake_file",
    "bake_many",
    "cache_clear",
    "cache_evict",
    "cache_stats",
    "discover",
    "inspect",
]

PathLike = Union[str, "os.PathLike[str]"]
#: A bake configuration: TOML text (a ``str``), a path to a TOML file (``os.PathLike``), or a
#: mapping of the same tables (``{"gradient": {"q": 12}, "part": [{"name": "gear", ...}]}``).
Config = Union[None, str, "os.PathLike[str]", Mapping[str, Any]]
Source = Union[bytes, bytearray, memoryview, PathLike]


def _config(config: Config) -> dict:
    if config is None:
        return {}
    if isinstance(config, os.PathLike):
        with open(config, encoding="utf-8") as f:
            return {"config_toml": f.read()}
    if isinstance(config, str):
        return {"config_toml": config}
    if isinstance(config, Mapping):
        return {"config_json": json.dumps(config)}
    raise TypeError(f"config must be TOML text, a path or a mapping, not {type(config).__name__}")


def _source(data_or_path: Source, name: Optional[str]) -> dict:
    if isinstance(data_or_path, (bytes, bytearray, memoryview)):
        return {"data": bytes(data_or_path), "name": name}
    if isinstance(data_or_path, (str, os.PathLike)):
        return {"path": os.fspath(data_or_path)}
    raise TypeError(f"expected bytes or a path, not {type(data_or_path).__name__}")


def bake(
    data_or_path: Source,
    config: Config = None,
    *,
    name: Optional[str] = None,
    threads: Optional[int] = None,
    max_triangles: Optional[int] = None,
) -> bytes:
    """Bakes a model (a path, or its bytes) and returns the baked GLB's bytes.

    ``name`` names in-memory bytes (``"part.stl"``): it breaks ties in format detection and is
    recorded in the output as the CLI records the input's file name. A glTF given as bytes can only
    use data URIs; give its path to resolve buffers beside it. ``threads`` runs the bake on a pool
    of its own (the output is the same bytes at any thread count).
    """
    return _drafter.bake(
        **_source(data_or_path, name), **_config(config), threads=threads, max_triangles=max_triangles
    )


def inspect(data_or_path: Source, *, name: Optional[str] = None, max_triangles: Optional[int] = None) -> dict:
    """What ``drafter inspect --json`` reports: format, instances, totals, bounds, welded topology,
    and for a baked file its parts, boxes, projectors and byte sections."""
    return json.loads(_drafter.inspect(**_source(data_or_path, name), max_triangles=max_triangles))


def bake_file(
    input: PathLike,
    output: PathLike,
    *,
    config: Config = None,
    cache: Optional[PathLike] = None,
    cache_max: Optional[int] = None,
    threads: Optional[int] = None,
    max_triangles: Optional[int] = None,
) -> dict:
    """Bakes ``input`` into ``output`` (.glb, or .gltf with its .bin) atomically, through the cache
    folder ``cache`` when given, and returns the file's record as in a batch report:
    ``{"input", "output", "status": "baked"|"cached"|"failed", "cache", "ms", "bytes_in",
    "bytes_out", "error", "exit_code", ...}``. A failure is reported in the record, not raised."""
    record = _drafter.bake_file(
        os.fspath(input),
        os.fspath(output),
        **_config(config),
        cache=None if cache is None else os.path.expanduser(os.fspath(cache)),
        cache_max=cache_max,
        threads=threads,
        max_triangles=max_triangles,
    )
    return json.loads(record)


def bake_many(
    inputs: Iterable[PathLike],
    out_dir: PathLike,
    *,
    manifests: Iterable[PathLike] = (),
    config: Config = None,
    cache: Optional[PathLike] = None,
    cache_max: Optional[int] = None,
    memory: Optional[int] = None,
    jobs: Optional[int] = None,
    max_triangles: Optional[int] = None,
) -> dict:
    """``drafter bake INPUTS... -o OUT_DIR`` in this process: files and folders (recursively) and
    manifests, baked side by side under a memory budget (``memory`` bytes; default half the
    available memory), ``jobs`` files at once. Returns the batch report (``files``, counts,
    ``wall_ms``)."""
    report = _drafter.bake_many(
        [os.fspath(p) for p in inputs],
        os.fspath(out_dir),
        manifests=[os.fspath(p) for p in manifests],
        **_config(config),
        cache=None if cache is None else os.path.expanduser(os.fspath(cache)),
        cache_max=cache_max,
        memory=memory,
        jobs=jobs,
        max_triangles=max_triangles,
    )
    return json.loads(report)


def discover(
    inputs: Iterable[PathLike], manifests: Iterable[PathLike] = (), skip: Optional[PathLike] = None
) -> List[Tuple[str, str]]:
    """The files a batch of ``inputs`` (files, folders) and ``manifests`` bakes, as
    ``(input, output path relative to the output folder)`` pairs; ``skip`` is a folder never
    entered (the output folder)."""
    pairs = _drafter.discover(
        [os.fspath(p) for p in inputs],
        [os.fspath(p) for p in manifests],
        None if skip is None else os.fspath(skip),
    )
    return [(os.fspath(i), os.fspath(o)) for i, o in pairs]


def cache_stats(cache: PathLike) -> dict:
    """Entries, bytes and temporary files of a cache folder (``drafter cache stats``)."""
    return json.loads(_drafter.cache(os.fspath(cache), "stats"))


def cache_evict(cache: PathLike, max_bytes: int) -> dict:
    """Removes the least recently used entries until the cache holds at most ``max_bytes``."""
    return json.loads(_drafter.cache(os.fspath(cache), "evict", max_bytes))


def cache_clear(cache: PathLike) -> int:
    """Removes every entry; returns how many there were."""
    return int(_drafter.cache(os.fspath(cache), "clear"))
