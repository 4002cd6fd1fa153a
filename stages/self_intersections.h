#pragma once
// Counting pairs of faces that cross each other: a refined surface must not fold through itself.

#include <cstddef>

#include "engine/mesh.h"

namespace mvflow {

//! The number of unordered pairs of faces that share no vertex and intersect (an edge of one
//! passes through the other). Faces are bucketed in a uniform grid of cell size ≈ the mean edge
//! length, so the cost is about linear in the number of faces. Coplanar overlaps are not counted.
std::size_t count_self_intersections(const TriMesh& mesh);

}  // namespace mvflow
