#pragma once
// Visibility of a vertex in each view (SPEC §3): the vertex is in front of the camera, its
// patch with its bilinear support lies inside the image, the view is not grazing
// (N·(C − P) > cos θ_max·|C − P|), and the segment from P (offset by ε along N) to the camera
// centre hits no triangle (Embree occlusion; the thesis used an OpenGL depth buffer, §9).

#include <vector>

#include "engine/model/mesh.h"
#include "engine/model/surface_query.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/photo_views.h"

namespace mvflow {

struct VisibilityOptions {
  //! Views beyond this angle between N and the direction to the camera are not used. 75° by
  //! default (SPEC §3: grazing patches mix object and background); the thesis preset uses 90°.
  double max_angle_degrees = 75.0;
  //! Half size of the photo-consistency patch whose support must lie inside the image.
  int half_patch = 2;
  //! The occlusion ray starts this far along N, relative to the mesh's mean edge length, so it
  //! does not hit the vertex's own faces (Embree traces in float).
  double ray_offset = 1e-3;
  //! Views between this angle and max_angle_degrees are used only to reach min_views (the
  //! closest to the normal first): oblique views foreshorten and mix shading, so they are a last
  //! resort, not a peer. 45° with 3 views (README, "Defaults and differences": better on the
  //! three synthetic scenes and on both photograph sets than 60° or none); ≥ max_angle_degrees:
  //! every view up to max_angle_degrees counts (the thesis preset).
  double preferred_angle_degrees = 45.0;
  int min_views = 3;  //!< see preferred_angle_degrees; ≥ 2
  //! View selection (Duan et al.): of the visible views at most this many are kept, those closest
  //! to the normal (the smallest angle; the lower view index on a tie), in view order. 0 keeps
  //! all (the thesis).
  int max_views = 0;
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! Fills visible_views / visible_count for the vertices of \p vertices, in view order.
//! \pre fields.normal is computed for those vertices; a vertex without a defined normal sees
//!      no view. \p surface is the current mesh (refitted); \p mean_edge scales the ray offset.
void compute_visibility(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                        const SurfaceQuery& surface, double mean_edge, const VisibilityOptions& options,
                        VertexFields& fields);

}  // namespace mvflow
