#include "stages/flow/photo_kernel.h"

#if defined(__x86_64__) || defined(__i386__)
#define MVFLOW_KERNEL_X86 1
#include <immintrin.h>
#endif

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <string>

#include "engine/model/error.h"
#include "stages/flow/surface_patch.h"

// The 8-lane vector types are passed only between always-inlined functions of one build.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace mvflow::detail {

namespace baseline {
constexpr int kLanes = 2;  // two doubles per register: SSE2 on x86-64, the portable vectors elsewhere (arm64)
#include "stages/flow/photo_kernel_body.inc"
#include "stages/flow/surface_patch_kernel_body.inc"
#include "stages/flow/surface_patch_samples_body.inc"
}  // namespace baseline

#ifdef MVFLOW_KERNEL_X86
#pragma GCC push_options
#pragma GCC target("arch=x86-64-v3")  // AVX2 with FMA, BMI2, F16C (no contraction: -ffp-contract=off keeps the bits)
#define MVFLOW_KERNEL_AVX2
namespace avx2 {
constexpr int kLanes = 4;  // four doubles per ymm register
#include "stages/flow/photo_kernel_body.inc"
#include "stages/flow/surface_patch_kernel_body.inc"
#include "stages/flow/surface_patch_samples_body.inc"
}  // namespace avx2
#undef MVFLOW_KERNEL_AVX2
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("arch=x86-64-v4")
#pragma GCC diagnostic push
// GCC 12's AVX-512 intrinsics start from _mm512_undefined_ps() and warn about it, and it does not
// see that PatchSums' rows are written by the first patch added (views == 0) before any read.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#define MVFLOW_KERNEL_AVX512
namespace avx512 {
constexpr int kLanes = 8;  // eight doubles per zmm register
#include "stages/flow/photo_kernel_body.inc"
#include "stages/flow/surface_patch_kernel_body.inc"
#include "stages/flow/surface_patch_samples_body.inc"
}  // namespace avx512
#undef MVFLOW_KERNEL_AVX512
#pragma GCC diagnostic pop
#pragma GCC pop_options
#endif

namespace {

// The one dispatcher (production and tests alike): MVFLOW_KERNEL when set, else the widest
// build this CPU runs. Chosen once, on first use.
PhotoKernelBuild choose_build() {
  const std::vector<PhotoKernelBuild> builds = photo_kernel_builds();
  const char* forced = std::getenv("MVFLOW_KERNEL");
  if (forced == nullptr || *forced == '\0') return builds.back();
  std::string runnable;
  for (const PhotoKernelBuild& build : builds) {
    if (std::strcmp(build.name, forced) == 0) return build;
    runnable += (runnable.empty() ? "" : ", ") + std::string(build.name);
  }
  const bool known = std::strcmp(forced, "baseline") == 0 || std::strcmp(forced, "avx2") == 0 ||
                     std::strcmp(forced, "avx512") == 0;
  throw Error(std::string("MVFLOW_KERNEL=") + forced +
              (known ? ": this CPU cannot run that build of the photo kernel (it runs: "
                     : ": unknown build of the photo kernel (expected baseline, avx2 or avx512; this CPU runs: ") +
              runnable + ")");
}

}  // namespace

const PhotoKernelBuild& active_photo_kernel() {
  static const PhotoKernelBuild build = choose_build();
  return build;
}

PhotoValue photo_consistency_5x5(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                                 const std::vector<PhotoView>& views) {
  return active_photo_kernel().consistency(X, view_ids, views);
}

void photo_consistency_5x5_samples(const Eigen::Vector3d& X, double spacing, int half,
                                std::span<const std::uint16_t> view_ids, const std::vector<PhotoView>& views,
                                std::span<PhotoValue> samples) {
  MVFLOW_CHECK(samples.size() >= static_cast<std::size_t>(6 * half + 1), "photo_consistency_5x5_samples: too few samples");
  active_photo_kernel().samples(X, spacing, half, view_ids, views, samples);
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
    prefetch_pixels(view, std::max(static_cast<int>(u) - 4, 0), std::min(static_cast<int>(u) + 5, view.width - 1),
                    std::max(static_cast<int>(v) - 4, 0), std::min(static_cast<int>(v) + 5, view.height - 1));
  }
}

void prefetch_pixels(const PhotoView& view, int x_first, int x_last, int y_first, int y_last) {
  const std::size_t stride = static_cast<std::size_t>(view.width) * 3;
  for (int y = y_first; y <= y_last; ++y) {
    const float* row = view.image->data() + static_cast<std::size_t>(y) * stride;
    for (int x = x_first; x <= x_last + 5; x += 5) __builtin_prefetch(row + std::min(x, x_last) * 3);  // 60 bytes apart
  }
}

std::vector<PhotoKernelBuild> photo_kernel_builds() {
  std::vector<PhotoKernelBuild> builds{
      {"baseline", &baseline::photo_consistency_5x5, &baseline::photo_consistency_5x5_samples,
       &baseline::surface_patch_consistency, &baseline::surface_patch_samples, nullptr}};
#ifdef MVFLOW_KERNEL_X86
  if (__builtin_cpu_supports("x86-64-v3"))
    builds.push_back({"avx2", &avx2::photo_consistency_5x5, &avx2::photo_consistency_5x5_samples,
                      &avx2::surface_patch_consistency, &avx2::surface_patch_samples, nullptr});
  if (__builtin_cpu_supports("x86-64-v4"))
    builds.push_back({"avx512", &avx512::photo_consistency_5x5, &avx512::photo_consistency_5x5_samples,
                      &avx512::surface_patch_consistency, &avx512::surface_patch_samples,
                      &avx512::surface_samples_across_lanes});
#endif
  return builds;
}

}  // namespace mvflow::detail

namespace mvflow {

std::string photo_kernel_summary() {
  const detail::PhotoKernelBuild& active = detail::active_photo_kernel();
  std::string runnable;
  for (const detail::PhotoKernelBuild& build : detail::photo_kernel_builds())
    runnable += (runnable.empty() ? "" : ", ") + std::string(build.name);
  const char* forced = std::getenv("MVFLOW_KERNEL");
  const bool by_variable = forced != nullptr && *forced != '\0';
  return std::string(active.name) + (by_variable ? " (forced by MVFLOW_KERNEL; this CPU runs: " : " (the widest this CPU runs: ") +
         runnable + ")";
}

}  // namespace mvflow
