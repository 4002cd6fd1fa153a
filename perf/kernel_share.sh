#!/usr/bin/env bash
# The photo kernel against its own gather bound, per build (issue 13's "≥ 40 % of its own
# bound"): `BM_PhotoGradientShareOfBound` of build/perf/mvflow_stages_benchmark runs g with its
# gradient (61 evaluations per vertex, `BM_PhotoGradient`'s pass) and the bare reads of the same
# 6×6-pixel blocks with that build's loads (`BM_PatchGatherBound`'s pass) alternated, pass by
# pass, and gives the median over the pairs of bound time / kernel time: the share of the bound's
# read rate. Since session 37: the two benchmarks run seconds apart read ±5 points apart on a
# machine whose speed drifts within minutes; alternated pass by pass, ±0.6. Each build is forced
# with MVFLOW_KERNEL, the builds alternated within each round. Prints per round and build the
# medians of the repetitions, then per build the median share over the rounds and its range.
#
#   perf/kernel_share.sh [ROUNDS [REPETITIONS]]        (defaults 2 and 3)
#
# BENCH=build/perf/mvflow_stages_benchmark and MVFLOW=build/tools/mvflow pass through;
# MVFLOW_KERNELS="baseline avx2" chooses the builds (default: every build this CPU runs, as
# `mvflow --version` lists them; one it cannot run is refused by the benchmark and reported);
# BENCH_MIN_TIME (seconds per repetition, Google Benchmark's default when unset) is for checks.
set -euo pipefail
cd "$(dirname "$0")/.."
bench=${BENCH:-build/perf/mvflow_stages_benchmark}
mvflow=${MVFLOW:-build/tools/mvflow}
rounds=${1:-2}
repetitions=${2:-3}
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || { echo "kernel_share.sh: ROUNDS must be a positive integer, got '$rounds'" >&2; exit 2; }
[[ "$repetitions" =~ ^[1-9][0-9]*$ ]] ||
  { echo "kernel_share.sh: REPETITIONS must be a positive integer, got '$repetitions'" >&2; exit 2; }
[ -x "$bench" ] || { echo "kernel_share.sh: $bench is missing: build first (bash tools/build.sh)" >&2; exit 1; }
if [ -n "${MVFLOW_KERNELS:-}" ]; then
  kernels=$MVFLOW_KERNELS
else
  [ -x "$mvflow" ] || { echo "kernel_share.sh: $mvflow is missing: build first, or set MVFLOW_KERNELS" >&2; exit 1; }
  # "photo kernel: avx2 (the widest this CPU runs: baseline, avx2)"
  kernels=$(env -u MVFLOW_KERNEL "$mvflow" --version | sed -n 's/.*this CPU runs: \(.*\))$/\1/p' | tr -d ',')
  [ -n "$kernels" ] || { echo "kernel_share.sh: could not read the builds from '$mvflow --version'" >&2; exit 1; }
fi
min_time=()
[ -z "${BENCH_MIN_TIME:-}" ] || min_time=(--benchmark_min_time="$BENCH_MIN_TIME")

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "CPU: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //'), $(nproc) cores; builds: $kernels"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
for ((round = 1; round <= rounds; ++round)); do
  for kernel in $kernels; do
    out="$work/$round.$kernel.json"
    if ! MVFLOW_KERNEL=$kernel "$bench" --benchmark_filter='^BM_PhotoGradientShareOfBound$' \
        --benchmark_repetitions="$repetitions" --benchmark_report_aggregates_only=true \
        --benchmark_format=json "${min_time[@]}" > "$out" 2> "$work/err.txt"; then
      echo "kernel_share.sh: the $kernel build failed: $(head -n 1 "$work/err.txt")" >&2
      exit 1
    fi
    python3 - "$out" "$round" "$kernel" "$work/rows.txt" <<'EOF'
import json, sys
path, round_, kernel, rows = sys.argv[1:]
runs = json.load(open(path))['benchmarks']
# With one repetition Google Benchmark writes the run itself and no aggregates.
if len(runs) == 1:
    median = runs[0]
else:
    median = next((run for run in runs if run.get('run_type') == 'aggregate' and run.get('aggregate_name') == 'median'), None)
if median is None:
    sys.exit(f'kernel_share.sh: no median of BM_PhotoGradientShareOfBound in {path}')
share = median['share_percent']
with open(rows, 'a') as out:  # for the summary over the rounds
    print(kernel, share, file=out)
print(f'round {round_} {kernel:<8} kernel {median["kernel_ms"]:8.2f} ms   bound {median["bound_ms"]:7.2f} ms   '
      f'share {share:5.1f} %   ({median["pairs"]:.0f} pairs per repetition)')
EOF
  done
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$work/rows.txt" $kernels <<'EOF'
import statistics, sys
rows = [line.split() for line in open(sys.argv[1])]
for kernel in sys.argv[2:]:
    shares = [float(r[1]) for r in rows if r[0] == kernel]
    print(f'{kernel}: median share of its own bound {statistics.median(shares):.1f} % '
          f'({min(shares):.1f}-{max(shares):.1f} % over {len(shares)} rounds)')
EOF
