#!/usr/bin/env python3
"""Catalog bakes side by side on one machine, every figure from the same run:

  - the shared models as a serial loop of single bakes, as `xargs -P2` of single bakes, and as one
    `drafter bake DIR -o OUT` (cold), in interleaved rounds; the batch's peak memory against --memory;
  - the batch with a cache: cold (filling it) and warm (every file cached and its output up to date),
    and warm with the outputs removed (every output written from the cache);
  - every batch output byte-identical to the single bake of its input;
  - Python: two threads each baking one file at one thread, against the same two bakes in turn;
  - Ray: drafter.ray on a local 2-CPU Ray instance (its start excluded) against the local batch.

    python3 bench/catalog/run.py --python target/py/bin/python   # a venv with the package (release) and ray

Run it on an otherwise idle machine: the ratios compare runs made seconds apart, but a busy
neighbour still moves them.
"""

import argparse
import json
import os
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

REPO = pathlib.Path(__file__).resolve().parents[2]
EXTENSIONS = {".gltf", ".glb", ".obj", ".stl", ".off", ".ply"}


def models_below(root: pathlib.Path):
    return sorted(p for p in root.rglob("*") if p.is_file() and p.suffix.lower() in EXTENSIONS and not p.name.startswith("."))


def timed(cmd, **kw):
    start = time.perf_counter()
    result = subprocess.run(cmd, **kw)
    return time.perf_counter() - start, result


def peak_kb(cmd):
    """Wall seconds and peak RSS (KB) of a command, through GNU time."""
    out = tempfile.NamedTemporaryFile(delete=False)
    start = time.perf_counter()
    subprocess.run(["/usr/bin/time", "-f", "%M", "-o", out.name, *cmd], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    kb = int(pathlib.Path(out.name).read_text().split()[-1])
    os.unlink(out.name)
    return wall, kb


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--drafter", default=str(REPO / "target/release/drafter"))
    ap.add_argument("--python", default=str(REPO / "target/py/bin/python"), help="a Python with the drafter package and ray")
    ap.add_argument("--models", default=str(REPO.parent / "shared/models"))
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--memory", default="2G", help="the batch's --memory")
    args = ap.parse_args()
    drafter = args.drafter
    models = pathlib.Path(args.models)
    files = models_below(models)
    scratch = pathlib.Path(tempfile.mkdtemp(prefix="drafter-catalog-bench-"))
    print(f"{len(files)} files of a supported format under {models} ({sum(f.stat().st_size for f in files):,} bytes)")
    print(f"machine: {os.cpu_count()} cores; drafter {drafter}")

    times = {k: [] for k in ["serial", "xargs", "batch", "batch+cache cold", "batch+cache warm", "batch+cache served"]}
    peaks = []
    for r in range(args.rounds):
        order = ["serial", "xargs", "batch"] if r % 2 == 0 else ["batch", "xargs", "serial"]
        for kind in order:
            out = scratch / kind
            shutil.rmtree(out, ignore_errors=True)
            out.mkdir()
            if kind == "serial":
                start = time.perf_counter()
                for i, f in enumerate(files):
                    subprocess.run([drafter, "bake", str(f), "-o", str(out / f"{i}.glb"), "-q"], stderr=subprocess.DEVNULL)
                times[kind].append(time.perf_counter() - start)
            elif kind == "xargs":
                listing = "".join(f"{i} {f}\n" for i, f in enumerate(files))
                script = f'{drafter} bake "$1" -o {out}/"$0".glb -q 2>/dev/null'
                wall, _ = timed(["xargs", "-P2", "-L1", "sh", "-c", script], input=listing.encode())
                times[kind].append(wall)
            else:
                wall, kb = peak_kb([drafter, "bake", str(models), "-o", str(out), "-q", "--memory", args.memory])
                times[kind].append(wall)
                peaks.append(kb)
        cache = scratch / f"cache{r}"
        out = scratch / f"cached{r}"
        for kind in ["batch+cache cold", "batch+cache warm"]:
            wall, _ = timed([drafter, "bake", str(models), "-o", str(out), "-q", "--cache", str(cache)], stderr=subprocess.DEVNULL)
            times[kind].append(wall)
        shutil.rmtree(out)
        wall, _ = timed([drafter, "bake", str(models), "-o", str(out), "-q", "--cache", str(cache)], stderr=subprocess.DEVNULL)
        times["batch+cache served"].append(wall)

    # Every batch output equals its single bake.
    mismatches = 0
    compared = 0
    for i, f in enumerate(files):
        single = scratch / "serial" / f"{i}.glb"
        if not single.exists():
            continue
        for folder in ["batch", f"cached{args.rounds - 1}"]:
            batch = scratch / folder / f.relative_to(models).with_suffix(".glb")
            compared += 1
            mismatches += batch.read_bytes() != single.read_bytes()
    baked = sum(1 for i in range(len(files)) if (scratch / "serial" / f"{i}.glb").exists())

    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"\n{args.rounds} rounds, medians (all runs in seconds):")
    for k, v in times.items():
        print(f"  {k:<20} {med[k]:7.3f} s   {' '.join(f'{x:.3f}' for x in v)}")
    print(f"  baked {baked} of {len(files)} inputs (the others refused with exit 2)")
    print(f"  batch vs xargs -P2: {med['xargs'] / med['batch']:.2f}x faster; vs the serial loop: {med['serial'] / med['batch']:.2f}x")
    print(f"  per round: xargs/batch {' '.join(f'{x / b:.2f}' for x, b in zip(times['xargs'], times['batch']))}; "
          f"serial/batch {' '.join(f'{s / b:.2f}' for s, b in zip(times['serial'], times['batch']))}")
    print(f"  cached rerun (outputs up to date): {med['batch+cache cold'] / med['batch+cache warm']:.0f}x faster than the cold run; "
          f"outputs written from the cache: {med['batch+cache cold'] / med['batch+cache served']:.1f}x")
    print(f"  batch peak RSS {max(peaks) / 1024:.0f} MB (runs: {' '.join(str(p // 1024) for p in peaks)}) under --memory {args.memory}")
    for budget in ["600M", "1G"]:
        out = scratch / f"tight{budget}"
        wall, kb = peak_kb([drafter, "bake", str(models), "-o", str(out), "-q", "--memory", budget, "--report", str(scratch / "tight.json")])
        admitted = json.loads((scratch / "tight.json").read_text())["peak_admitted_bytes"] >> 20
        print(f"  --memory {budget}: peak RSS {kb / 1024:.0f} MB, at most {admitted} MB of estimates admitted at once, {wall:.3f} s")
    print(f"  outputs compared with single bakes: {compared}, different: {mismatches}")

    if pathlib.Path(args.python).exists():
        python_figures(args.python, models, scratch)
    else:
        print(f"\n(no {args.python}: Python and Ray figures skipped)")
    shutil.rmtree(scratch, ignore_errors=True)


