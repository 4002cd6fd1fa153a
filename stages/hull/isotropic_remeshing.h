#pragma once
// Isotropic remeshing (Botsch & Kobbelt, "A remeshing approach to multiresolution modeling",
// SGP 2004): near-equilateral triangles with edges close to one target length, kept on a
// reference surface. The refiner's global split/collapse works against the initial mesh's
// shortest edge, so an initial mesh needs edges of nearly one length.

#include <cstddef>

#include "engine/model/mesh.h"
#include "engine/model/surface_query.h"

namespace mvflow {

struct IsotropicRemeshingOptions {
  //! Target edge length L in world units, > 0. Edges longer than 4/3·L are split and edges
  //! shorter than 4/5·L collapsed: Botsch & Kobbelt's bounds, under which neither operation
  //! makes an edge that the other would undo.
  double target_edge = 0.0;
  //! Rounds of split, collapse, flip, relax and project (≥ 0). 10: enough for the edge lengths
  //! to settle starting from a decimated mesh of about the target density.
  int iterations = 10;
  //! \throw InputError naming the field when a value is out of range.
  void check() const;
};

//! What remesh_isotropic did, summed over the rounds.
struct IsotropicRemeshingResult {
  std::size_t splits = 0;
  std::size_t collapses = 0;
  std::size_t flips = 0;
};

//! Each round: (1) split every edge longer than 4/3·L at its midpoint, until none is;
//! (2) visit the edges in id order and collapse each one shorter than 4/5·L into one of its
//! ends, unless that would break manifoldness (OpenMesh's link condition), make an edge longer
//! than 4/3·L, or flip or degenerate a face (the end of lower valence goes, as in pmp-library);
//! (3) flip every edge whose flip brings the valences of its four vertices closer to 6 without
//! turning either triangle over; (4) move every vertex towards the centroid of its neighbours
//! within its tangent plane, then onto the closest point of \p reference.
//!
//! Serial topology changes in id order and a Jacobi relaxation (parallel, each vertex computed
//! on its own), so the result does not depend on the thread count.
//! \param mesh      A closed manifold triangle mesh, changed in place; it stays closed and
//!                  manifold, with the same Euler characteristic.
//! \param reference The surface to stay on (e.g. the mesh before it was decimated).
//! \post Vertex, edge and face ids are contiguous (garbage collected).
//! \throw InputError when the options are invalid.
IsotropicRemeshingResult remesh_isotropic(TriMesh& mesh, const SurfaceQuery& reference,
                                          const IsotropicRemeshingOptions& options);

//! The edge length at which an equilateral closed mesh of \p area has about \p vertices
//! vertices (F ≈ 2V triangles of area √3/4·L²): L = √(2·area / (√3·vertices)).
double edge_length_for_vertices(double area, std::size_t vertices);

}  // namespace mvflow
