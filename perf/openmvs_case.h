#pragma once
// The peer comparison of mvflow_bench: OpenMVS RefineMesh (CPU, 2 threads) refines a textured
// unit sphere seen by 24 views of 640×480 from 2 562 to 7 147 vertices in about 37 s, its mean
// radial error going from 0.040 to 0.0027. Here the same-sized case: mvflow's bumpy sphere with
// no bumps (a unit sphere) and its solid texture, 24 ring views of 640×480, an initial mesh of
// 2 562 vertices pushed out to a mean radial error of 0.040, refined with the default options
// until a stopping rule fires. Rendering is not timed; `perf/openmvs_case.sh` times the
// whole `mvflow refine` command (with image decoding) on the same scene.

#include <Eigen/Core>
#include <vector>

#include "perf/bench_table.h"

namespace mvflow::perf {

struct OpenMvsCaseSettings {
  std::vector<int> threads{2, 1};
  double initial_error = 0.040;  //!< mean radial error of the initial mesh (the peer's start)
};

//! Mean over the vertices of | |p| − 1 |: the radial error against the unit sphere at the origin.
double mean_radial_error(const std::vector<Eigen::Vector3d>& positions);

//! One row per thread count. \throw Error when the refinement fails, or (when \p validate) when
//! the error does not fall or the thread counts disagree bit for bit.
std::vector<Row> run_openmvs_case(const OpenMvsCaseSettings& settings, bool validate);

}  // namespace mvflow::perf