PY_GIL = r"""
import statistics, sys, threading, time, drafter
path = sys.argv[1]
def one(): drafter.bake(path, threads=1)
one()
seq, par = [], []
for _ in range(5):
    t = time.perf_counter(); one(); one(); seq.append(time.perf_counter() - t)
    ts = [threading.Thread(target=one) for _ in range(2)]
    t = time.perf_counter(); [x.start() for x in ts]; [x.join() for x in ts]; par.append(time.perf_counter() - t)
s, p = statistics.median(seq), statistics.median(par)
print(f"  two bakes of {path.split('/')[-1]} at one thread each: in turn {s:.3f} s, two Python threads at once {p:.3f} s: {s / p:.2f}x sooner")
print(f"    runs in turn {' '.join(f'{x:.3f}' for x in seq)}; at once {' '.join(f'{x:.3f}' for x in par)}")
"""

PY_RAY = r"""
import json, os, shutil, statistics, sys, tempfile, time, logging
# Every Ray process on the loopback address only (read when ray is imported): its node address is
# then 127.0.0.1, and its servers listen there rather than on the machine's network address.
os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"
import ray, drafter, drafter.ray
models, scratch = sys.argv[1], sys.argv[2]
t = time.perf_counter()
ray.init(num_cpus=2, include_dashboard=False, logging_level=logging.ERROR, log_to_driver=False, _node_ip_address="127.0.0.1")
start = time.perf_counter() - t
first = None
local, remote = [], []
for r in range(3):
    for kind in (["local", "ray"] if r % 2 == 0 else ["ray", "local"]):
        out = os.path.join(scratch, f"{kind}{r}")
        t = time.perf_counter()
        if kind == "local":
            rep = drafter.bake_many([models], out)
            local.append(time.perf_counter() - t)
        else:
            rep = drafter.ray.bake_catalog([models], out)
            remote.append(time.perf_counter() - t)
            first = first or rep
l, m = statistics.median(local), statistics.median(remote)
print(f"  Ray instance start {start:.2f} s (excluded); local batch {l:.3f} s, drafter.ray {m:.3f} s: {m / l:.2f}x the local batch")
print(f"    runs local {' '.join(f'{x:.3f}' for x in local)}; ray {' '.join(f'{x:.3f}' for x in remote)} (the first Ray run starts its workers)")
print(f"    per-file Ray overhead: tasks {first['tasks']}, baked {first['baked']}, failed {first['failed']}")
same = all(open(os.path.join(scratch, 'local0', p), 'rb').read() == open(os.path.join(scratch, 'ray0', p), 'rb').read()
           for d, _, fs in os.walk(os.path.join(scratch, 'local0')) for p in [os.path.relpath(os.path.join(d, f), os.path.join(scratch, 'local0')) for f in fs])
print(f"    Ray outputs byte-identical to the local batch: {same}")
# Per-task overhead: empty tasks through the same path.
@ray.remote(num_cpus=1)
def noop(): return 0
ray.get([noop.remote() for _ in range(50)])
t = time.perf_counter(); ray.get([noop.remote() for _ in range(1000)]); per = (time.perf_counter() - t) / 1000
print(f"    Ray round trip of an empty task here: {per * 1e3:.2f} ms (1000 tasks)")
"""


def python_figures(python, models, scratch):
    print("\nPython:")
    bunny = models / "obj/common-3d-test-models/stanford-bunny.obj"
    subprocess.run([python, "-c", PY_GIL, str(bunny)], check=False)
    print("\nRay:")
    subprocess.run([python, "-c", PY_RAY, str(models), str(scratch / "ray")], check=False)


if __name__ == "__main__":
    sys.exit(main())
