// Fuzz target: PLY, ASCII and binary (little- and big-endian) meshes, read as `mvflow` reads them (io::load_mesh: parse, then build
// the half-edge mesh).

#include "io/mesh_io.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = mvflow::fuzz::write_input("input.ply", data, size);
  mvflow::fuzz::expect_clean_refusal([&] { mvflow::io::load_mesh(file); });
  return 0;
}
