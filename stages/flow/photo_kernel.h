#pragma once
// The hot loops of the photo stages, for the default 5×5 patch (SPEC §3) and for surface patches
// (stages/flow/surface_patch.h, surface_patch_kernel_body.inc), in three builds of the
// same source (x86-64 baseline, AVX2, AVX-512; the baseline alone on other processors), one of
// them chosen once, on first use, by active_photo_kernel(): the one named by the environment
// variable MVFLOW_KERNEL (baseline, avx2 or avx512), else the widest one the CPU runs. Every build gives the same bits: each patch value is
// interpolated, shifted by the first view's value and summed over the views by the same float
// operations in the same order (no FMA contraction; SPEC §3's float sums on shifted data), and
// the values' totals are summed in one fixed order; only the lane width differs. Callers use photo_consistency(),
// surface_patch_consistency() and PhotoGradientStage.

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_views.h"

namespace mvflow {
struct SurfacePatchLayout;
}

namespace mvflow::detail {

//! g at \p X over the views \p view_ids with the 5×5 patch; photo_consistency() with
//! half_patch = 2.
PhotoValue photo_consistency_5x5(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                                 const std::vector<PhotoView>& views);

//! The 3k+1 samples of the gradient stage with the 5×5 patch, over the views \p view_ids:
//! samples[0] = g(X) (the same bits as photo_consistency_5x5), then g(X + s·spacing·e_a) for
//! a = x, y, z and s = −half..−1, 1..half (6·half values). When g(X) is undefined, only
//! samples[0] is written. For pinhole views the projection of the samples is P·X + s·spacing·P_a
//! (linear in s): per view, an axis's samples are projected a register's width at once, then each
//! sample sums its views' patches in the order of view_ids.
void photo_consistency_5x5_samples(const Eigen::Vector3d& X, double spacing, int half,
                                   std::span<const std::uint16_t> view_ids, const std::vector<PhotoView>& views,
                                   std::span<PhotoValue> samples);

//! Starts loading into the cache the image blocks the patches around \p X read in the views
//! \p view_ids (pinhole views), so that a later evaluation near X does not wait for memory.
void prefetch_patches(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                      const std::vector<PhotoView>& views);

//! Starts loading into the cache the pixels x_first..x_last of the rows y_first..y_last of
//! \p view's image (all inside the image).
void prefetch_pixels(const PhotoView& view, int x_first, int x_last, int y_first, int y_last);

//! One build of the kernels, for tests that check that the builds agree bit for bit.
struct PhotoKernelBuild {
  const char* name;  //!< "baseline", "avx2" or "avx512"
  PhotoValue (*consistency)(const Eigen::Vector3d&, std::span<const std::uint16_t>, const std::vector<PhotoView>&);
  void (*samples)(const Eigen::Vector3d&, double, int, std::span<const std::uint16_t>, const std::vector<PhotoView>&,
                  std::span<PhotoValue>);
  //! surface_patch_consistency() (stages/flow/surface_patch.h)
  PhotoValue (*surface)(const Eigen::Vector3d&, const SurfacePatchLayout&, const std::vector<PhotoView>&);
  //! surface_patch_samples() (stages/flow/surface_patch.h)
  void (*surface_samples)(const Eigen::Vector3d&, double, int, const SurfacePatchLayout&, const std::vector<PhotoView>&,
                          std::span<PhotoValue>);
  //! surface_patch_samples()'s samples across the lanes alone (the AVX-512 build; nullptr in the
  //! others): false, nothing written, where it would fall back to one evaluation per sample. For
  //! tests that must know that path ran.
  bool (*surface_samples_across_lanes)(const Eigen::Vector3d&, double, int, const SurfacePatchLayout&,
                                       const std::vector<PhotoView>&, std::span<PhotoValue>);
};
//! The builds this CPU can run, baseline first.
std::vector<PhotoKernelBuild> photo_kernel_builds();

//! The build photo_consistency_5x5 and photo_consistency_5x5_samples run: MVFLOW_KERNEL's when
//! set, else the last (widest) of photo_kernel_builds(). Chosen on the first call.
//! \throw Error when MVFLOW_KERNEL names an unknown build or one this CPU cannot run (every later
//!        call throws again).
const PhotoKernelBuild& active_photo_kernel();

}  // namespace mvflow::detail

namespace mvflow {

//! Which build of the photo kernel runs and why, e.g. "avx512 (the widest this CPU runs: baseline,
//! avx2, avx512)" or "baseline (forced by MVFLOW_KERNEL; this CPU runs: baseline, avx2)".
//! \throw Error as detail::active_photo_kernel().
std::string photo_kernel_summary();

}  // namespace mvflow
