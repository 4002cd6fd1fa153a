#pragma once
// Three small valid views (no distortion, radial, OpenCV) for the COLMAP targets' fixed partner
// files and for the seed corpora (make_seeds.cpp).

#include <Eigen/Geometry>
#include <vector>

#include "engine/model/camera.h"

namespace mvflow::fuzz {

inline std::vector<View> sample_views() {
  Eigen::Matrix3d K;
  K << 500, 0, 319.5, 0, 510, 239.5, 0, 0, 1;
  const Distortion radial{DistortionModel::Radial, {-0.1, 0.01, 0.0, 0.0}};
  const Distortion opencv{DistortionModel::OpenCV, {-0.1, 0.01, 0.001, -0.002}};
  std::vector<View> views;
  const Distortion distortions[] = {Distortion{}, radial, opencv};
  for (int i = 0; i < 3; ++i) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Vector3d t(0.1 * i, -0.2, 2.0 + i);
    views.push_back({Camera(K, R, t, 640, 480, distortions[i]), "view0" + std::to_string(i) + ".png"});
  }
  return views;
}

}  // namespace mvflow::fuzz
