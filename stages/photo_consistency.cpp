#include "stages/photo_consistency.h"

#include <array>
#include <cmath>

#include "engine/error.h"

namespace mvflow {

namespace {

constexpr int kMaxSide = 15;  // 2·7 + 1
constexpr int kMaxValues = 3 * kMaxSide * kMaxSide;

}  // namespace

PhotoValue photo_consistency(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                             const std::vector<PhotoView>& views, const PhotoConsistencyOptions& options) {
  const int h = options.half_patch;
  const int side = 2 * h + 1;
  const int values = 3 * side * side;
  // Per (offset, channel): Σ C and Σ C² over the views, in double (SPEC §3).
  std::array<double, kMaxValues> sum{};
  std::array<double, kMaxValues> sum_squares{};
  int used = 0;
  for (const std::uint16_t id : view_ids) {
    const PhotoView& view = views[id];
    const Projection p = view.project(X);
    if (!(p.depth > 0) || !view.patch_inside(p.u, p.v, h)) continue;
    ++used;
    const int x0 = static_cast<int>(std::floor(p.u));
    const int y0 = static_cast<int>(std::floor(p.v));
    // One set of bilinear weights serves the whole patch: the offsets are whole pixels.
    // Weights and sums in double: g is a difference of large sums (SPEC §3).
    const double fx = p.u - x0, fy = p.v - y0;
    const double w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
    const float* data = view.image->data();
    const std::size_t stride = static_cast<std::size_t>(view.width) * 3;
    int k = 0;
    for (int dy = -h; dy <= h; ++dy) {
      const float* row = data + static_cast<std::size_t>(y0 + dy) * stride + static_cast<std::size_t>(x0 - h) * 3;
      const float* next = row + stride;
      for (int dx = 0; dx < side; ++dx, row += 3, next += 3)
        for (int c = 0; c < 3; ++c, ++k) {
          const double value = w00 * row[c] + w10 * row[c + 3] + w01 * next[c] + w11 * next[c + 3];
          sum[k] += value;
          sum_squares[k] += value * value;
        }
    }
  }
  PhotoValue result;
  result.views = used;
  if (used < 2) return result;
  const double m = used;
  double total = 0.0;
  for (int k = 0; k < values; ++k) total += (sum_squares[k] - sum[k] * sum[k] / m) / (m - 1);
  // Rounding can leave a tiny negative variance where all views agree; g is a variance sum.
  result.g = std::max(0.0, total / (side * side));
  return result;
}

void compute_photo_consistency(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                               const PhotoConsistencyOptions& options, VertexFields& fields) {
  MVFLOW_CHECK(options.check(), "photo consistency options out of range");
  for (std::uint32_t v = vertices.begin; v < vertices.end; ++v) {
    const std::span<const std::uint16_t> visible(fields.visible_views.data() + v * fields.view_capacity,
                                                 fields.visible_count[v]);
    const PhotoValue value =
        photo_consistency(to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v)))), visible, views, options);
    fields.photo_consistency[v] = value.defined() ? value.g : 0.0;
    if (value.defined())
      fields.defined[v] |= kPhotoDefined;
    else
      fields.defined[v] &= static_cast<std::uint8_t>(~kPhotoDefined);
  }
}

}  // namespace mvflow
