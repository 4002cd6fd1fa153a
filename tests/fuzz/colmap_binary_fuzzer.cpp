// Fuzz target: COLMAP binary models (cameras.bin + images.bin). The model is two files, so the first byte
// picks the one the rest of the input becomes (even: cameras.bin, odd: images.bin); the other is a fixed
// valid file written by write_colmap_binary (fuzz_two_file_model).

#include "io/camera_io.h"
#include "tests/fuzz/fuzz_support.h"
#include "tests/fuzz/sample_views.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  mvflow::fuzz::fuzz_two_file_model(
      data, size, "cameras.bin", "images.bin",
      [](const std::filesystem::path& folder) { mvflow::io::write_colmap_binary(folder, mvflow::fuzz::sample_views()); },
      [](const std::filesystem::path& folder) { mvflow::io::read_colmap_binary(folder); });
  return 0;
}
