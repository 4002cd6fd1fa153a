#include "stages/flow/normals.h"

#include <cmath>

#include "engine/model/one_ring.h"

namespace mvflow {

void compute_normals(const TriMesh& mesh, IndexRange vertices, VertexFields& fields) {
  detail::check_range(vertices, mesh.n_vertices(), "compute_normals");
  MVFLOW_CHECK(fields.size() == mesh.n_vertices() && fields.normal.size() == mesh.n_vertices(),
               "compute_normals: fields are not sized for the mesh");
  for (std::uint32_t id = vertices.begin; id < vertices.end; ++id) {
    const auto v = detail::handle(id);
    const Eigen::Vector3d p = detail::point(mesh, v);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    bool defined = false;
    for (auto it = mesh.cvoh_iter(v); it.is_valid(); ++it) {
      const TriMesh::HalfedgeHandle h = *it;
      if (!mesh.face_handle(h).is_valid()) continue;  // boundary gap: no face here
      const Eigen::Vector3d q = detail::point(mesh, mesh.to_vertex_handle(h));
      const Eigen::Vector3d r = detail::point(mesh, mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
      // (Q−P)×(R−P) has the face's orientation and length |(P2−P1)×(P3−P1)|.
      const Eigen::Vector3d cross = (q - p).cross(r - p);
      if (detail::is_degenerate(p, q, r, cross)) {
        defined = false;
        break;
      }
      // w_j n_j = (2/|c|)·(c/|c|).
      sum += (2.0 / cross.squaredNorm()) * cross;
      defined = true;
    }
    const double length = sum.norm();
    // A vanishing or non-finite sum (faces cancelling out) has no direction.
    if (defined && length > 0.0 && std::isfinite(length)) {
      fields.normal[id] = sum / length;
      fields.defined[id] |= kNormalDefined;
    } else {
      fields.normal[id] = Eigen::Vector3d::Zero();
      fields.defined[id] &= static_cast<std::uint8_t>(~kNormalDefined);
    }
  }
}

}  // namespace mvflow
