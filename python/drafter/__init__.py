"""drafter: bake CAD assemblies and meshes into glTF assets for technical illustration.

The same bake as the ``drafter`` command line, byte for byte (both run the Rust crate
drafter-catalog). Every call releases the GIL while it works, so Python threads bake in parallel.

    import drafter
    glb = drafter.bake("gearbox.gltf")                       # bytes of the baked .glb
    glb = drafter.bake(stl_bytes, name="part.stl", config={"gradient": {"q": 12}})
    info = drafter.inspect(glb)                              # what ``drafter inspect --json`` prints
    record = drafter.bake_file("a.obj", "out/a.glb", cache="~/.cache/drafter")
    report = drafter.bake_many("models/", "baked/", cache="drafter-cache/")
    drafter.draw("gearbox.gltf", "gearbox.pdf", sheet="A3", projection="third", hidden="dashed")
    report = drafter.draw_many("models/", "sheets/", format=["svg", "pdf"], sheet="A3", cache="drafter-cache/")

Errors raise :class:`InputError` (bad input or options: the CLI's exit code 2), :class:`IoError`
(a file could not be read or written: 3; also an :class:`OSError`) or :class:`InternalError` (a
bug: 1), all subclasses of :class:`DrafterError`. A number out of range (``threads=-1``) raises
:class:`ValueError` before anything runs. ``bake_file``, ``bake_many`` and ``draw_many`` report a
failed file in their records instead of raising.

**Paths.** Wherever a list of paths is asked for (``bake_many``'s inputs and manifests,
``discover``), one ``str`` or ``os.PathLike`` is one path, never a sequence of characters.

**Configurations** (``config=``): ``None`` (the defaults), a mapping of the TOML file's tables
(``{"gradient": {"q": 12}}``), an ``os.PathLike`` naming a TOML file, or a ``str``. A ``str`` is a
file's path when it has no line break and no ``=`` and either names an existing file or ends in
``.toml`` (a missing ``c.toml`` raises :class:`FileNotFoundError`); any other ``str`` is TOML text
(``"[gradient]\\nq = 12"``).

``drafter.ray`` bakes catalogs across a Ray cluster (``pip install drafter[ray]``).
"""

import json as _json
import numbers as _numbers
import os as _os
import typing as _t

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
    "draw",
    "draw_many",
    "inspect",
]

_PathLike = _t.Union[str, "_os.PathLike[str]"]
#: A bake configuration: a mapping of the TOML file's tables, a TOML file's path, or TOML text
#: (the module's docs give the rule that tells a path from text).
_Config = _t.Union[None, str, "_os.PathLike[str]", _t.Mapping[str, _t.Any]]
_Source = _t.Union[bytes, bytearray, memoryview, _PathLike]
#: ``progress(record, done, total)`` of ``bake_many``.
_Progress = _t.Callable[[dict, int, int], _t.Any]


def _is_config_path(text: str) -> bool:
    """The rule of the module's docs: a ``str`` is a path when it has no line break and no ``=``
    and names an existing file or ends in ``.toml``."""
    if not text or "\n" in text or "\r" in text or "=" in text:
        return False
    return text.lower().endswith(".toml") or _os.path.isfile(_os.path.expanduser(text))


def _config_value(config: _Config) -> _t.Union[None, str, _t.Mapping[str, _t.Any]]:
    """``config`` with a path read: ``None``, TOML text or a mapping (what ``drafter.ray`` sends
    to its workers, whose working folder is not the caller's)."""
    if config is None or isinstance(config, _t.Mapping):
        return config
    if isinstance(config, str) and not _is_config_path(config):
        return config
    if isinstance(config, (str, _os.PathLike)):
        with open(_os.path.expanduser(_os.fspath(config)), encoding="utf-8") as f:
            return f.read()
    raise TypeError(f"config must be TOML text, a path or a mapping, not {type(config).__name__}")


def _config(config: _Config) -> dict:
    value = _config_value(config)
    if value is None:
        return {}
    if isinstance(value, str):
        return {"config_toml": value}
    return {"config_json": _json.dumps(value)}


