#pragma once
// The views as the photo-consistency stages read them: per view a 3×4 projection matrix (used
// directly when the lens has no distortion), the image and its size. Built once per run; the
// per-sample path then does no allocation and no virtual call.

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <vector>

#include "engine/model/camera.h"
#include "engine/model/image.h"
#include "engine/model/scene.h"

namespace mvflow {

struct PhotoView {
  const Camera* camera = nullptr;
  const Image* image = nullptr;
  Eigen::Matrix<double, 3, 4> projection;  //!< K·[R|t]
  bool pinhole = true;                      //!< no distortion: projection alone maps to pixels
  int width = 0;
  int height = 0;

  //! Pixel position and depth of \p X (distortion included).
  Projection project(const Eigen::Vector3d& X) const {
    if (!pinhole) return camera->project(X);
    const Eigen::Vector3d x = projection.leftCols<3>() * X + projection.col(3);
    return {x.x() / x.z(), x.y() / x.z(), x.z()};
  }
  //! True when the 5×5 patch around (u, v), with its bilinear support, lies inside the image
  //! (SPEC §3: 2 ≤ u < W−3 and 2 ≤ v < H−3, for a patch half-size of 2).
  bool patch_inside(double u, double v, int half_patch) const {
    return u >= half_patch && v >= half_patch && u < width - half_patch - 1 && v < height - half_patch - 1;
  }
};

//! Views of \p cameras with \p images (same order and count; both must outlive the result).
std::vector<PhotoView> make_photo_views(const std::vector<Camera>& cameras, const std::vector<const Image*>& images);
//! The world length one pixel covers at \p point in the finest of \p views: the smallest
//! depth / Camera::focal_pixels() over the views that have \p point in front of them.
//! 0 when no view has it in front.
double finest_pixel_size(const std::vector<PhotoView>& views, const Eigen::Vector3d& point);

//! Decodes the images of \p store with the given \p indices side by side, in the current task
//! arena (the store is safe to use from any thread). A failure is left for the caller's next
//! ImageStore::get to report, so that of several bad images the first in view order is named,
//! whatever the thread count and timing.
void decode_images(const ImageStore& store, std::span<const std::size_t> indices);

//! Views of a scene, decoding its images now (decode_images).
//! \throw what decoding throws, for the first view whose image fails.
std::vector<PhotoView> make_photo_views(const Scene& scene);
//! The views of \p scene with the given \p indices, in that order, decoding only their images
//! (an excluded view's photograph is never read). \throw as make_photo_views(scene).
std::vector<PhotoView> make_photo_views(const Scene& scene, std::span<const std::size_t> indices);

}  // namespace mvflow
