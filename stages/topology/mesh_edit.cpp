#include "stages/topology/mesh_edit.h"

#include "engine/model/one_ring.h"

namespace mvflow::detail {

CollapseVerdict check_collapse_ring(const TriMesh& mesh, TriMesh::VertexHandle moved, TriMesh::VertexHandle other,
                                    const Eigen::Vector3d& target, double max_edge,
                                    const Eigen::Vector3d* ring_normal) {
  const Eigen::Vector3d p = point(mesh, moved);
  for (auto h = mesh.cvoh_iter(moved); h.is_valid(); ++h) {
    const TriMesh::VertexHandle q = mesh.to_vertex_handle(*h);
    if (q == other) continue;
    const Eigen::Vector3d pq = point(mesh, q);
    if ((pq - target).norm() > max_edge) return CollapseVerdict::LongEdge;
    if (!mesh.face_handle(*h).is_valid()) continue;
    const TriMesh::VertexHandle r = mesh.to_vertex_handle(mesh.next_halfedge_handle(*h));  // face (moved, q, r)
    if (r == other) continue;
    const Eigen::Vector3d pr = point(mesh, r);
    const Eigen::Vector3d before = (pq - p).cross(pr - p);
    const Eigen::Vector3d after = (pq - target).cross(pr - target);
    if (is_degenerate(target, pq, pr, after) || !(before.dot(after) > 0.0) ||
        (ring_normal && !(ring_normal->dot(after) > 0.0)))
      return CollapseVerdict::FoldOver;
  }
  return CollapseVerdict::Ok;
}

}  // namespace mvflow::detail
