#pragma once
// Per-vertex step damping: a vertex whose speed along its normal reverses between iterations has
// stepped across the minimum of g, so its next steps are halved; while it keeps its direction
// they grow back to the CFL step (README, "Defaults and differences").
//
// Why: near convergence the CFL step is set by a few fast vertices whose ∇g·N flips sign every
// iteration (noise around the minimum of g). They jitter at the CFL distance while the rest of
// the surface creeps, and the jitter keeps Σg and the per-iteration moves from settling. Damping
// only the reversing vertices removes the jitter and leaves every other vertex's step alone; the
// scale never exceeds 1, so no vertex moves farther than the CFL bound allows. The whole speed
// is scaled, so the surface's equilibrium (F = 0) is unchanged: damping only the photo term
// −(∇g·N)N tips the balance g·(v + H) = −∇g·N toward the shrinking curvature term, and on the
// photographs the held-out gain against the hull fell from 23.2 % / 13.6 % to 18.6 % / 7.8 %.

#include <vector>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow {

struct StepDampingOptions {
  //! Whether to damp at all. true (default); false in the thesis preset (plain forward Euler).
  bool enabled = true;
  //! The factor a reversing vertex's step scale is multiplied by; in (0, 1). 0.5.
  double shrink = 0.5;
  //! The factor after an iteration without a reversal, up to 1; ≥ 1. 1.25 (as the global step
  //! control, RefineOptions::step_control).
  double grow = 1.25;
  //! The smallest scale; in (0, 1]. 0.125: three reversals in a row.
  double min_scale = 0.125;

  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! What the damping remembers per vertex between iterations of one topology.
struct StepDampingState {
  std::vector<double> scale;         //!< the fraction of its step a vertex takes, in [min_scale, 1]
  std::vector<double> normal_speed;  //!< F·N of the last iteration with a defined speed; 0 = none

  //! Every vertex at the full step with no history (a new topology, or other images).
  void reset(std::size_t n_vertices);
};

//! For every vertex v in \p vertices with kSpeedDefined: updates its scale from the sign of its
//! speed along its normal s = F·N against the last one p (s·p < 0 multiplies the scale by shrink,
//! not below min_scale; s·p > 0 by grow, not above 1), then F ← scale·F. A vertex without a
//! defined speed forgets its direction (p = 0) and keeps its scale. Run after the CFL step is set
//! (the step follows the undamped speeds) and before the move. Each vertex reads and writes only
//! its own entries, so blocks may run in any order.
//! \throw Error if the state or the fields are not sized for the range.
void damp_speeds(IndexRange vertices, const StepDampingOptions& options, VertexFields& fields, StepDampingState& state);

}  // namespace mvflow
