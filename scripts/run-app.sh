#!/usr/bin/env bash
# Quick start (1): installs what is needed, builds, and runs TissueProbe on the shipped default
# tissue (the desktop application; extra arguments are passed to it, e.g. a tissue file). Without
# a display (no DISPLAY or WAYLAND_DISPLAY) it runs the command-line indentation instead.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
if [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; then
  exec build/bin/tissueprobe "$@"
fi
echo "run-app: no display found; running build/bin/tissueprobe-cli indent on the default tissue" >&2
exec build/bin/tissueprobe-cli indent "$@"
