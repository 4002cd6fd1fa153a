#!/usr/bin/env bash
# README command 1: install what is missing, build (Release), and run the main job on the
# built-in default scene: render it (mvflow synth), refine its initial mesh (mvflow refine), and
# compare the initial and the refined mesh with the ground truth (mvflow eval).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
bash tools/build.sh -DMVFLOW_BUILD_PYTHON=ON
scene=out/default
mkdir -p out
build/tools/mvflow synth --preset default -o "$scene"
build/tools/mvflow refine "$scene" -o "$scene/refined.ply" --report "$scene/report.json"
echo
echo "== initial mesh against the ground truth"
build/tools/mvflow eval "$scene/init.ply" "$scene/truth.ply" --json "$scene/eval_init.json"
echo
echo "== refined mesh against the ground truth"
build/tools/mvflow eval "$scene/refined.ply" "$scene/truth.ply" --json "$scene/eval_refined.json"
echo
echo "result: $scene/refined.ply (report: $scene/report.json)"
