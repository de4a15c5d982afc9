#!/usr/bin/env python3
"""Oriented boxes: drafter's `optimal` against trimesh's `oriented_bounds` on the same part points.

Reads the dump written by
    cargo run --release -p drafter-bake --example obb_corpus -- ../shared/models --dump DIR
(one little-endian f64 xyz file per part, plus index.json with drafter's volumes and times), runs
trimesh.bounds.oriented_bounds on every part in this process, and prints the comparison.

Usage: bench/peers/setup.sh && bench/peers/.venv/bin/python bench/peers/obb_trimesh.py DIR
"""
import json
import sys
import time

import numpy as np
import trimesh


def main() -> int:
    folder = sys.argv[1] if len(sys.argv) > 1 else "/tmp/obbdump"
    rows = json.load(open(f"{folder}/index.json"))
    larger = 0
    ratios = []
    ours_ms = 0.0
    theirs_ms = 0.0
    failures = 0
    for row in rows:
        points = np.fromfile(f"{folder}/{row['dump']}", dtype="<f8").reshape(-1, 3)
        methods = {name: (ms, vol) for name, ms, vol in row["methods"]}
        ours_ms_part, ours = methods["optimal"]
        start = time.perf_counter()
        try:
            _, extents = trimesh.bounds.oriented_bounds(points)
        except Exception:  # trimesh fails on flat or tiny inputs (qhull); count and go on
            failures += 1
            continue
        theirs_ms += (time.perf_counter() - start) * 1e3
        ours_ms += ours_ms_part
        theirs = float(np.prod(extents))
        scale = float(np.max(extents)) ** 3
        if theirs <= 1e-12 * scale:
            continue  # flat part: both volumes are ~0
        ratio = ours / theirs
        ratios.append(ratio)
        if ratio > 1.0 + 1e-6:
            larger += 1
            print(f"  larger than trimesh: {row['model']} / {row['part']}: ours {ours:.6g} vs {theirs:.6g} ({ratio:.6f})")
    ratios = np.array(ratios)
    print(f"trimesh {trimesh.__version__}, {len(rows)} parts ({failures} trimesh failures, {len(rows) - len(ratios) - failures} flat)")
    print(f"drafter optimal / trimesh oriented_bounds volume: mean {ratios.mean():.4f}, min {ratios.min():.4f}, max {ratios.max():.6f}")
    print(f"parts where drafter's box is larger (> 1e-6 relative): {larger}")
    print(f"time: drafter optimal {ours_ms / len(ratios):.2f} ms/part, trimesh {theirs_ms / len(ratios):.2f} ms/part")
    return 1 if larger else 0


if __name__ == "__main__":
    sys.exit(main())
