#pragma once
// Keeps a moving surface inside the visual hull of its silhouettes: a point that projects
// outside the object's silhouette in a view where it falls inside the image cannot lie on the
// object. Used by the refinement when the photographs have a background that separates from the
// object (e.g. the Middlebury sets' black), where the flow's curvature terms would otherwise push
// concave, textureless parts outward beyond the silhouettes.

#include <Eigen/Core>
#include <vector>

#include "stages/flow/photo_views.h"
#include "stages/flow/silhouette.h"

namespace mvflow {

class SilhouetteConstraint {
 public:
  //! One mask per view, of that view's size. Both must outlive the constraint.
  //! \throw Error when the counts or sizes differ.
  SilhouetteConstraint(const std::vector<PhotoView>& views, std::vector<Mask> masks);

  //! False when \p X projects, in front of a camera and inside its image (nearest pixel), onto
  //! that view's background.
  bool admits(const Eigen::Vector3d& X) const;

  //! Where a vertex at \p from may go on its way to \p to: \p to when admitted; otherwise the
  //! farthest admitted point of to's halving steps toward \p from (5 halvings), else \p from.
  //! A vertex already outside the hull (\p from not admitted) moves freely: the constraint only
  //! stops the surface from leaving the hull, never holds it outside.
  Eigen::Vector3d limit_move(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const;

 private:
  const std::vector<PhotoView>& views_;
  std::vector<Mask> masks_;
};

//! Silhouettes of every view by thresholding its image (stages/flow/silhouette.h).
std::vector<Mask> threshold_silhouettes(const std::vector<PhotoView>& views, const SilhouetteOptions& options);

}  // namespace mvflow
