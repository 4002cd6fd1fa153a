#pragma once
// A scene: the calibrated views, their photographs (decoded on first use), an optional initial
// mesh file and the region of space that holds the object.

#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "engine/model/bounding_box.h"
#include "engine/model/camera.h"
#include "engine/model/image.h"

namespace mvflow {

//! Photographs decoded on first request, each once, safe to call from any thread. Memory is
//! spent only for the views a job touches (`mvflow info` decodes none unless asked to check).
class ImageStore {
 public:
  using Loader = std::function<Image(std::size_t view)>;
  ImageStore() = default;
  ImageStore(std::size_t count, Loader loader);

  std::size_t size() const { return slots_.size(); }
  //! The image of \p view, decoding it on first use. \throw whatever the loader throws.
  const Image& get(std::size_t view) const;
  bool is_loaded(std::size_t view) const;
  //! Replaces the image of \p view (synthetic scenes and tests hand images in directly).
  void set(std::size_t view, Image image);

 private:
  struct Slot {
    mutable std::mutex mutex;
    mutable std::unique_ptr<Image> image;
  };
  std::vector<std::unique_ptr<Slot>> slots_;
  Loader loader_;
};

struct Scene {
  std::filesystem::path folder;          //!< the scene folder
  std::filesystem::path camera_file;     //!< the file the views came from
  std::string camera_format;             //!< "colmap", "colmap-bin", "middlebury" or "photomodeler"
  std::vector<View> views;               //!< in the order of the camera file
  std::shared_ptr<ImageStore> images;    //!< one image per view
  //! One silhouette image per view (a pixel is object where a channel is non-zero), e.g. from
  //! io::mask_store; null: the refinement thresholds the photographs where their border is dark.
  std::shared_ptr<ImageStore> masks;
  std::optional<std::filesystem::path> mesh_file;  //!< initial mesh found in the folder, if any
  BoundingBox bounding_box;              //!< region that holds the object (may be empty)
  std::string bounding_box_source;       //!< where bounding_box came from, for reports

  std::size_t size() const { return views.size(); }
  const Image& image(std::size_t view) const { return images->get(view); }
};

//! A scene held in memory (no files behind it): \p views with their \p images (one each), for
//! programs that embed mvflow, the refiner's tests and benchmarks that render instead of reading.
//! \throw Error when the counts differ.
Scene in_memory_scene(std::vector<View> views, std::vector<Image> images, const BoundingBox& bounding_box = {});

}  // namespace mvflow
