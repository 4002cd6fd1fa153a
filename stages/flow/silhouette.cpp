#include "stages/flow/silhouette.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "engine/model/error.h"
#include "engine/model/option_check.h"

namespace mvflow {

void SilhouetteOptions::check() const {
  require_option(threshold >= 0.0 && threshold < 1.0, "threshold", threshold, "[0, 1)");
  require_option(dilate >= 0 && dilate <= 1000, "dilate", dilate, "[0, 1000]");
}

namespace {

float largest_channel(const float* rgb) { return std::max({rgb[0], rgb[1], rgb[2]}); }

}  // namespace

std::size_t Mask::count() const {
  return static_cast<std::size_t>(std::count_if(inside.begin(), inside.end(), [](std::uint8_t b) { return b != 0; }));
}

Mask threshold_silhouette(const Image& image, const SilhouetteOptions& options) {
  options.check();
  Mask mask(image.width(), image.height());
  const float* data = image.data();
  const float threshold = static_cast<float>(options.threshold);
  for (std::size_t i = 0; i < mask.inside.size(); ++i) mask.inside[i] = largest_channel(data + 3 * i) > threshold;
  return dilate_mask(mask, options.dilate);
}

Mask mask_from_image(const Image& image) {
  Mask mask(image.width(), image.height());
  const float* data = image.data();
  for (std::size_t i = 0; i < mask.inside.size(); ++i) mask.inside[i] = largest_channel(data + 3 * i) > 0.0f;
  return mask;
}

Image mask_image(const Mask& mask) {
  Image image(mask.width, mask.height);
  float* rgb = image.data();
  for (std::size_t p = 0; p < mask.inside.size(); ++p)
    if (mask.inside[p]) rgb[3 * p] = rgb[3 * p + 1] = rgb[3 * p + 2] = 1.0f;
  return image;
}

Mask dilate_mask(const Mask& mask, int radius) {
  MVFLOW_CHECK(radius >= 0, "dilation radius must be non-negative");
  if (radius == 0) return mask;
  // A disc is a union of horizontal runs: for each row offset dy the run half-width is
  // floor(sqrt(r² − dy²)). First a 1-D running dilation per row for each half-width needed,
  // then an OR over the rows: O(W·H·r) instead of O(W·H·r²).
  const int w = mask.width, h = mask.height;
  std::vector<int> half_width(static_cast<std::size_t>(radius) + 1);
  for (int dy = 0; dy <= radius; ++dy) half_width[dy] = static_cast<int>(std::floor(std::sqrt(double(radius) * radius - double(dy) * dy)));

  // Distance along the row to the nearest object pixel (left or right), capped at radius + 1.
  std::vector<int> row_distance(static_cast<std::size_t>(w) * h, radius + 1);
  for (int y = 0; y < h; ++y) {
    int* d = row_distance.data() + static_cast<std::size_t>(y) * w;
    int last = -(radius + 2);
    for (int x = 0; x < w; ++x) {
      if (mask.at(x, y)) last = x;
      d[x] = std::min(radius + 1, x - last);
    }
    last = w + radius + 2;
    for (int x = w - 1; x >= 0; --x) {
      if (mask.at(x, y)) last = x;
      d[x] = std::min(d[x], last - x);
    }
  }
  Mask dilated(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool hit = false;
      for (int dy = -radius; dy <= radius && !hit; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= h) continue;
        hit = row_distance[static_cast<std::size_t>(yy) * w + x] <= half_width[std::abs(dy)];
      }
      dilated.inside[static_cast<std::size_t>(y) * w + x] = hit;
    }
  return dilated;
}

}  // namespace mvflow
