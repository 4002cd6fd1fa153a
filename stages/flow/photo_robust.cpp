#include "stages/flow/photo_robust.h"

#include <algorithm>
#include <cmath>

#include "engine/model/error.h"

namespace mvflow {

namespace {

using detail::kMaxPatchValues;

int patch_values(int half_patch) { return 3 * (2 * half_patch + 1) * (2 * half_patch + 1); }

ViewGainBias gain_bias_of(const float* patch, int values, double noise_floor) {
  double mean[3] = {0.0, 0.0, 0.0};
  for (int k = 0; k < values; ++k) mean[k % 3] += patch[k];
  const double per_channel = values / 3;
  for (double& m : mean) m /= per_channel;
  double squares = 0.0;
  for (int k = 0; k < values; ++k) {
    const double d = patch[k] - mean[k % 3];
    squares += d * d;
  }
  ViewGainBias map;
  for (int c = 0; c < 3; ++c) map.offset[c] = static_cast<float>(mean[c]);
  map.scale = static_cast<float>(1.0 / std::sqrt(squares / values + noise_floor * noise_floor));
  return map;
}

void apply(const ViewGainBias& map, float* patch, int values) {
  for (int k = 0; k < values; ++k) patch[k] = (patch[k] - map.offset[k % 3]) * map.scale;
}

}  // namespace

void gain_bias_at(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids, const std::vector<PhotoView>& views,
                  int half_patch, double noise_floor, std::vector<ViewGainBias>& maps) {
  MVFLOW_CHECK(half_patch >= 1 && half_patch <= 7, "gain_bias_at: patch half size out of range");
  const int count = patch_values(half_patch);
  maps.assign(view_ids.size(), ViewGainBias{});
  float patch[kMaxPatchValues];
  for (std::size_t i = 0; i < view_ids.size(); ++i)
    if (detail::read_patch(views[view_ids[i]], X, half_patch, patch)) maps[i] = gain_bias_of(patch, count, noise_floor);
}

PhotoValue normalized_photo_consistency(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                                        std::span<const ViewGainBias> maps, const std::vector<PhotoView>& views,
                                        int half_patch) {
  MVFLOW_CHECK(maps.size() == view_ids.size(), "normalized_photo_consistency: one map per view expected");
  const int count = patch_values(half_patch);
  detail::PatchVariance variance(half_patch);
  float patch[kMaxPatchValues];
  for (std::size_t i = 0; i < view_ids.size(); ++i) {
    if (!detail::read_patch(views[view_ids[i]], X, half_patch, patch)) continue;
    apply(maps[i], patch, count);
    variance.add(patch);
  }
  return variance.finish();
}

void drop_outlier_views(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                        const PhotoConsistencyOptions& options, VertexFields& fields) {
  options.check();
  if (options.drop_views == 0) return;
  const int count = patch_values(options.half_patch);
  // Buffers for the whole block: the patches of one vertex's views (normalised when asked), the
  // view (position in its visible list) each belongs to, the rows still in, the mean patch.
  std::vector<float> patches(fields.view_capacity * kMaxPatchValues);
  std::vector<std::size_t> owner, kept;
  std::vector<double> mean(static_cast<std::size_t>(count));
  std::vector<std::uint8_t> dropped;
  for (std::uint32_t v = vertices.begin; v < vertices.end; ++v) {
    const std::span<const std::uint16_t> visible = fields.visible(v);
    if (static_cast<int>(visible.size()) <= options.min_views) continue;
    const Eigen::Vector3d X = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
    owner.clear();
    for (std::size_t i = 0; i < visible.size(); ++i) {
      float* patch = patches.data() + owner.size() * kMaxPatchValues;
      if (!detail::read_patch(views[visible[i]], X, options.half_patch, patch)) continue;
      if (options.normalize) apply(gain_bias_of(patch, count, options.noise_floor), patch, count);
      owner.push_back(i);
    }
    kept.resize(owner.size());
    for (std::size_t r = 0; r < kept.size(); ++r) kept[r] = r;
    dropped.assign(visible.size(), 0);
    for (int round = 0; round < options.drop_views && static_cast<int>(kept.size()) > options.min_views; ++round) {
      std::fill(mean.begin(), mean.end(), 0.0);
      for (const std::size_t r : kept)
        for (int k = 0; k < count; ++k) mean[static_cast<std::size_t>(k)] += patches[r * kMaxPatchValues + k];
      for (double& value : mean) value /= static_cast<double>(kept.size());
      // The farthest patch from the mean (the first one on a tie: the same choice every run).
      std::size_t worst = 0;
      double worst_distance = -1.0;
      for (std::size_t i = 0; i < kept.size(); ++i) {
        const float* patch = patches.data() + kept[i] * kMaxPatchValues;
        double distance = 0.0;
        for (int k = 0; k < count; ++k) {
          const double d = patch[k] - mean[static_cast<std::size_t>(k)];
          distance += d * d;
        }
        if (distance > worst_distance) {
          worst_distance = distance;
          worst = i;
        }
      }
      dropped[owner[kept[worst]]] = 1;
      kept.erase(kept.begin() + static_cast<std::ptrdiff_t>(worst));
    }
    std::uint16_t* out = fields.visible_views.data() + v * fields.view_capacity;
    std::uint16_t n = 0;
    for (std::size_t i = 0; i < visible.size(); ++i)
      if (!dropped[i]) out[n++] = visible[i];  // in place: n ≤ i
    fields.visible_count[v] = n;
  }
}

}  // namespace mvflow
