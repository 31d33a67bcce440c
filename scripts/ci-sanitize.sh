#!/usr/bin/env bash
# CI's second build: clang with AddressSanitizer + UndefinedBehaviorSanitizer (-O1: Debug's -O0
# makes the simulator's renders too slow; -gline-tables-only: reports still name file and line of
# every frame, inlined ones included, and the build takes about a quarter less than with -g) and the libFuzzer targets, in one build directory.
# Runs the unit tests in it (the whole suite with ROMO_ASAN_CTEST_ARGS=), then the fuzz smoke
# (every target, ROMO_FUZZ_RUNS inputs from seed 1) with the same binaries.
# .ci/run calls it after ./scripts/test.sh.
#
#   ROMO_ASAN_BUILD_DIR   build directory (default build-asan-clang)
#   ROMO_ASAN_CTEST_ARGS  ctest selection (default "-L unit": CI's ~30 min cannot hold a second full
#                         suite on 2 cores after test.sh; set it empty for the whole suite)
#   ROMO_FUZZ_RUNS        inputs per fuzz target for the smoke (default 5000, from seed 1: a smoke
#                         that passes once passes again; 0 skips it). Open-ended fuzzing that finds
#                         new crashes is scripts/fuzz.sh --seconds N.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${ROMO_ASAN_BUILD_DIR:-build-asan-clang}
fuzz_runs=${ROMO_FUZZ_RUNS:-5000}
ctest_args=${ROMO_ASAN_CTEST_ARGS--L unit}
# shellcheck source=sanitizers/env.sh
source scripts/sanitizers/env.sh

./scripts/setup.sh
t0=$(date +%s)
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" \
  -DROMO_SANITIZE=address,undefined -DROMO_FUZZ=ON
# Only what runs below: the unit suites (with romo, which their CLI tests call) and the fuzzers;
# the whole suite (ROMO_ASAN_CTEST_ARGS=) needs the whole build.
targets=(--target romo_unit_tests romo_fuzzers)
if [ "$ctest_args" != "-L unit" ]; then targets=(); fi
cmake --build "$build_dir" -j "${ROMO_JOBS:-$(nproc)}" "${targets[@]}"
t1=$(date +%s)
# shellcheck disable=SC2086  # ctest_args is a list of arguments
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)" $ctest_args
t2=$(date +%s)
if [ "$fuzz_runs" -gt 0 ]; then
  ./scripts/fuzz.sh --build-dir "$build_dir" --no-build --runs "$fuzz_runs" --seed 1
fi
t3=$(date +%s)
echo "ci-sanitize: build $((t1 - t0)) s, tests $((t2 - t1)) s, fuzz smoke $((t3 - t2)) s"
