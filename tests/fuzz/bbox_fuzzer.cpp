// Fuzz target: scene bounding boxes. The first byte picks the file the rest of the input becomes
// (even: bbox.txt, io::read_bounding_box; odd: a Middlebury README.txt,
// io::read_middlebury_readme_box).

#include "io/scene_io.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool readme = data[0] % 2 == 1;
  const auto file = mvflow::fuzz::write_input(readme ? "README.txt" : "bbox.txt", data + 1, size - 1);
  mvflow::fuzz::expect_clean_refusal([&] {
    if (readme)
      mvflow::io::read_middlebury_readme_box(file);
    else
      mvflow::io::read_bounding_box(file);
  });
  return 0;
}
