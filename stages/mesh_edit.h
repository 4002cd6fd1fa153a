#pragma once
// Internal to mvflow_stages: what the stages that change the mesh's topology (remeshing,
// adaptive refinement) share. Not part of the stages' public interface.

#include "engine/mesh.h"

namespace mvflow::detail {

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
