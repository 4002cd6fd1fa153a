#pragma once
// Holes in silhouettes: background regions that the object's outline encloses. A thresholded
// photograph has them where the object is in deep shadow (the Middlebury dino), and each one
// would carve a tunnel through the visual hull; real see-through openings (between the
// Middlebury temple's columns) are larger. Filling the small ones keeps the hull conservative.

#include <cstddef>
#include <vector>

#include "stages/flow/silhouette.h"

namespace mvflow {

//! The areas in pixels of the enclosed background regions of \p mask (4-connected background
//! regions that do not touch the image border), in the order of their first pixel (row-major).
std::vector<std::size_t> silhouette_hole_areas(const Mask& mask);

//! \p mask with every enclosed background region of at most \p max_area pixels turned into
//! object. max_area 0 returns the mask unchanged.
Mask fill_silhouette_holes(const Mask& mask, std::size_t max_area);

}  // namespace mvflow
