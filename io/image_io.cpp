#include "io/image_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <fstream>
#include <map>
#include <vector>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/little_endian.h"
#include "io/opencv_decoder.h"
#include "io/png_codec.h"

namespace mvflow::io {

namespace {

void require_file(const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) throw IoError(file, "image file not found");
}

std::uint32_t big_endian_32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

// What a header states: the size (a PNG's is 32-bit unsigned) and what decoding it allocates.
struct HeaderSize {
  std::uint32_t width = 0, height = 0;
  //! Of the image OpenCV decodes into (IMREAD_ANYDEPTH keeps 16-bit and float samples).
  std::uint32_t bytes_per_sample = 1;
  //! The decoder's own buffer beside that image (TIFF: one strip or tile).
  std::uint64_t buffer_bytes = 0;
  bool is_png = false;
};

// 1, 2, 4 or 8: the sample size OpenCV gives \p bits (10, 12 and 14 bits widen to 16).
std::uint32_t sample_bytes(std::uint32_t bits) {
  std::uint32_t bytes = 1;
  while (bytes < 8 && bytes * 8 < bits) bytes *= 2;
  return bytes;
}

// PNG: the IHDR chunk follows the 8-byte signature; width, height and bit depth are its first
// 9 bytes (a missing depth counts as 16 bits).
std::optional<HeaderSize> png_size(std::istream& in) {
  std::array<unsigned char, 24> header{};
  if (!in.read(reinterpret_cast<char*>(header.data()), header.size())) return std::nullopt;
  static constexpr std::array<unsigned char, 8> signature{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!std::equal(signature.begin(), signature.end(), header.begin())) return std::nullopt;
  if (std::string(reinterpret_cast<const char*>(header.data()) + 12, 4) != "IHDR") return std::nullopt;
  const int depth = in.get();
  return HeaderSize{big_endian_32(&header[16]), big_endian_32(&header[20]), depth >= 1 && depth <= 8 ? 1u : 2u, 0, true};
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
                        static_cast<std::uint32_t>((frame[1] << 8) | frame[2]), sample_bytes(frame[0])};
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

// PNM (P1..P6): magic, then width, height and (but for the bitmaps P1 and P4) the largest value as
// decimal numbers between whitespace and comments; a largest value beyond 255 is 16-bit, and one
// that cannot be read counts as 16-bit.
std::optional<HeaderSize> pnm_size(std::istream& in) {
  char magic[2];
  if (!in.read(magic, 2) || magic[0] != 'P' || magic[1] < '1' || magic[1] > '6') return std::nullopt;
  const auto number = [&in]() -> std::optional<std::uint64_t> {
    int c = in.get();
    while (c == '#' || std::isspace(c)) {
      if (c == '#')
        while (c != '\n' && c != std::char_traits<char>::eof()) c = in.get();
      c = in.get();
    }
    if (!std::isdigit(c)) return std::nullopt;
    std::uint64_t value = 0;
    for (; std::isdigit(c); c = in.get()) value = std::min<std::uint64_t>(value * 10 + (c - '0'), 1ULL << 32);
    return value;
  };
  const std::optional<std::uint64_t> width = number(), height = width ? number() : std::nullopt;
  if (!height) return std::nullopt;
  std::uint32_t bytes = 1;
  if (magic[1] != '1' && magic[1] != '4') {
    const std::optional<std::uint64_t> largest = number();
    bytes = largest && *largest <= 255 ? 1 : 2;
  }
  return HeaderSize{static_cast<std::uint32_t>(std::min<std::uint64_t>(*width, UINT32_MAX)),
                    static_cast<std::uint32_t>(std::min<std::uint64_t>(*height, UINT32_MAX)), bytes};
}

// TIFF (classic, either byte order): from the first image directory, the width and height (tags
// 256, 257), and what OpenCV allocates to decode it: the sample size from the bits per sample
// (258; 1 bit when absent, 64 when unreadable), and its strip or tile buffer, a strip being
// RowsPerStrip (278, default the whole height) rows of the width, a tile TileWidth x TileLength
// (322, 323), at SamplesPerPixel (277) samples but at least 4 (OpenCV reads 8-bit images as RGBA).
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
  // The largest of an entry's first 16 values of a type libtiff reads as a number (BYTE, SHORT,
  // LONG and their signed kinds; a negative one is huge here): in the entry when they fit in its
  // 4 bytes, else at the offset it holds. nullopt for another type or values beyond the file.
  const auto largest_value = [&](const unsigned char* entry) -> std::optional<std::uint32_t> {
    const std::uint32_t type = u16(entry + 2), count = std::min<std::uint32_t>(u32(entry + 4), 16);
    const std::uint32_t size = type == 1 || type == 6 ? 1 : type == 3 || type == 8 ? 2 : type == 4 || type == 9 ? 4 : 0;
    if (size == 0 || count == 0) return std::nullopt;
    std::array<unsigned char, 64> bytes{};
    if (count * size <= 4) {
      std::copy(entry + 8, entry + 12, bytes.begin());
    } else {
      const std::streampos next = in.tellg();
      in.seekg(u32(entry + 8));
      const bool read = static_cast<bool>(in.read(reinterpret_cast<char*>(bytes.data()), count * size));
      in.clear();
      in.seekg(next);
      if (!read) return std::nullopt;
    }
    std::uint32_t largest = 0;
    for (std::uint32_t i = 0; i < count; ++i) {
      const unsigned char* p = &bytes[i * size];
      largest = std::max(largest, size == 1 ? std::uint32_t{*p} : size == 2 ? u16(p) : u32(p));
    }
    return largest;
  };
  in.seekg(u32(&header[4]));
  unsigned char count_bytes[2];
  if (!in.read(reinterpret_cast<char*>(count_bytes), 2)) return std::nullopt;
  // Every entry of a tag counts and the largest value wins: libtiff reads the first of a repeated
  // tag and skips an entry of a type it does not read as a number, so the last entry (or a zero
  // for such a type) could state a smaller image than the one decoded.
  std::map<std::uint32_t, std::uint32_t> values;  // tag → largest value
  bool unreadable_bits = false;
  for (std::uint32_t i = 0, n = u16(count_bytes); i < n; ++i) {
    unsigned char entry[12];
    if (!in.read(reinterpret_cast<char*>(entry), 12)) return std::nullopt;
    const std::uint32_t tag = u16(entry);
    if (tag != 256 && tag != 257 && tag != 258 && tag != 277 && tag != 278 && tag != 322 && tag != 323) continue;
    const std::optional<std::uint32_t> value = largest_value(entry);
    if (!value) {
      unreadable_bits |= tag == 258;
      continue;
    }
    values[tag] = std::max(values.count(tag) ? values[tag] : 0, *value);
  }
  if (!values.count(256) || !values.count(257)) return std::nullopt;
  HeaderSize size{values[256], values[257]};
  size.bytes_per_sample = unreadable_bits ? 8 : sample_bytes(values.count(258) ? values[258] : 1);
  const bool tiled = values.count(322) || values.count(323);
  const std::uint64_t rows = values.count(278) ? values[278] : size.height;
  const std::uint64_t tile_width = tiled && values[322] ? values[322] : size.width;
  const std::uint64_t tile_height = tiled ? (values[323] ? values[323] : size.height)
                                          : (rows == 0 || rows == UINT32_MAX ? size.height : rows);
  const std::uint64_t samples = std::max<std::uint64_t>(values.count(277) ? values[277] : 1, 4);
  // Saturating: each factor may be as large as 2^32.
  const auto times = [](std::uint64_t a, std::uint64_t b) { return b != 0 && a > UINT64_MAX / b ? UINT64_MAX : a * b; };
  size.buffer_bytes = times(times(times(tile_width, tile_height), samples), size.bytes_per_sample);
  return size;
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

// Refuses an image whose decoding would allocate more than kMaxDecodedBytes: OpenCV decodes into
// 3 channels (IMREAD_COLOR) of the header's sample size, beside the decoder's own buffer.
void check_decoded_bytes(const std::filesystem::path& file, const HeaderSize& size) {
  // Within kMaxImagePixels already, so the image's bytes are far from overflowing.
  const std::uint64_t image_bytes = std::uint64_t{size.width} * size.height * 3 * size.bytes_per_sample;
  const std::uint64_t bytes = image_bytes + std::min(size.buffer_bytes, UINT64_MAX / 2);
  if (bytes <= static_cast<std::uint64_t>(kMaxDecodedBytes)) return;
  constexpr std::uint64_t mib = 1 << 20;
  throw InputError(file, 0,
                   "the image is " + std::to_string(size.width) + "x" + std::to_string(size.height) + " pixels of " +
                       std::to_string(size.bytes_per_sample) + "-byte samples: decoding it takes " +
                       std::to_string((bytes + mib - 1) / mib) + " MiB; at most " +
                       std::to_string(kMaxDecodedBytes / mib) + " MiB is decoded");
}

// The size the header states, refused when beyond the limits or when the format is not one whose
// header is read here.
HeaderSize stated_size(const std::filesystem::path& file) {
  const auto size = header_size(file);
  if (!size)
    throw InputError(file, 0,
                     "cannot decode the image: no PNG, JPEG, TIFF, BMP or PNM header (the formats read) or a damaged one");
  check_image_size(file, size->width, size->height);
  check_decoded_bytes(file, *size);
  return *size;
}

}  // namespace

Image read_image(const std::filesystem::path& file) {
  require_file(file);
  const HeaderSize stated = stated_size(file);  // first: a huge image is refused before anything is allocated
  if (stated.is_png)
    if (std::optional<Image> image = read_png(file)) return *std::move(image);
  return read_image_with_opencv(file, [&file](int width, int height) {
    check_image_size(file, static_cast<std::uint64_t>(width), static_cast<std::uint64_t>(height));
  });
}

ImageSize read_image_size(const std::filesystem::path& file) {
  require_file(file);
  const HeaderSize size = stated_size(file);
  return {static_cast<int>(size.width), static_cast<int>(size.height)};
}

void write_png(const std::filesystem::path& file, const Image& image, int bits) {
  // Encoded in memory first and written through a checked stream, so that a full disk is noticed.
  const std::vector<std::uint8_t> bytes = encode_png(image, bits);
  write_atomically(file, true, [&](std::ostream& stream) {
    stream.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  });
}

}  // namespace mvflow::io
