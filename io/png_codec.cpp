#include "io/png_codec.h"

#include <png.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "engine/model/error.h"

namespace mvflow::io {

namespace {

// libpng reports errors by longjmp: the message is kept here and turned into an exception once
// the decoding function has returned, so that no C++ frame is jumped over.
struct PngErrors {
  std::string message;
};

void keep_error(png_structp png, png_const_charp message) {
  static_cast<PngErrors*>(png_get_error_ptr(png))->message = message ? message : "unknown libpng error";
  png_longjmp(png, 1);
}

void ignore_warning(png_structp, png_const_charp) {}

struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};

// The samples as OpenCV's PNG decoder gives them with IMREAD_COLOR | IMREAD_ANYDEPTH, with the
// same libpng transformations in the same order, but RGB instead of BGR. Returns false (with the
// message in errors) when libpng gives up; the buffers belong to the caller, so nothing with a
// destructor lives in this frame across the setjmp.
bool decode_samples(std::FILE* file, PngErrors& errors, std::vector<std::uint8_t>& samples,
                    std::vector<png_bytep>& rows, png_uint_32& width, png_uint_32& height, int& depth,
                    bool& has_exif) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &errors, keep_error, ignore_warning);
  if (!png) {
    errors.message = "out of memory";
    return false;
  }
  png_infop info = png_create_info_struct(png);
  png_infop end_info = png_create_info_struct(png);
  if (!info || !end_info) {
    png_destroy_read_struct(&png, &info, &end_info);
    errors.message = "out of memory";
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, &end_info);
    return false;
  }
  png_init_io(png, file);
  png_read_info(png, info);
  int colour = 0;
  png_get_IHDR(png, info, &width, &height, &depth, &colour, nullptr, nullptr, nullptr);
  if (depth == 16)
    png_set_swap(png);  // native (little-endian) 16-bit samples
  png_set_strip_alpha(png);
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((colour & PNG_COLOR_MASK_COLOR) == 0 && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if ((colour & PNG_COLOR_MASK_COLOR) == 0) png_set_gray_to_rgb(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  depth = png_get_bit_depth(png, info);
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  // The header check (io/image_io.cpp) bounds width and height: this fits easily.
  samples.resize(row_bytes * height);
  rows.resize(height);
  for (png_uint_32 y = 0; y < height; ++y) rows[y] = samples.data() + y * row_bytes;
  png_read_image(png, rows.data());
  png_read_end(png, end_info);
  has_exif = png_get_valid(png, info, PNG_INFO_eXIf) || png_get_valid(png, end_info, PNG_INFO_eXIf);
  png_destroy_read_struct(&png, &info, &end_info);
  return true;
}

// OpenCV's convertTo with a scale: one float product, rounded once (8- and 16-bit to float).
template <typename Sample>
void scale_into(const std::uint8_t* bytes, std::size_t count, float scale, float* out) {
  const Sample* sample = reinterpret_cast<const Sample*>(bytes);
  for (std::size_t i = 0; i < count; ++i) out[i] = static_cast<float>(sample[i]) * scale;
}

// OpenCV's saturate_cast of v * steps: rounded to nearest (ties to even), clamped, NaN to 0.
template <typename Sample>
Sample quantise(float value, float steps) {
  const float scaled = value * steps;
  if (!(scaled > 0.0f)) return 0;
  if (scaled >= steps) return static_cast<Sample>(steps);
  return static_cast<Sample>(std::nearbyint(scaled));
}

void append_bytes(png_structp png, png_bytep data, png_size_t size) {
  auto* bytes = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
  bytes->insert(bytes->end(), data, data + size);
}

void flush_nothing(png_structp) {}

bool encode_rows(std::vector<png_bytep>& rows, int width, int height, int bits, PngErrors& errors,
                 std::vector<std::uint8_t>& bytes) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &errors, keep_error, ignore_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    errors.message = "out of memory";
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, &bytes, append_bytes, flush_nothing);
  // OpenCV's defaults for imencode(".png"): tuned for speed.
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, Z_BEST_SPEED);
  png_set_compression_strategy(png, Z_RLE);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), bits,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (bits == 16) png_set_swap(png);
  png_write_image(png, rows.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

std::optional<Image> read_png(const std::filesystem::path& file) {
  const std::unique_ptr<std::FILE, FileCloser> stream(std::fopen(file.c_str(), "rb"));
  if (!stream) throw IoError(file, "cannot open for reading");
  PngErrors errors;
  std::vector<std::uint8_t> samples;
  std::vector<png_bytep> rows;
  png_uint_32 width = 0, height = 0;
  int depth = 0;
  bool has_exif = false;
  if (!decode_samples(stream.get(), errors, samples, rows, width, height, depth, has_exif))
    throw InputError(file, 0, "cannot decode the PNG: " + errors.message);
  if (has_exif) return std::nullopt;
  Image image = Image::uninitialized(static_cast<int>(width), static_cast<int>(height));  // every value written
  const std::size_t count = std::size_t{width} * height * 3;
  if (depth == 16)
    scale_into<std::uint16_t>(samples.data(), count, static_cast<float>(1.0 / 65535.0), image.data());
  else
    scale_into<std::uint8_t>(samples.data(), count, static_cast<float>(1.0 / 255.0), image.data());
  return image;
}

std::vector<std::uint8_t> encode_png(const Image& image, int bits) {
  MVFLOW_CHECK(bits == 8 || bits == 16, "PNG bit depth must be 8 or 16");
  const int width = image.width(), height = image.height();
  const std::size_t count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3;
  const std::size_t sample_bytes = bits == 8 ? 1 : 2;
  std::vector<std::uint8_t> samples(count * sample_bytes);
  const float* value = image.data();
  if (bits == 8) {
    for (std::size_t i = 0; i < count; ++i) samples[i] = quantise<std::uint8_t>(value[i], 255.0f);
  } else {
    auto* out = reinterpret_cast<std::uint16_t*>(samples.data());
    for (std::size_t i = 0; i < count; ++i) out[i] = quantise<std::uint16_t>(value[i], 65535.0f);
  }
  std::vector<png_bytep> rows(static_cast<std::size_t>(height));
  const std::size_t row_bytes = static_cast<std::size_t>(width) * 3 * sample_bytes;
  for (int y = 0; y < height; ++y) rows[static_cast<std::size_t>(y)] = samples.data() + y * row_bytes;
  PngErrors errors;
  std::vector<std::uint8_t> bytes;
  MVFLOW_CHECK(encode_rows(rows, width, height, bits, errors, bytes), "libpng cannot encode the image: " + errors.message);
  return bytes;
}

}  // namespace mvflow::io
