#include "stages/flow/photo_views.h"

#include <oneapi/tbb/parallel_for.h>

#include <atomic>

#include "engine/model/error.h"
#include "engine/model/parallel.h"

namespace mvflow {

std::vector<PhotoView> make_photo_views(const std::vector<Camera>& cameras, const std::vector<const Image*>& images) {
  MVFLOW_CHECK(cameras.size() == images.size(), "one image per camera");
  std::vector<PhotoView> views(cameras.size());
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const Camera& camera = cameras[i];
    MVFLOW_CHECK(images[i] != nullptr, "image missing");
    MVFLOW_CHECK(images[i]->width() == camera.width() && images[i]->height() == camera.height(),
                 "image size differs from its camera's");
    views[i] = {&camera, images[i], camera.projection_matrix(), camera.distortion().is_identity(), camera.width(),
                camera.height()};
  }
  return views;
}

double finest_pixel_size(const std::vector<PhotoView>& views, const Eigen::Vector3d& point) {
  double finest = 0.0;
  for (const PhotoView& view : views) {
    const Camera& camera = *view.camera;
    const double depth = (camera.R() * point + camera.t()).z();
    const double focal = camera.focal_pixels();
    if (!(depth > 0) || !(focal > 0)) continue;
    const double size = depth / focal;
    if (finest == 0.0 || size < finest) finest = size;
  }
  return finest;
}

void decode_images(const ImageStore& store, std::span<const std::size_t> indices) {
  // Past the first failure (in index order) nothing more need be decoded: the caller stops there.
  std::atomic<std::size_t> first_failure{indices.size()};
  parallel::parallel_for(std::size_t{0}, indices.size(), [&](std::size_t i) {
    if (i > first_failure.load(std::memory_order_relaxed)) return;
    try {
      store.get(indices[i]);
    } catch (...) {  // not rethrown: oneTBB would pass on whichever failure came first in time
      std::size_t seen = first_failure.load(std::memory_order_relaxed);
      while (i < seen && !first_failure.compare_exchange_weak(seen, i, std::memory_order_relaxed)) {
      }
    }
  });
}

std::vector<PhotoView> make_photo_views(const Scene& scene, std::span<const std::size_t> indices) {
  for (std::size_t i : indices) MVFLOW_CHECK(i < scene.size(), "view index out of range");
  decode_images(*scene.images, indices);
  std::vector<PhotoView> views(indices.size());
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const Camera& camera = scene.views[indices[k]].camera;
    const Image& image = scene.image(indices[k]);
    MVFLOW_CHECK(image.width() == camera.width() && image.height() == camera.height(),
                 "image size differs from its camera's");
    views[k] = {&camera, &image, camera.projection_matrix(), camera.distortion().is_identity(), camera.width(),
                camera.height()};
  }
  return views;
}

std::vector<PhotoView> make_photo_views(const Scene& scene) {
  std::vector<std::size_t> all(scene.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  return make_photo_views(scene, all);
}

}  // namespace mvflow
