#pragma once
// Internal to mvflow_topology and mvflow_hull: what the stages that change the mesh's topology
// (remeshing, adaptive refinement, the hull's isotropic remeshing) share. Not part of the
// stages' public interface.

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
