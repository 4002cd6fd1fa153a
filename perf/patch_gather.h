#pragma once
// The read bound of the photo kernel on this machine: the same 6×6-pixel blocks (the bilinear
// support of a 5×5 patch), at the same places in the same order as the g samples read them,
// loaded and summed with nothing else to do. What g reaches of this rate is what its
// arithmetic costs over the bare reads.

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "stages/flow/photo_views.h"

namespace mvflow::perf {

//! One patch read: the image pixel (x0 − 2, y0 − 2) and the image's row length in floats.
struct PatchBlock {
  const float* top_left;
  std::uint32_t stride;
};

//! The blocks the gradient stage reads for vertex positions \p points with visible views
//! \p visible (per point), sample spacing \p spacing and k/2 = \p half: per point the centre and
//! the 6·half axis samples, per sample the views whose patch lies in the image, in that order.
std::vector<PatchBlock> gradient_patch_blocks(const std::vector<Eigen::Vector3d>& points,
                                              const std::vector<std::vector<std::uint16_t>>& visible,
                                              const std::vector<PhotoView>& views, double spacing, int half);

//! Loads every float of every block (6 rows × 18 floats) and returns their sum, compiled for the
//! build of the photo kernel that runs (detail::active_photo_kernel(), MVFLOW_KERNEL).
float gather_patch_blocks(std::span<const PatchBlock> blocks);

}  // namespace mvflow::perf
