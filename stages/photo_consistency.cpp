#include "stages/photo_consistency.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "engine/error.h"
#include "stages/photo_kernel.h"

namespace mvflow {

namespace {

constexpr int kMaxSide = 15;  // 2·7 + 1
constexpr int kMaxValues = 3 * kMaxSide * kMaxSide;

// g for any patch size (the default 5×5 has its own kernel, stages/photo_kernel.h). Value
// (dy, dx, c) is element (dy+h)·3·side + 3·(dx+h) + c, so a patch row is 3·side contiguous floats
// of the image read at two horizontal offsets (0 and 3 = the next pixel) in two image rows: loops
// the compiler vectorizes, each value computed as the scalar formula w00·a + w10·b + w01·c + w11·d.
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
PhotoValue photo_consistency_any(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                                 const std::vector<PhotoView>& views, int h) {
  const int side = 2 * h + 1;
  const int width = 3 * side;
  const int values = width * side;
  // Per (offset, channel): Σ C and Σ C² over the views, in double (SPEC §3).
  std::array<double, kMaxValues> sum;
  std::array<double, kMaxValues> sum_squares;
  std::fill_n(sum.begin(), values, 0.0);
  std::fill_n(sum_squares.begin(), values, 0.0);
  int used = 0;
  for (const std::uint16_t id : view_ids) {
    const PhotoView& view = views[id];
    const Projection p = view.project(X);
    if (!(p.depth > 0) || !view.patch_inside(p.u, p.v, h)) continue;
    ++used;
    const int x0 = static_cast<int>(std::floor(p.u));
    const int y0 = static_cast<int>(std::floor(p.v));
    // One set of bilinear weights serves the whole patch: the offsets are whole pixels.
    const double fx = p.u - x0, fy = p.v - y0;
    const double w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
    const std::size_t stride = static_cast<std::size_t>(view.width) * 3;
    const float* top = view.image->data() + static_cast<std::size_t>(y0 - h) * stride + static_cast<std::size_t>(x0 - h) * 3;
    for (int r = 0; r < side; ++r, top += stride) {
      const float* __restrict next = top + stride;
      double* __restrict row_sum = sum.data() + r * width;
      double* __restrict row_squares = sum_squares.data() + r * width;
      for (int j = 0; j < width; ++j) {
        const double value = w00 * top[j] + w10 * top[j + 3] + w01 * next[j] + w11 * next[j + 3];
        row_sum[j] += value;
        row_squares[j] += value * value;
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

}  // namespace

PhotoValue photo_consistency(const Eigen::Vector3d& X, std::span<const std::uint16_t> view_ids,
                             const std::vector<PhotoView>& views, const PhotoConsistencyOptions& options) {
  if (options.half_patch == 2) return detail::photo_consistency_5x5(X, view_ids, views);
  return photo_consistency_any(X, view_ids, views, options.half_patch);
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
