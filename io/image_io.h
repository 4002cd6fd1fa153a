#pragma once
// Photographs: 8- and 16-bit PNG, TIFF, PNM (PBM/PGM/PPM), BMP, and JPEG: the formats whose size
// mvflow reads from the header before decoding; other formats are refused. PNG through libpng
// (io/png_codec.h), the others through OpenCV in a module loaded on first use
// (io/opencv_decoder.h); the same values either way. Grey images become RGB, alpha is dropped,
// values are scaled to [0,1].

#include <filesystem>
#include <optional>

#include "engine/model/image.h"

namespace mvflow::io {

//! The largest photograph read: this many pixels on a side and in all (2^28 = 268 M pixels,
//! 3.2 GB as float RGB). The size is read from the file's header and refused before anything is
//! allocated. (OpenCV's own limit, OPENCV_IO_MAX_IMAGE_PIXELS, is read once when OpenCV is loaded,
//! too early for a program to set it: so mvflow reads the headers itself.)
inline constexpr int kMaxImageSide = 32768;
inline constexpr long long kMaxImagePixels = 1LL << 28;
//! The most that decoding may allocate: OpenCV's image (3 channels of the file's sample size:
//! 1 byte, 2 for 16-bit, 4 for float) and, for TIFF, its strip or tile buffer, as the header
//! states them, refused before decoding. 1 GiB: a 2^28-pixel 8-bit image (768 MiB), 13 000 x
//! 13 000 16-bit RGB or 9 000 x 9 000 float RGB pixels. mvflow's own float RGB copy (12 bytes a
//! pixel) comes on top.
inline constexpr long long kMaxDecodedBytes = 1LL << 30;

//! \throw IoError when the file does not exist; InputError when it is not one of the formats above,
//!        cannot be decoded or is larger than kMaxImageSide / kMaxImagePixels / kMaxDecodedBytes.
Image read_image(const std::filesystem::path& file);

struct ImageSize {
  int width = 0;
  int height = 0;
};

//! The pixel size from the file header alone (no decoding). \throw as read_image.
ImageSize read_image_size(const std::filesystem::path& file);

//! Writes an 8-bit (or 16-bit) RGB PNG through a temporary file. Values are clamped to [0,1].
void write_png(const std::filesystem::path& file, const Image& image, int bits = 8);

}  // namespace mvflow::io
