#include "stages/flow/commit.h"

#include "engine/model/one_ring.h"

namespace mvflow {

void commit_positions(TriMesh& mesh, IndexRange vertices, const std::vector<Eigen::Vector3d>& new_positions,
                      const SilhouetteConstraint* inside) {
  detail::check_range(vertices, mesh.n_vertices(), "commit_positions");
  MVFLOW_CHECK(new_positions.size() == mesh.n_vertices(),
               "commit_positions: buffer is not sized for the mesh");
  for (std::uint32_t id = vertices.begin; id < vertices.end; ++id) {
    const auto v = detail::handle(id);
    mesh.set_point(v, to_openmesh(inside ? inside->limit_move(to_eigen(mesh.point(v)), new_positions[id])
                                         : new_positions[id]));
  }
}

}  // namespace mvflow
