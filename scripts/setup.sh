#!/usr/bin/env bash
# Installs every Debian 12 package TissueProbe needs to build, test, benchmark and run.
# Idempotent: packages already installed are skipped, so a second run costs a second.
# Uses sudo when not root. Sourced or executed by scripts/run-app.sh and scripts/run-tests.sh.
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkg-config git
  # numerics: Eigen, CHOLMOD (SuiteSparse) on OpenBLAS, METIS, voro++, CGAL, TBB
  libeigen3-dev libsuitesparse-dev libmetis-dev libopenblas-dev voro++-dev libcgal-dev libgmp-dev libmpfr-dev libtbb-dev
  # formats and command line
  nlohmann-json3-dev libcli11-dev
  # fitting measured curves: Ceres Solver (Levenberg-Marquardt)
  libceres-dev
  # GUI: Qt 6 widgets/OpenGL/SVG/print support, QCustomPlot for Qt 6, GL headers, Mesa software GL
  qt6-base-dev qt6-base-dev-tools libqt6opengl6-dev qt6-svg-dev libgl-dev libgl1-mesa-dri
  libqcustomplot-dev libqcustomplot2.1-qt6
  # tests and benchmarks; clang with libFuzzer and the sanitizer runtimes for the ASan+UBSan build and fuzzers
  libgtest-dev libbenchmark-dev clang-14 libclang-rt-14-dev libomp-14-dev
  # stiffness maps on a cluster: Slurm and MUNGE (the test starts a single-node cluster)
  slurm-wlm munge
  # headless GUI testing and looking at the window
  xvfb xauth xdotool imagemagick
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "setup: installing ${#missing[@]} package(s): ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "setup: all ${#PACKAGES[@]} packages present"
fi
