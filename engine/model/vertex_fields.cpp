#include "engine/model/vertex_fields.h"

#include <algorithm>

#include "engine/model/error.h"

namespace mvflow {

void VertexFields::resize(std::size_t n_vertices, std::size_t n_views) {
  MVFLOW_CHECK(n_views <= 65535, "at most 65535 views are supported");
  normal.assign(n_vertices, Eigen::Vector3d::Zero());
  mean_curvature.assign(n_vertices, 0.0);
  curvature_normal_length.assign(n_vertices, 0.0);
  photo_consistency.assign(n_vertices, 0.0);
  photo_gradient.assign(n_vertices, Eigen::Vector3d::Zero());
  speed.assign(n_vertices, Eigen::Vector3d::Zero());
  local_edge.assign(n_vertices, 0.0);
  defined.assign(n_vertices, 0);
  patch_kind.assign(n_vertices, PatchKind::Undecided);
  view_capacity = n_views;
  visible_views.assign(n_vertices * n_views, 0);
  visible_count.assign(n_vertices, 0);
}

std::vector<IndexRange> split_into_blocks(std::size_t count, std::size_t block_size) {
  MVFLOW_CHECK(block_size > 0, "block size must be positive");
  MVFLOW_CHECK(count <= UINT32_MAX, "too many elements for 32-bit ids");
  std::vector<IndexRange> blocks;
  blocks.reserve((count + block_size - 1) / block_size);
  for (std::size_t begin = 0; begin < count; begin += block_size)
    blocks.push_back({static_cast<std::uint32_t>(begin),
                      static_cast<std::uint32_t>(std::min(count, begin + block_size))});
  return blocks;
}

}  // namespace mvflow
