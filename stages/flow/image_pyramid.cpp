#include "stages/flow/image_pyramid.h"

#include "engine/model/error.h"
#include "engine/model/parallel.h"

namespace mvflow {

Image half_image(const Image& image) {
  const int width = image.width() / 2, height = image.height() / 2;
  Image half = Image::uninitialized(width, height);  // every value written below
  const float* source = image.data();
  float* target = half.data();
  const std::size_t stride = static_cast<std::size_t>(image.width()) * 3;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float* top = source + static_cast<std::size_t>(2 * y) * stride + static_cast<std::size_t>(2 * x) * 3;
      const float* bottom = top + stride;
      for (int c = 0; c < 3; ++c)
        target[(static_cast<std::size_t>(y) * width + x) * 3 + c] = 0.25f * ((top[c] + top[c + 3]) + (bottom[c] + bottom[c + 3]));
    }
  return half;
}

Camera half_camera(const Camera& camera) {
  Eigen::Matrix3d scale;
  scale << 0.5, 0.0, -0.25, 0.0, 0.5, -0.25, 0.0, 0.0, 1.0;
  return Camera(scale * camera.K(), camera.R(), camera.t(), camera.width() / 2, camera.height() / 2,
                camera.distortion());
}

void attach_views(ImageLevel& level) {
  std::vector<const Image*> images;
  for (const Image& image : level.images) images.push_back(&image);
  level.views = make_photo_views(level.cameras, images);
}

std::unique_ptr<ImageLevel> half_resolution(const std::vector<PhotoView>& views) {
  auto level = std::make_unique<ImageLevel>();
  level->cameras.reserve(views.size());
  for (const PhotoView& view : views) {
    MVFLOW_CHECK(halvable(view), "image pyramid: an image is too small to halve");
    level->cameras.push_back(half_camera(*view.camera));
  }
  // The views in parallel: one after another this was a serial stretch of a whole refine (24
  // views of 640×480: ~50 ms with its page faults, 3 % of the peer-sized sphere case at 2 threads;
  // perf/README "Session 37").
  level->images.resize(views.size());
  parallel::parallel_for(std::size_t{0}, views.size(),
                         [&](std::size_t i) { level->images[i] = half_image(*views[i].image); });
  attach_views(*level);
  return level;
}

}  // namespace mvflow
