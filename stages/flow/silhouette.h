#pragma once
// Silhouettes of the object in its photographs: the visual hull carves with them and the
// held-out-view error compares inside them. A silhouette is a binary mask, one byte per pixel
// (1 = object), either thresholded from the photograph (black background, as the Middlebury sets)
// or read from a mask file (io/), optionally dilated so that a hull built from it stays
// conservative (Middlebury's README: threshold 0.19, 10 pixels).

#include <cstdint>
#include <vector>

#include "engine/model/image.h"

namespace mvflow {

//! One byte per pixel, row-major, 1 = object, 0 = background.
struct Mask {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> inside;

  Mask() = default;
  Mask(int w, int h) : width(w), height(h), inside(static_cast<std::size_t>(w) * h, 0) {}
  bool at(int x, int y) const { return inside[static_cast<std::size_t>(y) * width + x] != 0; }
  std::size_t count() const;
};

struct SilhouetteOptions {
  //! A pixel is object when its largest channel exceeds this value (on [0,1]); in [0, 1).
  //! 0.19: the Middlebury README's value for its black-background sets.
  double threshold = 0.19;
  //! Dilation radius in pixels (a disc), ≥ 0; 0 keeps the thresholded mask.
  int dilate = 0;
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! The object's silhouette in \p image by thresholding its largest channel, then dilated.
//! \throw Error if the options are invalid.
Mask threshold_silhouette(const Image& image, const SilhouetteOptions& options = {});

//! A mask from a mask image: every pixel whose largest channel is non-zero is object.
Mask mask_from_image(const Image& image);

//! The mask as a mask image: object white, the rest black (mask_from_image reads it back).
Image mask_image(const Mask& mask);

//! \p mask dilated by a disc of \p radius pixels (a pixel becomes object when an object pixel
//! lies within Euclidean distance \p radius). radius 0 returns the mask unchanged.
Mask dilate_mask(const Mask& mask, int radius);

}  // namespace mvflow
