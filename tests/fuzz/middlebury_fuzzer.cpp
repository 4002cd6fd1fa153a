// Fuzz target: Middlebury camera files (*_par.txt).

#include "io/camera_io.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = mvflow::fuzz::write_input("input_par.txt", data, size);
  mvflow::fuzz::expect_clean_refusal([&] { mvflow::io::read_middlebury(file); });
  return 0;
}
