#include "stages/commit.h"

#include "stages/one_ring.h"

namespace mvflow {

void commit_positions(TriMesh& mesh, IndexRange vertices, const std::vector<Eigen::Vector3d>& new_positions) {
  detail::check_range(vertices, mesh.n_vertices(), "commit_positions");
  MVFLOW_CHECK(new_positions.size() == mesh.n_vertices(),
               "commit_positions: buffer is not sized for the mesh");
  for (std::uint32_t id = vertices.begin; id < vertices.end; ++id)
    mesh.set_point(detail::handle(id), to_openmesh(new_positions[id]));
}

}  // namespace mvflow
