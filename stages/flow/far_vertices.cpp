#include "stages/flow/far_vertices.h"

#include <cmath>
#include <numbers>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "stages/flow/speed.h"  // median_g_where

namespace mvflow {

void FarVertexOptions::check() const {
  require_option(g_ratio == 0.0 || (g_ratio > 1.0 && std::isfinite(g_ratio)), "g_ratio", g_ratio,
                 "0 (off) or > 1 and finite");
  require_option(view_angle_degrees > 0.0 && view_angle_degrees <= 90.0, "view_angle_degrees", view_angle_degrees,
                 "(0, 90]");
  require_option(release > 0.0 && release <= 1.0, "release", release, "(0, 1]");
}

namespace {

// Whether one of v's visible views lies within the angle whose cosine is min_cos of its normal.
bool seen_frontally(const TriMesh& mesh, const std::vector<PhotoView>& views, const VertexFields& fields,
                    std::size_t v, double min_cos) {
  const Eigen::Vector3d X = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
  for (const std::uint16_t id : fields.visible(v)) {
    const Eigen::Vector3d to_camera = (views[id].camera->centre() - X).normalized();
    if (fields.normal[v].dot(to_camera) >= min_cos) return true;
  }
  return false;
}

}  // namespace

std::size_t update_far_vertices(const TriMesh& mesh, const std::vector<PhotoView>& views, const VertexFields& fields,
                                const FarVertexOptions& options, std::vector<std::uint8_t>& far) {
  const std::size_t n = mesh.n_vertices();
  MVFLOW_CHECK(fields.size() == n, "update_far_vertices: the fields are not sized for the mesh");
  if (far.size() != n) far.assign(n, 0);
  // With no near vertex with g the median is 0: no vertex becomes far and none is released (g ≥ 0).
  const double far_above =
      options.g_ratio * median_g_where(fields, [&](std::size_t v) { return (fields.defined[v] & kPhotoDefined) && !far[v]; });
  const double near_below = options.release * far_above;
  const double min_cos = std::cos(options.view_angle_degrees * std::numbers::pi / 180.0);
  std::size_t count = 0;
  for (std::size_t v = 0; v < n; ++v) {
    if (fields.defined[v] & kPhotoDefined) {
      const double g = fields.photo_consistency[v];
      if (far[v])
        far[v] = g < near_below ? 0 : 1;
      else if (far_above > 0.0 && g > far_above && seen_frontally(mesh, views, fields, v, min_cos))
        far[v] = 1;
    }
    count += far[v];
  }
  return count;
}

}  // namespace mvflow