def _paths(paths: _t.Union[_PathLike, _t.Iterable[_PathLike]], what: str) -> _t.List[str]:
    """A list of paths: one ``str`` or ``os.PathLike`` is one path."""
    if isinstance(paths, (str, _os.PathLike)):
        return [_os.fspath(paths)]
    if isinstance(paths, (bytes, bytearray)):
        raise TypeError(f"{what}: give paths as str or os.PathLike, not bytes")
    return [_os.fspath(p) for p in paths]


def _count(name: str, value: _t.Optional[int], low: int = 1, high: int = (1 << 64) - 1) -> _t.Optional[int]:
    """``value`` checked to be a whole number in ``low..=high`` (``None`` passes)."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, _numbers.Integral):
        raise TypeError(f"{name} must be a whole number, not {type(value).__name__}")
    value = int(value)
    if not low <= value <= high:
        raise ValueError(f"{name} must be between {low} and {high}, not {value}")
    return value


def _cache_path(cache: _t.Optional[_PathLike]) -> _t.Optional[str]:
    return None if cache is None else _os.path.expanduser(_os.fspath(cache))


def _source(data_or_path: _Source, name: _t.Optional[str]) -> dict:
    if isinstance(data_or_path, (bytes, bytearray, memoryview)):
        return {"data": bytes(data_or_path), "name": name}
    if isinstance(data_or_path, (str, _os.PathLike)):
        return {"path": _os.fspath(data_or_path)}
    raise TypeError(f"expected bytes or a path, not {type(data_or_path).__name__}")


def bake(
    data_or_path: _Source,
    config: _Config = None,
    *,
    name: _t.Optional[str] = None,
    threads: _t.Optional[int] = None,
    max_triangles: _t.Optional[int] = None,
) -> bytes:
    """Bakes a model (a path, or its bytes) and returns the baked GLB's bytes.

    ``name`` names in-memory bytes (``"part.stl"``): it breaks ties in format detection and is
    recorded in the output as the CLI records the input's file name. A glTF given as bytes can only
    use data URIs; give its path to resolve buffers beside it. ``threads`` (1 to 1024) runs the
    bake on a pool of its own (the output is the same bytes at any thread count).
    """
    return _drafter.bake(
        **_source(data_or_path, name),
        **_config(config),
        threads=_count("threads", threads, 1, 1024),
        max_triangles=_count("max_triangles", max_triangles),
    )


def inspect(data_or_path: _Source, *, name: _t.Optional[str] = None, max_triangles: _t.Optional[int] = None) -> dict:
    """What ``drafter inspect --json`` reports: format, instances, totals, bounds, welded topology,
    and for a baked file its parts, boxes, projectors and byte sections."""
    return _json.loads(
        _drafter.inspect(**_source(data_or_path, name), max_triangles=_count("max_triangles", max_triangles))
    )


def bake_file(
    input: _PathLike,
    output: _PathLike,
    *,
    config: _Config = None,
    cache: _t.Optional[_PathLike] = None,
    cache_max: _t.Optional[int] = None,
    threads: _t.Optional[int] = None,
    max_triangles: _t.Optional[int] = None,
    out_dir: _t.Optional[_PathLike] = None,
) -> dict:
    """Bakes ``input`` into ``output`` (.glb, or .gltf with its .bin) atomically, through the cache
    folder ``cache`` when given, and returns the file's record as in a batch report:
    ``{"input", "output", "status": "baked"|"cached"|"failed", "cache", "ms", "bytes_in",
    "bytes_out", "error", "exit_code", ...}``. A failure is reported in the record, not raised.

    With ``out_dir``, ``output`` is a path relative to that folder and is kept below it as
    ``bake_many``'s outputs are: plain names only (no ``..``, not absolute), no symbolic link inside
    the folder followed; anything else is a failed record and nothing is written (``drafter.ray``'s
    tasks bake so)."""
    record = _drafter.bake_file(
        _os.fspath(input),
        _os.fspath(output),
        root=None if out_dir is None else _os.fspath(out_dir),
        **_config(config),
        cache=_cache_path(cache),
        cache_max=_count("cache_max", cache_max, 0),
        threads=_count("threads", threads, 1, 1024),
        max_triangles=_count("max_triangles", max_triangles),
    )
    return _json.loads(record)


def bake_many(
    inputs: _t.Union[_PathLike, _t.Iterable[_PathLike]],
    out_dir: _PathLike,
    *,
    manifests: _t.Union[_PathLike, _t.Iterable[_PathLike]] = (),
    config: _Config = None,
    cache: _t.Optional[_PathLike] = None,
    cache_max: _t.Optional[int] = None,
    memory: _t.Optional[int] = None,
    jobs: _t.Optional[int] = None,
    max_triangles: _t.Optional[int] = None,
    progress: _t.Optional[_Progress] = None,
) -> dict:
    """``drafter bake INPUTS... -o OUT_DIR`` in this process: files and folders (recursively) and
    manifests (``inputs`` and ``manifests``: a path or a list of paths), baked side by side under a
    memory budget (``memory`` bytes; default half the available memory), ``jobs`` files at once.
    Returns the batch report (``files``, counts, ``wall_ms``, ...). No file is written outside
    ``out_dir`` (and the cache folder).

    ``progress(record, done, total)`` is called once for each file baked, written from the cache
    or failed, as it finishes, with its record (as in the report), how many have finished and how
    many the batch holds. It runs on a baking thread with the GIL held: keep it short. If it
    raises, the batch stops as on Ctrl-C and the exception is raised with ``.report`` set.

    **Ctrl-C** (SIGINT, while Python's default handler is installed and ``bake_many`` runs on the
    main thread) stops the batch as the CLI's first Ctrl-C does: no file is started after it, the
    files being baked finish and are written, and ``KeyboardInterrupt`` is raised with the partial
    report as its ``.report`` attribute (the files not started have status ``"skipped"``)::

        try:
            report = drafter.bake_many("models/", "baked/")
        except KeyboardInterrupt as stopped:
            report = stopped.report
    """
    on_finished = None
    if progress is not None:
        if not callable(progress):
            raise TypeError(f"progress must be callable, not {type(progress).__name__}")

        def on_finished(record: str, done: int, total: int) -> None:
            progress(_json.loads(record), done, total)

    report, error = _drafter.bake_many(
        _paths(inputs, "inputs"),
        _os.fspath(out_dir),
        manifests=_paths(manifests, "manifests"),
        **_config(config),
        cache=_cache_path(cache),
        cache_max=_count("cache_max", cache_max, 0),
        memory=_count("memory", memory),
        jobs=_count("jobs", jobs, 1, 1 << 16),
        max_triangles=_count("max_triangles", max_triangles),
        progress=on_finished,
    )
    report = _json.loads(report)
    if error is not None:
        error.report = report
        raise error
    return report


_SHEET_OPTIONS = ("views", "projection", "scale", "up", "front", "units", "date", "title", "section", "uncut")


def _names(value: _t.Union[str, _t.Iterable[str]], what: str) -> _t.List[str]:
    """A list of names: one ``str`` (``"front,top"``, commas allowed) or an iterable of them."""
    if isinstance(value, str):
        return [value]
    if isinstance(value, (bytes, bytearray)):
        raise TypeError(f"{what}: give names as str, not bytes")
    return [str(v) for v in value]


def _pair(value: _t.Any, what: str, kind: type) -> _t.List[_t.Any]:
    """Two numbers from a pair (``(800, 600)``) or ``"800x600"`` / ``"35,25"`` text."""
    if isinstance(value, str):
        parts = value.replace("x", ",").split(",")
        value = [p.strip() for p in parts]
    try:
        first, second = value
        return [kind(first), kind(second)]
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be two numbers, not {value!r}") from None


def _draw_spec(options: _t.Mapping[str, _t.Any]) -> str:
    """The drawing options as the JSON of drafter-catalog's ``DrawSpec`` (what ``drafter draw``'s
    flags fill): only the options given, the CLI's defaults for the rest."""
    spec: _t.Dict[str, _t.Any] = {}
    for name in ("hidden", "smooth", "style", "fill"):
        if options.get(name) is not None:
            spec[name] = str(options[name]).lower()
    if options.get("tolerance") is not None:
        spec["tolerance_px"] = float(options["tolerance"])
    if options.get("size") is not None:
        spec["size"] = _pair(options["size"], "size", int)
    if options.get("view") is not None:
        spec["view"] = _pair(options["view"], "view", float)
    if options.get("ortho") is not None:
        spec["orthographic"] = bool(options["ortho"])
    sheet = options.get("sheet")
    given = [n for n in _SHEET_OPTIONS if options.get(n) is not None]
    if sheet is None:
        if given:
            raise ValueError(f"{', '.join(given)}: options of a sheet; give sheet='A3' (or A4, A2, A1, A0)")
    else:
        for name in ("size", "view", "ortho", "fill"):
            if options.get(name) is not None:
                raise ValueError(f"{name}: an option of one view, which a sheet does not read")
        table: _t.Dict[str, _t.Any] = {"size": str(sheet)}
        for name in given:
            value = options[name]
            if name in ("views", "uncut"):
                table[name] = _names(value, name)
            elif name in ("projection", "units"):
                table[name] = str(value).lower()
            else:
                table[name] = str(value)
        spec["sheet"] = table
    return _json.dumps(spec)


