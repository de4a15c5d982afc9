#!/usr/bin/env bash
# Issue 59's sheet timing: GearboxAssy's A3 sheet (front, top, right, iso, third angle, hidden lines
# dashed) against one view of the same file drawn alone (the default perspective view, hidden lines
# dashed), in one run, each the best of N (default 3): wall time and CPU time (user + system) of the
# whole command, and the drawing's own milliseconds from --json (after the file is read). The CPU
# time is the figure that holds on a shared machine; on an idle one the wall time of a sheet is
# about its CPU time over the cores. Needs target/release/drafter
# (cargo build --release -p drafter-cli).
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=${1:-3}
out=target/draw-bench
mkdir -p "$out"
drafter=target/release/drafter
[ -x "$drafter" ] || { echo "bench/draw/sheet.sh: build target/release/drafter first" >&2; exit 1; }
baked="$out/GearboxAssy.glb"
[ -f "$baked" ] || "$drafter" bake ../shared/models/gltf/GearboxAssy/GearboxAssy.gltf -o "$baked" --quiet
echo "$(date -u +'%Y-%m-%d %H:%M UTC'); $(nproc) cores; load average $(cut -d' ' -f1-3 /proc/loadavg)"
best() { # label, then the command: prints the best wall, its CPU and the drawing's ms
  local label=$1 best_wall=1e9 line
  shift
  for _ in $(seq "$runs"); do
    line=$( { /usr/bin/time -f 'TIME %e %U %S' "$@" --json 2>&1 >"$out/run.json"; } | grep '^TIME')
    read -r _ wall user sys <<<"$line"
    ms=$(python3 -c 'import json,sys; print(round(json.load(open(sys.argv[1]))["ms"]))' "$out/run.json")
    if python3 -c "import sys; sys.exit(0 if $wall < $best_wall else 1)"; then
      best_wall=$wall
      best_line=$(printf '%-28s wall %6.2f s  cpu %6.2f s  drawing %6d ms' "$label" "$wall" "$(python3 -c "print($user + $sys)")" "$ms")
    fi
  done
  echo "$best_line"
}
best "one view (perspective)" "$drafter" draw "$baked" -o "$out/one.svg" --hidden dashed -q
best "A3 sheet, 4 views" "$drafter" draw "$baked" -o "$out/sheet.pdf" --sheet A3 --views front,top,right,iso \
  --projection third --hidden dashed -q
echo "done $(date -u +'%H:%M UTC'); load average $(cut -d' ' -f1-3 /proc/loadavg)"
