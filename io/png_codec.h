#pragma once
// PNG through libpng, decoded exactly as OpenCV's imread decodes it for mvflow (grey and palette
// become RGB, alpha is dropped, 16-bit samples stay 16-bit, values scaled to [0,1] floats) and
// encoded as OpenCV's imencode encodes it. Why not OpenCV: its codec library loads about 120
// shared libraries (GDAL, poppler, DICOM, ...) at start-up, 0.13 s of every mvflow command.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "engine/model/image.h"

namespace mvflow::io {

//! The decoded PNG; nullopt when it carries Exif data (an eXIf chunk), whose orientation OpenCV
//! applies: such a file is left to OpenCV.
//! \pre the file's header was checked against the size limits (io/image_io.h).
//! \throw InputError when libpng refuses the file (damaged, truncated), with libpng's message.
std::optional<Image> read_png(const std::filesystem::path& file);

//! The PNG file's bytes: RGB at \p bits (8 or 16) bits, values clamped to [0,1] and rounded to
//! the nearest step; compressed as OpenCV does (sub filter, zlib level 1, run-length strategy).
std::vector<std::uint8_t> encode_png(const Image& image, int bits);

}  // namespace mvflow::io
