"""The Python package against the CLI: same bytes, same errors, the GIL released, the cache."""

import json
import os
import pathlib
import signal
import threading
import time

import pytest
from conftest import TETRAHEDRON, assert_confined, hostile_tree

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


# The rough edges of the package, each against what it once did.


def many_small_files(folder: pathlib.Path, count: int) -> pathlib.Path:
    folder.mkdir(parents=True)
    for k in range(count):
        (folder / f"t{k:02}.obj").write_bytes(TETRAHEDRON)
    return folder


def test_bake_many_reports_progress_once_per_file(tmp_path):
    folder = many_small_files(tmp_path / "in", 6)
    seen = []
    report = drafter.bake_many(folder, tmp_path / "out", jobs=2, progress=lambda r, d, t: seen.append((r, d, t)))
    assert report["baked"] == 6
    assert [d for _, d, _ in seen] == list(range(1, 7)) and {t for _, _, t in seen} == {6}
    assert sorted(r["input"] for r, _, _ in seen) == sorted(r["input"] for r in report["files"])
    assert all(r["status"] == "baked" and pathlib.Path(r["output"]).is_file() for r, _, _ in seen)


def test_a_raising_progress_callback_stops_the_batch_with_the_report(tmp_path):
    folder = many_small_files(tmp_path / "in", 8)

    def fail(record, done, total):
        raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough") as raised:
        drafter.bake_many(folder, tmp_path / "out", jobs=1, progress=fail)
    report = raised.value.report
    assert len(report["files"]) == 8 and report["baked"] >= 1 and report["skipped"] >= 1


def test_ctrl_c_stops_bake_many_at_the_next_file_with_the_partial_report(tmp_path):
    """SIGINT during the batch (sent once the first file is done, while the callback holds the
    batch for a moment, so that the batch's next step comes after it): the file done is written,
    no other file is started, and KeyboardInterrupt carries the partial report. Before, the
    batch ran to its end and the report was lost."""
    folder = many_small_files(tmp_path / "in", 10)

    def interrupt(record, done, total):
        if done == 1:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.5)  # the GIL released: the calling thread sees the signal meanwhile

    started = time.monotonic()
    with pytest.raises(KeyboardInterrupt) as raised:
        drafter.bake_many(folder, tmp_path / "out", jobs=1, progress=interrupt)
    assert time.monotonic() - started < 30
    report = raised.value.report
    statuses = [r["status"] for r in report["files"]]
    assert len(statuses) == 10 and statuses.count("baked") == 1 and statuses.count("skipped") == 9, statuses
    assert report["baked"] == 1 and report["skipped"] == 9
    (done,) = [r for r in report["files"] if r["status"] == "baked"]
    assert [p.name for p in (tmp_path / "out").rglob("*")] == [pathlib.Path(done["output"]).name]
    # The handler is Python's again: a batch after it runs to its end.
    assert drafter.bake_many(folder, tmp_path / "again", jobs=1)["baked"] == 10


def test_a_config_given_as_a_str_path_is_read_as_a_file(sample, tmp_path, monkeypatch):
    (tmp_path / "c.toml").write_text("[gradient]\nq = 12\n")
    expected = drafter.bake(sample, config={"gradient": {"q": 12}})
    assert expected != drafter.bake(sample)
    monkeypatch.chdir(tmp_path)
    assert drafter.bake(sample, config="c.toml") == expected
    assert drafter.bake(sample, config=str(tmp_path / "c.toml")) == expected
    (tmp_path / "settings").write_text("[gradient]\nq = 12\n")  # an existing file, any name
    assert drafter.bake(sample, config="settings") == expected
    assert drafter.bake(sample, config="[gradient]\nq = 12\n") == expected  # TOML text stays text
    assert drafter.bake(sample, config="") == drafter.bake(sample)
    with pytest.raises(FileNotFoundError):
        drafter.bake(sample, config="missing.toml")
    report = drafter.bake_many([sample], tmp_path / "out", config="c.toml")
    assert (tmp_path / "out" / "assembly.glb").read_bytes() == expected, report
    record = drafter.bake_file(sample, tmp_path / "one.glb", config="c.toml")
    assert record["status"] == "baked" and (tmp_path / "one.glb").read_bytes() == expected


