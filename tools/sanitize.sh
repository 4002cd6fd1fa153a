#!/usr/bin/env bash
# Builds mvflow and its tests with a sanitizer into a build folder of its own and runs the CTest
# suite under it. Fails on a failing test or on any sanitizer report, also one from an mvflow
# process a test started (the reports go to files, so a test that expects exit code 1 from bad
# input cannot hide one).
#
#   tools/sanitize.sh address|undefined|thread|address,undefined [--targets "T1 T2 ..."] [CTEST ARGS...]
#
# address → build-asan, undefined → build-ubsan, thread → build-tsan, address,undefined →
# build-asan-ubsan. --targets builds only those targets (and what they need); pass a matching
# -R to ctest then (tools/check.sh does, for its subset). Suppressions, for the dependencies'
# own code only, are in tools/sanitizers/. Under thread, engine/model/parallel.h states to TSan the
# hand-offs that Debian's uninstrumented oneTBB makes.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { echo "usage: tools/sanitize.sh address|undefined|thread|address,undefined [--targets \"T ...\"] [ctest args]" >&2; exit 2; }
[ $# -ge 1 ] || usage
kind=$1
shift
case "$kind" in
  address) dir=build-asan ;;
  undefined) dir=build-ubsan ;;
  thread) dir=build-tsan ;;
  address,undefined) dir=build-asan-ubsan ;;
  *) usage ;;
esac
targets=()
if [ "${1:-}" = "--targets" ]; then
  [ $# -ge 2 ] || usage
  read -r -d '' -a targets <<< "$2" || true  # any whitespace, newlines too
  shift 2
fi

# GCC's -Wmaybe-uninitialized gives false positives with sanitizers (libstdc++'s std::function,
# OpenMesh's property vectors); the release build's warnings are the ones that count.
flags="-fsanitize=$kind -fno-omit-frame-pointer -O1 -g -Wno-maybe-uninitialized"
# A UBSan report must fail the test, not print and go on; only the checks that
# tools/sanitizers/ubsan.supp suppresses in a dependency recover (UBSan ignores suppressions
# otherwise), and halt_on_error=1 below still stops at any other report of theirs.
[[ $kind == *undefined* ]] && flags="$flags -fno-sanitize-recover=all -fsanitize-recover=vptr"

generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
# RelWithDebInfo with our own flags: -O1 -g instead of -O2, NDEBUG kept so that the code under
# test is the release code.
cmake -S . -B "$dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-DNDEBUG" \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=$kind" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=$kind" \
  -DMVFLOW_BUILD_TESTS=ON -DMVFLOW_BUILD_PERF=OFF >/dev/null
if [ ${#targets[@]} -gt 0 ]; then
  cmake --build "$dir" --parallel "$(nproc)" --target "${targets[@]}"
else
  cmake --build "$dir" --parallel "$(nproc)"
fi

reports="$PWD/$dir/sanitizer-reports"
rm -rf "$reports"
mkdir -p "$reports"
suppressions="$PWD/tools/sanitizers"
common="log_path=$reports/report:print_suppressions=0"
export ASAN_OPTIONS="$common:detect_leaks=1:strict_string_checks=1:check_initialization_order=1:detect_stack_use_after_return=1"
export LSAN_OPTIONS="suppressions=$suppressions/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="$common:suppressions=$suppressions/ubsan.supp:print_stacktrace=1:halt_on_error=1"
# history_size=7: the longest per-thread history TSan keeps (4M accesses, default 128K), so the
# earlier access of a report keeps its stack. Without it a report can come with "[failed to
# restore the stack]" for that access, which no suppression can match (seen once in RealData: the
# write was parallel.h's HandedOver built into a new oneTBB task's memory, which an earlier task
# had used; the earlier read, on another thread, had lost its stack).
export TSAN_OPTIONS="$common:suppressions=$suppressions/tsan.supp:halt_on_error=0:second_deadlock_stack=1:history_size=7"

status=0
ctest --test-dir "$dir" --output-on-failure --parallel "$(nproc)" "$@" || status=$?
shopt -s nullglob
found=("$reports"/report.*)
if [ ${#found[@]} -gt 0 ]; then
  echo "sanitize: ${#found[@]} sanitizer report(s) in $reports:" >&2
  for report in "${found[@]}"; do
    echo "== $report" >&2
    head -n 60 "$report" >&2
  done
  status=1
fi
[ $status -eq 0 ] && echo "sanitize: $kind: clean"
exit $status
