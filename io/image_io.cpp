#include "io/image_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <fstream>
#include <vector>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/little_endian.h"

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
// Bytes before a marker are skipped as libjpeg skips them ("extraneous bytes before marker"), so
// that every file libjpeg would decode has its size checked here first.
std::optional<HeaderSize> jpeg_size(std::istream& in) {
  unsigned char soi[2];
  if (!in.read(reinterpret_cast<char*>(soi), 2) || soi[0] != 0xFF || soi[1] != 0xD8) return std::nullopt;
  const auto next_byte = [&in]() -> std::optional<int> {
    const int c = in.get();
    if (c == std::char_traits<char>::eof()) return std::nullopt;
    return c;
  };
  for (int segments = 0; segments < 100000; ++segments) {
    std::optional<int> c = next_byte();
    while (c && *c != 0xFF) c = next_byte();  // extraneous bytes
    while (c && *c == 0xFF) c = next_byte();  // fill bytes
    if (!c) return std::nullopt;
    const int type = *c;
    const bool standalone = type == 0x00 || type == 0x01 || (type >= 0xD0 && type <= 0xD8);
    if (standalone) continue;
    if (type == 0xD9) return std::nullopt;  // end of image before any frame
    unsigned char length_bytes[2];
    if (!in.read(reinterpret_cast<char*>(length_bytes), 2)) return std::nullopt;
    const int length = (length_bytes[0] << 8) | length_bytes[1];
    if (length < 2) continue;  // libjpeg reads on: scan for the next marker
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

// BMP: the info header's width and height (signed; a negative height is a top-down image) follow
// the 14-byte file header; the old 12-byte core header has 16-bit ones.
std::optional<HeaderSize> bmp_size(std::istream& in) {
  std::array<unsigned char, 26> header{};
  if (!in.read(reinterpret_cast<char*>(header.data()), header.size())) return std::nullopt;
  if (header[0] != 'B' || header[1] != 'M') return std::nullopt;
  if (decode_little_endian<std::uint32_t>(&header[14]) == 12)
    return HeaderSize{decode_little_endian<std::uint16_t>(&header[18]), decode_little_endian<std::uint16_t>(&header[20])};
  const auto magnitude = [](const unsigned char* p) {
    const std::int64_t value = decode_little_endian<std::int32_t>(p);
    return static_cast<std::uint32_t>(value < 0 ? -value : value);
  };
  return HeaderSize{magnitude(&header[18]), magnitude(&header[22])};
}

// PNM (P1..P6): magic, then width and height as decimal numbers between whitespace and comments.
std::optional<HeaderSize> pnm_size(std::istream& in) {
  char magic[2];
  if (!in.read(magic, 2) || magic[0] != 'P' || magic[1] < '1' || magic[1] > '6') return std::nullopt;
  std::array<std::uint64_t, 2> numbers{};
  for (std::uint64_t& number : numbers) {
    int c = in.get();
    while (c == '#' || std::isspace(c)) {
      if (c == '#')
        while (c != '\n' && c != std::char_traits<char>::eof()) c = in.get();
      c = in.get();
    }
    if (!std::isdigit(c)) return std::nullopt;
    for (; std::isdigit(c); c = in.get()) number = std::min<std::uint64_t>(number * 10 + (c - '0'), 1ULL << 32);
  }
  return HeaderSize{static_cast<std::uint32_t>(std::min<std::uint64_t>(numbers[0], UINT32_MAX)),
                    static_cast<std::uint32_t>(std::min<std::uint64_t>(numbers[1], UINT32_MAX))};
}

// TIFF (classic, either byte order): tags 256 and 257 (width, height) of the first image directory.
std::optional<HeaderSize> tiff_size(std::istream& in) {
  std::array<unsigned char, 8> header{};
  if (!in.read(reinterpret_cast<char*>(header.data()), header.size())) return std::nullopt;
  const bool little = header[0] == 'I' && header[1] == 'I' && header[2] == 42 && header[3] == 0;
  const bool big = header[0] == 'M' && header[1] == 'M' && header[2] == 0 && header[3] == 42;
  if (!little && !big) return std::nullopt;
  const auto u16 = [little](const unsigned char* p) {
    return static_cast<std::uint32_t>(little ? p[0] | (p[1] << 8) : (p[0] << 8) | p[1]);
  };
  const auto u32 = [little](const unsigned char* p) { return little ? decode_little_endian<std::uint32_t>(p) : big_endian_32(p); };
  in.seekg(u32(&header[4]));
  unsigned char count_bytes[2];
  if (!in.read(reinterpret_cast<char*>(count_bytes), 2)) return std::nullopt;
  // Every width or height entry counts and the largest wins: libtiff reads the first of a repeated
  // tag and skips an entry of a type it does not read as a size, so the last entry (or a zero
  // for such a type) could state a smaller image than the one decoded.
  std::optional<std::uint32_t> width, height;
  for (std::uint32_t i = 0, n = u16(count_bytes); i < n; ++i) {
    unsigned char entry[12];
    if (!in.read(reinterpret_cast<char*>(entry), 12)) return std::nullopt;
    const std::uint32_t tag = u16(entry), type = u16(entry + 2);
    if (tag != 256 && tag != 257) continue;
    std::uint32_t value = 0;
    switch (type) {
      case 1: case 6: value = entry[8]; break;           // BYTE, SBYTE
      case 3: case 8: value = u16(entry + 8); break;     // SHORT, SSHORT (a negative one is huge here)
      case 4: case 9: value = u32(entry + 8); break;     // LONG, SLONG
      default: continue;                                 // not a size libtiff reads
    }
    std::optional<std::uint32_t>& side = tag == 256 ? width : height;
    side = std::max(side.value_or(0), value);
  }
  if (!width || !height) return std::nullopt;
  return HeaderSize{*width, *height};
}

// The size a PNG, JPEG, BMP, PNM or TIFF header states, without decoding; nullopt for other formats.
std::optional<HeaderSize> header_size(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(file, "cannot open for reading");
  for (const auto reader : {png_size, jpeg_size, bmp_size, pnm_size, tiff_size}) {
    in.clear();
    in.seekg(0);
    if (auto size = reader(in)) return size;
  }
  return std::nullopt;
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

// The size the header states, refused when beyond the limits or when the format is not one whose
// header is read here.
HeaderSize stated_size(const std::filesystem::path& file) {
  const auto size = header_size(file);
  if (!size)
    throw InputError(file, 0,
                     "cannot decode the image: no PNG, JPEG, TIFF, BMP or PNM header (the formats read) or a damaged one");
  check_image_size(file, size->width, size->height);
  return *size;
}

}  // namespace

Image read_image(const std::filesystem::path& file) {
  require_file(file);
  stated_size(file);  // first, so that a huge image is refused before anything is allocated
  cv::Mat decoded;
  try {
    decoded = cv::imread(file.string(), cv::IMREAD_COLOR | cv::IMREAD_ANYDEPTH);
  } catch (const cv::Exception& error) {
    // OpenCV refuses some files by throwing (its own size limit, assertions in its decoders).
    throw InputError(file, 0, "cannot decode the image: " + error.err);
  }
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
  const HeaderSize size = stated_size(file);
  return {static_cast<int>(size.width), static_cast<int>(size.height)};
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
