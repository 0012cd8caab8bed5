#!/usr/bin/env bash
# The sanitizer and fuzzing run of CI (issue 9), after the main test suite:
#  1. core, CLI and their tests built with clang-14, AddressSanitizer and UndefinedBehaviorSanitizer
#     (undefined behaviour fatal, assertions on, -O1) into ./build-asan, and their tests run there,
#     but for those in $heavy below: under the sanitizers they take 30 s to 8 min each (ten times
#     Release), which CI's 30 minutes cannot hold; they run in the Release suite, and the code they
#     reach (assembly, Newton, contact, refinement, the CLI's whole run) is reached here by smaller
#     tests (Indentation.*, ContactKept.*, Refine.*, Cli.CtrlC*, the closed forms on small meshes);
#  2. the libFuzzer targets (PLY reader, centroid reader, session reader) each run for
#     TP_FUZZ_SECONDS (default 60; the three run at once) on a copy of their committed seed corpus fuzz/corpus/<target>;
#     a crash input is kept in build-asan/fuzz-findings/ and fails the run.
# Leaks inside system libraries are suppressed by scripts/sanitizers/lsan.supp, which names them.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
bash scripts/setup.sh
seconds=${TP_FUZZ_SECONDS:-60}

CC=clang-14 CXX=clang++-14 cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
  -DTP_SANITIZE=ON -DTP_BUILD_FUZZERS=ON -DTP_BUILD_GUI=OFF -DTP_BUILD_BENCH=OFF
cmake --build build-asan --parallel "$(nproc)"

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$root/scripts/sanitizers/lsan.supp:print_suppressions=0"

heavy='PlateBending\.CircularPlates|Experiment\.AutomaticMesh|Experiment\.RefinedPatch|Experiment\.LevelsRefine'
heavy+='|Experiment\.CancelStops|ContactKept\.TensionFree|RealTissue\.IndentationCurve|Refine\.ForceDepthCurve'
heavy+='|Refine\.CoarseMeshLets|ClosedForm\.Clamped|ClosedForm\.Hencky|Cli\.DepthControl|Cli\.ForceControl'
heavy+='|Cli\.DeepIndentation|Cli\.ReferenceSolverGives|Cli\.RefinementAtTheSite|Meristem\.ValidForManySeeds'
# The fits take ~60 s each under the sanitizers (45 times Release): one full fit
# (Fit.TurgidAndPlasmolysed...) and every sensitivity test still run here.
heavy+='|Fit\.NoisyCurves|Fit\.ATurgidCurveAlone|Cli\.FitReadsBackTheModulus'
# 33-60 s each under the sanitizers (CI took 1958 s on 2026-12-04 with them, over its 30 minutes):
# the CG tangent solve on a refined tissue (the same CG is reached by every Newton solve here, the
# tangent solve by the other sensitivity tests) and the CLI's rest-state line (three whole runs
# with their error estimates; the CLI's run is reached by Cli.CtrlC* and the closed forms).
heavy+='|ForceSensitivity\.RefinedTissueSolvedByConjugateGradients|Cli\.RestStateLine'
# A second whole fit (34-38 s under the sanitizers, CI of 2026-12-04 evening); one whole fit,
# Fit.TurgidAndPlasmolysed..., still runs here.
heavy+='|Fit\.FactoringOutTheModulus'
# Maps: 30-130 s each under the sanitizers (35 times Release); the map code (workers, result
# files, resume, cancel, refusals, the table) is still reached by MapRun.Another* and MapRun.ASweep*.
heavy+='|MapRun\.WorkersShards|MapRun\.EachTask|Cli\.CtrlCStopsAMap|Cli\.MapShards'
echo "== sanitizers: the tests under ASan + UBSan (but the slow and the heavy ones)"
(cd build-asan && ctest --output-on-failure --timeout 900 -j "$(nproc)" -LE slow -E "$heavy")

echo "== fuzzing: ${seconds} s per reader, the three at once"
mkdir -p build-asan/fuzz-findings
targets=(ply centroids session)
pids=()
for target in "${targets[@]}"; do
  work=build-asan/fuzz-corpus/$target
  rm -rf "$work" && mkdir -p "$work" && cp fuzz/corpus/$target/* "$work"/
  dict=(); [ -f fuzz/$target.dict ] && dict=(-dict=fuzz/$target.dict)
  build-asan/bin/fuzz_$target "${dict[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix=build-asan/fuzz-findings/$target- \
    "$work" >build-asan/fuzz-$target.log 2>&1 &
  pids+=($!)
done
status=0
for i in "${!targets[@]}"; do
  target=${targets[$i]}
  log=build-asan/fuzz-$target.log
  if wait "${pids[$i]}"; then
    echo "fuzz_$target: $(grep -E '^stat::number_of_executed_units' "$log" | awk '{print $2}') executions, no finding"
  else
    echo "fuzz_$target: FINDING (see $log and build-asan/fuzz-findings/)"
    tail -n 40 "$log"
    status=1
  fi
done
exit $status
