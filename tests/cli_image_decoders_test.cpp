// The two image decoders as the program uses them: PNG photographs never need the OpenCV decoder
// module, other formats load it on first use, and a module that cannot be loaded is a clear
// error (exit 1, naming the path tried), never a crash.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>

#include "engine/model/image.h"
#include "io/image_io.h"
#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;
const fs::path kScene = fs::path(MVFLOW_TEST_DATA) / "scenes" / "default";

// A binary 8-bit PPM of \p image, written by hand: the format needs no library.
void write_ppm(const fs::path& file, const Image& image) {
  std::ofstream out(file, std::ios::binary);
  out << "P6\n" << image.width() << ' ' << image.height() << "\n255\n";
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const Eigen::Vector3f rgb = image.pixel(x, y);
      for (int c = 0; c < 3; ++c) out.put(static_cast<char>(std::lround(std::clamp(rgb[c], 0.0f, 1.0f) * 255.0f)));
    }
}

// The test scene with its photographs as PPM files (the camera file names them so).
fs::path ppm_scene(const fs::path& folder) {
  const fs::path scene = folder / "ppm";
  fs::create_directories(scene);
  fs::copy_file(kScene / "bbox.txt", scene / "bbox.txt");
  fs::copy_file(kScene / "init.off", scene / "init.off");
  std::ifstream in(kScene / "default_par.txt");
  std::ofstream out(scene / "default_par.txt");
  std::string line;
  while (std::getline(in, line)) {
    std::smatch name;
    if (std::regex_search(line, name, std::regex(R"(^(view\d+)\.png)"))) {
      write_ppm(scene / (name[1].str() + ".ppm"), io::read_image(kScene / (name[1].str() + ".png")));
      line = name[1].str() + ".ppm" + name.suffix().str();
    }
    out << line << '\n';
  }
  return scene;
}

TEST(CliImageDecoders, VersionSaysWhichDecoderReadsWhat) {
  const auto version = test::run_mvflow("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.output.find("images: PNG by libpng, other formats by OpenCV ("), std::string::npos) << version.output;
  EXPECT_NE(version.output.find("libmvflow_opencv_decoder.so)"), std::string::npos) << version.output;
  const auto missing = test::run_mvflow_with_environment("MVFLOW_OPENCV_DECODER=/nonexistent/module.so", "--version");
  EXPECT_EQ(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("module for other formats is missing (looked for /nonexistent/module.so)"),
            std::string::npos)
      << missing.output;
}

TEST(CliImageDecoders, OtherFormatsLoadTheModuleAndAMissingOneIsAClearError) {
  const test::ScratchFolder folder;
  const fs::path scene = ppm_scene(folder.path());
  const auto decoded = test::run_mvflow("info " + scene.string() + " --decode");
  EXPECT_EQ(decoded.exit_code, 0) << decoded.output;

  const std::string no_module = "MVFLOW_OPENCV_DECODER=" + (folder / "absent.so").string();
  const auto refused = test::run_mvflow_with_environment(no_module, "info " + scene.string() + " --decode");
  EXPECT_EQ(refused.exit_code, 1) << refused.output;
  EXPECT_NE(refused.output.find("OpenCV decoder module, which cannot be loaded"), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find((folder / "absent.so").string()), std::string::npos) << refused.output;

  // Not a module of this version (any shared object without its functions): refused too.
  const auto foreign = test::run_mvflow_with_environment("MVFLOW_OPENCV_DECODER=libm.so.6",
                                                         "info " + scene.string() + " --decode");
  EXPECT_EQ(foreign.exit_code, 1) << foreign.output;
  EXPECT_NE(foreign.output.find("not a decoder module of this mvflow version"), std::string::npos) << foreign.output;

  // PNG photographs never need it.
  const auto png = test::run_mvflow_with_environment(no_module, "info " + kScene.string() + " --decode");
  EXPECT_EQ(png.exit_code, 0) << png.output;
}

}  // namespace
}  // namespace mvflow
