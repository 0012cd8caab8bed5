#!/usr/bin/env bash
# Quick start (1): installs what is needed, builds, and runs TissueProbe on the shipped default
# tissue. Extra arguments are passed to the program.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
exec build/bin/tissueprobe-cli indent "$@"
