#pragma once
// Meshes generated in code: the shapes tests, benchmarks and synthetic scenes start from.

#include <Eigen/Core>

#include "engine/model/mesh.h"

namespace mvflow {

//! A sphere of \p radius around \p centre: the icosahedron with each face split into four
//! \p level times, vertices projected onto the sphere. #V = 10·4^level + 2, faces outward.
IndexedMesh make_icosphere(double radius, int level, const Eigen::Vector3d& centre = Eigen::Vector3d::Zero());

//! A flat square [0, size]² in the z = 0 plane, \p cells × \p cells quads split into
//! triangles, normals along +z. Open: its border is a boundary.
IndexedMesh make_grid(double size, int cells);

}  // namespace mvflow
