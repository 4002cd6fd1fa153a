// Fuzz target: PhotoModeler-style camera files (*_pm.txt).

#include "io/camera_io.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = mvflow::fuzz::write_input("input_pm.txt", data, size);
  mvflow::fuzz::expect_clean_refusal([&] { mvflow::io::read_photomodeler(file); });
  return 0;
}
