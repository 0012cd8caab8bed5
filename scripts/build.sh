#!/usr/bin/env bash
# Configures and builds TissueProbe (Release) into ./build after installing the Debian packages.
# Executables land in build/bin/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build --parallel "$(nproc)"
