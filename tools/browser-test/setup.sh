#!/bin/sh
# Installs what the browser-client tests need on Debian 12, and nothing that is already there:
# Chromium (Debian's), f3d, Xvfb and xauth from apt; node and npm if missing; `npm ci` in this folder.
# Usage: sh tools/browser-test/setup.sh   (as root, or as a user with sudo)
set -eu

here=$(cd "$(dirname "$0")" && pwd)
say() { echo "setup: $*"; }

if [ "$(id -u)" -eq 0 ]; then
  as_root=""
elif command -v sudo >/dev/null 2>&1; then
  as_root="sudo"
else
  as_root="MISSING"
fi

# Debian package for each command we need.
missing=""
command -v chromium >/dev/null 2>&1 || missing="$missing chromium"
command -v f3d >/dev/null 2>&1 || missing="$missing f3d"
command -v xvfb-run >/dev/null 2>&1 || missing="$missing xvfb"
command -v xauth >/dev/null 2>&1 || missing="$missing xauth"
command -v node >/dev/null 2>&1 || missing="$missing nodejs"
command -v npm >/dev/null 2>&1 || missing="$missing npm"

if [ -n "$missing" ]; then
  if [ "$as_root" = "MISSING" ]; then
    say "need root (or sudo) to install:$missing" >&2
    exit 1
  fi
  say "apt-get update"
  $as_root apt-get update -qq
  say "apt-get install$missing"
  # No recommends: f3d would otherwise pull in a desktop's worth of packages.
  DEBIAN_FRONTEND=noninteractive $as_root apt-get install -y -qq --no-install-recommends $missing
else
  say "chromium, f3d, xvfb, xauth, node and npm already installed"
fi

# npm ci when node_modules is missing or older than the lock file.
stamp="$here/node_modules/.package-lock.json"
if [ ! -f "$stamp" ] || [ "$here/package-lock.json" -nt "$stamp" ]; then
  say "npm ci in $here"
  (cd "$here" && npm ci --no-audit --no-fund)
else
  say "node_modules up to date"
fi
say "done"
