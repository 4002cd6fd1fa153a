#pragma once
// Silhouette rims: where the surface grazes a view (its normal perpendicular to the view's ray)
// and nothing hides it, it makes that view's outline, so its projection belongs on the
// silhouette's boundary. The flow's curvature terms erode thin parts there and leave bloated
// parts of a visual hull, because patches that straddle object and background give g no
// direction. The rims move each such vertex along its normal toward the boundary, past a dead
// zone of the masks' pixel precision (finer than that is the photo consistency's job). Not in
// the thesis (README, "Defaults and differences"). It needs silhouettes, i.e. photographs
// whose background separates from the object: by default it runs when every view's border is
// dark (dark_background), as with the Middlebury sets.

#include <Eigen/Core>
#include <vector>

#include "engine/model/mesh.h"
#include "engine/model/surface_query.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/photo_views.h"
#include "stages/flow/silhouette.h"

namespace mvflow {

enum class RimFit {
  Off,
  On,
  Auto,  //!< on when every view's border is background (dark_background) or the scene has masks
};

struct SilhouetteRimOptions {
  RimFit fit = RimFit::Auto;
  //! A vertex is a rim of a view when the angle between its normal and the view's ray is within
  //! this of 90°. 8°: 15° gained more on the photographs but made the black-background spot
  //! worse (README, "Quality" and "Real photographs").
  double rim_angle_degrees = 8.0;
  //! Boundaries nearer than this many pixels are left to the photo consistency: a thresholded
  //! mask is exact only to a pixel. 1: 0 made two black-background scenes worse, 2 gained less
  //! on the temple (README).
  double dead_zone_pixels = 1.0;
  //! The boundary is looked for this many pixels along the projected normal, both ways (> the dead zone).
  double search_pixels = 4.0;
  //! The fraction of the distance to the boundary moved per iteration, in (0, 1]. 0.2: 0.5
  //! gained more on the temple and less on the dino and three of the four black-background
  //! scenes (README).
  double step = 0.2;
  //! The occlusion ray starts this far out along N, relative to the mean edge: a rim's ray grazes
  //! its own faces.
  double ray_offset = 0.5;
  //! Holes in a silhouette up to this fraction of the image are filled (deep shadows), as
  //! `mvflow hull` does by default.
  double fill_holes = 0.005;
  //! RimFit::Auto: a view's border counts as background when at least this fraction of its
  //! pixels is at or below the silhouette threshold.
  double dark_border_fraction = 0.95;
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! True when, in every view, at least \p fraction of the pixels on the image's border have no
//! channel above \p threshold: a dark background all round, so thresholds give silhouettes.
bool dark_background(const std::vector<PhotoView>& views, double threshold, double fraction);

//! Whether the rims are fitted: options.fit, with Auto decided by dark_background.
bool fits_rims(const std::vector<PhotoView>& views, double threshold, const SilhouetteRimOptions& options);

//! The silhouettes the rims are fitted to: one mask per view (thresholded, holes up to
//! options.fill_holes filled; no dilation).
std::vector<Mask> rim_silhouettes(const std::vector<PhotoView>& views, const SilhouetteOptions& threshold,
                                  const SilhouetteRimOptions& options);

//! The signed move along \p N (world units, + outward) that brings \p X's projections toward the
//! silhouette boundary in every view where X is an unoccluded rim, averaged over those views
//! and scaled by options.step; 0 where X is a rim of no view or every boundary lies within the
//! dead zone. \p surface answers the occlusion test (the current mesh; nullptr: none).
//! \p rim_views, when given, receives the number of views whose outline X makes (within the
//! search, dead zone or not): the silhouettes observe X.
double rim_move(const Eigen::Vector3d& X, const Eigen::Vector3d& N, const std::vector<PhotoView>& views,
                const std::vector<Mask>& masks, const SurfaceQuery* surface, double mean_edge,
                const SilhouetteRimOptions& options, int* rim_views = nullptr);

//! new_positions[v] = P + rim_move(P, N)·N for every vertex of \p vertices with a normal (the
//! others keep P). Reads fields.normal. \p on_rim, when given (one flag per vertex), gets 1 where
//! the vertex makes some view's outline (rim_move's rim_views > 0), 0 elsewhere in \p vertices.
void fit_silhouette_rims(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                         const std::vector<Mask>& masks, const SurfaceQuery* surface, double mean_edge,
                         const SilhouetteRimOptions& options, const VertexFields& fields,
                         std::vector<Eigen::Vector3d>& new_positions, std::vector<std::uint8_t>* on_rim = nullptr);

}  // namespace mvflow
