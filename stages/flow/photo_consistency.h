#pragma once
// Photo consistency g (SPEC §3; thesis eq. 4.14, §5.3.3, figure 5.3b): project a point into
// each of its views, take the (2h+1)×(2h+1) patch around the projection (bilinear), and sum the
// unbiased variance across views over channels and patch offsets, averaged over the offsets:
//   var_{c,o} = (Σ_i C_i² − (Σ_i C_i)²/m) / (m − 1),   g = Σ_c (1/(2h+1)²) Σ_o var_{c,o}.
// g ≥ 0, 0 when all views agree; undefined with fewer than 2 usable views (a view whose patch
// would leave its image does not count for that point).
// Computed as (Σ_i Σ_o C² − Σ_o (Σ_i C)²/m) / ((m − 1)·(2h+1)²) with the sums in double; each
// patch value is interpolated in float (along the row, then down), which puts g within 1e-5
// relative of a double-precision evaluation (tests/stages_photo_test.cpp measures 2.5e-6).

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/photo_views.h"

namespace mvflow {

//! Where g lays its patches on the surface (PhotoConsistencyOptions::surface_patch).
enum class SurfacePatchUse : std::uint8_t {
  Off,      //!< whole-pixel image patches everywhere (the thesis)
  Oblique,  //!< surface patches where a view is beyond surface_patch_angle_degrees, else whole-pixel
  On,       //!< surface patches everywhere
};

//! The command line's name of \p use: "off", "oblique" or "on".
const char* to_string(SurfacePatchUse use);
//! The SurfacePatchUse called \p name ("off", "oblique" or "on").
//! \throw InputError naming the valid names otherwise.
SurfacePatchUse surface_patch_use_from_string(std::string_view name);

struct PhotoConsistencyOptions {
  int half_patch = 2;  //!< patch of (2·half_patch+1)² pixels; 2 = the thesis's 5×5 (range 1..7)
  //! Per-view gain/bias normalisation of the patches before the variance (stages/flow/photo_robust.h):
  //! exposure and lighting that differ between photographs no longer count as inconsistency.
  //! false: the thesis's g on raw colours.
  bool normalize = false;
  //! σ₀ of the normalisation on [0,1] values, ≥ 0: patches with less contrast than this are not
  //! stretched to unit contrast (their noise would be). 0.02 ≈ 5 grey levels of 8-bit photos.
  double noise_floor = 0.02;
  //! Up to this many outlier views are removed from a vertex's view set (stages/flow/photo_robust.h)
  //! while more than min_views remain; 0 keeps every view (the thesis).
  int drop_views = 0;
  int min_views = 4;  //!< views kept at least when dropping outliers (≥ 2)
  //! Where patches are laid on the vertex's tangent plane, the same surface points in every view
  //! (stages/flow/surface_patch.h), instead of the thesis's whole-pixel image patches (which cover
  //! 1/cos θ more surface in a view at θ to the normal). Needs the vertex normal. Oblique by
  //! default: on 32 synthetic scenes 0.860× the error of Off (better by > 3 % on 24, worse on
  //! none; On at the same settled tolerance 0.863×, worse on 4), held-out error of the photographs
  //! −26.6 % / −16.7 % against the hull (Off −27.2 % / −15.0 %), for 1.10–1.25× Off's time where
  //! On takes 1.14–1.45× (README, "Surface patches at oblique vertices"). On cannot go with
  //! normalize; Oblique leaves normalized patches as they are. Off: the thesis.
  SurfacePatchUse surface_patch = SurfacePatchUse::Oblique;
  //! Oblique: a vertex with a view farther than this from its normal (degrees, (0, 90]) uses surface
  //! patches. 60 (1/cos θ = 2): 50° gave 0.834× but worse by > 3 % on 4 scenes, 70° 0.951×.
  double surface_patch_angle_degrees = 60.0;
  //! Surface patch: the spacing of its points in pixels of the finest view (> 0, ≤ 8). 1.5 (the
  //! 5×5 points span 6 pixels of a frontal view): 1 was better on the photographs and worse on the
  //! synthetic scenes, 2 the reverse (README, "Surface patches").
  double surface_patch_spacing = 1.5;
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! g at one point and the number of views that contributed.
struct PhotoValue {
  double g = 0.0;
  int views = 0;
  bool defined() const { return views >= 2; }
};

namespace detail {

//! The most values one patch has (half_patch 7: 15 × 15 pixels × RGB).
inline constexpr int kMaxPatchValues = 3 * 15 * 15;

//! The 3·(2h+1)² values of the patch of \p view around \p X (rows top to bottom, RGB
//! interleaved), each interpolated in float along the row, then down: h = a + fx·(b − a),
//! C = h + fy·(h' − h). False (nothing written) when X is behind the camera or the patch with its
//! bilinear support leaves the image.
bool read_patch(const PhotoView& view, const Eigen::Vector3d& X, int half_patch, float* out);

//! Σ_i C per patch value and Σ_i Σ_values C² over the views added, in double and in the order
//! added, and g from them: (Σ C² − Σ_values (Σ_i C)²/m) / ((m − 1)·side²).
class PatchVariance {
 public:
  explicit PatchVariance(int half_patch);
  void add(const float* patch);
  PhotoValue finish() const;

 private:
  int side_;
  int count_;
  int views_ = 0;
  double squares_ = 0.0;
  double sum_[kMaxPatchValues];
};

}  // namespace detail

//! g(X) over the views \p view_ids of \p views, with whole-pixel image patches: the surface patch
//! (options.surface_patch) needs the surface's normal, photo_consistency_at_surface() takes it.
PhotoValue photo_consistency(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                             const std::vector<PhotoView>& views, const PhotoConsistencyOptions& options = {});

//! g at every vertex of \p vertices over its visible views (fields.visible_views, from the
//! visibility stage). Writes photo_consistency and the kPhotoDefined bit of those vertices only.
//! Surface patches read \p surface_views when given (the same cameras, other photographs), else
//! \p views.
void compute_photo_consistency(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                               const PhotoConsistencyOptions& options, VertexFields& fields,
                               const std::vector<PhotoView>* surface_views = nullptr);

//! The points of the gradient's 6·half + 1 samples of g around \p X, in the slots the gradient
//! stage reads: slot 0 = X, then X + s·spacing·e_a for a = x, y, z and s = −half..−1, 1..half.
//! Calls visit(slot, point) in slot order while it returns true.
template <class Visit>
void for_each_gradient_sample(const Eigen::Vector3d& X, double spacing, int half, Visit visit) {
  std::size_t slot = 0;
  if (!visit(slot++, X)) return;
  for (int axis = 0; axis < 3; ++axis)
    for (int s = -half; s <= half; ++s) {
      if (s == 0) continue;
      Eigen::Vector3d sample = X;
      sample[axis] += s * spacing;
      if (!visit(slot++, sample)) return;
    }
}

}  // namespace mvflow
