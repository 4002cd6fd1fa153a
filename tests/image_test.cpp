// Images: bilinear sampling against a hand computation, and PNG/JPEG/TIFF reading through OpenCV.

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "engine/error.h"
#include "engine/image.h"
#include "io/image_io.h"
#include "test_support.h"

namespace mvflow {
namespace {

Image ramp_image(int width, int height) {
  Image image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      image.set_pixel(x, y, Eigen::Vector3f(0.01f * x, 0.02f * y, 0.5f * ((x + y) % 2)));
  return image;
}

TEST(Image, BilinearSampleMatchesHandComputation) {
  const Image image = ramp_image(7, 5);
  // At pixel centres the sample is the pixel.
  EXPECT_EQ(image.sample_bilinear(3, 2), image.pixel(3, 2));
  // Between four pixels: weights (1−a)(1−b), a(1−b), (1−a)b, ab.
  const double u = 2.25, v = 1.75;
  const Eigen::Vector3f expected = 0.75f * 0.25f * image.pixel(2, 1) + 0.25f * 0.25f * image.pixel(3, 1) +
                                   0.75f * 0.75f * image.pixel(2, 2) + 0.25f * 0.75f * image.pixel(3, 2);
  EXPECT_LT((image.sample_bilinear(u, v) - expected).norm(), 1e-6f);
  // The last row and column are reachable.
  EXPECT_EQ(image.sample_bilinear(6, 4), image.pixel(6, 4));
}

TEST(ImageIo, PngRoundTripsAt8And16Bits) {
  test::ScratchFolder folder;
  const Image image = ramp_image(9, 6);
  for (int bits : {8, 16}) {
    const auto file = folder / ("ramp" + std::to_string(bits) + ".png");
    io::write_png(file, image, bits);
    const Image back = io::read_image(file);
    ASSERT_EQ(back.width(), 9);
    ASSERT_EQ(back.height(), 6);
    const float step = bits == 8 ? 0.5f / 255 : 0.5f / 65535;
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 9; ++x) EXPECT_LE((back.pixel(x, y) - image.pixel(x, y)).cwiseAbs().maxCoeff(), step + 1e-7f);
  }
}

TEST(ImageIo, GreyBecomesRgbAndSizeComesFromHeader) {
  test::ScratchFolder folder;
  cv::Mat grey(4, 6, CV_8UC1);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 6; ++x) grey.at<unsigned char>(y, x) = static_cast<unsigned char>(40 * y + x);
  for (const char* name : {"grey.png", "grey.tif", "grey.jpg"}) {
    ASSERT_TRUE(cv::imwrite((folder / name).string(), grey));
    const auto size = io::read_image_size(folder / name);
    EXPECT_EQ(size.width, 6) << name;
    EXPECT_EQ(size.height, 4) << name;
    const Image image = io::read_image(folder / name);
    const Eigen::Vector3f p = image.pixel(2, 3);
    EXPECT_EQ(p.x(), p.y()) << name;
    EXPECT_EQ(p.y(), p.z()) << name;
    if (std::string(name) != "grey.jpg") {  // JPEG is lossy
      EXPECT_FLOAT_EQ(p.x(), 122.0f / 255.0f) << name;
    }
  }
}

TEST(ImageIo, ChannelsAreRgbNotBgr) {
  test::ScratchFolder folder;
  cv::Mat bgr(1, 1, CV_8UC3, cv::Scalar(255, 0, 0));  // pure blue in OpenCV's BGR order
  ASSERT_TRUE(cv::imwrite((folder / "blue.png").string(), bgr));
  const Eigen::Vector3f p = io::read_image(folder / "blue.png").pixel(0, 0);
  EXPECT_EQ(p, Eigen::Vector3f(0, 0, 1));
}

TEST(ImageIo, UnreadableAndMissingFilesAreClearErrors) {
  test::ScratchFolder folder;
  test::write_text(folder / "broken.png", "\x89PNG\r\n\x1a\nthis is not a png");
  try {
    io::read_image(folder / "broken.png");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.png"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("cannot decode"), std::string::npos);
  }
  EXPECT_THROW(io::read_image(folder / "absent.png"), IoError);
}

TEST(ImageIo, FailedWriteLeavesExistingFileIntact) {
  test::ScratchFolder folder;
  const auto file = folder / "keep.png";
  test::write_text(file, "previous content");
  // A folder that does not exist: the temporary file cannot be created, the target is untouched.
  EXPECT_THROW(io::write_png(folder / "missing-folder" / "x.png", ramp_image(2, 2)), Error);
  EXPECT_EQ(test::read_text(file), "previous content");
}

}  // namespace
}  // namespace mvflow
