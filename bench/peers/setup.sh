#!/usr/bin/env bash
# Creates bench/peers/.venv with the peer libraries the comparison scripts use (pinned).
set -euo pipefail
cd "$(dirname "$0")"
[ -x .venv/bin/python ] || python3 -m venv .venv
.venv/bin/pip install -q "trimesh==5.2.0" "scipy>=1.11" "numpy>=1.26"
