#include "io/image_io.h"

#include <array>
#include <cstdint>
#include <fstream>
#include <vector>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "engine/error.h"
#include "io/atomic_write.h"

namespace mvflow::io {

namespace {

void require_file(const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) throw IoError(file, "image file not found");
}

std::uint32_t big_endian_32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

// Sizes as the headers state them: a PNG's are 32-bit unsigned.
struct HeaderSize {
  std::uint32_t width = 0, height = 0;
};

// PNG: the IHDR chunk follows the 8-byte signature; width and height are its first 8 bytes.
std::optional<HeaderSize> png_size(std::istream& in) {
  std::array<unsigned char, 24> header{};
  if (!in.read(reinterpret_cast<char*>(header.data()), header.size())) return std::nullopt;
  static constexpr std::array<unsigned char, 8> signature{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!std::equal(signature.begin(), signature.end(), header.begin())) return std::nullopt;
  if (std::string(reinterpret_cast<const char*>(header.data()) + 12, 4) != "IHDR") return std::nullopt;
  return HeaderSize{big_endian_32(&header[16]), big_endian_32(&header[20])};
}

// JPEG: walk the marker segments to the first start-of-frame (SOF0..SOF15 except DHT/JPG/DAC).
std::optional<HeaderSize> jpeg_size(std::istream& in) {
  unsigned char soi[2];
  if (!in.read(reinterpret_cast<char*>(soi), 2) || soi[0] != 0xFF || soi[1] != 0xD8) return std::nullopt;
  for (int segments = 0; segments < 1000; ++segments) {
    unsigned char marker[4];
    if (!in.read(reinterpret_cast<char*>(marker), 4) || marker[0] != 0xFF) return std::nullopt;
    const int type = marker[1];
    const int length = (marker[2] << 8) | marker[3];
    if (length < 2) return std::nullopt;
    const bool is_frame = type >= 0xC0 && type <= 0xCF && type != 0xC4 && type != 0xC8 && type != 0xCC;
    if (is_frame) {
      unsigned char frame[5];
      if (!in.read(reinterpret_cast<char*>(frame), 5)) return std::nullopt;
      return HeaderSize{static_cast<std::uint32_t>((frame[3] << 8) | frame[4]),
                        static_cast<std::uint32_t>((frame[1] << 8) | frame[2])};
    }
    in.seekg(length - 2, std::ios::cur);
  }
  return std::nullopt;
}

// The size a PNG or JPEG header states, without decoding; nullopt for other formats.
std::optional<HeaderSize> header_size(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(file, "cannot open for reading");
  if (auto size = png_size(in)) return size;
  in.clear();
  in.seekg(0);
  return jpeg_size(in);
}

// Refuses a size beyond kMaxImageSide / kMaxImagePixels, naming the file.
void check_image_size(const std::filesystem::path& file, std::uint64_t width, std::uint64_t height) {
  if (width <= static_cast<std::uint64_t>(kMaxImageSide) && height <= static_cast<std::uint64_t>(kMaxImageSide) &&
      width * height <= static_cast<std::uint64_t>(kMaxImagePixels))
    return;
  throw InputError(file, 0,
                   "the image is " + std::to_string(width) + "x" + std::to_string(height) + " pixels; at most " +
                       std::to_string(kMaxImageSide) + " on a side and " + std::to_string(kMaxImagePixels) +
                       " in all are read");
}

}  // namespace

Image read_image(const std::filesystem::path& file) {
  require_file(file);
  // The header's size first, so that a huge image is refused before anything is allocated.
  if (const auto size = header_size(file)) check_image_size(file, size->width, size->height);
  const cv::Mat decoded = cv::imread(file.string(), cv::IMREAD_COLOR | cv::IMREAD_ANYDEPTH);
  if (decoded.empty())
    throw InputError(file, 0, "cannot decode the image (unreadable, truncated or not an image format OpenCV reads)");
  double scale = 1.0;
  switch (decoded.depth()) {
    case CV_8U: scale = 1.0 / 255.0; break;
    case CV_16U: scale = 1.0 / 65535.0; break;
    case CV_32F: scale = 1.0; break;
    default: throw InputError(file, 0, "unsupported pixel depth (expected 8-bit, 16-bit or float)");
  }
  check_image_size(file, static_cast<std::uint64_t>(decoded.cols), static_cast<std::uint64_t>(decoded.rows));
  cv::Mat rgb;
  cv::cvtColor(decoded, rgb, cv::COLOR_BGR2RGB);
  Image image(rgb.cols, rgb.rows);
  cv::Mat target(rgb.rows, rgb.cols, CV_32FC3, image.data());  // wraps the Image's buffer
  rgb.convertTo(target, CV_32FC3, scale);
  return image;
}

ImageSize read_image_size(const std::filesystem::path& file) {
  require_file(file);
  if (const auto size = header_size(file)) {
    check_image_size(file, size->width, size->height);
    return {static_cast<int>(size->width), static_cast<int>(size->height)};
  }
  const Image image = read_image(file);
  return {image.width(), image.height()};
}

void write_png(const std::filesystem::path& file, const Image& image, int bits) {
  MVFLOW_CHECK(bits == 8 || bits == 16, "PNG bit depth must be 8 or 16");
  const cv::Mat rgb(image.height(), image.width(), CV_32FC3, const_cast<float*>(image.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  cv::Mat out;
  const double scale = bits == 8 ? 255.0 : 65535.0;
  bgr.convertTo(out, bits == 8 ? CV_8UC3 : CV_16UC3, scale);  // saturates: clamps to [0,1]
  // Encoded in memory and written through a checked stream: cv::imwrite reports success on a
  // full disk and leaves an empty file.
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", out, bytes)) throw IoError(file, "cannot encode the PNG");
  write_atomically(file, true, [&](std::ostream& stream) {
    stream.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  });
}

}  // namespace mvflow::io
