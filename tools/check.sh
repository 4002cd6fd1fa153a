#!/usr/bin/env bash
# README command 2: install what is missing, build, run the whole test suite through CTest, then a
# short bounded fuzz run (README "Fuzzing"): every parser's fuzz target replays its seeds and fuzzes
# for MVFLOW_CHECK_FUZZ_SECONDS seconds (default 10; 0 only replays the seeds) from a fixed seed.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
bash tools/build.sh -DMVFLOW_BUILD_TESTS=ON -DMVFLOW_BUILD_PYTHON=ON
ctest --test-dir build --output-on-failure --parallel "$(nproc)"
MVFLOW_FUZZ_SEED=${MVFLOW_FUZZ_SEED:-1} bash tools/fuzz.sh "${MVFLOW_CHECK_FUZZ_SECONDS:-10}"