def test_one_str_input_is_one_path_not_its_characters(tmp_path, monkeypatch):
    many_small_files(tmp_path / "models", 3)
    monkeypatch.chdir(tmp_path)
    report = drafter.bake_many("models", "out", jobs=1)
    assert report["baked"] == 3 and sorted(p.name for p in (tmp_path / "out").iterdir()) == ["t00.glb", "t01.glb", "t02.glb"]
    assert len(drafter.discover("models")) == 3
    assert len(drafter.bake_many(pathlib.Path("models"), "out2", jobs=1)["files"]) == 3
    (tmp_path / "list.txt").write_text("models/t00.obj\n")
    assert drafter.bake_many([], "out3", manifests="list.txt")["baked"] == 1


def test_cache_stats_of_a_missing_folder_creates_nothing(tmp_path):
    missing = tmp_path / "nothing-here"
    with pytest.raises(drafter.InputError, match="not a drafter cache"):
        drafter.cache_stats(missing)
    with pytest.raises(drafter.InputError):
        drafter.cache_clear(missing)
    with pytest.raises(drafter.InputError):
        drafter.cache_evict(missing, 0)
    assert not missing.exists()


@pytest.mark.parametrize(
    "call",
    [
        lambda s, t: drafter.bake(s, threads=-1),
        lambda s, t: drafter.bake(s, threads=0),
        lambda s, t: drafter.bake(s, threads=5000),
        lambda s, t: drafter.bake(s, max_triangles=-3),
        lambda s, t: drafter.bake_file(s, t / "a.glb", threads=-1),
        lambda s, t: drafter.bake_file(s, t / "a.glb", cache=t / "c", cache_max=-1),
        lambda s, t: drafter.bake_many([s], t / "out", jobs=-1),
        lambda s, t: drafter.bake_many([s], t / "out", memory=-1),
        lambda s, t: drafter.cache_evict(t, -1),
    ],
)
def test_out_of_range_numbers_raise_value_error_before_anything_runs(sample, tmp_path, call):
    with pytest.raises(ValueError, match="must be between"):
        call(sample, tmp_path)
    assert not list(tmp_path.iterdir())


def test_io_error_is_an_os_error(sample, tmp_path):
    assert issubclass(drafter.IoError, OSError) and issubclass(drafter.IoError, drafter.DrafterError)
    (tmp_path / "a-file").write_bytes(b"")
    with pytest.raises(OSError) as raised:
        drafter.bake_many([sample], tmp_path / "a-file" / "out")
    assert isinstance(raised.value, drafter.IoError) and "a-file" in str(raised.value)


def test_the_modules_names_are_its_api():
    public = {n for n in dir(drafter) if not n.startswith("_")}
    assert public <= set(drafter.__all__) | {"ray"}, public - set(drafter.__all__)
    assert not {"os", "json", "typing", "annotations", "Any", "Optional"} & set(dir(drafter))
    for name in drafter.__all__:
        assert hasattr(drafter, name), name


def test_bake_many_writes_nothing_outside_its_output_folder_and_the_cache(tmp_path):
    root = pathlib.Path(os.path.realpath(tmp_path))
    cases = hostile_tree(root)

    def bake(inputs, manifests, out_dir, cache):
        return drafter.bake_many(inputs, out_dir, manifests=manifests, cache=cache, jobs=2)

    outcomes = assert_confined(root, cases, bake)
    assert isinstance(outcomes["collide"], drafter.InputError), outcomes["collide"]
    assert (root / "victim" / "keep.txt").read_bytes() == b"not to be touched\n"
