#pragma once
// One iteration's state vertex by vertex, as the refinement hands it to RefineControl's
// on_vertex_fields and io::write_vertex_fields writes it (`refine --dump-fields`).

#include <span>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow {

//! One iteration's per-vertex state, for diagnosing the flow vertex by vertex (where a region
//! creeps, whose speed is noise; README "Convergence"): the positions the iteration reached, before
//! the stopping rules decide (a refinement or spread at a resolution's end comes after it), and
//! what the iteration computed on its way. Valid only during the callback.
struct IterationVertexFields {
  int iteration = 0;              //!< 1-based, as IterationReport::iteration
  double time_step = 0.0;         //!< Δt of the iteration
  const TriMesh* mesh = nullptr;  //!< the positions after the iteration; its vertex ids index the rest
  //! N as the tangential regularization last computed it (at the smoothed positions); H, g and ∇g
  //! from the iteration's start; F as the vertices moved by it (averaged where g is implausible,
  //! damped, with momentum; the CFL bound clips the step, not F); the defined bits
  const VertexFields* fields = nullptr;
  std::span<const double> damping_scale;  //!< the step damping's scale per vertex; empty with damping off
  std::span<const double> moved;          //!< the length of each vertex's flow step (0 without a speed)
};

}  // namespace mvflow
