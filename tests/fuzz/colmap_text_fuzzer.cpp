// Fuzz target: COLMAP text models (cameras.txt + images.txt). The model is two files, so the first byte
// picks the one the rest of the input becomes (even: cameras.txt, odd: images.txt); the other is a fixed
// valid file written by write_colmap (fuzz_two_file_model).

#include "io/camera_io.h"
#include "tests/fuzz/fuzz_support.h"
#include "tests/fuzz/sample_views.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  mvflow::fuzz::fuzz_two_file_model(
      data, size, "cameras.txt", "images.txt",
      [](const std::filesystem::path& folder) { mvflow::io::write_colmap(folder, mvflow::fuzz::sample_views()); },
      [](const std::filesystem::path& folder) { mvflow::io::read_colmap(folder); });
  return 0;
}
