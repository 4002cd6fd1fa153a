#pragma once
// Global remeshing before the flow: one pass of edge splits, then one pass of edge collapses
// against bounds relative to the initial mesh's shortest edge (thesis 5.3.2, B.3, B.7; SPEC §5).

#include <cstddef>

#include "engine/model/mesh.h"

namespace mvflow {

struct RemeshingOptions {
  //! b_u = split_factor · e_S: edges longer than this are split at their midpoint. 2: thesis B.7.
  double split_factor = 2.0;
  //! b_l = collapse_factor · e_S: edges shorter than this are collapsed. 0.8: thesis B.7 (4/5).
  double collapse_factor = 0.8;

  //! Both factors finite, collapse_factor > 0 and split_factor ≥ 2·collapse_factor (so the halves
  //! of a split edge, longer than b_u/2, are never collapse candidates).
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! What remesh_edges did. Rejected collapses are counted once per reason (the first that failed).
struct RemeshingResult {
  std::size_t splits = 0;               //!< edges split (each into two, with its faces)
  std::size_t collapses = 0;            //!< edges collapsed
  std::size_t rejected_collapses = 0;   //!< short edges kept: the sum of the four below
  std::size_t rejected_boundary = 0;    //!< boundary edge, or both ends on the boundary
  std::size_t rejected_topology = 0;    //!< OpenMesh's is_collapse_ok (link condition) refused
  std::size_t rejected_fold_over = 0;   //!< a face around the merged vertex would flip or degenerate
  std::size_t rejected_long_edge = 0;   //!< an edge at the merged vertex would be longer than b_u
};

//! Regularizes the node density of \p mesh before the flow (thesis 5.3.2; SPEC §5), with
//! b_u = options.split_factor · e_S and b_l = options.collapse_factor · e_S:
//!  1. Split: every edge longer than b_u at the start of the call is split once at its midpoint,
//!     longest first (ties in id order); its (one or two) faces are bisected by joining the
//!     midpoint to their opposite corners. Boundary edges are split too (the new vertex lies on
//!     the straight boundary edge; no boundary vertex moves).
//!  2. Collapse: then every edge, visited once in edge-id order and measured when visited, that is
//!     shorter than b_l is replaced by one vertex at its midpoint — or at the boundary end when
//!     the other end is interior — unless that would (a) collapse a boundary edge or an interior
//!     edge between two boundary vertices, (b) break manifoldness (OpenMesh is_collapse_ok, the
//!     link condition), (c) flip or degenerate a face around the merged vertex (its normal must keep
//!     a positive dot product with its old normal and with the area-weighted normal of the two
//!     ends' rings), or (d) make an edge at the merged vertex longer than b_u. Boundary vertices
//!     therefore never move.
//! One pass each, as the thesis ("the two operators are used only once") and SPEC §5 say, so the
//! bounds b_l ≤ |e| ≤ b_u are not guaranteed afterwards. What can remain:
//!  - longer than b_u: halves of edges longer than 2·b_u, and the new edges from a midpoint to
//!    an opposite corner (about 0.87× the split edge in an equilateral triangle, more in obtuse
//!    ones; on the test's warped sphere 5.3 % of the edges, up to 1.36·b_u);
//!  - shorter than b_l: rejected collapses, and edges that a later collapse in the pass shortened
//!    after they had been visited.
//! A second call (same e_S) treats what the first left (on that sphere: 5.5 % of the edges
//! outside [b_l, b_u] after one call, 0.08 % after two).
//!
//! Serial and deterministic (edges in id order, no hash containers). Standard properties other
//! than positions (normals, colours, texture coordinates) are not computed for new elements.
//!
//! \param mesh           The surface, modified in place; closed or with boundary, manifold.
//! \param reference_edge e_S, the shortest edge of the initial mesh (world units), > 0.
//! \param options        Checked with check().
//! \pre \p mesh has no deleted elements (ids contiguous) and is a manifold triangle mesh.
//! \post Vertex, edge and face ids are again contiguous: split vertices are appended, and when
//!       something was collapsed garbage_collection ran, which fills each hole with the last
//!       element (a deterministic renumbering). Per-vertex arrays of the old mesh no longer
//!       match: rebuild them.
//!       The Euler characteristic, boundary loops and manifoldness are unchanged. The vertex,
//!       edge, halfedge and face status attributes are requested for the call and released
//!       again (OpenMesh counts requests, so a caller's own requests stay in place).
//! \throw Error if the options are invalid or \p reference_edge is not positive and finite.
RemeshingResult remesh_edges(TriMesh& mesh, double reference_edge, const RemeshingOptions& options = {});

}  // namespace mvflow
