#pragma once
// Iso-surface extraction by marching tetrahedra: the zero set of the piecewise-linear
// interpolation of a sampled field over the Kuhn (Freudenthal) split of every grid cell into six
// tetrahedra. Unlike marching cubes' lookup table, this has no ambiguous cases: the split is the
// same in every cell, so neighbouring cells agree on their shared faces, and the level set of a
// piecewise-linear function whose value at no sample equals the level is a 2-manifold without
// holes (Doi & Koide 1991; Bloomenthal 1994).

#include "engine/model/mesh.h"
#include "stages/hull/scalar_grid.h"

namespace mvflow {

struct IsoSurfaceOptions {
  //! The iso-value; a sample is inside when its value is greater (a value equal to it is outside).
  double level = 0.0;
  //! A crossing closer to a sample than this fraction of its lattice edge is moved to that
  //! fraction, so no triangle collapses to a point when a sample lies (almost) on the surface;
  //! in [0, 0.25]. The cleanup and remeshing that follow remove the short edges this leaves.
  double min_edge_fraction = 0.01;
  //! \throw InputError naming the field when a value is out of range.
  void check() const;
};

//! The surface {f = level} of \p grid: one vertex per lattice edge (axis, face-diagonal or
//! body-diagonal edge of the Kuhn split) with a sign change, where the linear interpolation
//! along it crosses the level; triangles oriented counter-clockwise seen from the outside
//! (the side where f ≤ level), i.e. outward normals when the inside is f > level.
//! Serial and deterministic: cells in lattice order, vertices numbered in order of creation.
//! \post When every sample of the grid's outer layer is outside, the result is closed and
//!       manifold (possibly several components, possibly empty).
//! \throw InputError when the options are invalid or the grid's values do not match its size.
IndexedMesh extract_iso_surface(const ScalarGrid& grid, const IsoSurfaceOptions& options = {});

}  // namespace mvflow
