#pragma once
// COLMAP's ImgFromCam for the five models mvflow reads, written from COLMAP's definitions
// (sensor/models.h), independent of io/: the tests' yardstick for COLMAP cameras, in COLMAP pixels.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace mvflow::test {

//! The COLMAP pixel of the normalised camera point (u, v) for \p model with \p p its parameters.
inline Eigen::Vector2d colmap_image_from_camera(const std::string& model, const std::vector<double>& p, double u,
                                                double v) {
  const double r2 = u * u + v * v;
  if (model == "SIMPLE_PINHOLE") return {p[0] * u + p[1], p[0] * v + p[2]};
  if (model == "PINHOLE") return {p[0] * u + p[2], p[1] * v + p[3]};
  if (model == "SIMPLE_RADIAL") {
    const double radial = p[3] * r2;
    return {p[0] * (u + u * radial) + p[1], p[0] * (v + v * radial) + p[2]};
  }
  if (model == "RADIAL") {
    const double radial = p[3] * r2 + p[4] * r2 * r2;
    return {p[0] * (u + u * radial) + p[1], p[0] * (v + v * radial) + p[2]};
  }
  // OPENCV
  const double k1 = p[4], k2 = p[5], p1 = p[6], p2 = p[7];
  const double radial = k1 * r2 + k2 * r2 * r2;
  const double du = u * radial + 2 * p1 * u * v + p2 * (r2 + 2 * u * u);
  const double dv = v * radial + 2 * p2 * u * v + p1 * (r2 + 2 * v * v);
  return {p[0] * (u + du) + p[2], p[1] * (v + dv) + p[3]};
}

}  // namespace mvflow::test
