#pragma once
// Photo consistency for real photographs (README, "Real photographs"): two per-vertex choices
// made once at the vertex X and kept for every one of its 3k+1 gradient samples, so that g stays
// a smooth function of the sample position.
//  - Gain/bias normalisation: each view's patch at X gives that view an affine map
//    z = (C − μ_c)·s with μ_c its per-channel mean and s = 1/√(σ² + σ₀²), σ the standard
//    deviation of its centred values (pooled over the channels). The variance of g is then taken
//    over z, so a per-view exposure or lighting change a·C + b (a > 0) leaves g unchanged where
//    σ ≫ σ₀ (σ₀ keeps flat, noise-only patches from being blown up to unit contrast).
//  - Outlier views: with m views, the view whose patch lies farthest from the mean patch is the
//    one whose removal lowers the variance most; up to `drop` such views are removed, one at a
//    time, while more than `min_views` remain (a specularity or an occlusion error in one view
//    no longer holds g up for the others).
// The patch values are photo_consistency's (detail::read_patch) and the sums are taken in double
// (detail::PatchVariance).

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_views.h"

namespace mvflow {

//! One view's affine map of its patch values, z = (C − offset[c])·scale.
struct ViewGainBias {
  float offset[3] = {0.0f, 0.0f, 0.0f};
  float scale = 1.0f;
};

//! \p maps = the maps of the views \p view_ids at \p X (one per id, in the same order; identity for
//! a view whose patch leaves its image there). \p noise_floor is σ₀ on [0,1] values. \p maps is
//! reused: no allocation once it has grown to the view count.
void gain_bias_at(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids, const std::vector<PhotoView>& views,
                  int half_patch, double noise_floor, std::vector<ViewGainBias>& maps);

//! g at \p X over \p view_ids with each view's values mapped by \p maps (same order as the ids).
PhotoValue normalized_photo_consistency(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                                        std::span<const ViewGainBias> maps, const std::vector<PhotoView>& views,
                                        int half_patch);

//! Removes from the visible views of each vertex in \p vertices the outlier views
//! (PhotoConsistencyOptions::drop_views, min_views; normalised first when normalize is set),
//! keeping the others in their order. Vertices with ≤ min_views usable views are left alone.
void drop_outlier_views(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                        const PhotoConsistencyOptions& options, VertexFields& fields);

}  // namespace mvflow
