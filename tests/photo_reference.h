#pragma once
// The double-precision reference of SPEC §3's photo consistency, for the tests that hold the
// photo kernel (float interpolation, float sums on shifted data) to its bounds.

#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/model/camera.h"
#include "engine/model/image.h"
#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_gradient.h"

namespace mvflow::test {

inline std::vector<const Image*> pointers(const std::vector<Image>& images) {
  std::vector<const Image*> result;
  for (const auto& image : images) result.push_back(&image);
  return result;
}

// The slow reference: every sample bilinear-interpolated on its own in double, variances by the
// two-pass formula (mean first), straight from SPEC §3; patch (2h+1)².
inline PhotoValue slow_photo_consistency(const Eigen::Vector3d& X, const std::vector<Camera>& cameras,
                                         const std::vector<Image>& images, const std::vector<std::uint16_t>& ids,
                                         int h = 2) {
  std::vector<std::vector<double>> patches;  // per usable view: 3·(2h+1)² values
  for (auto id : ids) {
    const Projection p = cameras[id].project(X);
    const int W = cameras[id].width(), H = cameras[id].height();
    if (p.depth <= 0 || p.u < h || p.v < h || p.u >= W - h - 1 || p.v >= H - h - 1) continue;
    std::vector<double> patch;
    for (int dy = -h; dy <= h; ++dy)
      for (int dx = -h; dx <= h; ++dx) {
        const double u = p.u + dx, v = p.v + dy;
        const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
        const double a = u - x0, b = v - y0;
        for (int c = 0; c < 3; ++c)
          patch.push_back((1 - a) * (1 - b) * images[id].pixel(x0, y0)[c] + a * (1 - b) * images[id].pixel(x0 + 1, y0)[c] +
                          (1 - a) * b * images[id].pixel(x0, y0 + 1)[c] + a * b * images[id].pixel(x0 + 1, y0 + 1)[c]);
      }
    patches.push_back(patch);
  }
  PhotoValue result;
  result.views = static_cast<int>(patches.size());
  if (patches.size() < 2) return result;
  const double m = static_cast<double>(patches.size());
  const double offsets = (2 * h + 1) * (2 * h + 1);
  double g = 0;
  for (std::size_t k = 0; k < patches.front().size(); ++k) {
    double mean = 0;
    for (const auto& p : patches) mean += p[k] / m;
    double variance = 0;
    for (const auto& p : patches) variance += (p[k] - mean) * (p[k] - mean) / (m - 1);
    g += variance / offsets;
  }
  result.g = g;
  return result;
}

//! ∇g at \p X by \p stage's Savitzky–Golay sum over the slow reference at its samples, spaced \p dx.
inline Eigen::Vector3d slow_photo_gradient(const PhotoGradientStage& stage, const Eigen::Vector3d& X, double dx,
                                           const std::vector<Camera>& cameras, const std::vector<Image>& images,
                                           const std::vector<std::uint16_t>& ids) {
  Eigen::Vector3d gradient;
  for (int axis = 0; axis < 3; ++axis) {
    double derivative = 0;
    for (int k = -10; k <= 10; ++k) {
      Eigen::Vector3d sample = X;
      sample[axis] += k * dx;
      derivative += stage.coefficients()[k + 10] * slow_photo_consistency(sample, cameras, images, ids).g;
    }
    gradient[axis] = derivative / dx;
  }
  return gradient;
}

}  // namespace mvflow::test
