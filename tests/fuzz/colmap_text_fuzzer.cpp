// Fuzz target: COLMAP text models (cameras.txt + images.txt). The model is two files, so the first
// byte picks the one the rest of the input becomes (even: cameras.txt, odd: images.txt); the
// other is a fixed valid file written by write_colmap.

#include "io/camera_io.h"
#include "tests/fuzz/fuzz_support.h"
#include "tests/fuzz/sample_views.h"

namespace {

const std::filesystem::path& model_folder(bool fuzz_images) {
  static const std::filesystem::path cameras = mvflow::fuzz::work_folder() / "cameras";
  static const std::filesystem::path images = mvflow::fuzz::work_folder() / "images";
  return fuzz_images ? images : cameras;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  for (bool fuzz_images : {false, true})
    mvflow::io::write_colmap(model_folder(fuzz_images), mvflow::fuzz::sample_views());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool fuzz_images = data[0] % 2 == 1;
  const auto& folder = model_folder(fuzz_images);
  mvflow::fuzz::write_input(fuzz_images ? "images.txt" : "cameras.txt", data + 1, size - 1, folder);
  mvflow::fuzz::expect_clean_refusal([&] { mvflow::io::read_colmap(folder); });
  return 0;
}
