#pragma once
// Per-vertex step momentum (heavy ball with restart): a vertex that keeps moving the same way
// along its normal carries a fraction of its last whole step into the next one (README,
// "Convergence").
//
// Why: far from the photo-consistent surface the time step is set by the fast tenth of the
// vertices (straddling and occluded patches, steep ∇g near the surface), while the median vertex
// moves a sixteenth of its CFL distance per iteration: a broken initial mesh or a coarse level's
// waist approaches for 50–100 iterations. Carrying β of the last step multiplies a steady
// approach by up to 1/(1 − β) without touching the fast vertices' CFL bound. It is the whole
// step (flow, smoothing, regularization, rims) that is carried, not the flow's move alone, so a
// surface at rest (last step 0) is a rest point still: wherever the surface comes to rest, the
// flow and the smoothing balance there as they do without momentum (carrying the flow's move
// alone would scale the flow against the smoothing). Momentum that opposes this iteration's speed is
// dropped (the gradient restart of O'Donoghue & Candès, 2015): a vertex crossing the minimum of
// g stops at once instead of overshooting, and the step damping takes over.

#include <vector>

#include <Eigen/Core>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow {

struct StepMomentumOptions {
  //! β, the fraction of a vertex's last whole step along its normal added to its next step while
  //! that agrees with the speed; in [0, 1), 0 = off (the thesis preset). 0.7: over the 32
  //! synthetic scenes (three runs each) 0.976× the error of β = 0, the longest run 161 iterations
  //! instead of 196, issue 12's item 5 on every sphere run; 0.5 / 0.6 / 0.85 gave 0.983 / 0.981 /
  //! 0.973 and missed item 5 on some runs (README, "Convergence").
  double carry = 0.7;

  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! For every vertex v in \p vertices with kSpeedDefined: with s = last_step[v]·N(v), the normal
//! part of its last whole step, and F·N(v) of the same sign, F ← F + (carry·s / time_step)·N(v),
//! so that the move time_step·F gains carry·s along the normal (the move's CFL limit still
//! applies to the sum). Vertices whose last step opposes their speed, or without a defined
//! speed, are left as they are. Run after the step damping and before the move. Each vertex
//! reads and writes only its own entries, so blocks may run in any order.
//! \param last_step #V displacements (the whole last iteration's, this topology's), or empty:
//!                  nothing to carry (the first iteration of a topology).
//! \throw Error if time_step ≤ 0 or not finite, or the sizes do not match.
void carry_momentum(IndexRange vertices, const StepMomentumOptions& options, double time_step,
                    const std::vector<Eigen::Vector3d>& last_step, VertexFields& fields);

}  // namespace mvflow
