#pragma once
// Removing the folds a refined surface can end with: pairs of nearby faces that cross each
// other (pleats a few rings wide, where neighbouring vertices moved past each other).

#include <cstddef>

#include "engine/model/mesh.h"

namespace mvflow {

struct UntanglingOptions {
  //! Rounds of find-crossing-faces-then-smooth; ≥ 0, 0 disables. 10.
  int max_rounds = 10;
  //! The smoothed region of a round: the corners of every crossing face, grown by this many
  //! vertex rings, plus one more ring per round that left crossings; ≥ 0. 1.
  int ring = 1;
  //! Uniform-Laplacian (umbrella) steps per round, each moving a region vertex this fraction of
  //! the way to the mean of its neighbours; steps ≥ 1, fraction in (0, 1]. 5 steps of 0.5: a
  //! pleat flattens while the region is only a few rings wide.
  int steps = 5;
  double fraction = 0.5;

  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

struct UntanglingResult {
  std::size_t crossing_pairs_before = 0;  //!< count_self_intersections before
  std::size_t crossing_pairs_after = 0;   //!< ... and after
  int rounds = 0;                          //!< rounds that smoothed something
  std::size_t smoothed_vertices = 0;       //!< region sizes summed over the rounds
};

//! Flattens the regions around crossing faces (self_intersecting_pairs) by umbrella smoothing
//! until no pair crosses or options.max_rounds rounds are used. Only vertices near crossing
//! faces move; boundary vertices never do. Serial and deterministic (ids in order, Jacobi steps).
//! \param mesh The surface, modified in place; its topology is not changed.
//! \pre \p mesh has no deleted elements (ids contiguous).
//! \throw Error if the options are invalid.
UntanglingResult untangle(TriMesh& mesh, const UntanglingOptions& options = {});

}  // namespace mvflow
