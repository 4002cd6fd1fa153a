// Fuzz target: silhouette mask files. The first byte picks the extension (every header is read by
// mvflow itself; a PNG is decoded by mvflow's libpng codec, the rest by the OpenCV decoder module,
// whatever the extension says); the rest of the input becomes the file, read as `mvflow` reads a
// mask: its size from the header, then decoded and checked against the camera.

#include <array>

#include "io/image_io.h"
#include "io/mask_files.h"
#include "tests/fuzz/fuzz_support.h"
#include "tests/fuzz/sample_views.h"


extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static constexpr std::array<const char*, 6> kExtensions{".png", ".jpg", ".pgm", ".ppm", ".bmp", ".tif"};
  if (size == 0) return 0;
  const std::string name = std::string("mask") + kExtensions[data[0] % kExtensions.size()];
  const auto file = mvflow::fuzz::write_input(name, data + 1, size - 1);
  static const mvflow::View view = mvflow::fuzz::sample_views().front();
  mvflow::fuzz::expect_clean_refusal([&] {
    const mvflow::io::ImageSize stated = mvflow::io::read_image_size(file);
    const mvflow::View sized{view.camera.with_image_size(stated.width, stated.height), view.image_name};
    mvflow::io::read_mask_image(file, sized, 0);
  });
  return 0;
}
