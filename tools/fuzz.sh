#!/usr/bin/env bash
# tools/fuzz.sh [SECONDS] [TARGET...]: builds the libFuzzer targets (tests/fuzz) with clang,
# ASan and UBSan into ./build-fuzz if needed, writes the seed corpora from tests/data, then runs
# each target (default: all; see tests/fuzz/CMakeLists.txt) for SECONDS (default 600), one at a time
# and at low priority. Every run first replays its seeds and the corpus grown by earlier runs
# (build-fuzz/corpus/TARGET); SECONDS = 0 only replays them. A crash, sanitizer report, uncaught exception other than mvflow's
# InputError/IoError, input slower than 10 s or memory beyond 2 GB is a finding: its input goes to
# build-fuzz/findings/TARGET/ and the script fails after running the other targets.
# MVFLOW_FUZZ_SEED fixes libFuzzer's random seed (tools/check.sh does, so that its short run makes
# the same mutations on every machine and a finding there can be replayed); unset, each run differs.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
shift || true
all_targets=(ply obj off stl vrml middlebury colmap_text colmap_binary photomodeler bbox mask)
targets=("${@:-${all_targets[@]}}")
build=build-fuzz

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
if [ ! -f $build/CMakeCache.txt ]; then
  nice -n 15 cmake -S . -B $build "${generator[@]}" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DMVFLOW_BUILD_FUZZERS=ON -DMVFLOW_BUILD_TESTS=OFF -DMVFLOW_BUILD_PERF=OFF >/dev/null
fi
nice -n 15 cmake --build $build --target fuzzers --parallel "$(nproc)"
$build/tests/fuzz/make_seeds tests/data $build/seeds

failed=()
printf '%-14s %8s %12s  %s\n' target seconds executions result
for target in "${targets[@]}"; do
  corpus=$build/corpus/$target
  findings=$build/findings/$target
  log=$build/logs/$target.log
  mkdir -p "$corpus" "$findings" "$(dirname "$log")"
  start=$SECONDS
  status=0
  duration=(-max_total_time="$seconds")
  [ "$seconds" -eq 0 ] && duration=(-runs=0)
  [ -n "${MVFLOW_FUZZ_SEED:-}" ] && duration+=(-seed="$MVFLOW_FUZZ_SEED")
  nice -n 15 "$build/tests/fuzz/${target}_fuzzer" "${duration[@]}" -timeout=10 -rss_limit_mb=2048 \
    -max_len=8192 -print_final_stats=1 -artifact_prefix="$findings/" "$corpus" "$build/seeds/$target" \
    >"$log" 2>&1 || status=$?
  executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  if [ $status -eq 0 ]; then
    result=clean
  else
    result="FINDING (exit $status): $(ls -t "$findings" | head -1), log $log"
    failed+=("$target")
  fi
  printf '%-14s %8d %12s  %s\n' "$target" $((SECONDS - start)) "${executions:-?}" "$result"
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz.sh: findings in ${failed[*]} (inputs in $build/findings/)" >&2
  exit 1
fi
