#pragma once
// Summary numbers of a surface: what `mvflow info` prints and what tests check meshes with.

#include <cstddef>

#include "engine/model/bounding_box.h"
#include "engine/model/mesh.h"

namespace mvflow {

struct MeshStats {
  std::size_t vertices = 0;
  std::size_t faces = 0;
  std::size_t edges = 0;
  std::size_t boundary_edges = 0;
  std::size_t boundary_loops = 0;
  std::size_t non_manifold_vertices = 0;  //!< vertices whose faces do not form one fan
  std::size_t isolated_vertices = 0;      //!< vertices with no face
  std::size_t components = 0;             //!< connected components of faces
  long euler_characteristic = 0;          //!< V − E + F over vertices that have faces
  long genus = 0;                         //!< (2·components − χ − boundary loops) / 2
  double shortest_edge = 0.0;
  double longest_edge = 0.0;
  double mean_edge = 0.0;
  BoundingBox bounding_box;

  bool is_closed() const { return boundary_edges == 0; }
  bool is_manifold() const { return non_manifold_vertices == 0; }
};

MeshStats compute_mesh_stats(const Mesh& mesh);

//! Shortest, longest and mean edge length (all 0 for a mesh without edges).
struct EdgeLengths {
  double shortest = 0.0;
  double longest = 0.0;
  double mean = 0.0;
};
EdgeLengths edge_lengths(const TriMesh& mesh);

//! The axis-aligned box of every vertex (isolated ones included); empty for a mesh without vertices.
BoundingBox bounding_box_of(const TriMesh& mesh);

}  // namespace mvflow
