// The Camera model itself: projection against the plain 3×4 matrix, the inverse ray, and the
// distortion models against their formulas.

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "engine/model/camera.h"
#include "engine/model/error.h"

namespace mvflow {
namespace {

Camera test_camera(Distortion distortion = {}) {
  Eigen::Matrix3d K;
  K << 800, 1.5, 321.25, 0, 790, 239.75, 0, 0, 1;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  return Camera(K, R, Eigen::Vector3d(0.1, -0.2, 4.0), 640, 480, distortion);
}

const std::vector<Eigen::Vector3d> kPoints{{0, 0, 0}, {0.3, -0.2, 0.1}, {-0.5, 0.4, -0.3}, {1.0, 0.9, 0.5}};

TEST(Camera, ProjectionEqualsHomogeneousMatrixProduct) {
  const Camera camera = test_camera();
  for (const auto& X : kPoints) {
    const Eigen::Vector3d x = camera.K() * (camera.R() * X + camera.t());
    const Projection p = camera.project(X);
    EXPECT_NEAR(p.u, x.x() / x.z(), 1e-9);
    EXPECT_NEAR(p.v, x.y() / x.z(), 1e-9);
    EXPECT_NEAR(p.depth, x.z(), 1e-12);
    const Eigen::Vector4d h(X.x(), X.y(), X.z(), 1.0);
    const Eigen::Vector3d y = camera.projection_matrix() * h;
    EXPECT_NEAR(p.u, y.x() / y.z(), 1e-9);
  }
}

TEST(Camera, CentreIsMinusRTransposeT) {
  const Camera camera = test_camera();
  EXPECT_TRUE(camera.centre().isApprox(-camera.R().transpose() * camera.t(), 1e-14));
  EXPECT_NEAR((camera.R() * camera.centre() + camera.t()).norm(), 0.0, 1e-12);
}

TEST(Camera, RayThroughProjectionHitsThePoint) {
  for (const Distortion& d : {Distortion{}, Distortion{DistortionModel::Radial, {-0.2, 0.05, 0, 0}},
                              Distortion{DistortionModel::OpenCV, {-0.1, 0.02, 0.001, -0.002}},
                              Distortion{DistortionModel::InverseRadial, {0.15, -0.03, 0, 0}}}) {
    const Camera camera = test_camera(d);
    for (const auto& X : kPoints) {
      const Projection p = camera.project(X);
      const Ray ray = camera.ray(p.u, p.v);
      EXPECT_NEAR(ray.direction.norm(), 1.0, 1e-12);
      const Eigen::Vector3d to_point = X - ray.origin;
      // The point lies on the ray: no component orthogonal to the direction.
      EXPECT_NEAR((to_point - to_point.dot(ray.direction) * ray.direction).norm(), 0.0, 1e-9);
      EXPECT_GT(to_point.dot(ray.direction), 0.0);
    }
  }
}

TEST(Distortion, RadialTangentialMatchesFormula) {
  const Distortion d{DistortionModel::OpenCV, {-0.1, 0.02, 0.001, -0.002}};
  const double x = 0.2, y = -0.15, r2 = x * x + y * y;
  const double radial = 1 - 0.1 * r2 + 0.02 * r2 * r2;
  const Eigen::Vector2d expected(x * radial + 2 * 0.001 * x * y + -0.002 * (r2 + 2 * x * x),
                                 y * radial + 0.001 * (r2 + 2 * y * y) + 2 * -0.002 * x * y);
  EXPECT_LT((d.distort({x, y}) - expected).norm(), 1e-15);
  EXPECT_LT((d.undistort(d.distort({x, y})) - Eigen::Vector2d(x, y)).norm(), 1e-12);
}

TEST(Distortion, InverseRadialUndistortsByTheThesisFormula) {
  // Thesis eq. 2.6/2.7: the true point is the distorted one times (1 + k1 r² + k2 r⁴), r = |d|.
  const Distortion d{DistortionModel::InverseRadial, {0.15, -0.03, 0, 0}};
  const Eigen::Vector2d distorted(0.25, 0.1);
  const double r2 = distorted.squaredNorm();
  EXPECT_LT((d.undistort(distorted) - distorted * (1 + 0.15 * r2 - 0.03 * r2 * r2)).norm(), 1e-15);
  EXPECT_LT((d.distort(d.undistort(distorted)) - distorted).norm(), 1e-12);
}

TEST(Camera, RejectsInvalidParameters) {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  EXPECT_THROW(Camera(K, 2 * Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 10, 10), InputError);
  K(2, 0) = 1;
  EXPECT_THROW(Camera(K, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 10, 10), InputError);
  EXPECT_THROW(Camera(Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(),
                      Eigen::Vector3d(0, std::nan(""), 0), 10, 10),
               InputError);
  EXPECT_THROW(Camera(Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), -1, 10),
               InputError);
}

TEST(Camera, InImageUsesPixelCentreConvention) {
  const Camera camera = test_camera();
  EXPECT_TRUE(camera.in_image(-0.5, -0.5));
  EXPECT_TRUE(camera.in_image(639.49, 479.49));
  EXPECT_FALSE(camera.in_image(639.5, 10));
  EXPECT_FALSE(camera.in_image(10, -0.51));
}

}  // namespace
}  // namespace mvflow
