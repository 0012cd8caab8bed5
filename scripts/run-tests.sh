#!/usr/bin/env bash
# Quick start (2): installs what is needed, builds, and runs every test (ctest). Tests that draw
# with OpenGL run under a virtual X server (xvfb-run), as on CI.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
cd build
if [ -z "${DISPLAY:-}" ]; then
  exec xvfb-run -a -s '-screen 0 1280x800x24' ctest --output-on-failure --timeout 1800 -j "$(nproc)" "$@"
else
  exec ctest --output-on-failure --timeout 1800 -j "$(nproc)" "$@"
fi
