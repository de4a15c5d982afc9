"""Shared fixtures: the repository, ../shared/models (required: a missing corpus fails, never
skips), and the drafter CLI to compare bytes with (DRAFTER_BIN, else target/release or target/debug)."""

import os
import pathlib
import subprocess

import pytest

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
