"""Shared fixtures: the repository, ../shared/models (required: a missing corpus fails, never
skips), the drafter CLI to compare bytes with (DRAFTER_BIN, else target/release or target/debug),
and a hostile path set (names with `..`, spaces, links, non-UTF-8 bytes) with a snapshot of a whole folder tree."""

import hashlib
import os
import pathlib
import subprocess

import pytest

# Every Ray process the tests start listens on the loopback address only. Ray reads this when it is
# imported (before any test module imports it): with it, the address of a node that names none is
# 127.0.0.1 instead of the machine's network address, and a node given 127.0.0.1 keeps it (ray.init
# would otherwise turn 127.0.0.1 back into the network address). test_ray.py checks the sockets.
os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"

REPO = pathlib.Path(__file__).resolve().parents[2]
MODELS = REPO.parent / "shared" / "models"


def cli_path() -> pathlib.Path:
    explicit = os.environ.get("DRAFTER_BIN")
    if explicit:
        return pathlib.Path(explicit)
    for profile in ("release", "debug"):
        candidate = REPO / "target" / profile / "drafter"
        if candidate.exists():
            return candidate
    raise RuntimeError("no drafter binary: build it (cargo build -p drafter-cli) or set DRAFTER_BIN")


@pytest.fixture(scope="session")
def cli():
    path = cli_path()

    def run(*args, check=True):
        return subprocess.run([str(path), *map(str, args)], capture_output=True, check=check)

    return run


@pytest.fixture(scope="session")
def models() -> pathlib.Path:
    if not (MODELS / "README.md").exists():
        raise RuntimeError(f"{MODELS} is missing: the tests need ../shared/models beside the repository")
    return MODELS


@pytest.fixture(scope="session")
def sample() -> pathlib.Path:
    return REPO / "samples" / "assembly.glb"


# A tetrahedron: the smallest closed mesh, baked in milliseconds.
TETRAHEDRON = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


def snapshot(root: pathlib.Path) -> dict:
    """Every entry below ``root`` (symbolic links not followed): its kind, and a file's digest and
    mode, a link's target. Two snapshots differ wherever a byte was written, a file or folder
    created, removed or replaced."""
    entries = {}
    for folder, dirs, files in os.walk(root, followlinks=False):
        for name in dirs + files:
            path = pathlib.Path(folder) / name
            relative = path.relative_to(root).as_posix()
            if path.is_symlink():
                entries[relative] = ("link", os.readlink(path))
            elif path.is_dir():
                entries[relative] = ("dir",)
            else:
                entries[relative] = ("file", hashlib.sha256(path.read_bytes()).hexdigest(), path.stat().st_mode)
    return entries


def changes_outside(before: dict, after: dict, allowed) -> list:
    """The entries that differ between two snapshots and are not below one of ``allowed`` (paths
    relative to the snapshot's root, as POSIX text)."""
    inside = lambda p: any(p == a or p.startswith(a + "/") for a in allowed)  # noqa: E731
    changed = {p for p in before.keys() | after.keys() if before.get(p) != after.get(p)}
    return sorted(p for p in changed if not inside(p))


def hostile_tree(root: pathlib.Path) -> list:
    """The hostile path set under ``root`` (which must have no symbolic link above it),
    as cases ``(name, inputs, manifests, out_dir)`` for one batch each, all through the cache
    ``root/cache``. Inputs live in ``root/models``; nothing outside each case's output folder and
    the cache may change:

    - ``up``: a manifest's folder entry ``../models`` (it once overwrote the inputs with their bakes);
    - ``up-up``: ``../../models`` from a manifest two folders down, and ``-o`` two folders down too;
    - ``absolute``: a manifest's absolute folder and absolute file entries (the file elsewhere);
    - ``link-in``: a manifest entry naming a symbolic link to a folder outside the manifest's;
    - ``link-out``: an output folder holding a symbolic link ``models -> ../victim``, where the
      outputs of ``../models`` would go;
    - ``link-parent``: ``-o`` below a symbolic link to another folder (the writes land in the
      link's target, the real output folder);
    - ``collide``: two entries whose outputs would be the same file (``a.obj`` and ``a.stl``).
    """
    models = root / "models"
    (models / "sub").mkdir(parents=True)
    (models / "a.obj").write_bytes(TETRAHEDRON)
    (models / "sub" / "b.obj").write_bytes(TETRAHEDRON)
    (root / "collide").mkdir()
    (root / "collide" / "a.obj").write_bytes(TETRAHEDRON)
    (root / "collide" / "a.stl").write_bytes(b"solid t\nendsolid t\n")
    (root / "victim").mkdir()
    (root / "victim" / "keep.txt").write_bytes(b"not to be touched\n")
    manifests = root / "manifests"
    manifests.mkdir()
    (manifests / "up.txt").write_text("../models\n")
    (root / "elsewhere").mkdir()
    (root / "elsewhere" / "c.obj").write_bytes(TETRAHEDRON)
    (manifests / "absolute.txt").write_text(f"{models}\n{root / 'elsewhere' / 'c.obj'}\n")
    (manifests / "linked").symlink_to(models, target_is_directory=True)
    (manifests / "link-in.txt").write_text("linked\n")
    (manifests / "collide.txt").write_text("../collide/a.obj\n../collide/a.stl\n")
    deep = root / "deep" / "er"
    deep.mkdir(parents=True)
    (deep / "up-up.txt").write_text("../../models\n")
    (root / "out-link").mkdir()
    (root / "out-link" / "models").symlink_to(root / "victim", target_is_directory=True)
    (root / "real-parent").mkdir()
    (root / "parent-link").symlink_to(root / "real-parent", target_is_directory=True)
    return [
        ("up", [], [manifests / "up.txt"], root / "out-up"),
        ("up-up", [], [deep / "up-up.txt"], root / "deep" / "er" / "out"),
        ("absolute", [], [manifests / "absolute.txt"], root / "out-absolute"),
        ("link-in", [], [manifests / "link-in.txt"], root / "out-link-in"),
        ("link-out", [], [manifests / "up.txt"], root / "out-link"),
        ("link-parent", [models], [manifests / "up.txt"], root / "parent-link" / "out"),
        ("collide", [], [manifests / "collide.txt"], root / "out-collide"),
    ]


def assert_confined(root: pathlib.Path, cases, bake) -> dict:
    """Runs ``bake(inputs, manifests, out_dir, cache)`` for each hostile case and checks, by a
    snapshot of all of ``root`` before and after, that nothing changed outside the case's output
    folder (where it really is: through ``parent-link``, ``real-parent``) and ``root/cache``.
    Returns each case's outcome: the report, or the exception that refused the batch."""
    outcomes = {}
    for name, inputs, manifests, out_dir in cases:
        before = snapshot(root)
        try:
            outcomes[name] = bake(inputs, manifests, out_dir, root / "cache")
        except Exception as e:  # a refused batch is confined too; what it wrote is checked below
            outcomes[name] = e
        real_out = pathlib.Path(os.path.realpath(out_dir)).relative_to(root).as_posix()
        outside = changes_outside(before, snapshot(root), [real_out, "cache"])
        assert not outside, f"case {name}: written outside {real_out} and the cache: {outside} ({outcomes[name]})"
    # Not vacuous: the cases that name plain inputs baked (or drew) them, inside their output folders.
    for name in ("up", "up-up", "absolute", "link-in", "link-parent"):
        report = outcomes[name]
        assert isinstance(report, dict), f"case {name}: {report!r}"
        done = [r for r in report["files"] if r["status"] in ("baked", "drawn", "cached")]
        assert done, f"case {name}: nothing baked: {report}"
    return outcomes
