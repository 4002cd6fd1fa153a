#include "stages/photo_robust.h"

#include <algorithm>
#include <cmath>

#include "engine/error.h"

namespace mvflow {

namespace {

constexpr int kMaxSide = 15;  // 2·7 + 1
constexpr int kMaxValues = 3 * kMaxSide * kMaxSide;

// The (2h+1)² × 3 patch values of \p view at \p X, row by row, interpolated as in
// photo_consistency; false (nothing written) when X is behind the camera or the patch leaves
// the image.
bool read_patch(const PhotoView& view, const Eigen::Vector3d& X, int h, float* out) {
  const Projection p = view.project(X);
  if (!(p.depth > 0) || !view.patch_inside(p.u, p.v, h)) return false;
  const int side = 2 * h + 1;
  const int width = 3 * side;
  const int x0 = static_cast<int>(std::floor(p.u));
  const int y0 = static_cast<int>(std::floor(p.v));
  const float fx = static_cast<float>(p.u - x0), fy = static_cast<float>(p.v - y0);
  const std::size_t stride = static_cast<std::size_t>(view.width) * 3;
  const float* row = view.image->data() + static_cast<std::size_t>(y0 - h) * stride + static_cast<std::size_t>(x0 - h) * 3;
  float top[3 * kMaxSide], bottom[3 * kMaxSide];
  for (int j = 0; j < width; ++j) top[j] = row[j] + fx * (row[j + 3] - row[j]);
  for (int r = 0; r < side; ++r) {
    row += stride;
    for (int j = 0; j < width; ++j) bottom[j] = row[j] + fx * (row[j + 3] - row[j]);
    for (int j = 0; j < width; ++j) out[r * width + j] = top[j] + fy * (bottom[j] - top[j]);
    std::copy(bottom, bottom + width, top);
  }
  return true;
}

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

// Patches of the usable views at X (optionally normalised), one row of kMaxValues each, and the
// positions (into view_ids) of the views they belong to.
struct PatchSet {
  std::vector<float> values;
  std::vector<int> owner;
};

PatchSet read_patches(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                      const std::vector<PhotoView>& views, const PhotoConsistencyOptions& options) {
  const int count = 3 * (2 * options.half_patch + 1) * (2 * options.half_patch + 1);
  PatchSet set;
  set.values.resize(view_ids.size() * kMaxValues);
  for (std::size_t i = 0; i < view_ids.size(); ++i) {
    float* patch = set.values.data() + set.owner.size() * kMaxValues;
    if (!read_patch(views[view_ids[i]], X, options.half_patch, patch)) continue;
    if (options.normalize) apply(gain_bias_of(patch, count, options.noise_floor), patch, count);
    set.owner.push_back(static_cast<int>(i));
  }
  return set;
}

}  // namespace

std::vector<ViewGainBias> gain_bias_at(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                                       const std::vector<PhotoView>& views, int half_patch, double noise_floor) {
  MVFLOW_CHECK(half_patch >= 1 && half_patch <= 7, "gain_bias_at: patch half size out of range");
  const int count = 3 * (2 * half_patch + 1) * (2 * half_patch + 1);
  std::vector<ViewGainBias> maps(view_ids.size());
  float patch[kMaxValues];
  for (std::size_t i = 0; i < view_ids.size(); ++i)
    if (read_patch(views[view_ids[i]], X, half_patch, patch)) maps[i] = gain_bias_of(patch, count, noise_floor);
  return maps;
}

PhotoValue normalized_photo_consistency(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                                        std::span<const ViewGainBias> maps, const std::vector<PhotoView>& views,
                                        int half_patch) {
  MVFLOW_CHECK(maps.size() == view_ids.size(), "normalized_photo_consistency: one map per view expected");
  const int side = 2 * half_patch + 1;
  const int count = 3 * side * side;
  double sum[kMaxValues];
  std::fill_n(sum, count, 0.0);
  double squares = 0.0;
  int used = 0;
  float patch[kMaxValues];
  for (std::size_t i = 0; i < view_ids.size(); ++i) {
    if (!read_patch(views[view_ids[i]], X, half_patch, patch)) continue;
    apply(maps[i], patch, count);
    ++used;
    for (int k = 0; k < count; ++k) {
      const double value = patch[k];
      sum[k] += value;
      squares += value * value;
    }
  }
  PhotoValue result;
  result.views = used;
  if (used < 2) return result;
  const double m = used;
  double sum_squared = 0.0;
  for (int k = 0; k < count; ++k) sum_squared += sum[k] * sum[k];
  result.g = std::max(0.0, (squares - sum_squared / m) / ((m - 1) * (side * side)));
  return result;
}

void drop_outlier_views(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                        const PhotoConsistencyOptions& options, VertexFields& fields) {
  MVFLOW_CHECK(options.check(), "photo consistency options out of range");
  if (options.drop_views == 0) return;
  const int count = 3 * (2 * options.half_patch + 1) * (2 * options.half_patch + 1);
  std::vector<double> mean(static_cast<std::size_t>(count));
  for (std::uint32_t v = vertices.begin; v < vertices.end; ++v) {
    std::span<const std::uint16_t> visible = fields.visible(v);
    if (static_cast<int>(visible.size()) <= options.min_views) continue;
    const Eigen::Vector3d X = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
    const PatchSet set = read_patches(X, visible, views, options);
    std::vector<int> kept(set.owner.size());  // rows of set.values still in
    for (std::size_t r = 0; r < kept.size(); ++r) kept[r] = static_cast<int>(r);
    std::vector<bool> dropped_view(visible.size(), false);
    for (int round = 0; round < options.drop_views && static_cast<int>(kept.size()) > options.min_views; ++round) {
      std::fill(mean.begin(), mean.end(), 0.0);
      for (int r : kept)
        for (int k = 0; k < count; ++k) mean[static_cast<std::size_t>(k)] += set.values[static_cast<std::size_t>(r) * kMaxValues + k];
      for (double& value : mean) value /= static_cast<double>(kept.size());
      // The farthest patch from the mean (the first one on a tie: the same choice every run).
      std::size_t worst = 0;
      double worst_distance = -1.0;
      for (std::size_t i = 0; i < kept.size(); ++i) {
        const float* patch = set.values.data() + static_cast<std::size_t>(kept[i]) * kMaxValues;
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
      dropped_view[static_cast<std::size_t>(set.owner[static_cast<std::size_t>(kept[worst])])] = true;
      kept.erase(kept.begin() + static_cast<std::ptrdiff_t>(worst));
    }
    std::uint16_t* out = fields.visible_views.data() + v * fields.view_capacity;
    std::uint16_t n = 0;
    for (std::size_t i = 0; i < visible.size(); ++i)
      if (!dropped_view[i]) out[n++] = visible[i];  // in place: n ≤ i
    fields.visible_count[v] = n;
  }
}

}  // namespace mvflow
