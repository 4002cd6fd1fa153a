#include "stages/flow/visibility.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "engine/model/error.h"
#include "engine/model/option_check.h"

namespace mvflow {

void VisibilityOptions::check() const {
  require_option(max_angle_degrees > 0 && max_angle_degrees <= 90, "max_angle_degrees", max_angle_degrees, "(0, 90]");
  require_option(preferred_angle_degrees > 0 && preferred_angle_degrees <= 90, "preferred_angle_degrees",
                 preferred_angle_degrees, "(0, 90]");
  require_option(min_views >= 2 && min_views <= 1000, "min_views", min_views, "[2, 1000]");
  require_option(half_patch >= 0, "half_patch", half_patch, ">= 0");
  require_option(ray_offset >= 0, "ray_offset", ray_offset, ">= 0");
  require_option(max_views == 0 || max_views >= 2, "max_views", max_views, "0 (all) or >= 2");
}

namespace {

// View selection among the \p count visible views in \p visible (view order), whose cosines to
// the normal are \p cosines: those within the preferred angle, topped up with the closest others
// to min_views, at most max_views (the closest first; the lower view index on a tie). Rewrites
// \p visible in view order; returns the count.
std::uint16_t select_views(const VisibilityOptions& options, double cos_preferred, const double* cosines,
                           std::uint16_t* visible, std::uint16_t count,
                           std::vector<std::pair<double, std::uint16_t>>& ranked) {
  const bool preferring = options.preferred_angle_degrees < options.max_angle_degrees;
  if (!preferring && (options.max_views == 0 || count <= options.max_views)) return count;
  ranked.clear();  // (−cos, view): the closest to the normal first
  for (std::uint16_t k = 0; k < count; ++k) ranked.emplace_back(-cosines[k], visible[k]);
  std::sort(ranked.begin(), ranked.end());
  std::size_t keep = ranked.size();
  if (preferring) {
    keep = 0;
    while (keep < ranked.size() && -ranked[keep].first > cos_preferred) ++keep;
    keep = std::max(keep, std::min(ranked.size(), static_cast<std::size_t>(options.min_views)));
  }
  if (options.max_views > 0) keep = std::min(keep, static_cast<std::size_t>(options.max_views));
  ranked.resize(keep);
  std::sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  for (std::size_t k = 0; k < keep; ++k) visible[k] = ranked[k].second;
  return static_cast<std::uint16_t>(keep);
}

}  // namespace

void compute_visibility(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                        const SurfaceQuery& surface, double mean_edge, const VisibilityOptions& options,
                        VertexFields& fields) {
  options.check();
  MVFLOW_CHECK(fields.view_capacity >= views.size(), "vertex fields sized for fewer views");
  const double cos_max = std::cos(options.max_angle_degrees * std::numbers::pi / 180.0);
  const double offset = options.ray_offset * mean_edge;
  const double cos_preferred = std::cos(options.preferred_angle_degrees * std::numbers::pi / 180.0);
  std::vector<std::pair<double, std::uint16_t>> ranked;
  std::vector<double> cosines(views.size());  // of the visible views, in their order
  for (std::uint32_t v = vertices.begin; v < vertices.end; ++v) {
    std::uint16_t* visible = fields.visible_views.data() + v * fields.view_capacity;
    std::uint16_t count = 0;
    if (fields.defined[v] & kNormalDefined) {
      const Eigen::Vector3d P = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
      const Eigen::Vector3d& N = fields.normal[v];
      const Eigen::Vector3d origin = P + offset * N;
      for (std::size_t i = 0; i < views.size(); ++i) {
        const PhotoView& view = views[i];
        // The cheapest test first (about half the views face away); all must pass.
        const Eigen::Vector3d to_camera = view.camera->centre() - P;
        const double distance = to_camera.norm();
        if (!(N.dot(to_camera) > cos_max * distance)) continue;
        const Projection p = view.project(P);
        if (!(p.depth > 0) || !view.patch_inside(p.u, p.v, options.half_patch)) continue;
        const Eigen::Vector3d from_origin = view.camera->centre() - origin;
        if (surface.occluded(origin, from_origin, 0.0, 1.0)) continue;
        cosines[count] = N.dot(to_camera) / distance;
        visible[count++] = static_cast<std::uint16_t>(i);
      }
      count = select_views(options, cos_preferred, cosines.data(), visible, count, ranked);
    }
    fields.visible_count[v] = count;
  }
}

}  // namespace mvflow
