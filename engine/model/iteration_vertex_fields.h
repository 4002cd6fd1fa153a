#pragma once
// One iteration's state vertex by vertex, as the refinement hands it to RefineControl's
// on_vertex_fields and io::write_vertex_fields writes it (`refine --dump-fields`).

#include <span>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow {

//! One iteration's per-vertex state, for diagnosing the flow vertex by vertex (where a region
//! creeps, whose speed is noise; README "Convergence"). Passed between iterations, before the
//! stopping rules decide (a refinement or spread at a resolution's end comes after it); valid only
//! during the call.
struct IterationVertexFields {
  int iteration = 0;              //!< 1-based, as IterationReport::iteration
  double time_step = 0.0;         //!< Δt of the iteration
  const TriMesh* mesh = nullptr;  //!< the positions the iteration reached; its vertex ids index the rest
  //! What the iteration computed at the positions it started from (the previous call's, unless a
  //! refinement or spread came between): H, g, ∇g, F, the defined bits; N as the tangential
  //! regularization last recomputed it (at the smoothed positions)
  const VertexFields* fields = nullptr;
  //! F·N as each vertex moved by it: after the step damping and momentum (and, where g is
  //! implausible, the ring means), N the normal F was built along; 0 without a speed
  std::span<const double> moving_speed;
  std::span<const double> damping_scale;  //!< the step damping's scale per vertex; empty with damping off
  std::span<const double> moved;          //!< the length of each vertex's flow step, after the CFL bound
};

}  // namespace mvflow
