#pragma once
// Photographs through OpenCV: 8- and 16-bit PNG, JPEG, TIFF (anything imread decodes).
// Grey images become RGB, alpha is dropped, values are scaled to [0,1].

#include <filesystem>
#include <optional>

#include "engine/image.h"

namespace mvflow::io {

//! \throw IoError when the file does not exist; InputError when it cannot be decoded.
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
