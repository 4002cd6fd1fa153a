#include "stages/flow/surface_patch.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "engine/model/error.h"
#include "stages/flow/photo_kernel.h"

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
  layout.points = (2 * half_patch + 1) * (2 * half_patch + 1);
  layout.padded_points = (layout.points + kSurfacePatchLanes - 1) / kSurfacePatchLanes * kSurfacePatchLanes;
  layout.views.clear();
  layout.du.clear();
  layout.dv.clear();
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
  const auto padded = static_cast<std::size_t>(layout.padded_points);
  for (const std::uint16_t id : view_ids) {
    const PhotoView& view = views[id];
    // The kernel addresses an image's floats with 32-bit offsets (up to about 715 megapixels).
    MVFLOW_CHECK(static_cast<long long>(view.width) * view.height * 3 < std::numeric_limits<int>::max(),
                 "surface patches: an image of more than 2^31 floats");
    const Projection centre = view.project(X);
    if (!(centre.depth > 0)) continue;
    const std::size_t first = layout.du.size();
    layout.du.resize(first + padded, 0.0f);
    layout.dv.resize(first + padded, 0.0f);
    float bounds[4] = {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                       std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
    bool finite = true;
    std::size_t i = first;
    for (int b = -half_patch; b <= half_patch; ++b)
      for (int a = -half_patch; a <= half_patch; ++a, ++i) {
        const Projection p = view.project(X + spacing * (a * t1 + b * t2));
        const float du = static_cast<float>(p.u - centre.u), dv = static_cast<float>(p.v - centre.v);
        finite = finite && std::isfinite(du) && std::isfinite(dv);
        layout.du[i] = du;
        layout.dv[i] = dv;
        bounds[0] = std::min(bounds[0], du), bounds[1] = std::max(bounds[1], du);
        bounds[2] = std::min(bounds[2], dv), bounds[3] = std::max(bounds[3], dv);
      }
    if (!finite) {
      layout.du.resize(first);
      layout.dv.resize(first);
      continue;
    }
    // The padding repeats the last point: the kernel reads the padded points too (and does not
    // sum them), so they must lie inside the box the bounds test checks.
    std::fill(layout.du.begin() + static_cast<std::ptrdiff_t>(i), layout.du.end(), layout.du[i - 1]);
    std::fill(layout.dv.begin() + static_cast<std::ptrdiff_t>(i), layout.dv.end(), layout.dv[i - 1]);
    layout.views.push_back(id);
    layout.bounds.insert(layout.bounds.end(), bounds, bounds + 4);
  }
}

PhotoValue surface_patch_consistency(const Eigen::Vector3d& X, const SurfacePatchLayout& layout,
                                     const std::vector<PhotoView>& views) {
  return detail::active_photo_kernel().surface(X, layout, views);
}

void surface_patch_samples(const Eigen::Vector3d& X, double spacing, int half, const SurfacePatchLayout& layout,
                           const std::vector<PhotoView>& views, std::span<PhotoValue> samples) {
  MVFLOW_CHECK(samples.size() >= static_cast<std::size_t>(6 * half + 1), "surface_patch_samples: too few samples");
  detail::active_photo_kernel().surface_samples(X, spacing, half, layout, views, samples);
}

void detail::prefetch_surface_patches(const Eigen::Vector3d& X, const SurfacePatchLayout& layout,
                                      const std::vector<PhotoView>& views) {
  for (std::size_t k = 0; k < layout.views.size(); ++k) {
    const PhotoView& view = views[layout.views[k]];
    const Projection centre = view.project(X);
    if (!(centre.depth > 0)) continue;
    // The patch's box and its samples' reach (a pixel or two) on every side.
    const float* bounds = layout.bounds.data() + 4 * k;
    const double margin = 3;
    const double left = centre.u + bounds[0] - margin, right = centre.u + bounds[1] + margin;
    const double top = centre.v + bounds[2] - margin, bottom = centre.v + bounds[3] + margin;
    if (!(left >= 0 && top >= 0 && right <= view.width - 1 && bottom <= view.height - 1)) continue;
    prefetch_pixels(view, static_cast<int>(left), static_cast<int>(right), static_cast<int>(top), static_cast<int>(bottom));
  }
}

bool uses_surface_patch(const Eigen::Vector3d& X, const Eigen::Vector3d& N, std::span<const std::uint16_t> view_ids,
                        const std::vector<PhotoView>& views, const PhotoConsistencyOptions& options) {
  if (options.surface_patch == SurfacePatchUse::On) return true;
  // Without a normal no view is oblique: the image patch, as the flow's visibility has no views then.
  if (options.surface_patch == SurfacePatchUse::Off || options.normalize || !(N.squaredNorm() > 0)) return false;
  const double cos_oblique = std::cos(options.surface_patch_angle_degrees * std::numbers::pi / 180.0);
  for (const std::uint16_t id : view_ids) {
    const Eigen::Vector3d to_camera = views[id].camera->centre() - X;
    if (N.dot(to_camera) < cos_oblique * to_camera.norm()) return true;
  }
  return false;
}

PhotoValue photo_consistency_at_surface(const Eigen::Vector3d& X, const Eigen::Vector3d& N,
                                        std::span<const std::uint16_t> view_ids, const std::vector<PhotoView>& views,
                                        const PhotoConsistencyOptions& options, SurfacePatchLayout& layout) {
  return photo_consistency_at_surface(X, N, view_ids, views, views, options, layout);
}

PhotoValue photo_consistency_at_surface(const Eigen::Vector3d& X, const Eigen::Vector3d& N,
                                        std::span<const std::uint16_t> view_ids, const std::vector<PhotoView>& views,
                                        const std::vector<PhotoView>& surface_views,
                                        const PhotoConsistencyOptions& options, SurfacePatchLayout& layout) {
  if (!uses_surface_patch(X, N, view_ids, views, options)) return photo_consistency(X, view_ids, views, options);
  layout_surface_patch(X, N, view_ids, surface_views, options.half_patch, options.surface_patch_spacing, layout);
  return surface_patch_consistency(X, layout, surface_views);
}

}  // namespace mvflow
