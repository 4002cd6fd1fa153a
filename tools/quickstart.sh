#!/usr/bin/env bash
# README command 1: install what is missing, build (Release), run the main job on the built-in
# default scene. Until refinement lands, the main job is `mvflow info` on that scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
bash tools/build.sh
echo
build/tools/mvflow info tests/data/scenes/default
