#pragma once
// Adaptive refinement around high-curvature vertices: red quadrisection with a conforming
// red–green closure (thesis 5.3.1, figure 5.1, B.4, B.7; SPEC §5, §9).

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/model/mesh.h"
#include "engine/model/vertex_fields.h"

namespace mvflow {

struct AdaptiveRefinementOptions {
  //! A vertex is marked when its curvature_normal_length exceeds curvature_factor · e_S.
  //! 0.5: thesis B.7 ("the tolerance is chosen as e_S/2"). > 0.
  double curvature_factor = 0.5;
  //! A face around a marked vertex is quadrisected only if all its edges are longer than
  //! min_edge_relative × the bounding-box diagonal of the mesh. 1e-3: thesis B.4 (absolute 1e−3
  //! there; relative here, SPEC §9). ≥ 0.
  double min_edge_relative = 1e-3;
  //! ... and longer than min_edge_pixels × the pixel size at the object (the world length one
  //! pixel of the finest view covers there): below the footprint of the 5×5 photo-consistency
  //! patch the photographs cannot place the new vertices. 5 (the patch width); 0 in the thesis
  //! preset. ≥ 0. See the README, "Defaults and differences", for the measurement.
  double min_edge_pixels = 5.0;
  //! A refinement that would add fewer than min_growth × #V vertices is not done: the mesh is
  //! left unchanged (RefinementResult::declined). Coarse to fine, each refinement restarts the
  //! stopping rules, so a small one costs ≥ min_iterations more iterations of the whole mesh for a
  //! local change; declined, it ends the run. 0.1; 0 (every refinement is done) in the thesis
  //! preset. In [0, 1). README, "Defaults and differences", for the measurement.
  double min_growth = 0.1;

  //! Every value finite, curvature_factor > 0, min_edge_relative ≥ 0, min_edge_pixels ≥ 0 and
  //! 0 ≤ min_growth < 1.
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! What refine_adaptively did.
struct RefinementResult {
  std::size_t marked_vertices = 0;  //!< vertices whose curvature_normal_length exceeded the threshold
  std::size_t red_faces = 0;        //!< faces quadrisected (1 → 4), promoted ones included
  std::size_t promoted_faces = 0;   //!< of red_faces: closure faces with ≥ 2 split edges
  std::size_t green_faces = 0;      //!< closure faces bisected (1 → 2)
  std::size_t new_vertices = 0;     //!< edge midpoints added (one per split edge)
  //! The ends of the split edge of each added midpoint, in the order they were appended (new
  //! vertex #V_before + i is the midpoint of parents[i]).
  std::vector<std::array<std::uint32_t, 2>> parents;
  //! Midpoints the refinement would have added when it was declined (fewer than
  //! options.min_growth × #V; nothing was changed), else 0.
  std::size_t declined = 0;
};

//! Refines \p mesh where it is curved (thesis 5.3.1 and figure 5.1; SPEC §5):
//!  1. Mark: every vertex v with kCurvatureDefined whose fields.curvature_normal_length[v]
//!     exceeds options.curvature_factor · e_S. Every face around a marked vertex whose three
//!     edges are all longer than options.min_edge_relative · (bounding-box diagonal of \p mesh)
//!     and than options.min_edge_pixels · pixel_size becomes red.
//!  2. Close (red–green, Bank et al. 1983): every edge of a red face is split. A face that is not
//!     red but has two or three split edges is promoted to red, repeated until nothing changes
//!     (the fixed point does not depend on the visiting order). Promotion ignores the
//!     min-edge rule: it only exists to keep the mesh conforming and to avoid the thin triangles
//!     that a 1 → 3 split of a two-split face would make.
//!  3. Split: red faces are quadrisected (1 → 4, the midpoints joined); the remaining faces with
//!     exactly one split edge are green and bisected (1 → 2, the midpoint joined to the opposite
//!     corner). New vertices sit at plain edge midpoints (no smoothing: the flow moves them), so
//!     the children of a face lie in its plane and the total area is unchanged.
//! The thesis does not say what happens to the green faces of an earlier call (classic red–green
//! refinement undoes a green bisection before refining its parent again); this stage keeps no
//! state between calls, so such a face is treated like any other face. A green child that becomes
//! red again is quadrisected as it is, which can thin triangles around a region that keeps
//! growing; the tangential regularization of every iteration evens them out.
//!
//! Serial and deterministic (faces, edges and vertices in id order, no hash containers). Does
//! nothing (and returns zeros except marked_vertices) when no face qualifies, and leaves the mesh
//! unchanged (returning marked_vertices and the midpoint count in `declined`, zeros otherwise)
//! when fewer than options.min_growth × #V midpoints would be added.
//!
//! \param mesh           The surface, modified in place; closed or with boundary, manifold.
//! \param fields         Per-vertex arrays sized #V: curvature_normal_length and the
//!                       kCurvatureDefined bit of defined (compute_mean_curvature) for the current
//!                       positions; not resized here.
//! \param reference_edge e_S, the shortest edge of the initial mesh (world units), > 0.
//! \param options        Checked with check().
//! \param pixel_size     World length of one pixel at the object (photo_views.h:
//!                       finest_pixel_size); 0 when unknown (min_edge_pixels then has no effect).
//! \pre \p mesh has no deleted elements (ids contiguous); fields.size() == #V.
//! \post Vertex ids 0..#V−1 keep their vertices and positions; the midpoints follow as
//!       #V..#V+new_vertices−1 in the id order of the edges they split. Faces that were not
//!       refined keep their corners; face and edge ids are contiguous again (garbage collection),
//!       renumbered. The mesh stays conforming and manifold with the same Euler characteristic.
//!       The status attributes are requested for the call and released again.
//! \throw Error if the options are invalid, \p reference_edge is not positive and finite, the
//!        fields are not sized for the mesh, or OpenMesh rejects a child face (an internal
//!        invariant that would leave the mesh partly rebuilt; never seen on manifold input).
RefinementResult refine_adaptively(TriMesh& mesh, const VertexFields& fields, double reference_edge,
                                   const AdaptiveRefinementOptions& options = {}, double pixel_size = 0.0);

}  // namespace mvflow
