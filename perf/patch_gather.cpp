#include "perf/patch_gather.h"

#include <cmath>
#include <cstring>

#include <string>

#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_kernel.h"

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

// The same loop compiled for each build of the photo kernel (stages/flow/photo_kernel.cpp), so that
// each build's reads are measured with that build's loads.
#define MVFLOW_GATHER_BODY                                                                          \
  using Floats = float __attribute__((vector_size(32)));                                            \
  [[gnu::always_inline]] inline Floats load(const float* p) {                                       \
    Floats f;                                                                                       \
    std::memcpy(&f, p, sizeof f);                                                                   \
    return f;                                                                                       \
  }                                                                                                 \
  float gather(std::span<const PatchBlock> blocks) {                                                \
    Floats a = {}, b = {}, c = {};                                                                  \
    for (const PatchBlock& block : blocks) {                                                        \
      const float* row = block.top_left;                                                            \
      for (int r = 0; r < 6; ++r, row += block.stride) { /* 18 floats: [0, 8) [8, 16) [10, 18) */   \
        a += load(row);                                                                             \
        b += load(row + 8);                                                                         \
        c += load(row + 10);                                                                        \
      }                                                                                             \
    }                                                                                               \
    const Floats total = a + b + c;                                                                 \
    float sum = 0;                                                                                  \
    for (int j = 0; j < 8; ++j) sum += total[j];                                                    \
    return sum;                                                                                     \
  }

namespace baseline {
MVFLOW_GATHER_BODY
}  // namespace baseline

#if defined(__x86_64__) || defined(__i386__)
#pragma GCC push_options
#pragma GCC target("arch=x86-64-v3")
namespace avx2 {
MVFLOW_GATHER_BODY
}  // namespace avx2
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("arch=x86-64-v4")
namespace avx512 {
MVFLOW_GATHER_BODY
}  // namespace avx512
#pragma GCC pop_options
#endif
#undef MVFLOW_GATHER_BODY

float gather_patch_blocks(std::span<const PatchBlock> blocks) {
#if defined(__x86_64__) || defined(__i386__)
  const std::string build = detail::active_photo_kernel().name;
  if (build == "avx512") return avx512::gather(blocks);
  if (build == "avx2") return avx2::gather(blocks);
#endif
  return baseline::gather(blocks);
}

}  // namespace mvflow::perf
