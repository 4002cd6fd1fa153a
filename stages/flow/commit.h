#pragma once
// The serial half of a Jacobi (double-buffered) update: copy the positions that the parallel
// half computed from the old state into the mesh (STYLE practice 4).

#include <vector>

#include <Eigen/Core>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/silhouette_constraint.h"

namespace mvflow {

//! Sets the position of every vertex v in \p vertices to new_positions[v].
//! Run it only after every block's new positions are computed: those reads see the old mesh.
//! \param mesh          The surface, #V vertices; positions of \p vertices are overwritten.
//! \param vertices      Range of vertex ids, within [0, #V).
//! \param new_positions #V positions (entries outside \p vertices are not read).
//! \throw Error if the range or the buffer size does not match the mesh.
//! \param inside        When given, no vertex leaves the visual hull (SilhouetteConstraint::limit_move).
void commit_positions(TriMesh& mesh, IndexRange vertices, const std::vector<Eigen::Vector3d>& new_positions,
                      const SilhouetteConstraint* inside = nullptr);

}  // namespace mvflow
