#pragma once
// The double-precision reference of SPEC §3's photo consistency, for the tests that hold the
// photo kernel (float interpolation, float sums on shifted data) to its bounds.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/model/camera.h"
#include "engine/model/image.h"
#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_gradient.h"
#include "stages/flow/surface_patch.h"

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

//! ∇g at \p X by \p stage's Savitzky–Golay sum over \p g_at (a point → g) at its samples, spaced \p dx.
template <typename GAt>
Eigen::Vector3d savitzky_golay_gradient(const PhotoGradientStage& stage, const Eigen::Vector3d& X, double dx,
                                        GAt g_at) {
  Eigen::Vector3d gradient;
  for (int axis = 0; axis < 3; ++axis) {
    double derivative = 0;
    for (int k = -10; k <= 10; ++k) {
      Eigen::Vector3d sample = X;
      sample[axis] += k * dx;
      derivative += stage.coefficients()[k + 10] * g_at(sample);
    }
    gradient[axis] = derivative / dx;
  }
  return gradient;
}

//! ∇g at \p X by \p stage's Savitzky–Golay sum over the slow reference at its samples, spaced \p dx.
inline Eigen::Vector3d slow_photo_gradient(const PhotoGradientStage& stage, const Eigen::Vector3d& X, double dx,
                                           const std::vector<Camera>& cameras, const std::vector<Image>& images,
                                           const std::vector<std::uint16_t>& ids) {
  return savitzky_golay_gradient(stage, X, dx, [&](const Eigen::Vector3d& sample) {
    return slow_photo_consistency(sample, cameras, images, ids).g;
  });
}

// The slow reference of the surface patch at X with the laid-out patch: per laid-out view, X
// projected by its camera, each point at that projection plus its layout offset, read bilinearly
// in double; a view counts when every point's 2×2 support lies in the image (positions rounded as
// the kernel's); variances by the two-pass formula.
inline PhotoValue slow_surface_patch_consistency(const Eigen::Vector3d& X, const SurfacePatchLayout& layout,
                                                 const std::vector<Camera>& cameras, const std::vector<Image>& images) {
  std::vector<std::vector<double>> patches;
  for (std::size_t k = 0; k < layout.views.size(); ++k) {
    const std::uint16_t id = layout.views[k];
    const Projection centre = cameras[id].project(X);
    if (!(centre.depth > 0)) continue;
    const int W = cameras[id].width(), H = cameras[id].height();
    std::vector<double> patch;
    bool inside = true;
    for (int i = 0; i < layout.points && inside; ++i) {
      const std::size_t e = k * static_cast<std::size_t>(layout.padded_points) + static_cast<std::size_t>(i);
      const double u = centre.u + layout.du[e], v = centre.v + layout.dv[e];
      // Inside as the kernel decides it, from its float positions (surface_patch.h): at an image's
      // border the double position may fall a rounding the other side.
      const double x_inside = std::floor(centre.u) + std::floor(static_cast<float>(centre.u - std::floor(centre.u)) + layout.du[e]);
      const double y_inside = std::floor(centre.v) + std::floor(static_cast<float>(centre.v - std::floor(centre.v)) + layout.dv[e]);
      inside = x_inside >= 0 && y_inside >= 0 && x_inside + 1 <= W - 1 && y_inside + 1 <= H - 1;
      if (!inside) break;
      const int x0 = std::clamp(static_cast<int>(std::floor(u)), 0, W - 2), y0 = std::clamp(static_cast<int>(std::floor(v)), 0, H - 2);
      const double a = u - x0, b = v - y0;
      for (int c = 0; c < 3; ++c)
        patch.push_back((1 - a) * (1 - b) * images[id].pixel(x0, y0)[c] + a * (1 - b) * images[id].pixel(x0 + 1, y0)[c] +
                        (1 - a) * b * images[id].pixel(x0, y0 + 1)[c] + a * b * images[id].pixel(x0 + 1, y0 + 1)[c]);
    }
    if (inside) patches.push_back(patch);
  }
  PhotoValue result;
  result.views = static_cast<int>(patches.size());
  if (patches.size() < 2) return result;
  const double m = static_cast<double>(patches.size());
  double g = 0;
  for (std::size_t k = 0; k < patches.front().size(); ++k) {
    double mean = 0;
    for (const auto& p : patches) mean += p[k] / m;
    for (const auto& p : patches) g += (p[k] - mean) * (p[k] - mean) / (m - 1) / layout.points;
  }
  result.g = g;
  return result;
}

//! ∇g at \p X as slow_photo_gradient, over slow_surface_patch_consistency with \p layout.
inline Eigen::Vector3d slow_surface_patch_gradient(const PhotoGradientStage& stage, const Eigen::Vector3d& X, double dx,
                                                   const SurfacePatchLayout& layout, const std::vector<Camera>& cameras,
                                                   const std::vector<Image>& images) {
  return savitzky_golay_gradient(stage, X, dx, [&](const Eigen::Vector3d& sample) {
    return slow_surface_patch_consistency(sample, layout, cameras, images).g;
  });
}

}  // namespace mvflow::test
