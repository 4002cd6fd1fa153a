#pragma once
// Coarser copies of the photographs for a coarse-to-fine start (README, "Defaults and
// differences"): at half the resolution the 5×5 patch covers twice the surface, so g varies more
// slowly and its basin around the surface is twice as wide; the flow starts there and moves to
// the full resolution once it has settled.

#include <memory>
#include <vector>

#include "engine/model/camera.h"
#include "engine/model/image.h"
#include "stages/flow/photo_views.h"

namespace mvflow {

//! The views of one pyramid level. Its views point into its own cameras and images, so a level
//! is held by pointer and never copied.
struct ImageLevel {
  std::vector<Camera> cameras;
  std::vector<Image> images;
  std::vector<PhotoView> views;
  ImageLevel() = default;
  ImageLevel(const ImageLevel&) = delete;
  ImageLevel& operator=(const ImageLevel&) = delete;
};

//! Fills level.views from its cameras and images (same count and order), once both are in place.
void attach_views(ImageLevel& level);

//! \p image at half its size: each pixel the mean of a 2×2 block (an odd last row or column is
//! dropped).
Image half_image(const Image& image);

//! \p camera for half_image of its photograph: pixel x' covers source pixels 2x' and 2x'+1, so
//! u' = (u − 0.5)/2 with pixel centres at integers (SPEC §2); the lens model is unchanged (it acts
//! on normalized coordinates).
Camera half_camera(const Camera& camera);

//! Whether half_resolution takes \p view: its image is at least 16 × 16 pixels (a level smaller
//! than 8 × 8 says nothing).
inline bool halvable(const PhotoView& view) { return view.width >= 16 && view.height >= 16; }

//! The views of \p views at half the resolution. \throw Error when an image is not halvable.
std::unique_ptr<ImageLevel> half_resolution(const std::vector<PhotoView>& views);

}  // namespace mvflow