def _raise_failed(record: dict) -> dict:
    """``record`` if its file was drawn or written from the cache; else its error, raised as the
    exception of its exit code."""
    if record.get("status") != "failed":
        return record
    message = record.get("error") or record.get("input", "")
    kind = {2: InputError, 3: IoError}.get(record.get("exit_code"), InternalError)
    raise kind(message)


def draw(
    input: _PathLike,
    output: _PathLike,
    *,
    sheet: _t.Optional[str] = None,
    views: _t.Union[None, str, _t.Iterable[str]] = None,
    projection: _t.Optional[str] = None,
    scale: _t.Optional[str] = None,
    up: _t.Optional[str] = None,
    front: _t.Optional[str] = None,
    units: _t.Optional[str] = None,
    date: _t.Optional[str] = None,
    title: _t.Optional[str] = None,
    section: _t.Optional[str] = None,
    uncut: _t.Union[None, str, _t.Iterable[str]] = None,
    hidden: _t.Optional[str] = None,
    smooth: _t.Optional[str] = None,
    style: _t.Optional[str] = None,
    tolerance: _t.Optional[float] = None,
    size: _t.Any = None,
    view: _t.Any = None,
    ortho: _t.Optional[bool] = None,
    fill: _t.Optional[str] = None,
    cache: _t.Optional[_PathLike] = None,
    cache_max: _t.Optional[int] = None,
    threads: _t.Optional[int] = None,
    max_triangles: _t.Optional[int] = None,
) -> dict:
    """``drafter draw INPUT -o OUTPUT [options]`` in this process: the same bytes. ``output`` ends
    in ``.svg``, ``.pdf`` or ``.dxf``; a model without baked lines is baked in memory first.

    One view (``size=(800, 600)``, ``view=(azimuth, elevation)`` in degrees, ``ortho``, ``fill``
    ``"none"|"flat"|"bands"``), or with ``sheet="A3"`` (A4 to A0) the standard views on a drawing
    sheet: ``views`` (``["front", "top", "right", "iso"]`` or ``"front,top"``), ``projection``
    (``"first"``, ``"third"``), ``scale`` (``"1:2"``), ``up`` and ``front`` (``"y"``, ``"-z"``, ...),
    ``units`` (``"m"``, ``"cm"``, ``"mm"``, ``"in"``), ``date``, ``title``, ``section``
    (``"x=10"``), ``uncut`` (``["shaft*", "*bolt*"]``). Both: ``hidden``
    (``"none"|"dashed"|"solid"``), ``smooth`` (``"none"|"thin"|"dashed"``), ``style``
    (``"iso128"|"gooch"``), ``tolerance`` (pixels). Options left ``None`` take the CLI's defaults.

    With ``cache`` (a folder), a drawing made before with the same input, options and build is
    written from it. Returns the file's record (``status``: ``"drawn"`` or ``"cached"``, ``cache``,
    ``ms``, ``bytes_out``, ``notes``, ...); a failure raises :class:`InputError`, :class:`IoError`
    or :class:`InternalError`.
    """
    spec = _draw_spec(locals())
    record = _drafter.draw_file(
        _os.fspath(input),
        _os.fspath(output),
        spec_json=spec,
        cache=_cache_path(cache),
        cache_max=_count("cache_max", cache_max, 0),
        threads=_count("threads", threads, 1, 1024),
        max_triangles=_count("max_triangles", max_triangles),
    )
    return _raise_failed(_json.loads(record))


