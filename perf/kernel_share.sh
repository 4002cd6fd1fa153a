#!/usr/bin/env bash
# The photo kernel against its own gather bound, per build (issue 13's "≥ 40 % of its own
# bound"): `BM_PhotoGradient` (g with its gradient, 61 evaluations per vertex) and
# `BM_PatchGatherBound` (the same 6×6-pixel blocks loaded and summed, nothing else, with that
# build's loads) of build/perf/mvflow_stages_benchmark, each build forced with MVFLOW_KERNEL, the
# builds alternated within each round (a shared machine's speed drifts within minutes). Prints per
# round and build the medians of the repetitions and the share (the kernel's patch-pixel reads per
# second over the bound's), then per build the median share over the rounds and its range.
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
    if ! MVFLOW_KERNEL=$kernel "$bench" --benchmark_filter='^(BM_PhotoGradient|BM_PatchGatherBound)$' \
        --benchmark_repetitions="$repetitions" --benchmark_report_aggregates_only=true \
        --benchmark_format=json "${min_time[@]}" > "$out" 2> "$work/err.txt"; then
      echo "kernel_share.sh: the $kernel build failed: $(head -n 1 "$work/err.txt")" >&2
      exit 1
    fi
    python3 - "$out" "$round" "$kernel" "$work/rows.txt" <<'EOF'
import json, sys
path, round_, kernel, rows = sys.argv[1:]
runs = json.load(open(path))['benchmarks']
def median(name):
    for run in runs:
        if run['run_name'] == name and run.get('aggregate_name', 'median') == 'median':
            scale = {'ns': 1e-6, 'us': 1e-3, 'ms': 1.0, 's': 1e3}[run['time_unit']]
            return run['real_time'] * scale, run['patch_pixel_reads/s']
    sys.exit(f'kernel_share.sh: no median of {name} in {path}')
kernel_ms, kernel_reads = median('BM_PhotoGradient')
bound_ms, bound_reads = median('BM_PatchGatherBound')
share = 100 * kernel_reads / bound_reads
with open(rows, 'a') as out:  # for the summary over the rounds
    print(kernel, share, file=out)
print(f'round {round_} {kernel:<8} kernel {kernel_ms:8.2f} ms ({kernel_reads:.3g} reads/s)   '
      f'bound {bound_ms:7.2f} ms ({bound_reads:.3g} reads/s)   share {share:5.1f} %')
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
