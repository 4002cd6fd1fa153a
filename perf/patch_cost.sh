#!/usr/bin/env bash
# What the photo patch costs end to end: the refinement's own seconds (the report's, no image
# decoding) of `mvflow refine --surface-patch off|oblique|on` on each scene, in each photo-kernel
# build the CPU runs, 2 threads, one run after another with the modes and builds alternated in
# each round (a shared machine's speed drifts within minutes), and per build the medians over the
# rounds, their ratio to `off` and the sum over the scenes.
#
#   perf/patch_cost.sh ROUNDS SCENE_DIR...
#
# MVFLOW=build/tools/mvflow passes through; MVFLOW_KERNELS="avx512 avx2 baseline" chooses the
# builds (those the CPU cannot run are refused by mvflow and reported).
set -euo pipefail
cd "$(dirname "$0")/.."
mvflow=${MVFLOW:-build/tools/mvflow}
kernels=${MVFLOW_KERNELS:-avx512 avx2 baseline}
[ $# -ge 2 ] || { echo "usage: perf/patch_cost.sh ROUNDS SCENE_DIR..." >&2; exit 2; }
rounds=$1
shift
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || { echo "patch_cost.sh: ROUNDS must be a positive integer, got '$rounds'" >&2; exit 2; }
for scene in "$@"; do
  [ -d "$scene" ] || { echo "patch_cost.sh: $scene is not a scene folder" >&2; exit 2; }
done

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "CPU: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //'), $(nproc) cores"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
: > "$work/runs.txt"
for ((round = 1; round <= rounds; ++round)); do
  for kernel in $kernels; do
    for scene in "$@"; do
      for mode in off oblique on; do
        if ! MVFLOW_KERNEL=$kernel "$mvflow" --log-level warn refine "$scene" -o "$work/out.ply" --report "$work/r.json" \
          --threads 2 --surface-patch "$mode" > "$work/log" 2>&1; then
          echo "patch_cost.sh: $kernel $scene $mode failed: $(tail -1 "$work/log")" >&2
          exit 1
        fi
        python3 -c 'import json, sys; r = json.load(open(sys.argv[1])); print(sys.argv[2], sys.argv[3], sys.argv[4], len(r["iterations"]), r["seconds"])' \
          "$work/r.json" "$kernel" "$scene" "$mode" >> "$work/runs.txt"
      done
    done
  done
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$work/runs.txt" <<'EOF'
import collections, os, statistics, sys
seconds, iterations, kernels, scenes = collections.defaultdict(list), {}, [], []
for line in open(sys.argv[1]):
    kernel, scene, mode, its, s = line.split()
    seconds[(kernel, scene, mode)].append(float(s)); iterations[(kernel, scene, mode)] = int(its)
    if kernel not in kernels: kernels.append(kernel)
    if scene not in scenes: scenes.append(scene)
modes = ['off', 'oblique', 'on']
for kernel in kernels:
    print(f"{kernel}: median seconds (iterations), ratio to off")
    total = collections.Counter()
    for scene in scenes:
        median = {m: statistics.median(seconds[(kernel, scene, m)]) for m in modes}
        total.update(median)
        cells = [f"{m} {median[m]:.3f} s ({iterations[(kernel, scene, m)]}) {median[m] / median['off']:.2f}x" for m in modes]
        print(f"  {os.path.basename(scene.rstrip('/')):10s} " + "  ".join(cells))
    print(f"  {'sum':10s} " + "  ".join(f"{m} {total[m]:.3f} s {total[m] / total['off']:.2f}x" for m in modes))
EOF
