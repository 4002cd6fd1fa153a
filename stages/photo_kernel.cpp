#include "stages/photo_kernel.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "engine/error.h"

// The 8-lane vector types are passed only between always-inlined functions of one build.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace mvflow::detail {

namespace baseline {
#include "stages/photo_kernel_body.inc"
}  // namespace baseline

#pragma GCC push_options
#pragma GCC target("avx2")
namespace avx2 {
#include "stages/photo_kernel_body.inc"
}  // namespace avx2
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("arch=x86-64-v4")
#pragma GCC diagnostic push
// GCC 12's _mm512_cvtps_pd starts from _mm512_undefined_pd() and warns about it.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#define MVFLOW_KERNEL_AVX512
namespace avx512 {
#include "stages/photo_kernel_body.inc"
}  // namespace avx512
#undef MVFLOW_KERNEL_AVX512
#pragma GCC diagnostic pop
#pragma GCC pop_options

// GCC function multiversioning: a resolver picks one build at load time. Callers in other
// files see only the unversioned functions below (GCC dispatches only where every version is
// visible).
#define MVFLOW_VERSIONED(target_name, build)                                                             \
  __attribute__((target(target_name))) PhotoValue evaluate_5x5(                                          \
      const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids, const std::vector<PhotoView>& views) { \
    return build::photo_consistency_5x5(X, view_ids, views);                                             \
  }                                                                                                      \
  __attribute__((target(target_name))) void evaluate_5x5_samples(                                        \
      const Eigen::Vector3d& X, double spacing, int half, std::span<const std::uint16_t> view_ids,       \
      const std::vector<PhotoView>& views, std::span<PhotoValue> samples) {                              \
    build::photo_consistency_5x5_samples(X, spacing, half, view_ids, views, samples);                    \
  }
MVFLOW_VERSIONED("default", baseline)
MVFLOW_VERSIONED("avx2", avx2)
MVFLOW_VERSIONED("arch=x86-64-v4", avx512)
#undef MVFLOW_VERSIONED

PhotoValue photo_consistency_5x5(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                                 const std::vector<PhotoView>& views) {
  return evaluate_5x5(X, view_ids, views);
}

void photo_consistency_5x5_samples(const Eigen::Vector3d& X, double spacing, int half,
                                std::span<const std::uint16_t> view_ids, const std::vector<PhotoView>& views,
                                std::span<PhotoValue> samples) {
  MVFLOW_CHECK(samples.size() >= static_cast<std::size_t>(6 * half + 1), "photo_consistency_5x5_samples: too few samples");
  evaluate_5x5_samples(X, spacing, half, view_ids, views, samples);
}

void prefetch_patches(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                      const std::vector<PhotoView>& views) {
  for (const std::uint16_t id : view_ids) {
    const PhotoView& view = views[id];
    if (!view.pinhole) continue;
    const Eigen::Vector3d x = view.projection.leftCols<3>() * X + view.projection.col(3);
    const double u = x.x() / x.z(), v = x.y() / x.z();
    if (!(x.z() > 0) || !view.patch_inside(u, v, 2)) continue;
    // The 6×6 block and a margin of 2 pixels on every side, where nearby samples read.
    const int x_first = std::max(static_cast<int>(u) - 4, 0), x_last = std::min(static_cast<int>(u) + 5, view.width - 1);
    const int y_first = std::max(static_cast<int>(v) - 4, 0), y_last = std::min(static_cast<int>(v) + 5, view.height - 1);
    const std::size_t stride = static_cast<std::size_t>(view.width) * 3;
    for (int y = y_first; y <= y_last; ++y) {
      const float* row = view.image->data() + static_cast<std::size_t>(y) * stride;
      for (int x = x_first; x <= x_last + 5; x += 5) __builtin_prefetch(row + std::min(x, x_last) * 3);  // 60 bytes apart
    }
  }
}

std::vector<PhotoKernelBuild> photo_kernel_builds() {
  std::vector<PhotoKernelBuild> builds{
      {"baseline", &baseline::photo_consistency_5x5, &baseline::photo_consistency_5x5_samples}};
  if (__builtin_cpu_supports("avx2"))
    builds.push_back({"avx2", &avx2::photo_consistency_5x5, &avx2::photo_consistency_5x5_samples});
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512cd"))
    builds.push_back({"avx512", &avx512::photo_consistency_5x5, &avx512::photo_consistency_5x5_samples});
  return builds;
}

}  // namespace mvflow::detail
