#include "stages/flow/image_noise.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <utility>

#include "engine/model/parallel.h"

namespace mvflow {
namespace {

// Whether the 3×3 pixels around above[stride] (rows \p stride apart) are all equal: clipped to black
// or white, or a synthetic fill. Noise never leaves that, so such pixels say nothing about it; a
// photograph's black background would otherwise be its flattest tenth and read σ = 0.
bool constant_around(const float* above, int stride) {
  const float value = above[stride];
  for (int row = 0; row < 3; ++row)
    for (int dx = -1; dx <= 1; ++dx)
      if (above[row * stride + dx] != value) return false;
  return true;
}

}  // namespace

double estimate_image_noise(const Image& image) {
  const int width = image.width(), height = image.height();
  if (width < 3 || height < 3) return 0.0;
  const float* rgb = image.data();
  std::vector<float> grey(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (std::size_t i = 0; i < grey.size(); ++i) grey[i] = (rgb[3 * i] + rgb[3 * i + 1] + rgb[3 * i + 2]) / 3.0f;
  // Each interior pixel's squared Sobel gradient (the key) and mask response. The two filters are
  // orthogonal, so on noise alone the gradient says nothing about the response and choosing the
  // flattest pixels does not bias the estimate; on texture it keeps the detail out.
  std::vector<std::pair<float, float>> pixels;
  pixels.reserve(static_cast<std::size_t>(width - 2) * static_cast<std::size_t>(height - 2));
  for (int y = 1; y + 1 < height; ++y) {
    const float* above = grey.data() + static_cast<std::size_t>(y - 1) * width;
    const float* row = above + width;
    const float* below = row + width;
    for (int x = 1; x + 1 < width; ++x) {
      if (constant_around(above + x, width)) continue;
      const float corners = above[x - 1] + above[x + 1] + below[x - 1] + below[x + 1];
      const float response = corners - 2.0f * (above[x] + below[x] + row[x - 1] + row[x + 1]) + 4.0f * row[x];
      const float gx = (above[x + 1] - above[x - 1]) + 2.0f * (row[x + 1] - row[x - 1]) + (below[x + 1] - below[x - 1]);
      const float gy = (below[x - 1] - above[x - 1]) + 2.0f * (below[x] - above[x]) + (below[x + 1] - above[x + 1]);
      pixels.emplace_back(gx * gx + gy * gy, std::abs(response));
    }
  }
  if (pixels.empty()) return 0.0;
  const std::size_t kept = std::max<std::size_t>(
      1, static_cast<std::size_t>(std::ceil(kNoiseFlattestFraction * static_cast<double>(pixels.size()))));
  const auto last = pixels.begin() + static_cast<std::ptrdiff_t>(kept);
  if (kept < pixels.size()) std::nth_element(pixels.begin(), last - 1, pixels.end());
  double sum = 0.0;
  for (auto it = pixels.begin(); it != last; ++it) sum += it->second;
  return std::sqrt(std::numbers::pi / 2.0) / (6.0 * static_cast<double>(kept)) * sum;
}

double estimate_views_noise(const std::vector<PhotoView>& views) {
  if (views.empty()) return 0.0;
  std::vector<double> sigmas(views.size());
  parallel::parallel_for(std::size_t{0}, views.size(),
                         [&](std::size_t i) { sigmas[i] = estimate_image_noise(*views[i].image); });
  const auto middle = sigmas.begin() + static_cast<std::ptrdiff_t>((sigmas.size() - 1) / 2);
  std::nth_element(sigmas.begin(), middle, sigmas.end());
  return *middle;
}

}  // namespace mvflow
