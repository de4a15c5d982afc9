#!/usr/bin/env python3
"""Gooch et al. 1999 Table 1, for our hierarchies: brute force against the stored hierarchy, per view.

Runs `drafter bench silhouettes --json` on a generated smooth UV sphere of 101,760 faces (the
paper's case) and on every model of ../shared/models (Draco originals excepted), orthographic
and perspective, and prints one markdown table: candidates, silhouettes per view, brute-force and
hierarchy time per view (warm and cold, see drafter_lines::measure), speedup, mismatching views
and what the index stored.

Usage:  python3 bench/lines/silhouette_table.py [--views N] [--only SUBSTRING] [--json OUT]

It builds the CLI with cargo (release); set CARGO_TARGET_DIR to share a build directory.
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
MODELS = ROOT.parent / "shared" / "models"
EXTENSIONS = {".obj", ".glb", ".gltf", ".stl", ".off", ".ply"}


def uv_sphere(path, segments=320, rings=160):
    """Writes a unit UV sphere OBJ with 2·segments·(rings−1) faces."""
    lines = ["v 0 0 1"]
    for r in range(1, rings):
        t = math.pi * r / rings
        for s in range(segments):
            p = 2 * math.pi * s / segments
            lines.append(f"v {math.sin(t) * math.cos(p):.9f} {math.sin(t) * math.sin(p):.9f} {math.cos(t):.9f}")
    lines.append("v 0 0 -1")
    south = 1 + (rings - 1) * segments + 1

    def ring(r, s):
        return 2 + (r - 1) * segments + s % segments

    for s in range(segments):
        lines.append(f"f 1 {ring(1, s)} {ring(1, s + 1)}")
        lines.append(f"f {south} {ring(rings - 1, s + 1)} {ring(rings - 1, s)}")
    for r in range(1, rings - 1):
        for s in range(segments):
            a, b, c, d = ring(r, s), ring(r, s + 1), ring(r + 1, s), ring(r + 1, s + 1)
            lines.append(f"f {a} {c} {d}")
            lines.append(f"f {a} {d} {b}")
    Path(path).write_text("\n".join(lines) + "\n")


def models():
    if not MODELS.is_dir():
        sys.exit(f"error: {MODELS} is missing (the shared models must sit beside the repository)")
    found = []
    for p in sorted(MODELS.rglob("*")):
        if p.suffix.lower() in EXTENSIONS and "draco" not in str(p).lower():
            found.append(p)
    return found


def drafter():
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "drafter-cli"], cwd=ROOT, check=True)
    return target / "release" / "drafter"


def choice(report):
    kinds = {m["choice"]["kind"] for m in report["meshes"] if m["candidates"] > 0}
    if kinds == {"brute_force"}:
        return "brute force"
    return " + ".join(sorted(k.replace("_", " ") for k in kinds))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--views", type=int, default=1000)
    ap.add_argument("--only", default="")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    exe = drafter()
    with tempfile.TemporaryDirectory() as tmp:
        sphere = Path(tmp) / "uv_sphere_101760.obj"
        uv_sphere(sphere)
        files = [sphere] + models()
        rows = []
        for f in files:
            name = f.name if f == sphere else str(f.relative_to(MODELS))
            if args.only and args.only not in name:
                continue
            for mode in ("orthographic", "perspective"):
                cmd = [str(exe), "bench", "silhouettes", str(f), "--views", str(args.views), "--json"]
                if mode == "perspective":
                    cmd.append("--perspective")
                run = subprocess.run(cmd, capture_output=True, text=True)
                if run.returncode != 0:
                    print(f"{name} ({mode}): {run.stderr.strip()}", file=sys.stderr)
                    continue
                r = json.loads(run.stdout)
                r["name"] = name
                rows.append(r)
                print(f"{name:55} {mode:12} {r['speedup']:6.2f}x", file=sys.stderr, flush=True)
    print("| model | mode | candidates | silhouettes / view | brute µs / view (M cand/s) | hierarchy µs / view "
          "| speedup | cold speedup | mismatches | stored |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---|")
    for r in rows:
        mean = sum(r["counts"]) / max(1, len(r["counts"]))
        print(
            f"| {r['name']} | {r['mode'][:5]} | {r['candidates']:,} | {mean:,.0f} | "
            f"{r['brute_ns_per_view'] / 1e3:,.1f} ({r['brute_candidates_per_s'] / 1e6:,.0f}) | "
            f"{r['hierarchy_ns_per_view'] / 1e3:,.1f} | {r['speedup']:.2f}× | {r['cold']['speedup']:.2f}× | "
            f"{r['mismatches']} / {r['views']} | {choice(r)} |"
        )
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