def draw_many(
    inputs: _t.Union[_PathLike, _t.Iterable[_PathLike]],
    out_dir: _PathLike,
    *,
    format: _t.Union[str, _t.Iterable[str]] = "svg",
    manifests: _t.Union[_PathLike, _t.Iterable[_PathLike]] = (),
    sheet: _t.Optional[str] = None,
    views: _t.Union[None, str, _t.Iterable[str]] = None,
    projection: _t.Optional[str] = None,
    scale: _t.Optional[str] = None,
    up: _t.Optional[str] = None,
    front: _t.Optional[str] = None,
    units: _t.Optional[str] = None,
    date: _t.Optional[str] = None,
    title: _t.Optional[str] = None,
    section: _t.Optional[str] = None,
    uncut: _t.Union[None, str, _t.Iterable[str]] = None,
    hidden: _t.Optional[str] = None,
    smooth: _t.Optional[str] = None,
    style: _t.Optional[str] = None,
    tolerance: _t.Optional[float] = None,
    size: _t.Any = None,
    view: _t.Any = None,
    ortho: _t.Optional[bool] = None,
    fill: _t.Optional[str] = None,
    cache: _t.Optional[_PathLike] = None,
    cache_max: _t.Optional[int] = None,
    memory: _t.Optional[int] = None,
    jobs: _t.Optional[int] = None,
    max_triangles: _t.Optional[int] = None,
    progress: _t.Optional[_Progress] = None,
) -> dict:
    """``drafter draw INPUTS... -o OUT_DIR --format ...`` in this process: a catalog of drawings.
    Each input (files, folders recursively, manifests, as :func:`bake_many` takes them) is drawn
    once with the options of :func:`draw` and written in each ``format`` (``"svg"``, ``"pdf"``,
    ``"dxf"``, or a list of them) as ``OUT_DIR/<its relative path>.<format>``; nothing is written
    outside ``out_dir`` and the cache. With ``cache``, a rerun writes the drawings from the cache
    without loading a model. Returns the report (``files``, ``drawn``, ``cached``, ``failed``,
    ``wall_ms``, ...); failed files are in it, not raised. ``progress`` and Ctrl-C behave as in
    :func:`bake_many`.
    """
    spec = _draw_spec(locals())
    on_finished = None
    if progress is not None:
        if not callable(progress):
            raise TypeError(f"progress must be callable, not {type(progress).__name__}")

        def on_finished(record: str, done: int, total: int) -> None:
            progress(_json.loads(record), done, total)

    report, error = _drafter.draw_many(
        _paths(inputs, "inputs"),
        _os.fspath(out_dir),
        manifests=_paths(manifests, "manifests"),
        formats=_names(format, "format"),
        spec_json=spec,
        cache=_cache_path(cache),
        cache_max=_count("cache_max", cache_max, 0),
        memory=_count("memory", memory),
        jobs=_count("jobs", jobs, 1, 1 << 16),
        max_triangles=_count("max_triangles", max_triangles),
        progress=on_finished,
    )
    report = _json.loads(report)
    if error is not None:
        error.report = report
        raise error
    return report


