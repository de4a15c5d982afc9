"""The Python package against the CLI: same bytes, same errors, the GIL released, the cache."""

import json
import os
import pathlib
import threading

import pytest

import drafter


def test_bake_returns_the_clis_bytes(cli, sample, models, tmp_path):
    inputs = [
        sample,
        models / "gltf" / "GearboxAssy" / "GearboxAssy.gltf",  # external .bin beside it
        models / "obj" / "common-3d-test-models" / "fandisk.obj",
        models / "obj" / "cgal" / "blade.off",
    ]
    for path in inputs:
        out = tmp_path / (path.stem + ".glb")
        cli("bake", path, "-o", out, "-q")
        assert drafter.bake(path) == out.read_bytes(), path
    # Bytes with the file's name are the same bake; a config as TOML text or as a mapping too.
    assert drafter.bake(sample.read_bytes(), name=sample.name) == (tmp_path / "assembly.glb").read_bytes()
    config = tmp_path / "c.toml"
    config.write_text('[gradient]\nq = 12\n[output]\ncompress = "meshopt"\n')
    out = tmp_path / "configured.glb"
    cli("bake", sample, "-o", out, "-q", "--config", config)
    expected = out.read_bytes()
    assert drafter.bake(sample, config=config.read_text()) == expected
    assert drafter.bake(sample, config=config) == expected
    assert drafter.bake(sample, config={"gradient": {"q": 12}, "output": {"compress": "meshopt"}}) == expected
    assert drafter.bake(sample, threads=1) == drafter.bake(sample, threads=2)


def test_errors_are_typed_and_name_the_place(tmp_path):
    with pytest.raises(drafter.InputError, match="garbage.stl"):
        drafter.bake(b"solid x\n facet nonsense", name="garbage.stl")
    with pytest.raises(drafter.InputError, match="missing.obj"):
        drafter.bake(tmp_path / "missing.obj")
    with pytest.raises(drafter.InputError, match="gradient"):
        drafter.bake(b"", config={"gradient": {"q": 0}})
    with pytest.raises(drafter.InputError, match="triangles"):
        drafter.bake(pathlib.Path(__file__).parents[2] / "samples" / "assembly.glb", max_triangles=10)
    assert issubclass(drafter.InputError, drafter.DrafterError)
    with pytest.raises(TypeError):
        drafter.bake(12)


def test_inspect_matches_the_cli(cli, sample):
    expected = json.loads(cli("inspect", sample, "--json").stdout)
    report = drafter.inspect(sample)
    assert report["triangles"] == expected["triangles"]
    assert report["parts"] == expected["parts"]
    assert report["topology"] == expected["topology"]
    baked = drafter.inspect(drafter.bake(sample), name="a.glb")
    assert baked["baked"]["root"]["partCount"] == len(baked["baked"]["parts"]) > 0


def test_the_gil_is_released_while_baking(models):
    """While a bake runs in a thread, the main thread keeps running Python: with the GIL held it
    would not run at all until the bake returned."""
    path = models / "obj" / "common-3d-test-models" / "stanford-bunny.obj"
    done = []
    worker = threading.Thread(target=lambda: done.append(drafter.bake(path, threads=1)))
    spins = 0
    worker.start()
    while worker.is_alive():
        spins += 1
    worker.join()
    assert done and spins > 10_000, spins


def test_bake_file_through_the_cache(cli, sample, tmp_path):
    cache = tmp_path / "cache"
    first = drafter.bake_file(sample, tmp_path / "a.glb", cache=cache)
    assert (first["status"], first["cache"]) == ("baked", "miss")
    second = drafter.bake_file(sample, tmp_path / "b.glb", cache=cache)
    assert (second["status"], second["cache"]) == ("cached", "hit")
    assert (tmp_path / "a.glb").read_bytes() == (tmp_path / "b.glb").read_bytes() == drafter.bake(sample)
    # A damaged entry is detected, removed and rebuilt: never served.
    (entry,) = [p for p in (cache / "entries").rglob("*") if p.is_file()]
    data = bytearray(entry.read_bytes())
    data[len(data) // 2] ^= 0xFF
    entry.write_bytes(bytes(data))
    third = drafter.bake_file(sample, tmp_path / "c.glb", cache=cache)
    assert (third["status"], third["cache"]) == ("baked", "rebuilt")
    assert (tmp_path / "c.glb").read_bytes() == (tmp_path / "a.glb").read_bytes()
    assert drafter.cache_stats(cache)["entries"] == 1
    # The CLI reads the same cache: a hit.
    out = tmp_path / "d.glb"
    result = cli("bake", sample, "-o", out, "--cache", cache)
    assert b"cached" in result.stderr and out.read_bytes() == (tmp_path / "a.glb").read_bytes()
    failed = drafter.bake_file(tmp_path / "nothing.obj", tmp_path / "x.glb", cache=cache)
    assert failed["status"] == "failed" and failed["exit_code"] == 2 and "nothing.obj" in failed["error"]
    assert drafter.cache_clear(cache) == 1


def test_bake_many_matches_the_cli_batch(cli, models, tmp_path):
    folder = models / "obj" / "cgal"
    cli("bake", folder, "-o", tmp_path / "cli", "-q")
    report = drafter.bake_many([folder], tmp_path / "py", jobs=2)
    assert report["failed"] == 0 and report["baked"] == len(report["files"]) > 3
    for record in report["files"]:
        relative = pathlib.Path(record["output"]).relative_to(tmp_path / "py")
        assert (tmp_path / "cli" / relative).read_bytes() == pathlib.Path(record["output"]).read_bytes()
    assert not [p for p in (tmp_path / "py").rglob("*") if p.name.startswith(".")], "no temporary file left"
