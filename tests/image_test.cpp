// Images: bilinear sampling against a hand computation, and PNG/JPEG/TIFF reading through OpenCV.

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "engine/model/error.h"
#include "engine/model/image.h"
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

// A PNG signature and IHDR chunk stating \p width × \p height (no pixel data follows).
std::string png_header(std::uint32_t width, std::uint32_t height) {
  std::string bytes = "\x89PNG\r\n\x1a\n";
  bytes += std::string("\0\0\0\x0d", 4) + "IHDR";
  for (const std::uint32_t v : {width, height})
    for (int shift = 24; shift >= 0; shift -= 8) bytes += static_cast<char>((v >> shift) & 0xFF);
  bytes += std::string("\x08\x02\0\0\0", 5) + std::string(4, '\0');  // 8-bit RGB; CRC not checked
  return bytes;
}

// A JPEG start of image and a baseline start-of-frame segment stating \p width × \p height.
std::string jpeg_header(int width, int height) {
  std::string bytes = "\xFF\xD8\xFF\xC0";
  bytes += std::string("\0\x11\x08", 3);
  for (const int v : {height, width}) bytes += static_cast<char>((v >> 8) & 0xFF), bytes += static_cast<char>(v & 0xFF);
  return bytes + std::string(12, '\0');
}

TEST(ImageIo, ImagesBeyondTheLimitsAreRefusedFromTheirHeader) {
  test::ScratchFolder folder;
  struct Case {
    std::string name, bytes, size;
  };
  const Case cases[] = {
      {"wide.png", png_header(100000, 100), "100000x100"},
      {"many.png", png_header(20000, 20000), "20000x20000"},  // each side allowed, 4e8 pixels not
      {"absurd.png", png_header(0xFFFFFFF0u, 0xFFFFFFF0u), "4294967280x4294967280"},
      {"wide.jpg", jpeg_header(40000, 100), "40000x100"},
  };
  for (const Case& c : cases) {
    test::write_text(folder / c.name, c.bytes);
    for (int size_only = 0; size_only < 2; ++size_only) {
      try {
        if (size_only) {
          io::read_image_size(folder / c.name);
        } else {
          io::read_image(folder / c.name);
        }
        FAIL() << c.name << ": expected InputError";
      } catch (const InputError& e) {
        // Refused for its size (no pixel data follows the header: decoding would fail otherwise).
        const std::string message = e.what();
        EXPECT_NE(message.find(c.name), std::string::npos) << message;
        EXPECT_NE(message.find("the image is " + c.size + " pixels; at most 32768 on a side"), std::string::npos)
            << message;
      }
    }
  }
  // Within the limits the header's size is read without decoding.
  test::write_text(folder / "fine.png", png_header(32768, 8192));
  const io::ImageSize fine = io::read_image_size(folder / "fine.png");
  EXPECT_EQ(fine.width, 32768);
  EXPECT_EQ(fine.height, 8192);
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
