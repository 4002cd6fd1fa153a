#pragma once
// Camera rigs for synthetic scenes: N pinhole cameras around an object, all looking at its
// centre, world +y up (the convention of the Stanford bunny and Spot).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "engine/model/camera.h"

namespace mvflow {

enum class RigKind {
  Ring,       //!< evenly spaced azimuths; elevations alternate between the min and the max
  Hemisphere  //!< a Fibonacci spiral: even coverage of the band of elevations
};

struct RigOptions {
  RigKind kind = RigKind::Ring;
  int views = 16;                 //!< number of cameras (1..1000)
  double distance = 3.0;          //!< camera to object centre, in object radii (> 1)
  double elevation_min = -10.0;   //!< degrees above the horizontal plane (−85..85)
  double elevation_max = 45.0;    //!< degrees, ≥ elevation_min
  int width = 640;                //!< image size in pixels (8..8192)
  int height = 480;
  double fov = 60.0;              //!< horizontal field of view in degrees (1..170), when focal is 0
  double focal = 0.0;             //!< focal length in pixels; 0 = from fov
  //! \throw InputError naming the field when a value is out of range.
  void check() const;
  //! The focal length in pixels (from fov when focal is 0).
  double focal_pixels() const;
};

//! A camera at \p eye looking at \p target with world \p up roughly up in the image; principal
//! point at the image centre, square pixels. \pre eye ≠ target, up not parallel to the view.
Camera look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up, double focal,
               int width, int height);

//! The rig around a sphere of \p radius at \p centre. View i is named "view_%03d.png".
std::vector<View> make_rig(const RigOptions& options, const Eigen::Vector3d& centre, double radius);

//! The name of the image of view \p index: view_000.png, view_001.png, ...
std::string synth_image_name(std::size_t index);

}  // namespace mvflow
