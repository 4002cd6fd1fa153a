#pragma once
// Curvature-normal smoothing (thesis 3.10, 3.11; SPEC §5).

#include <vector>

#include <Eigen/Core>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow {

struct SmoothingOptions {
  //! λ·dt of thesis eq. 3.11, the fraction of the way to the cotangent-weighted centroid moved
  //! per step; in (0, 1). 0.1: the thesis gives no value, SPEC §5 sets it (each step shrinks a
  //! sphere of radius r by about λ·dt·e²/(2r)).
  double lambda_dt = 0.1;
  //! Smoothing steps per call of apply_smoothing (per flow iteration); ≥ 0, 0 disables.
  int steps = 1;
  //! Taubin's pass-band frequency k_PB (λ|μ smoothing, SIGGRAPH 1995): after each step a second
  //! one with the factor −μ, μ = λ·dt/(1 − k_PB·λ·dt), moves every vertex away from its
  //! centroid, so the pair removes noise without shrinking the surface (plain steps shrink thin,
  //! weakly textured parts away: README, "Defaults and differences"). 0.1, Taubin's usual value;
  //! 0 = no second step (the thesis); in [0, 1/λ·dt − 1).
  double taubin_pass_band = 0.1;
  //! μ of the second step (0 when taubin_pass_band is 0).
  double taubin_mu() const { return taubin_pass_band > 0.0 ? lambda_dt / (1.0 - taubin_pass_band * lambda_dt) : 0.0; }

  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! One Jacobi step of curvature-normal smoothing (thesis eq. 3.11 with the normalized operator
//! 3.10, sign as in SPEC §5): for every vertex P in \p vertices with neighbours Q_j and cotangent
//! weights c_j = cot α_j + cot β_j,
//!   P' = P + λ·dt · (Σ_j c_j Q_j / Σ_j c_j − P),
//! i.e. P moves toward its cotangent-weighted centroid. Single weights may be negative (obtuse
//! angles). Where a face around P is degenerate or Σ_j c_j ≤ 0 or is not finite, that centroid
//! is meaningless or far away, so the uniform centroid (1/m) Σ_j Q_j is used instead.
//! Boundary and isolated vertices keep their position.
//!
//! Reads only the current mesh positions; writes new_positions[v] for v in \p vertices only,
//! so disjoint ranges can run in parallel and the result does not depend on the ranges.
//! \param mesh          The surface, #V vertices with ids 0..#V−1 (not modified).
//! \param vertices      Range of vertex ids, within [0, #V).
//! \param options       Checked with check().
//! \param new_positions #V positions; the entries of \p vertices are overwritten.
//! \throw Error if the options are invalid or the range or buffer size does not match the mesh.
void smooth_curvature_normal(const TriMesh& mesh, IndexRange vertices, const SmoothingOptions& options,
                             std::vector<Eigen::Vector3d>& new_positions);

//! The same step with the factor −options.taubin_mu() (away from the centroid): Taubin's second
//! step. \pre options.taubin_pass_band > 0.
void inflate_curvature_normal(const TriMesh& mesh, IndexRange vertices, const SmoothingOptions& options,
                              std::vector<Eigen::Vector3d>& new_positions);

//! Runs options.steps steps of smooth_curvature_normal (each followed by
//! inflate_curvature_normal when taubin_pass_band > 0) over the whole mesh, each computed into a buffer
//! from the previous step's positions and then committed.
//! \param mesh    The surface, modified in place.
//! \param options Checked with check().
void apply_smoothing(TriMesh& mesh, const SmoothingOptions& options = {});

}  // namespace mvflow
