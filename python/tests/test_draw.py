"""drafter.draw and drafter.draw_many against the CLI: the same bytes, the same errors,
the cache's hits with the bytes of a drawing, nothing written outside the output folder."""

import os
import pathlib
import shutil

import pytest
from conftest import REPO, assert_confined, hostile_tree

import drafter

SAMPLES = REPO / "samples"


def test_draw_returns_the_clis_bytes(cli, tmp_path):
    gear = SAMPLES / "gear.glb"
    cases = [
        (["--sheet", "A3", "--projection", "third", "--hidden", "dashed"], "svg",
         dict(sheet="A3", projection="third", hidden="dashed")),
        (["--sheet", "A4", "--views", "front,iso", "--scale", "1:1", "--title", "Gear"], "dxf",
         dict(sheet="A4", views=["front", "iso"], scale="1:1", title="Gear")),
        (["--hidden", "solid", "--view", "-30,10", "--size", "640x480"], "pdf",
         dict(hidden="solid", view=(-30, 10), size=(640, 480))),
        ([], "svg", {}),
    ]
    for k, (flags, ext, options) in enumerate(cases):
        expected = tmp_path / f"cli{k}.{ext}"
        cli("draw", gear, "-o", expected, "-q", *flags)
        out = tmp_path / f"py{k}.{ext}"
        record = drafter.draw(gear, out, **options)
        assert record["status"] == "drawn" and record["cache"] == "off", record
        assert out.read_bytes() == expected.read_bytes(), (flags, options)


def test_draw_raises_typed_errors_and_refuses_misplaced_options(tmp_path):
    gear = SAMPLES / "gear.glb"
    with pytest.raises(drafter.InputError, match="A9"):
        drafter.draw(gear, tmp_path / "a.svg", sheet="A9")
    with pytest.raises(drafter.InputError, match="frnt"):
        drafter.draw(gear, tmp_path / "a.svg", sheet="A3", views="front,frnt")
    with pytest.raises(drafter.InputError, match="missing.obj"):
        drafter.draw(tmp_path / "missing.obj", tmp_path / "a.svg")
    with pytest.raises(drafter.InputError, match="svg, .pdf or .dxf"):
        drafter.draw(gear, tmp_path / "a.png")
    with pytest.raises(ValueError, match="sheet="):
        drafter.draw(gear, tmp_path / "a.svg", views=["front"])
    with pytest.raises(ValueError, match="one view"):
        drafter.draw(gear, tmp_path / "a.svg", sheet="A3", fill="flat")
    assert not list(tmp_path.iterdir()), "nothing written"


def catalog(folder: pathlib.Path) -> pathlib.Path:
    (folder / "sub").mkdir(parents=True)
    shutil.copy(SAMPLES / "gear.glb", folder / "gear.glb")
    shutil.copy(SAMPLES / "bracket.glb", folder / "sub" / "bracket.glb")
    (folder / "broken.stl").write_bytes(b"solid x\n facet nonsense\n")
    return folder


def test_draw_many_matches_the_cli_and_a_rerun_is_all_cache_hits(cli, tmp_path):
    models = catalog(tmp_path / "models")
    options = dict(sheet="A3", projection="third", hidden="dashed")
    flags = ["--sheet", "A3", "--projection", "third", "--hidden", "dashed"]
    cli("draw", models, "-o", tmp_path / "cli", "--format", "svg,pdf", "-q", *flags, check=False)
    cache = tmp_path / "cache"
    seen = []
    first = drafter.draw_many(models, tmp_path / "py", format=["svg", "pdf"], cache=cache, jobs=2,
                              progress=lambda r, d, t: seen.append(d), **options)
    assert (first["drawn"], first["failed"], first["cached"]) == (2, 1, 0), first
    assert sorted(seen) == [1, 2, 3]
    (broken,) = [r for r in first["files"] if r["status"] == "failed"]
    assert broken["exit_code"] == 2 and "broken.stl" in broken["error"]
    names = ["gear.svg", "gear.pdf", "sub/bracket.svg", "sub/bracket.pdf"]
    for name in names:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    second = drafter.draw_many(models, tmp_path / "again", format="svg,pdf", cache=cache, **options)
    assert (second["drawn"], second["cached"], second["failed"]) == (0, 2, 1), second
    assert all(r["cache"] == "hit" for r in second["files"]), second
    for name in names:
        assert (tmp_path / "again" / name).read_bytes() == (tmp_path / "py" / name).read_bytes(), name
    # One drawing through the same cache: a hit, the catalog's bytes.
    record = drafter.draw(models / "gear.glb", tmp_path / "one.svg", cache=cache, **options)
    assert (record["status"], record["cache"]) == ("cached", "hit")
    assert (tmp_path / "one.svg").read_bytes() == (tmp_path / "py" / "gear.svg").read_bytes()
    assert not [p for p in (tmp_path / "py").rglob("*") if p.name.startswith(".")], "no temporary file left"


def test_draw_many_writes_nothing_outside_its_output_folder_and_the_cache(tmp_path):
    root = pathlib.Path(os.path.realpath(tmp_path))
    cases = hostile_tree(root)

    def draw(inputs, manifests, out_dir, cache):
        return drafter.draw_many(inputs, out_dir, manifests=manifests, cache=cache, jobs=2, format=["svg", "dxf"])

    outcomes = assert_confined(root, cases, draw)
    assert isinstance(outcomes["collide"], drafter.InputError), outcomes["collide"]
    assert (root / "victim" / "keep.txt").read_bytes() == b"not to be touched\n"
