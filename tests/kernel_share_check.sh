#!/usr/bin/env bash
# perf/kernel_share.sh, one short round of the baseline build: with one kernel/bound pair per
# repetition (BENCH_MIN_TIME=0.01 s, shorter than a pair) the share it prints is that pair's bound
# time over its kernel time (recomputed here from the printed times), the summary line quotes it;
# an unknown build and bad counts are refused.
#   tests/kernel_share_check.sh STAGES_BENCHMARK MVFLOW SOURCE_DIR WORK_DIR
set -euo pipefail
bench=$1 mvflow=$2 root=$3 work=$4
rm -rf "$work"
mkdir -p "$work"
# check_round FILE REPETITIONS: the round's row and the summary of `kernel_share.sh 1 REPETITIONS`.
check_round() {
  python3 - "$1" "$2" <<'PY'
import re, sys
text, repetitions = open(sys.argv[1]).read(), int(sys.argv[2])
row = re.search(r'round 1 baseline +kernel +([\d.]+) ms +bound +([\d.]+) ms +share +([\d.]+) % +\((\d+) pairs per repetition\)', text)
assert row, text
kernel_ms, bound_ms, share, pairs = map(float, row.groups())
assert kernel_ms > 0 and bound_ms > 0, text
assert share > 0, text  # no upper bound: one pair under ctest --parallel is timing, not a check
summary = re.search(r'baseline: median share of its own bound ([\d.]+) % \(([\d.]+)-([\d.]+) % over 1 rounds\)', text)
assert summary and summary.group(2) == summary.group(3), text  # one round: its range is one value
assert abs(float(summary.group(1)) - share) <= 0.05, text
if repetitions == 1:
    assert pairs == 1, text  # a pass takes well over 0.01 s: 10k vertices, 16 views
    # The times are printed to 0.01 ms, the share to 0.1 % from the unrounded times.
    expected = 100 * bound_ms / kernel_ms
    assert abs(share - expected) <= 0.05 + expected * (0.005 / bound_ms + 0.005 / kernel_ms), (share, expected, text)
    assert summary.group(1) == summary.group(2), text
PY
}
# One pair per repetition: the share printed is that pair's bound time over its kernel time.
BENCH=$bench MVFLOW=$mvflow MVFLOW_KERNELS=baseline BENCH_MIN_TIME=0.01 bash "$root/perf/kernel_share.sh" 1 1 > "$work/out.txt"
check_round "$work/out.txt" 1
# Two repetitions: the summary quotes the median aggregate the row prints.
BENCH=$bench MVFLOW=$mvflow MVFLOW_KERNELS=baseline BENCH_MIN_TIME=0.01 bash "$root/perf/kernel_share.sh" 1 2 > "$work/out2.txt"
check_round "$work/out2.txt" 2
if BENCH=$bench MVFLOW=$mvflow MVFLOW_KERNELS=bogus BENCH_MIN_TIME=0.01 bash "$root/perf/kernel_share.sh" 1 1 \
    > /dev/null 2> "$work/err.txt"; then
  echo "an unknown build was not refused" >&2; exit 1
fi
grep -q 'the bogus build failed: mvflow_stages_benchmark: MVFLOW_KERNEL=bogus: unknown build' "$work/err.txt" ||
  { cat "$work/err.txt" >&2; exit 1; }
for counts in "0" "1 0" "x"; do
  status=0
  # shellcheck disable=SC2086
  BENCH=$bench MVFLOW=$mvflow bash "$root/perf/kernel_share.sh" $counts > /dev/null 2>&1 || status=$?
  [ "$status" -eq 2 ] || { echo "counts '$counts' gave exit $status, expected 2" >&2; exit 1; }
done
echo "kernel_share.sh: ok"
