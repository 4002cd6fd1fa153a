#pragma once
// Tangential Laplace regularization (thesis 3.7, 3.9; SPEC §5).

#include <vector>

#include <Eigen/Core>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow {

struct RegularizationOptions {
  //! C of thesis eq. 3.9, the fraction of the tangential part of the umbrella vector applied per
  //! step; in (0, 1] (above 1 a vertex overshoots its neighbours' centroid). 0.5: unspecified in
  //! the thesis, SPEC §5 sets it.
  double strength = 0.5;
  //! Regularization steps per call of apply_regularization (per flow iteration); ≥ 0.
  int steps = 1;

  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! One Jacobi step of tangential Laplace regularization (thesis eq. 3.9 with the umbrella
//! operator 3.7): for every vertex P in \p vertices with its m neighbours Q_j and unit normal N,
//!   U = (1/m) Σ_j Q_j − P,   P' = P + C · (U − (U·N) N).
//! Only the part of U in the tangent plane is applied, so vertices spread evenly over the
//! surface without shrinking it. Vertices without a defined normal (kNormalDefined clear),
//! boundary vertices and isolated vertices keep their position.
//!
//! Reads the current mesh positions and fields.normal / fields.defined; writes
//! new_positions[v] for v in \p vertices only (Jacobi: ranges can run in parallel).
//! \param mesh          The surface, #V vertices with ids 0..#V−1 (not modified).
//! \param vertices      Range of vertex ids, within [0, #V).
//! \param fields        Per-vertex arrays sized #V with normals of the current positions.
//! \param options       Checked with check().
//! \param new_positions #V positions; the entries of \p vertices are overwritten.
//! \pre compute_normals has run on \p vertices for the current positions.
//! \throw Error if the options are invalid or the range or sizes do not match the mesh.
void regularize_tangential(const TriMesh& mesh, IndexRange vertices, const VertexFields& fields,
                           const RegularizationOptions& options, std::vector<Eigen::Vector3d>& new_positions);

//! Runs options.steps steps of regularize_tangential over the whole mesh; each step computes
//! the normals of the current positions, then the new positions into a buffer, then commits.
//! \param mesh    The surface, modified in place.
//! \param options Checked with check().
void apply_regularization(TriMesh& mesh, const RegularizationOptions& options = {});

}  // namespace mvflow
