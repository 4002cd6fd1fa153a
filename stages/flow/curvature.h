#pragma once
// Discrete mean curvature from the cotangent Laplace–Beltrami operator (thesis 3.6, 3.10; SPEC §3).

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow {

//! The area A that turns the cotangent sum into the Laplace–Beltrami operator.
enum class CurvatureArea {
  Barycentric,  //!< one third of the faces around P: the thesis and SPEC §3
  Mixed         //!< Meyer et al. 2003 mixed Voronoi area: exact where the barycentric one is not
};

struct CurvatureOptions {
  //! Mixed by default: on icospheres the barycentric area puts H 14.5 % too high at the twelve
  //! 5-valent vertices (at every subdivision level), the mixed area within 1e-13 % (README,
  //! "Differences from the thesis"). The thesis preset uses Barycentric.
  CurvatureArea area = CurvatureArea::Mixed;
};

//! Computes the mean curvature H of every vertex in \p vertices (thesis eq. 3.6 divided by the
//! area A of options.area): with c_j = cot α_j + cot β_j for each neighbour Q_j (α_j, β_j the
//! angles opposite the edge P–Q_j) and A = one third of the areas of the faces around P
//! (Barycentric) or the mixed Voronoi area (Mixed),
//!   L(P) = (1 / (2A)) Σ_j c_j (Q_j − P) = −2 H N,   H = −(L·N) / 2,
//! so a sphere of radius r has H = +1/r with the outward normal N. Also stores the
//! unnormalized mean-curvature-normal length |Σ_j c_j (Q_j − P)| / 2 (no area division) in
//! fields.curvature_normal_length, which adaptive refinement compares with e_S/2 (SPEC §5).
//!
//! Writes fields.mean_curvature[v], fields.curvature_normal_length[v] and the
//! kCurvatureDefined bit for v in \p vertices only; reads mesh positions and fields.normal /
//! kNormalDefined of the same vertices (so compute_normals must have run on this range).
//! Undefined (bit cleared, H = 0, length = 0, never NaN) for a vertex without a defined normal,
//! with a degenerate (≈ zero-area) face around it, without faces, or on a boundary (boundary
//! vertices never move and their one ring is incomplete).
//!
//! \param mesh     The surface, #V vertices with ids 0..#V−1 (no deleted elements).
//! \param vertices Range of vertex ids to process, within [0, #V).
//! \param fields   Per-vertex arrays sized #V; inputs normal/defined, outputs as above.
//! \pre compute_normals has run on \p vertices for the current positions.
//! \throw Error if the range or the field size does not match the mesh.
void compute_mean_curvature(const TriMesh& mesh, IndexRange vertices, VertexFields& fields,
                            const CurvatureOptions& options = {});

}  // namespace mvflow
