#include "stages/flow/silhouette_constraint.h"

#include <cmath>

#include "engine/model/error.h"

namespace mvflow {

SilhouetteConstraint::SilhouetteConstraint(const std::vector<PhotoView>& views, std::vector<Mask> masks)
    : views_(views), masks_(std::move(masks)) {
  MVFLOW_CHECK(masks_.size() == views_.size(), "silhouette constraint: one mask per view");
  for (std::size_t i = 0; i < views_.size(); ++i)
    MVFLOW_CHECK(masks_[i].width == views_[i].width && masks_[i].height == views_[i].height,
                 "silhouette constraint: a mask differs in size from its view");
}

bool SilhouetteConstraint::admits(const Eigen::Vector3d& X) const {
  for (std::size_t i = 0; i < views_.size(); ++i) {
    const Projection p = views_[i].project(X);
    // Behind the camera or outside the image (NaN included): this view says nothing.
    if (!(p.depth > 0) || !views_[i].camera->in_image(p.u, p.v)) continue;
    const long x = std::lround(p.u), y = std::lround(p.v);
    if (x < 0 || y < 0 || x >= masks_[i].width || y >= masks_[i].height) continue;
    if (!masks_[i].at(static_cast<int>(x), static_cast<int>(y))) return false;
  }
  return true;
}

Eigen::Vector3d SilhouetteConstraint::limit_move(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const {
  if (admits(to) || !admits(from)) return to;
  Eigen::Vector3d step = to - from;
  for (int halving = 0; halving < 5; ++halving) {
    step *= 0.5;
    if (admits(from + step)) return from + step;
  }
  return from;
}

std::vector<Mask> threshold_silhouettes(const std::vector<PhotoView>& views, const SilhouetteOptions& options) {
  std::vector<Mask> masks;
  masks.reserve(views.size());
  for (const PhotoView& view : views) masks.push_back(threshold_silhouette(*view.image, options));
  return masks;
}

}  // namespace mvflow
