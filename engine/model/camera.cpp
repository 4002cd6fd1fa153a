#include "engine/model/camera.h"

#include <Eigen/LU>
#include <cmath>

#include "engine/model/error.h"

namespace mvflow {

namespace {

bool all_finite(const auto& m) { return m.allFinite(); }

// Newton iterations for an invertible 2-D map f: solves f(x) = target from x = target.
template <class F>
Eigen::Vector2d invert_map(const F& f, const Eigen::Vector2d& target) {
  Eigen::Vector2d x = target;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Eigen::Vector2d residual = f(x) - target;
    if (residual.squaredNorm() < 1e-30) break;
    // Numerical Jacobian: the maps are smooth and cheap, and this path is not per-sample hot.
    constexpr double h = 1e-7;
    Eigen::Matrix2d J;
    J.col(0) = (f(x + Eigen::Vector2d(h, 0)) - f(x - Eigen::Vector2d(h, 0))) / (2 * h);
    J.col(1) = (f(x + Eigen::Vector2d(0, h)) - f(x - Eigen::Vector2d(0, h))) / (2 * h);
    x -= J.inverse() * residual;
  }
  return x;
}

Eigen::Vector2d radial_tangential(const Eigen::Vector2d& n, const std::array<double, 4>& c) {
  const double x = n.x(), y = n.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + c[0] * r2 + c[1] * r2 * r2;
  return {x * radial + 2 * c[2] * x * y + c[3] * (r2 + 2 * x * x),
          y * radial + c[2] * (r2 + 2 * y * y) + 2 * c[3] * x * y};
}

}  // namespace

bool Distortion::is_identity() const {
  return model == DistortionModel::None ||
         (coefficients[0] == 0 && coefficients[1] == 0 && coefficients[2] == 0 && coefficients[3] == 0);
}

Eigen::Vector2d Distortion::distort(const Eigen::Vector2d& n) const {
  switch (model) {
    case DistortionModel::None:
      return n;
    case DistortionModel::Radial:
      return radial_tangential(n, {coefficients[0], coefficients[1], 0.0, 0.0});
    case DistortionModel::OpenCV:
      return radial_tangential(n, coefficients);
    case DistortionModel::InverseRadial:
      return invert_map([this](const Eigen::Vector2d& d) { return undistort(d); }, n);
  }
  return n;
}

Eigen::Vector2d Distortion::undistort(const Eigen::Vector2d& d) const {
  switch (model) {
    case DistortionModel::None:
      return d;
    case DistortionModel::InverseRadial: {
      const double r2 = d.squaredNorm();
      return d * (1.0 + coefficients[0] * r2 + coefficients[1] * r2 * r2);
    }
    case DistortionModel::Radial:
    case DistortionModel::OpenCV:
      return invert_map([this](const Eigen::Vector2d& n) { return distort(n); }, d);
  }
  return d;
}

Camera::Camera(const Eigen::Matrix3d& K, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
               int width, int height, Distortion distortion)
    : K_(K), R_(R), t_(t), distortion_(distortion), width_(width), height_(height) {
  if (!all_finite(K) || !all_finite(R) || !all_finite(t))
    throw InputError("camera has a value that is not a finite number");
  if (K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0 || K(2, 2) != 1)
    throw InputError("camera intrinsics K must be upper triangular with K(2,2) = 1");
  if (K(0, 0) == 0 || K(1, 1) == 0) throw InputError("camera intrinsics K has a zero focal length");
  if (!(R * R.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0)
    throw InputError("camera rotation R is not a rotation (orthonormal with determinant +1)");
  if (width < 0 || height < 0) throw InputError("camera image size must not be negative");
  for (double c : distortion.coefficients)
    if (!std::isfinite(c)) throw InputError("camera distortion coefficient is not finite");
  K_inverse_ = K_.inverse();
  centre_ = -R_.transpose() * t_;
  P_.leftCols<3>() = K_ * R_;
  P_.col(3) = K_ * t_;
}

double Camera::focal_pixels() const { return std::sqrt(K_(0, 0) * K_(1, 1)); }

Projection Camera::project(const Eigen::Vector3d& X) const {
  const Eigen::Vector3d x = R_ * X + t_;
  Eigen::Vector2d d(x.x() / x.z(), x.y() / x.z());
  if (!distortion_.is_identity()) d = distortion_.distort(d);
  return {K_(0, 0) * d.x() + K_(0, 1) * d.y() + K_(0, 2), K_(1, 1) * d.y() + K_(1, 2), x.z()};
}

Ray Camera::ray(double u, double v) const {
  const Eigen::Vector3d d = K_inverse_ * Eigen::Vector3d(u, v, 1.0);
  Eigen::Vector2d n(d.x() / d.z(), d.y() / d.z());
  if (!distortion_.is_identity()) n = distortion_.undistort(n);
  return {centre_, (R_.transpose() * Eigen::Vector3d(n.x(), n.y(), 1.0)).normalized()};
}

Camera Camera::with_image_size(int width, int height) const {
  return Camera(K_, R_, t_, width, height, distortion_);
}

bool Camera::in_image(double u, double v) const {
  return u >= -0.5 && v >= -0.5 && u < width_ - 0.5 && v < height_ - 0.5;
}

}  // namespace mvflow
