#pragma once
// A calibrated pinhole camera with optional lens distortion (SPEC §2).
//
// Convention: x_cam = R·X + t, in front of the camera when z_cam > 0; normalized coordinates
// n = x_cam.xy / z_cam are distorted (d = distort(n)) and mapped to pixels by K·(d, 1). Pixel
// (0,0) is the centre of the top-left pixel, u goes right and v goes down. Formats with another
// convention are converted by their readers and writers (io/), never here.

#include <Eigen/Core>
#include <array>
#include <string>

namespace mvflow {

//! Lens distortion models, all acting on normalized image coordinates.
enum class DistortionModel {
  None,          //!< no distortion
  Radial,        //!< d = n·(1 + k1 r² + k2 r⁴), r = |n| (COLMAP SIMPLE_RADIAL with k2 = 0, RADIAL)
  OpenCV,        //!< radial k1, k2 plus tangential p1, p2 (COLMAP OPENCV, OpenCV's first 4)
  InverseRadial  //!< n = d·(1 + k1 r_d² + k2 r_d⁴), r_d = |d|: the thesis §2.1 eq. 2.6/2.7
};

//! Distortion model plus up to four coefficients (k1, k2, p1, p2; unused ones are 0).
struct Distortion {
  DistortionModel model = DistortionModel::None;
  std::array<double, 4> coefficients{0.0, 0.0, 0.0, 0.0};

  bool is_identity() const;
  //! Normalized undistorted → distorted coordinates.
  Eigen::Vector2d distort(const Eigen::Vector2d& n) const;
  //! Normalized distorted → undistorted coordinates (closed form or Newton iterations).
  Eigen::Vector2d undistort(const Eigen::Vector2d& d) const;
};

//! Where a world point lands in an image. depth = z_cam; the pixel is meaningful only if depth > 0.
struct Projection {
  double u = 0.0;
  double v = 0.0;
  double depth = 0.0;
};

//! A ray in world space; direction has unit length.
struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;
};

class Camera {
 public:
  Camera() = default;
  //! \param K upper-triangular intrinsics (fx, skew, cx; 0, fy, cy; 0, 0, 1)
  //! \param R world-to-camera rotation (orthonormal, det +1)
  //! \param t world-to-camera translation
  //! \throw InputError when K or R is not of that form or a value is not finite
  Camera(const Eigen::Matrix3d& K, const Eigen::Matrix3d& R, const Eigen::Vector3d& t, int width,
         int height, Distortion distortion = {});

  const Eigen::Matrix3d& K() const { return K_; }
  const Eigen::Matrix3d& R() const { return R_; }
  const Eigen::Vector3d& t() const { return t_; }
  const Distortion& distortion() const { return distortion_; }
  //! Image size in pixels; 0 × 0 while unknown (a Middlebury file before its images are read).
  int width() const { return width_; }
  int height() const { return height_; }
  //! The focal length in pixels as one number, √(fx·fy): depth / focal_pixels() is the side of
  //! the square with the area of one pixel at that depth.
  double focal_pixels() const;
  //! Camera centre C = −Rᵀt in world coordinates.
  const Eigen::Vector3d& centre() const { return centre_; }
  //! The 3×4 matrix K·[R|t] (exact projection only when distortion().is_identity()).
  const Eigen::Matrix<double, 3, 4>& projection_matrix() const { return P_; }
  //! Viewing direction (the camera's +z axis) in world coordinates.
  Eigen::Vector3d viewing_direction() const { return R_.row(2).transpose(); }

  //! Projects a world point, distortion included.
  Projection project(const Eigen::Vector3d& X) const;
  //! The ray from the camera centre through pixel (u, v), distortion removed.
  Ray ray(double u, double v) const;
  //! The same camera with its image size set.
  Camera with_image_size(int width, int height) const;
  //! True when (u, v) lies inside the image area [-0.5, W-0.5) × [-0.5, H-0.5).
  bool in_image(double u, double v) const;

 private:
  Eigen::Matrix3d K_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d K_inverse_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 3, 4> P_ = Eigen::Matrix<double, 3, 4>::Zero();
  Distortion distortion_;
  int width_ = 0;
  int height_ = 0;
};

//! A camera plus the file of its photograph (relative paths are relative to the scene folder).
struct View {
  Camera camera;
  std::string image_name;
};

}  // namespace mvflow
