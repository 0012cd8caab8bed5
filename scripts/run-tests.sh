#!/usr/bin/env bash
# Quick start (2): installs what is needed, builds, and runs every test (ctest). Tests that draw
# with OpenGL run under a virtual X server (xvfb-run), as on CI. Then the sanitizer and fuzzing
# run (scripts/run-sanitizers.sh: the tests again under ASan + UBSan, each reader fuzzed for
# TP_FUZZ_SECONDS); TP_SANITIZERS=0 skips it. Arguments go to the first ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
(
  cd build
  if [ -z "${DISPLAY:-}" ]; then
    xvfb-run -a -s '-screen 0 1280x800x24' ctest --output-on-failure --timeout 1800 -j "$(nproc)" "$@"
  else
    ctest --output-on-failure --timeout 1800 -j "$(nproc)" "$@"
  fi
)
if [ "${TP_SANITIZERS:-1}" != 0 ]; then
  TP_FUZZ_SECONDS=${TP_FUZZ_SECONDS:-20} bash scripts/run-sanitizers.sh
fi
