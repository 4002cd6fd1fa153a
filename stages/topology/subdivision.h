#pragma once
// Subdivision of the user's initial mesh (thesis 3.4.1 and B.2; SPEC §5): Loop, modified Loop
// with sharp edges, and modified Butterfly, on the whole mesh or on a selected set of faces.

#include <cstdint>
#include <vector>

#include "engine/model/mesh.h"

namespace mvflow {

enum class SubdivisionScheme {
  Loop,          //!< approximating, C. Loop 1987
  ModifiedLoop,  //!< approximating with sharp edges and corners, Hoppe et al. 1994
  Butterfly,     //!< interpolating, modified Butterfly of Zorin, Schröder, Sweldens 1996
};

struct SubdivisionOptions {
  SubdivisionScheme scheme = SubdivisionScheme::Loop;
  //! Quadrisection steps; ≥ 0 (0 returns a copy). Each whole-mesh step multiplies #F by 4.
  int iterations = 1;
  //! ModifiedLoop only: an edge whose dihedral angle (the angle between its two face normals)
  //! exceeds this many degrees is sharp; in [0, 180]. The thesis's tolerance `tol` (B.2) has
  //! no value; 30° keeps smooth any surface sampled with at least 12 edges per full turn
  //! (360°/12) and keeps the 90° edges of boxes and buildings sharp. It is also the common
  //! default of modelling tools (Blender's auto-smooth angle).
  double sharp_angle_degrees = 30.0;

  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! Subdivides \p mesh options.iterations times with options.scheme; each step quadrisects
//! triangles by splitting edges at new ("odd") vertices.
//!
//! Vertex ids: the old vertices keep their ids 0..#V−1 in every step; the vertex of split edge
//! i (in edge-id order among split edges) gets id #V + i, so on a whole-mesh step edge e's
//! vertex is #V + e, as in OpenMesh's uniform subdividers. Faces come in input-face order
//! (4 children per quadrisected face, 2 per bisected one, 1 per untouched one). The same input
//! gives the same output, bit for bit.
//!
//! Selected faces (thesis B.2): when \p selected_faces is given (one flag per face, non-zero =
//! selected), only those faces are quadrisected, with red–green closure to keep the mesh
//! conforming: an unselected face with one split edge is bisected (green: split vertex to the
//! opposite corner); one with two or three split edges is quadrisected too (red), which can
//! split further edges, until no face has two split edges unless it is red. Smoothing happens
//! only inside the refined region: an old vertex moves only when all its faces are
//! quadrisected, and a new vertex takes the scheme's edge mask only when every face of its
//! edge is quadrisected (else the edge midpoint). So the surface outside the quadrisected
//! faces keeps its exact shape, and vertices away from them their exact positions. In further
//! iterations the selection is the children of selected faces (not the closure).
//!
//! \param mesh           A triangle mesh, closed or with boundaries (not modified).
//! \param options        Checked with check().
//! \param selected_faces nullptr (whole mesh) or #F flags.
//! \return The subdivided mesh: closed and manifold when \p mesh is, same Euler characteristic.
//! \throw Error if the options are invalid or \p selected_faces has the wrong size.
TriMesh subdivide(const TriMesh& mesh, const SubdivisionOptions& options,
                  const std::vector<std::uint8_t>* selected_faces = nullptr);

//! One step of Loop subdivision (C. Loop, "Smooth subdivision surfaces based on triangles",
//! MS thesis, Univ. of Utah, 1987), with Loop's own weight for interior old vertices,
//!   p' = (1 − nβ) p + β Σ q_j,   β = (5/8 − (3/8 + cos(2π/n)/4)²) / n,
//! (the one OpenMesh's LoopT uses, not Warren's 3/(8n)), new vertices 3/8·(a + b) + 1/8·(c + d).
//! Boundaries: the cubic B-spline masks, (1, 6, 1)/8 for boundary vertices along the boundary
//! and (1, 1)/2 for boundary edges. A vertex with more than two boundary edges stays put.
//! \p selected_faces as in subdivide().
TriMesh loop_subdivide(const TriMesh& mesh, const std::vector<std::uint8_t>* selected_faces = nullptr);

//! One step of modified Loop subdivision (H. Hoppe, T. DeRose, T. Duchamp, M. Halstead,
//! H. Jin, J. McDonald, J. Schweitzer, W. Stuetzle, "Piecewise smooth surface reconstruction",
//! SIGGRAPH 1994). \p sharp_edges (#E flags) tags the sharp edges; boundary edges are always
//! sharp. Vertices are classed by their number s of sharp edges: smooth (s = 0) and dart
//! (s = 1) take Loop's mask, crease (s = 2) the (1, 6, 1)/8 mask along its two sharp edges,
//! corner (s ≥ 3) stays put. New vertices on sharp edges are midpoints. Simplification: on
//! every smooth edge the regular 3/8-3/8-1/8-1/8 mask is used, also next to crease and corner
//! vertices (Hoppe's special masks for those edges are not implemented); this keeps flat
//! faces flat and straight creases straight, but the surface next to a non-regular crease is
//! not exactly Hoppe's. Sharp edges hand their tag on to their two halves (\p next_sharp_edges,
//! #E of the result, if not null); new edges inside faces are smooth.
TriMesh modified_loop_subdivide(const TriMesh& mesh, const std::vector<std::uint8_t>& sharp_edges,
                                const std::vector<std::uint8_t>* selected_faces = nullptr,
                                std::vector<std::uint8_t>* next_sharp_edges = nullptr);

//! #E flags: an edge is sharp when it is a boundary edge or the angle between its two face
//! normals exceeds \p angle_degrees. Edges next to a degenerate (zero-area) face are smooth.
std::vector<std::uint8_t> sharp_edges_by_angle(const TriMesh& mesh, double angle_degrees);

//! One step of the modified Butterfly scheme (D. Zorin, P. Schröder, W. Sweldens,
//! "Interpolating subdivision for meshes with arbitrary topology", SIGGRAPH 1996). Old vertices
//! stay. New vertex on an interior edge (a, b):
//!  - a, b both regular (valence 6) or on the boundary: the butterfly stencil with tension
//!    w = 1/16 of Dyn, Gregory, Levin 1990, i.e. Zorin's 10-point stencil with w = 0:
//!    1/2·(a + b) + 1/8·(c + d) − 1/16·(four wing vertices); a wing missing because its edge
//!    is a boundary edge is replaced by its reflection across that edge (x + y − opposite);
//!  - one endpoint interior with valence K ≠ 6: that vertex's stencil 3/4·v + Σ_j s_j q_j,
//!    q_0 = the other endpoint, j around v; s = (5/12, −1/12, −1/12) for K = 3,
//!    (3/8, 0, −1/8, 0) for K = 4, s_j = (1/4 + cos(2πj/K) + cos(4πj/K)/2) / K for K ≥ 5;
//!  - both endpoints interior and extraordinary: the mean of the two stencils.
//! Boundary edges: the 4-point rule (−1, 9, 9, −1)/16 along the boundary. These are the rules
//! of OpenMesh's ModifiedButterFlyT (Zorin's boundary rules of the SIGGRAPH 2000 course notes
//! are not implemented). \p selected_faces as in subdivide().
TriMesh butterfly_subdivide(const TriMesh& mesh, const std::vector<std::uint8_t>* selected_faces = nullptr);

}  // namespace mvflow
