#!/usr/bin/env bash
# README command 2: install what is missing, build, run the whole test suite through CTest, then
# ASan+UBSan on a subset (README "Sanitizers") and a short bounded fuzz run (README "Fuzzing"):
# every parser's fuzz target replays its seeds and fuzzes for MVFLOW_CHECK_FUZZ_SECONDS seconds
# (default 10; 0 only replays the seeds) from a fixed seed.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
bash tools/build.sh -DMVFLOW_BUILD_TESTS=ON -DMVFLOW_BUILD_PYTHON=ON
ctest --test-dir build --output-on-failure --parallel "$(nproc)"

# ASan and UBSan in one build (build-asan-ubsan), only these test programs and what they need
# (every mvflow library and the mvflow program): the tests of every parser (meshes; Middlebury,
# COLMAP text and binary, PhotoModeler cameras; scenes with their bounding boxes; images; mask
# files; the text reader; the fuzzers' regression inputs), the engine's iteration graph
# (Refiner.*), the worker (WorkerTest.*, with its cancel tests), the vertex renumbering every
# refinement runs (VertexOrder.*) and the surface patch kernel's reads near the image's end
# (SurfacePatch.*).
sanitized_targets="mesh_io_test camera_formats_test colmap_binary_test scene_test image_test model_test
  fuzz_regression_test engine_test worker_test png_codec_test stages_vertex_order_test stages_photo_test"
sanitized_tests='^(MeshFormat|MeshIoShared|MeshIoTest|CameraFormats|ColmapBinary|ColmapBinaryBadInput|Scene|Image|ImageIo|PngCodec|MaskFiles|TextReader|BuildMesh|AtomicWrite|FuzzRegression|Refiner|WorkerTest|VertexOrder|SurfacePatch)\.'
bash tools/sanitize.sh address,undefined --targets "$sanitized_targets" -R "$sanitized_tests"

MVFLOW_FUZZ_SEED=${MVFLOW_FUZZ_SEED:-1} bash tools/fuzz.sh "${MVFLOW_CHECK_FUZZ_SECONDS:-10}"
