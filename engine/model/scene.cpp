#include "engine/model/scene.h"

#include "engine/model/error.h"

namespace mvflow {

ImageStore::ImageStore(std::size_t count, Loader loader) : loader_(std::move(loader)) {
  slots_.reserve(count);
  for (std::size_t i = 0; i < count; ++i) slots_.push_back(std::make_unique<Slot>());
}

const Image& ImageStore::get(std::size_t view) const {
  MVFLOW_CHECK(view < slots_.size(), "view index out of range");
  Slot& slot = *slots_[view];
  std::lock_guard lock(slot.mutex);
  if (!slot.image) {
    MVFLOW_CHECK(static_cast<bool>(loader_), "image not loaded and no loader given");
    slot.image = std::make_unique<Image>(loader_(view));
  }
  return *slot.image;
}

bool ImageStore::is_loaded(std::size_t view) const {
  MVFLOW_CHECK(view < slots_.size(), "view index out of range");
  std::lock_guard lock(slots_[view]->mutex);
  return static_cast<bool>(slots_[view]->image);
}

void ImageStore::set(std::size_t view, Image image) {
  MVFLOW_CHECK(view < slots_.size(), "view index out of range");
  std::lock_guard lock(slots_[view]->mutex);
  slots_[view]->image = std::make_unique<Image>(std::move(image));
}

Scene in_memory_scene(std::vector<View> views, std::vector<Image> images, const BoundingBox& bounding_box) {
  MVFLOW_CHECK(images.size() == views.size(), "in_memory_scene: one image per view");
  Scene scene;
  scene.views = std::move(views);
  scene.images = std::make_shared<ImageStore>(scene.views.size(), nullptr);
  for (std::size_t i = 0; i < images.size(); ++i) scene.images->set(i, std::move(images[i]));
  scene.bounding_box = bounding_box;
  return scene;
}

}  // namespace mvflow
