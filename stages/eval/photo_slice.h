#pragma once
// Photo consistency g sampled on a plane through the object, with the mesh's cross-section:
// the picture of the thesis's figures 5.4–5.6, and the first thing to look at to judge whether a
// scene's photo consistency is usable (a clear valley of g along the true surface).

#include <Eigen/Core>
#include <vector>

#include "engine/model/bounding_box.h"
#include "engine/model/mesh.h"
#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_views.h"
#include "stages/flow/visibility.h"

namespace mvflow {

//! Which views a point of the slice uses.
enum class SliceViews {
  NearestVertex,  //!< the visible views of the nearest mesh vertex: g as the flow sees it
  All             //!< every view whose patch fits in its image (no occlusion)
};

struct PhotoSliceOptions {
  int axis = 2;                    //!< the plane is normal to this axis (0 = x, 1 = y, 2 = z)
  double position = 0.5;           //!< where along the axis, as a fraction of the region's extent
  int resolution = 400;            //!< samples along the longer side of the region
  double margin = 0.15;            //!< the region is the mesh's box grown by this fraction per side
  SliceViews views = SliceViews::NearestVertex;
  VisibilityOptions visibility;    //!< for SliceViews::NearestVertex
  PhotoConsistencyOptions photo;
  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! The sampled plane. Sample (i, j) is at origin + i·step·u_axis + j·step·v_axis, i < width,
//! j < height; row j = 0 is the region's minimum along v_axis.
struct PhotoSlice {
  int width = 0;
  int height = 0;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d u_axis = Eigen::Vector3d::UnitX();
  Eigen::Vector3d v_axis = Eigen::Vector3d::UnitY();
  double step = 0.0;
  std::vector<double> g;             //!< #width·#height, row-major; NaN where undefined
  //! The mesh's cross-section as segments in slice coordinates (units of samples).
  std::vector<std::array<Eigen::Vector2d, 2>> cross_section;

  double at(int i, int j) const { return g[static_cast<std::size_t>(j) * width + i]; }
  Eigen::Vector3d point(double i, double j) const { return origin + step * (i * u_axis + j * v_axis); }
};

//! Samples g on the plane (parallel over rows; the result does not depend on the thread count).
//! \param mesh the current surface (closed or not); its box sets the region.
//! \throw InputError when the options are out of range or the mesh is empty.
PhotoSlice compute_photo_slice(const TriMesh& mesh, const std::vector<PhotoView>& views,
                               const PhotoSliceOptions& options = {});

//! Points where the plane {x : x[axis] = value} cuts the triangles, as 3-D segments.
std::vector<std::array<Eigen::Vector3d, 2>> plane_cross_section(const TriMesh& mesh, int axis, double value);

}  // namespace mvflow
