#include "stages/eval/point_colouring.h"

#include <cmath>
#include <numbers>

#include "engine/model/error.h"
#include "engine/model/option_check.h"

namespace mvflow {

void PointColouringOptions::check() const {
  require_option(max_angle_degrees > 0 && max_angle_degrees <= 90, "max_angle_degrees", max_angle_degrees, "(0, 90]");
  require_option(ray_offset >= 0, "ray_offset", ray_offset, ">= 0");
}

PointColour colour_surface_point(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                                 const std::vector<PhotoView>& views, const SurfaceQuery& surface,
                                 double mean_edge, const PointColouringOptions& options) {
  options.check();
  const double cos_max = std::cos(options.max_angle_degrees * std::numbers::pi / 180.0);
  const Eigen::Vector3d origin = point + options.ray_offset * mean_edge * normal;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  PointColour result;
  for (const PhotoView& view : views) {
    const Projection p = view.project(point);
    // Bilinear support inside the image (Image::sample_bilinear's precondition).
    if (!(p.depth > 0) || !(p.u >= 0 && p.v >= 0 && p.u <= view.width - 1 && p.v <= view.height - 1))
      continue;
    const Eigen::Vector3d to_camera = view.camera->centre() - point;
    if (!(normal.dot(to_camera) > cos_max * to_camera.norm())) continue;
    if (surface.occluded(origin, view.camera->centre() - origin, 0.0, 1.0)) continue;
    sum += view.image->sample_bilinear(p.u, p.v).cast<double>();
    ++result.views;
  }
  if (result.views > 0) result.colour = (sum / result.views).cast<float>();
  return result;
}

}  // namespace mvflow
