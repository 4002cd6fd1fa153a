#pragma once
// The visual hull (Laurentini 1994): the points of the bounding box that lie inside the object's
// silhouette in every view that sees them. Instead of a 0/1 occupancy per voxel, every grid
// sample gets an estimate of its signed distance to the hull's surface, so that the iso-surface
// at 0 (stages/hull/iso_surface.h) lands between samples where the silhouette outlines put it rather
// than on a staircase of voxel faces. The sign is exactly the carving decision.

#include <cstddef>
#include <vector>

#include "engine/model/bounding_box.h"
#include "engine/model/camera.h"
#include "stages/hull/scalar_grid.h"
#include "stages/flow/silhouette.h"

namespace mvflow {

struct VisualHullOptions {
  //! Grid samples along the longest side of the bounding box (8..1024). 128 resolves ~0.8 % of
  //! that side, finer than the edges of a 2000–3000-vertex hull mesh (about a quarter of
  //! their length on the Middlebury sets), in about 0.5 s for 16 views of 640×480 on 2 cores.
  int resolution = 128;
  //! A point seen by fewer views than this (in front of the camera and inside its image) is
  //! carved away, whatever its silhouettes say (≥ 1). With 1, the corners of the box that only
  //! one camera sees would survive as slabs bounded by that one silhouette cone; 2 removes them.
  int min_views = 2;
  //! \throw InputError naming the field when a value is out of range.
  void check() const;
};

//! A silhouette as a signed distance in pixels to its outline: > 0 inside, < 0 outside, 0 on
//! the outline, which runs along the pixel edges between object and background pixels (object
//! pixels hold their distance to the nearest background pixel centre minus ½, background pixels
//! minus their distance to the nearest object pixel centre plus ½). Sampled bilinearly.
struct SilhouetteDistance {
  int width = 0;
  int height = 0;
  std::vector<float> values;  //!< width·height, row-major

  //! The bilinear value at (u, v), pixel centres at integers, clamped to the image.
  float sample(double u, double v) const;
};

//! Exact Euclidean distance transforms of \p mask (Felzenszwalb & Huttenlocher 2012), combined
//! as SilhouetteDistance describes. A mask without any object (or background) pixel holds
//! −(or +)(width + height) everywhere.
SilhouetteDistance silhouette_distance(const Mask& mask);

//! Samples the visual hull of \p silhouettes (one per camera, of its image size) over \p box.
//!
//! The lattice has spacing h = longest side of \p box / options.resolution, is centred on the
//! box and reaches at least h beyond it on every side, so its outer layer is outside the hull and
//! the iso-surface is closed. A sample X holds
//!     f(X) = min( box(X), min over the views i that see X of s_i(u_i, v_i) · z_i / f_i )
//! clamped to ±3h, where box(X) is the signed distance to \p box (> 0 inside), s_i the
//! silhouette's SilhouetteDistance, (u_i, v_i, z_i) the projection of X and f_i the view's focal
//! length in pixels (√(fx·fy)): a pixel distance turned into a distance at X's depth. A view sees
//! X when z_i > 0 and (u_i, v_i) is inside its image; views where X falls outside the image do
//! not carve. X is kept (f > 0) when it is in the box and inside every silhouette that sees it;
//! seen by fewer than options.min_views views, it gets −3h (carved).
//!
//! Parallel over z slices (oneTBB); every sample is computed on its own, so the grid does not
//! depend on the thread count.
//! \throw InputError when the options are invalid, the box is empty or not finite, the counts
//!        of cameras and silhouettes differ, or a silhouette's size is not its camera's
//!        (naming the view).
ScalarGrid carve_visual_hull(const std::vector<Camera>& cameras, const std::vector<Mask>& silhouettes,
                             const BoundingBox& box, const VisualHullOptions& options = {});

}  // namespace mvflow
