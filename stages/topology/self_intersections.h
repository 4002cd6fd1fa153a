#pragma once
// Counting pairs of faces that cross each other: a refined surface must not fold through itself.

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "engine/model/mesh.h"

namespace mvflow {

//! The number of unordered pairs of faces that share no vertex and intersect (an edge of one
//! passes through the other). Faces are bucketed in a uniform grid of cell size ≈ the mean edge
//! length, so the cost is about linear in the number of faces. Coplanar overlaps are not counted.
std::size_t count_self_intersections(const TriMesh& mesh);

//! The pairs count_self_intersections counts, as (smaller face id, larger face id), sorted.
//! \pre \p mesh has no deleted elements (ids contiguous), as for count_self_intersections.
std::vector<std::pair<std::uint32_t, std::uint32_t>> self_intersecting_pairs(const TriMesh& mesh);

}  // namespace mvflow