def discover(
    inputs: _t.Union[_PathLike, _t.Iterable[_PathLike]],
    manifests: _t.Union[_PathLike, _t.Iterable[_PathLike]] = (),
    skip: _t.Optional[_PathLike] = None,
) -> _t.List[_t.Tuple[str, str]]:
    """The files a batch of ``inputs`` (files, folders) and ``manifests`` bakes, as
    ``(input, output path relative to the output folder)`` pairs; ``skip`` is a folder never
    entered (the output folder)."""
    pairs = _drafter.discover(
        _paths(inputs, "inputs"),
        _paths(manifests, "manifests"),
        None if skip is None else _os.fspath(skip),
    )
    return [(_os.fspath(i), _os.fspath(o)) for i, o in pairs]


def cache_stats(cache: _PathLike) -> dict:
    """Entries, bytes and temporary files of a cache folder (``drafter cache stats``). A folder
    that is not a cache raises :class:`InputError` and is left as it was (not created)."""
    return _json.loads(_drafter.cache(_cache_path(cache), "stats"))


def cache_evict(cache: _PathLike, max_bytes: int) -> dict:
    """Removes the least recently used entries until the cache holds at most ``max_bytes``."""
    return _json.loads(_drafter.cache(_cache_path(cache), "evict", _count("max_bytes", max_bytes, 0)))


def cache_clear(cache: _PathLike) -> int:
    """Removes every entry; returns how many there were."""
    return int(_drafter.cache(_cache_path(cache), "clear"))
