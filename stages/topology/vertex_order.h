#pragma once
// The order of the vertices and faces in memory. Refinement appends the vertices it adds, so after
// a few levels a vertex's one-ring neighbours lie far apart in the arrays: a block of 128 vertex ids
// holds under a tenth of its one rings' edges, and at two threads every phase that walks the one
// rings (smoothing, regularization, normals, curvature) reads positions the other thread has just
// written. Renumbering along a space-filling curve keeps the neighbours in the same block.

#include <cstdint>
#include <string>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/mesh.h"

namespace mvflow {

//! Renumbers the vertices of \p mesh in the Morton (Z-order) of their positions quantised to 2^21
//! steps per axis of the bounding box (ties by old id), and rebuilds the faces in the order of
//! their corners' new ids, each face's corners rotated, never reordered (orientation kept).
//! Returns the new id of each old vertex; positions and connectivity are those of the input.
//! The same mesh gives the same order on any machine and at any thread count.
//! \return empty, with \p mesh untouched, when the mesh has no vertices or a vertex that is not
//!         finite, when it carries per-element properties other than its points (status, so also
//!         deleted elements, normals, ...), which the rebuilt mesh would not have, or when OpenMesh
//!         refuses the faces in the new order (possible only for a mesh that is not a manifold).
std::vector<std::uint32_t> order_vertices_by_locality(TriMesh& mesh);

//! Applies the renumbering \p new_of_old (order_vertices_by_locality's result) to a per-vertex
//! array: element i moves to new_of_old[i].
//! \throw Error if the sizes differ.
template <typename T>
void renumber_vertices(std::vector<T>& values, const std::vector<std::uint32_t>& new_of_old) {
  MVFLOW_CHECK(values.size() == new_of_old.size(), "renumber_vertices: " + std::to_string(values.size()) +
                                                       " values for " + std::to_string(new_of_old.size()) + " vertices");
  std::vector<T> renumbered(values.size());
  for (std::size_t old = 0; old < values.size(); ++old) renumbered[new_of_old[old]] = std::move(values[old]);
  values = std::move(renumbered);
}

}  // namespace mvflow
