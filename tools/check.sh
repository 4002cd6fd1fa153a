#!/usr/bin/env bash
# README command 2: install what is missing, build, run the whole test suite through CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
bash tools/build.sh -DMVFLOW_BUILD_TESTS=ON
ctest --test-dir build --output-on-failure --parallel "$(nproc)"
