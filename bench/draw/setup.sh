#!/usr/bin/env bash
# Creates target/cq-env with CadQuery (OpenCascade through cadquery-ocp wheels, cp311) for
# bench/draw/cadquery_hlr.py. Pinned to the versions the figures in docs/drawing.md were taken with.
set -euo pipefail
cd "$(dirname "$0")/../.."
[ -x target/cq-env/bin/python ] || python3 -m venv target/cq-env
target/cq-env/bin/pip install -q "cadquery==2.8.0" "cadquery-ocp==7.9.3.1.1" "numpy>=1.26" "scipy>=1.11"
