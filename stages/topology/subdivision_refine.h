#pragma once
// Internal to the subdivision stage: the quadrisection shared by all schemes. A scheme supplies
// two rules (new position of an old vertex, position of an edge's new vertex); refine() decides
// which faces are split (red–green closure on a selection), calls the rules where smoothing is
// allowed and rebuilds the connectivity.

#include <cstdint>
#include <functional>
#include <vector>

#include "engine/model/mesh.h"

namespace mvflow::subdivision_detail {

using VertexRule = std::function<TriMesh::Point(const TriMesh&, TriMesh::VertexHandle)>;
using EdgeRule = std::function<TriMesh::Point(const TriMesh&, TriMesh::EdgeHandle)>;

struct StepOutput {
  TriMesh mesh;
  std::vector<std::uint8_t> selected;  //!< #F of mesh: children of selected faces (empty if no selection)
  std::vector<std::uint8_t> sharp;     //!< #E of mesh: halves of sharp edges (empty if no tags given)
};

//! One quadrisection step (see subdivide() in stages/topology/subdivision.h for the selection rules).
//! \param selected #F flags or nullptr (all faces); \param sharp #E tags to hand on, or nullptr.
StepOutput refine(const TriMesh& mesh, const std::vector<std::uint8_t>* selected,
                  const std::vector<std::uint8_t>* sharp, const VertexRule& even, const EdgeRule& odd);

//! Loop (sharp = boundary edges only) or modified Loop step; \p sharp is #E.
StepOutput loop_step(const TriMesh& mesh, const std::vector<std::uint8_t>& sharp,
                     const std::vector<std::uint8_t>* selected, bool hand_on_sharp);
//! Modified Butterfly step.
StepOutput butterfly_step(const TriMesh& mesh, const std::vector<std::uint8_t>* selected);

//! #E flags: the boundary edges.
std::vector<std::uint8_t> boundary_edges(const TriMesh& mesh);

}  // namespace mvflow::subdivision_detail
