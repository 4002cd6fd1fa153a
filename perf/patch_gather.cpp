#include "perf/patch_gather.h"

#include <cmath>
#include <cstring>

#include "stages/photo_consistency.h"

namespace mvflow::perf {

std::vector<PatchBlock> gradient_patch_blocks(const std::vector<Eigen::Vector3d>& points,
                                              const std::vector<std::vector<std::uint16_t>>& visible,
                                              const std::vector<PhotoView>& views, double spacing, int half) {
  std::vector<PatchBlock> blocks;
  for (std::size_t p = 0; p < points.size(); ++p) {
    const auto add_sample = [&](const Eigen::Vector3d& X) {
      for (const std::uint16_t id : visible[p]) {
        const PhotoView& view = views[id];
        const Projection q = view.project(X);
        if (!(q.depth > 0) || !view.patch_inside(q.u, q.v, 2)) continue;
        const auto stride = static_cast<std::uint32_t>(view.width * 3);
        const auto x0 = static_cast<std::size_t>(std::floor(q.u)) - 2, y0 = static_cast<std::size_t>(std::floor(q.v)) - 2;
        blocks.push_back({view.image->data() + y0 * stride + x0 * 3, stride});
      }
    };
    for_each_gradient_sample(points[p], spacing, half, [&](std::size_t, const Eigen::Vector3d& X) {
      add_sample(X);
      return true;
    });
  }
  return blocks;
}

// The 8-lane vector type is passed only to an always-inlined function of the same build.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace {
using Floats = float __attribute__((vector_size(32)));

[[gnu::always_inline]] inline Floats load(const float* p) {
  Floats f;
  std::memcpy(&f, p, sizeof f);
  return f;
}
}  // namespace

// The widest loads this CPU has, as the photo kernel (stages/photo_kernel.cpp).
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
float gather_patch_blocks(std::span<const PatchBlock> blocks) {
  Floats a = {}, b = {}, c = {};
  for (const PatchBlock& block : blocks) {
    const float* row = block.top_left;
    for (int r = 0; r < 6; ++r, row += block.stride) {  // 18 floats: [0, 8) [8, 16) [10, 18)
      a += load(row);
      b += load(row + 8);
      c += load(row + 10);
    }
  }
  const Floats total = a + b + c;
  float sum = 0;
  for (int j = 0; j < 8; ++j) sum += total[j];
  return sum;
}

}  // namespace mvflow::perf
