#pragma once
// Vertex normals weighted by inverse face area (thesis 3.1, 3.2; SPEC §3).

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow {

//! Computes the outward unit normal of every vertex in \p vertices:
//! N = normalize(Σ_j w_j n_j) over the faces j around the vertex, n_j the unit face normal
//! (counter-clockwise corners seen from outside), w_j = 2 / |(P2−P1)×(P3−P1)| (inverse area).
//! Small faces weigh more, so the normal follows the local fine geometry.
//!
//! Writes fields.normal[v] and the kNormalDefined bit of fields.defined[v] for v in
//! \p vertices only; reads only mesh positions and connectivity, so disjoint ranges can run in
//! parallel and the result does not depend on how the vertices are cut into ranges.
//! An isolated vertex, a vertex with a degenerate (≈ zero-area) face around it, or one whose
//! weighted sum vanishes gets normal = 0 with the bit cleared; never NaN.
//! Boundary vertices get the normal of the faces they have.
//!
//! \param mesh     The surface, #V vertices with ids 0..#V−1 (no deleted elements).
//! \param vertices Range of vertex ids to process, within [0, #V).
//! \param fields   Per-vertex arrays sized #V (VertexFields::resize); outputs for \p vertices.
//! \pre fields.size() == mesh.n_vertices().
//! \throw Error if the range or the field size does not match the mesh.
void compute_normals(const TriMesh& mesh, IndexRange vertices, VertexFields& fields);

}  // namespace mvflow
