#include "stages/synth/synth_cameras.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "engine/model/error.h"
#include "engine/model/option_check.h"

namespace mvflow {

namespace {

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

Eigen::Vector3d direction(double azimuth, double elevation) {
  return {std::cos(elevation) * std::sin(azimuth), std::sin(elevation), std::cos(elevation) * std::cos(azimuth)};
}

}  // namespace

void RigOptions::check() const {
  require_option(views >= 1 && views <= 1000, "views", views, "[1, 1000]");
  require_option(distance > 1.0 && distance < 1e6, "distance", distance, "(1, 1e6) object radii");
  require_option(elevation_min >= -85 && elevation_min <= elevation_max, "elevation_min", elevation_min,
                 "[-85, elevation_max] degrees");
  require_option(elevation_max <= 85, "elevation_max", elevation_max, "<= 85 degrees");
  require_option(width >= 8 && width <= 8192, "width", width, "[8, 8192] pixels");
  require_option(height >= 8 && height <= 8192, "height", height, "[8, 8192] pixels");
  if (focal == 0.0)
    require_option(fov >= 1 && fov <= 170, "fov", fov, "[1, 170] degrees");
  else
    require_option(focal > 0 && std::isfinite(focal), "focal", focal, "0 (from fov) or > 0 pixels");
}

double RigOptions::focal_pixels() const {
  return focal > 0 ? focal : 0.5 * width / std::tan(0.5 * radians(fov));
}

Camera look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up, double focal,
               int width, int height) {
  const Eigen::Vector3d forward = (target - eye).normalized();
  const Eigen::Vector3d right = forward.cross(up).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  MVFLOW_CHECK(right.allFinite(), "look_at: the up vector is parallel to the viewing direction");
  Eigen::Matrix3d R;
  R.row(0) = right.transpose();  // camera x: image u, to the right
  R.row(1) = down.transpose();   // camera y: image v, downwards
  R.row(2) = forward.transpose();
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  K(0, 0) = K(1, 1) = focal;
  K(0, 2) = 0.5 * (width - 1);  // pixel (0,0) is a pixel centre (SPEC §2)
  K(1, 2) = 0.5 * (height - 1);
  return Camera(K, R, -R * eye, width, height);
}

std::vector<View> make_rig(const RigOptions& options, const Eigen::Vector3d& centre, double radius) {
  options.check();
  MVFLOW_CHECK(radius > 0, "make_rig: the radius must be positive");
  const int n = options.views;
  const double lo = radians(options.elevation_min), hi = radians(options.elevation_max);
  std::vector<View> views;
  views.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    double azimuth = 0.0, elevation = 0.0;
    if (options.kind == RigKind::Ring) {
      azimuth = 2.0 * std::numbers::pi * i / n;
      elevation = (n == 1 || i % 2 == 0) ? lo : hi;
    } else {
      // Equal-area spiral: sin(elevation) uniform over the band, azimuth by the golden angle.
      const double s = std::sin(lo) + (std::sin(hi) - std::sin(lo)) * (i + 0.5) / n;
      elevation = std::asin(s);
      azimuth = i * std::numbers::pi * (3.0 - std::sqrt(5.0));
    }
    const Eigen::Vector3d eye = centre + options.distance * radius * direction(azimuth, elevation);
    views.push_back({look_at(eye, centre, Eigen::Vector3d::UnitY(), options.focal_pixels(), options.width,
                             options.height),
                     synth_image_name(static_cast<std::size_t>(i))});
  }
  return views;
}

std::string synth_image_name(std::size_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "view_%03zu.png", index);
  return name;
}

}  // namespace mvflow
