#!/usr/bin/env bash
# Builds romo's libFuzzer targets (clang, AddressSanitizer + UndefinedBehaviorSanitizer, -O1 -g,
# -DROMO_FUZZ=ON) and runs each for N seconds, printing executions and crashes per target.
#
#   scripts/fuzz.sh                      # every target, 10 s each
#   scripts/fuzz.sh --seconds 600        # the longer run (10 min per target)
#   scripts/fuzz.sh --seconds 60 pcd recording
#   scripts/fuzz.sh --build-dir build-asan-clang --no-build   # reuse an existing fuzz build
#   scripts/fuzz.sh --runs 5000 --seed 1   # CI's smoke: a fixed number of inputs from a fixed
#                                          # seed, so a run is repeatable on any machine
#
# Targets are fuzz/fuzz_<name>.cpp; seeds come from fuzz/corpus/<name>/ (read only), inputs
# libFuzzer finds interesting go to <build>/fuzz-work/<name>/corpus/, crashing inputs to
# <build>/fuzz-work/<name>/crash-* (or oom-*, timeout-*). Fix the parser, then check the input in
# as fuzz/regressions/<name>/<short-name>: ctest fuzz_replay.<name> replays it in every build.
# Exit status: 0 when no target crashed.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=10
runs=0
seed=0
build_dir=${ROMO_FUZZ_BUILD_DIR:-build-fuzz}
build=1
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    --build-dir) build_dir=$2; shift 2 ;;
    --no-build) build=0; shift ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1" >&2; exit 2 ;;
    *) targets+=("$1"); shift ;;
  esac
done
if [ ${#targets[@]} -eq 0 ]; then
  for f in fuzz/fuzz_*.cpp; do
    name=${f#fuzz/fuzz_}
    targets+=("${name%.cpp}")
  done
fi
for t in "${targets[@]}"; do
  [ -f "fuzz/fuzz_$t.cpp" ] || { echo "fuzz.sh: no target '$t' (fuzz/fuzz_$t.cpp)" >&2; exit 2; }
done

# shellcheck source=sanitizers/env.sh
source scripts/sanitizers/env.sh

if [ "$build" -eq 1 ]; then
  ./scripts/setup.sh
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g" "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g" \
    -DROMO_SANITIZE=address,undefined -DROMO_FUZZ=ON >/dev/null
  cmake --build "$build_dir" -j "${ROMO_JOBS:-$(nproc)}" --target "${targets[@]/#/fuzz_}"
fi

# Limits: 2 GB resident, and no single allocation above 512 MB: every seed is a few KB, so a
# parser asking for more than that is trusting a size field it should have checked.
fuzz_args=(-timeout=20 -rss_limit_mb=2048 -malloc_limit_mb=512 -print_final_stats=1 -max_len=65536)
if [ "$runs" -gt 0 ]; then
  # Repeatable: with a fixed seed and input count, and the work corpus starting empty (a clean
  # clone), libFuzzer mutates the same inputs on any machine.
  fuzz_args+=(-runs="$runs" -seed="$seed")
else
  fuzz_args+=(-max_total_time="$seconds")
fi
summary=()
failed=0
for t in "${targets[@]}"; do
  work="$build_dir/fuzz-work/$t"
  mkdir -p "$work/corpus" "$work/earlier"
  # Artifacts of earlier runs move aside, so what is left after this run is this run's.
  find "$work" -maxdepth 1 -type f \( -name 'crash-*' -o -name 'oom-*' -o -name 'timeout-*' -o -name 'leak-*' \) \
    -exec mv -t "$work/earlier" {} +
  log="$work/fuzz.log"
  if [ "$runs" -gt 0 ]; then echo "== fuzz_$t: $runs inputs, seed $seed"; else echo "== fuzz_$t: ${seconds} s"; fi
  rc=0
  "$build_dir/fuzz/fuzz_$t" "${fuzz_args[@]}" -artifact_prefix="$work/" \
    "$work/corpus" "fuzz/corpus/$t" >"$log" 2>&1 || rc=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  crashes=$(find "$work" -maxdepth 1 -type f \( -name 'crash-*' -o -name 'oom-*' -o -name 'timeout-*' -o -name 'leak-*' \) | wc -l)
  if [ "$rc" -ne 0 ]; then
    failed=1
    grep -E 'ERROR|SUMMARY|runtime error|Test unit written|terminate called|what\(\)' "$log" | head -8 || true
    echo "   full log: $log"
  fi
  line=$(printf '%-18s %12s execs  %s crash file(s)  exit %s' "$t" "${execs:-?}" "$crashes" "$rc")
  echo "   $line"
  summary+=("$line")
done
if [ "$runs" -gt 0 ]; then
  echo "== fuzz summary ($runs inputs from seed $seed per target, build $build_dir)"
else
  echo "== fuzz summary (${seconds} s per target, build $build_dir)"
fi
printf '   %s\n' "${summary[@]}"
exit "$failed"
