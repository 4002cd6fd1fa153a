#pragma once
// Internal to mvflow_topology and mvflow_hull: what the stages that change the mesh's topology
// (remeshing, adaptive refinement, the hull's isotropic remeshing) share: the midpoint split, the
// test of a collapse and the status attributes. Not part of the stages' public interface.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "engine/model/mesh.h"

namespace mvflow::detail {

//! Σ (Q−P)×(R−P) over the faces (P, Q, R) around \p v: twice the area-weighted normal of its ring.
inline Eigen::Vector3d area_normal(const TriMesh& mesh, TriMesh::VertexHandle v) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const Eigen::Vector3d p = to_eigen(mesh.point(v));
  for (auto h = mesh.cvoh_iter(v); h.is_valid(); ++h) {
    if (!mesh.face_handle(*h).is_valid()) continue;
    const Eigen::Vector3d q = to_eigen(mesh.point(mesh.to_vertex_handle(*h)));
    const Eigen::Vector3d r = to_eigen(mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(*h))));
    sum += (q - p).cross(r - p);
  }
  return sum;
}

//! The midpoint of edge \p e.
inline TriMesh::Point midpoint(const TriMesh& mesh, TriMesh::EdgeHandle e) {
  const auto h = mesh.halfedge_handle(e, 0);
  return 0.5 * (mesh.point(mesh.from_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(h)));
}

//! Splits \p e at its midpoint, joining the new vertex to the opposite corners. OpenMesh keeps
//! e's handle as one half and only adds elements, so other handles stay valid.
inline void split_at_midpoint(TriMesh& mesh, TriMesh::EdgeHandle e) { mesh.split_edge(e, mesh.add_vertex(midpoint(mesh, e))); }

//! Why moving one end of an edge to the collapse target is refused.
enum class CollapseVerdict { Ok, FoldOver, LongEdge };

//! Would moving \p moved (one end of a collapsed edge, \p other the other end) to \p target keep
//! every edge at it ≤ \p max_edge and every face around it that survives the collapse
//! non-degenerate and facing the way it did? Given \p ring_normal, each such face must also face
//! its side (which stops a face from turning over in several steps of < 90° each). Faces
//! containing both ends vanish with the collapse and are skipped.
CollapseVerdict check_collapse_ring(const TriMesh& mesh, TriMesh::VertexHandle moved, TriMesh::VertexHandle other,
                                    const Eigen::Vector3d& target, double max_edge,
                                    const Eigen::Vector3d* ring_normal = nullptr);

//! Requests the status attributes that delete, collapse and garbage_collection need for its
//! lifetime and releases them at scope exit. OpenMesh counts requests, so attributes the caller
//! had requested itself stay in place.
class StatusScope {
 public:
  explicit StatusScope(TriMesh& mesh) : mesh_(mesh) {
    mesh_.request_vertex_status();
    mesh_.request_edge_status();
    mesh_.request_halfedge_status();
    mesh_.request_face_status();
  }
  ~StatusScope() {
    mesh_.release_face_status();
    mesh_.release_halfedge_status();
    mesh_.release_edge_status();
    mesh_.release_vertex_status();
  }
  StatusScope(const StatusScope&) = delete;
  StatusScope& operator=(const StatusScope&) = delete;

 private:
  TriMesh& mesh_;
};

}  // namespace mvflow::detail
