#pragma once
// Cutting necks thinner than the mesh resolution. Where a part of a surface is so thin that three
// edges go around it, the short one among them cannot be collapsed (the collapse would pinch the
// surface: OpenMesh's link condition) and remeshing cannot make it longer, so it stays far below
// the target length. Such a part is below the resolution of the mesh anyway: cutting the
// surface along the three-edge loop and capping both sides removes it.

#include <cstddef>

#include "engine/model/mesh.h"

namespace mvflow {

//! Repeatedly finds the first edge (in id order) shorter than \p max_edge whose two ends have a
//! common neighbour x with which they form no face — the loop (a, b, x) then goes around a
//! handle or a neck of the surface — and cuts \p mesh along that loop: every vertex of the loop
//! is split into two, one for the faces on each side of it, and each side's hole is closed with
//! one triangle. A neck cut in two leaves two pieces, of which the one with more triangles stays;
//! a handle cut open lowers the genus by one. Deterministic; at most \p max_cuts cuts.
//! \pre \p mesh is a closed manifold triangle mesh without deleted elements.
//! \post \p mesh is closed, manifold, one component if it was one; ids are contiguous. Per-vertex
//!       and per-face arrays of the old mesh no longer match.
//! \return the number of cuts made.
std::size_t cut_thin_necks(TriMesh& mesh, double max_edge, std::size_t max_cuts = 1000);

}  // namespace mvflow
