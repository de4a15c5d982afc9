#!/usr/bin/env bash
# Creates bench/peers/.venv with the peer libraries the comparison scripts use (pinned).
# Open3D is optional: its wheel is large (~400 MB) and missing on some platforms; peers.py says
# so in its table header when it could not be imported. On Debian it needs libusb-1.0-0
# (apt-get install --no-install-recommends libusb-1.0-0), or its import fails.
set -euo pipefail
cd "$(dirname "$0")"
[ -x .venv/bin/python ] || python3 -m venv .venv
.venv/bin/pip install -q "trimesh==5.2.0" "scipy>=1.11" "numpy>=1.26" "pymeshlab==2025.7.post1" "networkx==3.6.1"
.venv/bin/pip install -q "open3d==0.20.0" || echo "setup.sh: Open3D did not install; peers.py runs without it" >&2
