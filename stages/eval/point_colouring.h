#pragma once
// The colour of a surface point seen in photographs: the mean of the bilinear samples of the
// views that see it. The held-out-view error colours a mesh this way at every pixel of the camera
// it renders into, so a coarse mesh is judged by its shape and not by its vertex spacing.
// "Sees" follows the flow's visibility (stages/flow/visibility.h, SPEC §3) for one point instead of a
// patch: the point is in front of the camera, its bilinear support lies inside the image, the view
// is not grazing (n·(C − X) > cos θ_max·|C − X|), and the segment from X (offset by ε along n)
// to the camera centre hits no triangle (Embree occlusion).

#include <Eigen/Core>
#include <vector>

#include "engine/model/surface_query.h"
#include "stages/flow/photo_views.h"

namespace mvflow {

struct PointColouringOptions {
  //! Views beyond this angle between the normal and the direction to the camera do not colour
  //! the point, in degrees (0, 90]. 75°: the flow's default (SPEC §3: grazing views mix the
  //! object with the background).
  double max_angle_degrees = 75.0;
  //! The occlusion ray starts this far along the normal, × the mesh's mean edge length (≥ 0), so
  //! it does not hit the point's own face (Embree traces in float). The flow's value.
  double ray_offset = 1e-3;
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

struct PointColour {
  Eigen::Vector3f colour = Eigen::Vector3f::Zero();  //!< mean over the views that see the point; 0 if none
  int views = 0;                                     //!< how many views see it
};

//! The colour of surface point \p point from the \p views that see it, each sampled bilinearly
//! and weighted equally (summed in view order, so the result never depends on the caller's threads).
//! \param normal unit normal at \p point on the side being coloured (a face normal)
//! \param surface the mesh \p point lies on (occlusion queries)
//! \param mean_edge the mesh's mean edge length; scales options.ray_offset
//! \throw Error if the options are invalid.
PointColour colour_surface_point(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                                 const std::vector<PhotoView>& views, const SurfaceQuery& surface,
                                 double mean_edge, const PointColouringOptions& options = {});

}  // namespace mvflow
