#pragma once
// Photographs through OpenCV: 8- and 16-bit PNG, JPEG, TIFF (anything imread decodes).
// Grey images become RGB, alpha is dropped, values are scaled to [0,1].

#include <filesystem>
#include <optional>

#include "engine/image.h"

namespace mvflow::io {

//! The largest photograph read: this many pixels on a side and in all (2^28 = 268 M pixels,
//! 3.2 GB as float RGB). A PNG or JPEG beyond them is refused from its header, before anything is
//! allocated; other formats after decoding (the program also sets OpenCV's own decoding limit,
//! CV_IO_MAX_IMAGE_PIXELS, to kMaxImagePixels unless the environment sets it).
inline constexpr int kMaxImageSide = 32768;
inline constexpr long long kMaxImagePixels = 1LL << 28;

//! \throw IoError when the file does not exist; InputError when it cannot be decoded or is larger
//!        than kMaxImageSide / kMaxImagePixels.
Image read_image(const std::filesystem::path& file);

struct ImageSize {
  int width = 0;
  int height = 0;
};

//! The pixel size from the file header alone for PNG and JPEG (no decoding), by decoding the
//! image otherwise. \throw as read_image.
ImageSize read_image_size(const std::filesystem::path& file);

//! Writes an 8-bit (or 16-bit) RGB PNG through a temporary file. Values are clamped to [0,1].
void write_png(const std::filesystem::path& file, const Image& image, int bits = 8);

}  // namespace mvflow::io
