#include "stages/flow/image_noise.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>

#include "engine/model/parallel.h"

namespace mvflow {

double estimate_image_noise(const Image& image) {
  const int width = image.width(), height = image.height();
  if (width < 3 || height < 3) return 0.0;
  const float* rgb = image.data();
  std::vector<double> grey(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (std::size_t i = 0; i < grey.size(); ++i)
    grey[i] = (static_cast<double>(rgb[3 * i]) + rgb[3 * i + 1] + rgb[3 * i + 2]) / 3.0;
  double sum = 0.0;
  for (int y = 1; y + 1 < height; ++y) {
    const double* above = grey.data() + static_cast<std::size_t>(y - 1) * width;
    const double* row = above + width;
    const double* below = row + width;
    for (int x = 1; x + 1 < width; ++x) {
      const double response = (above[x - 1] + above[x + 1] + below[x - 1] + below[x + 1]) -
                              2.0 * (above[x] + below[x] + row[x - 1] + row[x + 1]) + 4.0 * row[x];
      sum += std::abs(response);
    }
  }
  return std::sqrt(std::numbers::pi / 2.0) / (6.0 * (width - 2) * (height - 2)) * sum;
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
