// The PNG codec (io/png_codec.h) against OpenCV, whose decoding and encoding it replaces: every
// PNG colour type, bit depth and interlacing decodes to the same floats as imread followed by the
// conversion mvflow applied before; the encoder's bytes equal imencode's. Other formats go through
// the OpenCV decoder module and give what imread gives.

#include <gtest/gtest.h>
#include <png.h>

#include <cstring>
#include <random>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "engine/model/error.h"
#include "engine/model/image.h"
#include "io/image_io.h"
#include "io/png_codec.h"
#include "test_support.h"

namespace mvflow {
namespace {

// What mvflow's decoding was before the PNG codec: imread, scaled to [0,1], BGR turned to RGB.
Image decoded_by_opencv(const std::filesystem::path& file) {
  const cv::Mat decoded = cv::imread(file.string(), cv::IMREAD_COLOR | cv::IMREAD_ANYDEPTH);
  EXPECT_FALSE(decoded.empty()) << file;
  const double scale = decoded.depth() == CV_16U ? 1.0 / 65535.0 : 1.0 / 255.0;
  cv::Mat values;
  decoded.convertTo(values, CV_32FC3, scale);
  Image image(values.cols, values.rows);
  for (int y = 0; y < values.rows; ++y)
    for (int x = 0; x < values.cols; ++x) {
      const cv::Vec3f bgr = values.at<cv::Vec3f>(y, x);
      image.set_pixel(x, y, Eigen::Vector3f(bgr[2], bgr[1], bgr[0]));
    }
  return image;
}

void expect_same_bits(const Image& actual, const Image& expected, const std::string& what) {
  ASSERT_EQ(actual.width(), expected.width()) << what;
  ASSERT_EQ(actual.height(), expected.height()) << what;
  const std::size_t n = static_cast<std::size_t>(actual.width()) * actual.height() * 3;
  EXPECT_EQ(std::memcmp(actual.data(), expected.data(), n * sizeof(float)), 0) << what;
}

struct PngKind {
  int colour;  // PNG_COLOR_TYPE_*
  int depth;   // bits per sample
  bool interlaced = false;
  bool transparency = false;  // a tRNS chunk (palette, grey, RGB)
  bool exif = false;          // an eXIf chunk stating orientation 6 (turned 90°)
  std::string name() const {
    return "colour " + std::to_string(colour) + ", " + std::to_string(depth) + " bits" + (interlaced ? ", interlaced" : "") +
           (transparency ? ", tRNS" : "") + (exif ? ", eXIf" : "");
  }
};

// Random samples of every kind, written with libpng directly (OpenCV writes only some kinds).
void write_png_of_kind(const std::filesystem::path& file, const PngKind& kind, int width, int height, unsigned seed) {
  std::FILE* out = std::fopen(file.c_str(), "wb");
  ASSERT_NE(out, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  ASSERT_EQ(setjmp(png_jmpbuf(png)), 0);
  png_init_io(png, out);
  png_set_IHDR(png, info, width, height, kind.depth, kind.colour,
               kind.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  std::mt19937 random(seed);
  if (kind.colour == PNG_COLOR_TYPE_PALETTE) {
    std::vector<png_color> palette(1u << kind.depth);
    for (png_color& entry : palette)
      entry = {static_cast<png_byte>(random()), static_cast<png_byte>(random()), static_cast<png_byte>(random())};
    png_set_PLTE(png, info, palette.data(), static_cast<int>(palette.size()));
    if (kind.transparency) {
      std::vector<png_byte> alpha(palette.size(), 128);
      png_set_tRNS(png, info, alpha.data(), static_cast<int>(alpha.size()), nullptr);
    }
  } else if (kind.transparency) {
    png_color_16 transparent{0, 1, 2, 3, 4};
    png_set_tRNS(png, info, nullptr, 0, &transparent);
  }
  if (kind.exif) {
    // A little-endian TIFF header and one IFD entry: orientation (274), SHORT, 1 value, 6.
    std::vector<png_byte> exif{'I', 'I', 42, 0, 8, 0, 0, 0, 1, 0, 0x12, 0x01, 3, 0, 1, 0, 0, 0, 6, 0, 0, 0, 0, 0, 0, 0};
    png_set_eXIf_1(png, info, static_cast<png_uint_32>(exif.size()), exif.data());
  }
  png_write_info(png, info);
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  std::vector<png_byte> samples(row_bytes * height);
  for (png_byte& b : samples) b = static_cast<png_byte>(random());
  std::vector<png_bytep> rows(height);
  for (int y = 0; y < height; ++y) rows[y] = samples.data() + y * row_bytes;
  png_write_image(png, rows.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  std::fclose(out);
}

TEST(PngCodec, EveryColourTypeDepthAndInterlacingDecodesAsOpenCvDoes) {
  test::ScratchFolder folder;
  std::vector<PngKind> kinds;
  for (const int depth : {1, 2, 4, 8, 16}) kinds.push_back({PNG_COLOR_TYPE_GRAY, depth});
  for (const int depth : {1, 2, 4, 8}) kinds.push_back({PNG_COLOR_TYPE_PALETTE, depth});
  for (const int depth : {8, 16}) {
    kinds.push_back({PNG_COLOR_TYPE_RGB, depth});
    kinds.push_back({PNG_COLOR_TYPE_RGB_ALPHA, depth});
    kinds.push_back({PNG_COLOR_TYPE_GRAY_ALPHA, depth});
    kinds.push_back({PNG_COLOR_TYPE_RGB, depth, true});
    kinds.push_back({PNG_COLOR_TYPE_RGB, depth, false, true});
    kinds.push_back({PNG_COLOR_TYPE_GRAY, depth, false, true});
  }
  kinds.push_back({PNG_COLOR_TYPE_PALETTE, 8, true, true});
  kinds.push_back({PNG_COLOR_TYPE_GRAY, 2, true});
  unsigned seed = 1;
  for (const PngKind& kind : kinds) {
    const auto file = folder / "kind.png";
    write_png_of_kind(file, kind, 37, 23, seed++);
    const std::optional<Image> native = io::read_png(file);
    ASSERT_TRUE(native.has_value()) << kind.name();
    expect_same_bits(*native, decoded_by_opencv(file), kind.name());
    expect_same_bits(io::read_image(file), *native, kind.name());
  }
}

TEST(PngCodec, EverySampleValueScalesAsOpenCvScalesIt) {
  test::ScratchFolder folder;
  cv::Mat every8(1, 256, CV_8UC1), every16(256, 256, CV_16UC1);
  for (int i = 0; i < 256; ++i) every8.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
  for (int i = 0; i < 65536; ++i) every16.at<std::uint16_t>(i / 256, i % 256) = static_cast<std::uint16_t>(i);
  for (const auto& [name, samples] : {std::pair{"every8.png", &every8}, std::pair{"every16.png", &every16}}) {
    ASSERT_TRUE(cv::imwrite((folder / name).string(), *samples));
    expect_same_bits(*io::read_png(folder / name), decoded_by_opencv(folder / name), name);
  }
}

TEST(PngCodec, ExifPngsAreLeftToOpenCvWhichAppliesTheirOrientation) {
  test::ScratchFolder folder;
  const auto file = folder / "exif.png";
  write_png_of_kind(file, {PNG_COLOR_TYPE_RGB, 8, false, false, true}, 7, 4, 3);
  EXPECT_FALSE(io::read_png(file).has_value());
  const Image read = io::read_image(file);  // through the OpenCV decoder module
  expect_same_bits(read, decoded_by_opencv(file), "eXIf");
}

Image random_image(int width, int height, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> value(-0.1f, 1.1f);  // some beyond [0,1]: clamped
  Image image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) image.set_pixel(x, y, Eigen::Vector3f(value(random), value(random), value(random)));
  // Exact halves of a step: OpenCV rounds them to even.
  image.set_pixel(0, 0, Eigen::Vector3f(0.5f / 255.0f, 1.5f / 255.0f, 2.5f / 255.0f));
  return image;
}

// imencode(".png") of the image as mvflow wrote it before: RGB to BGR, scaled, saturated.
std::vector<std::uint8_t> encoded_by_opencv(const Image& image, int bits) {
  cv::Mat bgr(image.height(), image.width(), CV_32FC3);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const Eigen::Vector3f rgb = image.pixel(x, y);
      bgr.at<cv::Vec3f>(y, x) = cv::Vec3f(rgb[2], rgb[1], rgb[0]);
    }
  cv::Mat out;
  bgr.convertTo(out, bits == 8 ? CV_8UC3 : CV_16UC3, bits == 8 ? 255.0 : 65535.0);
  std::vector<std::uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(".png", out, bytes));
  return bytes;
}

TEST(PngCodec, EncodedBytesEqualOpenCvsAt8And16Bits) {
  for (const int bits : {8, 16}) {
    const Image image = random_image(53, 29, static_cast<unsigned>(bits));
    EXPECT_EQ(io::encode_png(image, bits), encoded_by_opencv(image, bits)) << bits << " bits";
  }
}

TEST(PngCodec, OtherFormatsGoThroughOpenCvAndMatchIt) {
  test::ScratchFolder folder;
  cv::Mat bgr(19, 31, CV_8UC3);
  cv::randu(bgr, 0, 256);
  cv::Mat deep(19, 31, CV_16UC3);
  cv::randu(deep, 0, 65536);
  const std::vector<std::pair<std::string, const cv::Mat*>> files{
      {"view.jpg", &bgr}, {"view.bmp", &bgr}, {"view.ppm", &bgr}, {"view.tif", &bgr}, {"deep.tif", &deep}, {"deep.ppm", &deep}};
  for (const auto& [name, pixels] : files) {
    ASSERT_TRUE(cv::imwrite((folder / name).string(), *pixels)) << name;
    expect_same_bits(io::read_image(folder / name), decoded_by_opencv(folder / name), name);
  }
}

TEST(PngCodec, DamagedPngsAreInputErrorsNamingTheFile) {
  test::ScratchFolder folder;
  const auto file = folder / "cut.png";
  write_png_of_kind(file, {PNG_COLOR_TYPE_RGB, 8}, 40, 30, 9);
  const auto size = std::filesystem::file_size(file);
  std::filesystem::resize_file(file, size / 2);  // the image data cut short
  try {
    io::read_png(file);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("cut.png"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("cannot decode the PNG"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace mvflow
