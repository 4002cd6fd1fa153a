#pragma once
// The shapes of synthetic scenes: built-in closed surfaces generated in code, and any closed
// mesh normalized to a unit-size box at the origin.

#include <Eigen/Core>
#include <string>

#include "engine/model/mesh.h"

namespace mvflow {

struct BuiltinShapeOptions {
  int level = 5;           //!< icosphere subdivision level: 10·4^level + 2 vertices (1..7)
  double amplitude = 0.08;  //!< bump height relative to the radius (0 = smooth; 0..0.5)
  double frequency = 5.0;   //!< bumps per radian along each axis (> 0, at most 40)
  double waist = 0.3;       //!< peanut: radius at the waist relative to the ends (0.2..1)
  //! \throw InputError naming the field when a value is out of range.
  void check() const;
};

//! A unit sphere at the origin displaced radially by r = 1 + amplitude·b(p), with the smooth
//! bump field b(p) = sin(f·x)·sin(f·y)·sin(f·z) + ... of the unit direction p. Closed, genus 0.
IndexedMesh make_bumpy_sphere(const BuiltinShapeOptions& options);

//! A peanut along x: a star-shaped radius r(p) = waist + (1 − waist)·x² of the unit direction
//! p (concave around the waist when waist < 0.67), plus the same bumps. Closed, genus 0, at
//! most 1 + amplitude from the origin.
IndexedMesh make_peanut(const BuiltinShapeOptions& options);

//! How a mesh was moved into the unit box: p' = scale · (p − centre).
struct Normalization {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double scale = 1.0;
};

//! Moves \p mesh so its bounding box is centred at the origin with its longest side 2.
//! \throw InputError when the mesh is empty or flat in every direction.
Normalization normalize_to_unit_box(IndexedMesh& mesh);

//! Gives every extra fan of faces around a vertex its own copy of the vertex (a "pinched"
//! vertex where two cones of a closed surface touch, as in cow.obj), so the mesh becomes
//! manifold without moving any point. \return the number of vertices added.
std::size_t split_pinched_vertices(IndexedMesh& mesh);

//! The largest distance of a vertex from the origin (the object radius used to place cameras).
double radius_about_origin(const IndexedMesh& mesh);

}  // namespace mvflow
