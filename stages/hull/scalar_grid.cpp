#include "stages/hull/scalar_grid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "engine/model/error.h"
#include "engine/model/parallel.h"

namespace mvflow {

namespace {

std::vector<double> gaussian_kernel(double sigma) {
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  std::vector<double> kernel(2 * static_cast<std::size_t>(radius) + 1);
  double sum = 0.0;
  for (int d = -radius; d <= radius; ++d) sum += kernel[d + radius] = std::exp(-0.5 * d * d / (sigma * sigma));
  for (double& w : kernel) w /= sum;
  return kernel;
}

//! Convolves every line of \p in along \p axis with \p kernel into \p out.
void blur_axis(const ScalarGrid& in, int axis, const std::vector<double>& kernel, std::vector<float>& out) {
  const int radius = static_cast<int>(kernel.size() / 2);
  const int n = in.size[axis];
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  const std::size_t stride = axis == 0 ? 1 : axis == 1 ? static_cast<std::size_t>(in.size[0])
                                                        : static_cast<std::size_t>(in.size[0]) * in.size[1];
  const int lines = in.size[a1] * in.size[a2];
  parallel::parallel_for(tbb::blocked_range<int>(0, lines, 64), [&](const tbb::blocked_range<int>& range) {
    for (int line = range.begin(); line < range.end(); ++line) {
      int index[3];
      index[axis] = 0;
      index[a1] = line % in.size[a1];
      index[a2] = line / in.size[a1];
      const std::size_t start = in.index(index[0], index[1], index[2]);
      for (int x = 0; x < n; ++x) {
        double sum = 0.0;
        for (int d = -radius; d <= radius; ++d)
          sum += kernel[d + radius] * in.values[start + stride * static_cast<std::size_t>(std::clamp(x + d, 0, n - 1))];
        out[start + stride * static_cast<std::size_t>(x)] = static_cast<float>(sum);
      }
    }
  });
}

}  // namespace

ScalarGrid gaussian_blur(const ScalarGrid& grid, double sigma) {
  if (!(std::isfinite(sigma) && sigma >= 0.0 && sigma <= 100.0))
    throw InputError("grid blur: sigma must be in [0, 100] samples");
  if (sigma == 0.0) return grid;
  const std::vector<double> kernel = gaussian_kernel(sigma);
  ScalarGrid result = grid;
  ScalarGrid scratch = grid;
  for (int axis = 0; axis < 3; ++axis) {
    blur_axis(result, axis, kernel, scratch.values);
    std::swap(result.values, scratch.values);
  }
  return result;
}

}  // namespace mvflow
