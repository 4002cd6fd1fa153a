#pragma once
// Axis-aligned bounding box.

#include <Eigen/Core>
#include <limits>

namespace mvflow {

struct BoundingBox {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d max = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());

  bool is_empty() const { return !(min.array() <= max.array()).all(); }
  void extend(const Eigen::Vector3d& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  Eigen::Vector3d centre() const { return 0.5 * (min + max); }
  Eigen::Vector3d size() const { return max - min; }
  double diagonal() const { return is_empty() ? 0.0 : size().norm(); }
};

}  // namespace mvflow
