#include "stages/flow/photo_consistency.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "stages/flow/photo_kernel.h"
#include "stages/flow/photo_robust.h"
#include "stages/flow/surface_patch.h"

namespace mvflow {

const char* to_string(SurfacePatchUse use) {
  switch (use) {
    case SurfacePatchUse::Off: return "off";
    case SurfacePatchUse::Oblique: return "oblique";
    case SurfacePatchUse::On: return "on";
  }
  return "?";
}

SurfacePatchUse surface_patch_use_from_string(std::string_view name) {
  for (const SurfacePatchUse use : {SurfacePatchUse::Off, SurfacePatchUse::Oblique, SurfacePatchUse::On})
    if (name == to_string(use)) return use;
  throw InputError("surface patch: expected off, oblique or on, got '" + std::string(name) + "'");
}

void PhotoConsistencyOptions::check() const {
  require_option(half_patch >= 1 && half_patch <= 7, "half_patch", half_patch, "[1, 7]");
  require_option(noise_floor >= 0 && noise_floor <= 1, "noise_floor", noise_floor, "[0, 1]");
  require_option(drop_views >= 0 && drop_views <= 64, "drop_views", drop_views, "[0, 64]");
  require_option(min_views >= 2 && min_views <= 1000, "min_views", min_views, "[2, 1000]");
  require_option(surface_patch_spacing > 0 && surface_patch_spacing <= 8, "surface_patch_spacing",
                 surface_patch_spacing, "(0, 8]");
  require_option(surface_patch_angle_degrees > 0 && surface_patch_angle_degrees <= 90, "surface_patch_angle_degrees",
                 surface_patch_angle_degrees, "(0, 90]");
  require_option(!(surface_patch == SurfacePatchUse::On && normalize), "surface_patch", to_string(surface_patch),
                 "off or oblique when normalize is on");
}

namespace detail {

bool read_patch(const PhotoView& view, const Eigen::Vector3d& X, int h, float* out) {
  const Projection p = view.project(X);
  if (!(p.depth > 0) || !view.patch_inside(p.u, p.v, h)) return false;
  const int side = 2 * h + 1;
  const int width = 3 * side;
  const int x0 = static_cast<int>(std::floor(p.u));
  const int y0 = static_cast<int>(std::floor(p.v));
  // One pair of weights serves the whole patch: the offsets are whole pixels.
  const float fx = static_cast<float>(p.u - x0), fy = static_cast<float>(p.v - y0);
  const std::size_t stride = static_cast<std::size_t>(view.width) * 3;
  const float* row = view.image->data() + static_cast<std::size_t>(y0 - h) * stride + static_cast<std::size_t>(x0 - h) * 3;
  // A patch row is 3·side contiguous floats, read at two horizontal offsets (0 and 3 = the next
  // pixel): loops the compiler vectorizes.
  std::array<float, 3 * 15> top, bottom;
  for (int j = 0; j < width; ++j) top[j] = row[j] + fx * (row[j + 3] - row[j]);
  for (int r = 0; r < side; ++r) {
    row += stride;
    for (int j = 0; j < width; ++j) bottom[j] = row[j] + fx * (row[j + 3] - row[j]);
    for (int j = 0; j < width; ++j) out[r * width + j] = top[j] + fy * (bottom[j] - top[j]);
    top = bottom;
  }
  return true;
}

PatchVariance::PatchVariance(int half_patch) : side_(2 * half_patch + 1), count_(3 * side_ * side_) {
  std::fill_n(sum_, count_, 0.0);
}

void PatchVariance::add(const float* patch) {
  ++views_;
  for (int k = 0; k < count_; ++k) {
    const double value = patch[k];
    sum_[k] += value;
    squares_ += value * value;
  }
}

PhotoValue PatchVariance::finish() const {
  PhotoValue result;
  result.views = views_;
  if (views_ < 2) return result;
  const double m = views_;
  double sum_squared = 0.0;
  for (int k = 0; k < count_; ++k) sum_squared += sum_[k] * sum_[k];
  // Rounding can leave a tiny negative variance where all views agree; g is a variance sum.
  result.g = std::max(0.0, (squares_ - sum_squared / m) / ((m - 1) * (side_ * side_)));
  return result;
}

}  // namespace detail

namespace {

// g for any patch size (the default 5×5 has its own kernel, stages/flow/photo_kernel.h) with the same
// arithmetic: the patch values of detail::read_patch, summed in double by detail::PatchVariance.
PhotoValue photo_consistency_any(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                                 const std::vector<PhotoView>& views, int h) {
  detail::PatchVariance variance(h);
  float patch[detail::kMaxPatchValues];
  for (const std::uint16_t id : view_ids)
    if (detail::read_patch(views[id], X, h, patch)) variance.add(patch);
  return variance.finish();
}

}  // namespace

PhotoValue photo_consistency(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                             const std::vector<PhotoView>& views, const PhotoConsistencyOptions& options) {
  if (options.normalize) {
    std::vector<ViewGainBias> maps;
    gain_bias_at(X, view_ids, views, options.half_patch, options.noise_floor, maps);
    return normalized_photo_consistency(X, view_ids, maps, views, options.half_patch);
  }
  if (options.half_patch == 2) return detail::photo_consistency_5x5(X, view_ids, views);
  return photo_consistency_any(X, view_ids, views, options.half_patch);
}

void compute_photo_consistency(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                               const PhotoConsistencyOptions& options, VertexFields& fields,
                               const std::vector<PhotoView>* surface_views) {
  options.check();
  SurfacePatchLayout layout;
  const std::vector<PhotoView>& laid = surface_views ? *surface_views : views;
  for (std::uint32_t v = vertices.begin; v < vertices.end; ++v) {
    const Eigen::Vector3d X = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
    const PhotoValue value = photo_consistency_at_surface(X, fields.normal[v], fields.visible(v), views, laid, options, layout);
    fields.photo_consistency[v] = value.defined() ? value.g : 0.0;
    if (value.defined())
      fields.defined[v] |= kPhotoDefined;
    else
      fields.defined[v] &= static_cast<std::uint8_t>(~kPhotoDefined);
  }
}

}  // namespace mvflow
