#pragma once
// Internal to mvflow_topology: red–green refinement as adaptive refinement and the subdivision
// schemes both do it. Which faces are quadrisected ("red") is the caller's choice; the closure
// makes the split conforming, and every face's children follow one pattern.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/model/mesh.h"

namespace mvflow::detail {

//! Whether edge \p e is split: a face of it is red (\p red, #F).
bool edge_is_split(const TriMesh& mesh, TriMesh::EdgeHandle e, const std::vector<std::uint8_t>& red);

//! Red–green closure over \p red (#F, 1 = quadrisected; an edge is split when a red face has it):
//! a face with two or three split edges becomes red, which splits its third edge too, until every
//! other face has at most one split edge. \return how many faces it made red.
std::size_t close_red_faces(const TriMesh& mesh, std::vector<std::uint8_t>& red);

//! A triangle's corner vertex ids.
using Corners = std::array<int, 3>;

//! The children of one face, corners counter-clockwise as the parent's.
struct ChildFaces {
  std::array<Corners, 4> faces;
  int count = 0;  //!< 4 (red), 2 (green), 1 (the face itself); 0: two split edges, a broken closure
};

//! The children of the face with corners \p c (in the face's order) whose edge from c[k] to
//! c[k+1] has the new vertex \p m[k] (−1: not split): three split edges give the three corner
//! triangles and the middle one, last; one gives two halves from the new vertex to the opposite
//! corner; none gives the face.
ChildFaces child_faces(const Corners& c, const Corners& m);

}  // namespace mvflow::detail
