#include "stages/flow/surface_patch.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace mvflow {

void surface_patch_frame(const Eigen::Vector3d& N, Eigen::Vector3d& t1, Eigen::Vector3d& t2) {
  const Eigen::Vector3d helper = std::abs(N.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  t1 = N.cross(helper).normalized();
  t2 = N.cross(t1);
}

void layout_surface_patch(const Eigen::Vector3d& X, const Eigen::Vector3d& N, std::span<const std::uint16_t> view_ids,
                          const std::vector<PhotoView>& views, int half_patch, double spacing_in_pixels,
                          SurfacePatchLayout& layout) {
  layout.half_patch = half_patch;
  layout.views.clear();
  layout.offsets.clear();
  layout.bounds.clear();
  // The spacing: spacing_in_pixels sides of the finest visible view's pixel at X (its footprint
  // on a surface facing it).
  double spacing = std::numeric_limits<double>::infinity();
  for (const std::uint16_t id : view_ids) {
    const Projection p = views[id].project(X);
    if (p.depth > 0) spacing = std::min(spacing, p.depth / views[id].camera->focal_pixels());
  }
  if (!std::isfinite(spacing)) return;
  spacing *= spacing_in_pixels;
  Eigen::Vector3d t1, t2;
  surface_patch_frame(N, t1, t2);
  for (const std::uint16_t id : view_ids) {
    const PhotoView& view = views[id];
    const Projection centre = view.project(X);
    if (!(centre.depth > 0)) continue;
    const std::size_t first = layout.offsets.size();
    float bounds[4] = {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                       std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
    bool finite = true;
    for (int b = -half_patch; b <= half_patch; ++b)
      for (int a = -half_patch; a <= half_patch; ++a) {
        const Projection p = view.project(X + spacing * (a * t1 + b * t2));
        const float du = static_cast<float>(p.u - centre.u), dv = static_cast<float>(p.v - centre.v);
        finite = finite && std::isfinite(du) && std::isfinite(dv);
        layout.offsets.push_back(du);
        layout.offsets.push_back(dv);
        bounds[0] = std::min(bounds[0], du), bounds[1] = std::max(bounds[1], du);
        bounds[2] = std::min(bounds[2], dv), bounds[3] = std::max(bounds[3], dv);
      }
    if (!finite) {
      layout.offsets.resize(first);
      continue;
    }
    layout.views.push_back(id);
    layout.bounds.insert(layout.bounds.end(), bounds, bounds + 4);
  }
}

namespace {

// Four floats: one pixel's RGB and a lane carried along (the next pixel's R), so that a point's
// bilinear read is three 4-wide interpolations instead of nine scalar ones. Each lane computes
// exactly the scalar formula (h = a + fx·(b − a), C = h + fy·(h' − h)).
using Float4 = float __attribute__((vector_size(16)));

Float4 load4(const float* p) {
  Float4 f;
  std::memcpy(&f, p, sizeof f);
  return f;
}

}  // namespace

PhotoValue surface_patch_consistency(const Eigen::Vector3d& X, const SurfacePatchLayout& layout,
                                     const std::vector<PhotoView>& views) {
  const int points = (2 * layout.half_patch + 1) * (2 * layout.half_patch + 1);
  const int count = 3 * points;
  // Per patch value Σ_i C and Σ_i C² (independent sums, so the loops vectorize), in double.
  double sum[detail::kMaxPatchValues], squares[detail::kMaxPatchValues];
  std::fill_n(sum, count, 0.0);
  std::fill_n(squares, count, 0.0);
  float patch[detail::kMaxPatchValues + 1];  // + 1: the last point's fourth lane
  int used = 0;
  for (std::size_t k = 0; k < layout.views.size(); ++k) {
    const PhotoView& view = views[layout.views[k]];
    const Projection centre = view.project(X);
    if (!(centre.depth > 0)) continue;
    const float* offset = layout.offsets.data() + k * 2 * static_cast<std::size_t>(points);
    // Every point with its 2×2 support inside the image, 0 ≤ u < W − 1 and 0 ≤ v < H − 1, tested
    // on the offsets' bounds: rounding is monotone, so min_i (u + du_i) is u + min_i du_i exactly.
    const float* bounds = layout.bounds.data() + 4 * k;
    if (!(centre.u + bounds[0] >= 0 && centre.u + bounds[1] < view.width - 1 && centre.v + bounds[2] >= 0 &&
          centre.v + bounds[3] < view.height - 1))
      continue;
    const std::size_t stride = static_cast<std::size_t>(view.width) * 3;
    const float* image = view.image->data();
    const float* last_float = image + stride * static_cast<std::size_t>(view.height) - 1;
    for (int i = 0; i < points; ++i) {
      const double u = centre.u + offset[2 * i], v = centre.v + offset[2 * i + 1];
      const int x0 = static_cast<int>(u), y0 = static_cast<int>(v);  // ≥ 0: the floor
      const float fx = static_cast<float>(u - x0), fy = static_cast<float>(v - y0);
      const float* top = image + static_cast<std::size_t>(y0) * stride + static_cast<std::size_t>(x0) * 3;
      const float* bottom = top + stride;
      if (bottom + 6 > last_float) {  // the 4-wide read of the image's last pixel would leave it
        for (int c = 0; c < 3; ++c) {
          const float upper = top[c] + fx * (top[c + 3] - top[c]);
          const float lower = bottom[c] + fx * (bottom[c + 3] - bottom[c]);
          patch[3 * i + c] = upper + fy * (lower - upper);
        }
        continue;
      }
      const Float4 upper = load4(top) + fx * (load4(top + 3) - load4(top));
      const Float4 lower = load4(bottom) + fx * (load4(bottom + 3) - load4(bottom));
      const Float4 value = upper + fy * (lower - upper);
      std::memcpy(patch + 3 * i, &value, sizeof value);
    }
    for (int j = 0; j < count; ++j) {
      const double value = patch[j];
      sum[j] += value;
      squares[j] += value * value;
    }
    ++used;
  }
  PhotoValue result;
  result.views = used;
  if (used < 2) return result;
  const double m = used;
  double total = 0.0;
  for (int j = 0; j < count; ++j) total += squares[j] - sum[j] * sum[j] / m;
  // Rounding can leave a tiny negative variance where all views agree; g is a variance sum.
  result.g = std::max(0.0, total / ((m - 1) * points));
  return result;
}

PhotoValue photo_consistency_at_surface(const Eigen::Vector3d& X, const Eigen::Vector3d& N,
                                        std::span<const std::uint16_t> view_ids, const std::vector<PhotoView>& views,
                                        const PhotoConsistencyOptions& options, SurfacePatchLayout& layout) {
  if (!options.surface_patch) return photo_consistency(X, view_ids, views, options);
  layout_surface_patch(X, N, view_ids, views, options.half_patch, options.surface_patch_spacing, layout);
  return surface_patch_consistency(X, layout, views);
}

}  // namespace mvflow
