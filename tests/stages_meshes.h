#pragma once
// Meshes and measurements for the stage tests: spheres (exact, noisy, tangentially jittered),
// flat grids, and the spread of a mesh's edge lengths. The icosphere itself is
// engine/model/primitives.h's make_icosphere (subdivided icosahedron projected onto the sphere), so
// the tests exercise the same generator the synthetic scenes use.

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "engine/model/mesh.h"
#include "engine/model/primitives.h"
#include "engine/model/vertex_fields.h"

namespace mvflow::test {

inline TriMesh to_trimesh(const IndexedMesh& indexed) {
  MeshBuildReport report;
  Mesh mesh = build_mesh(indexed, "test mesh", &report);
  EXPECT_EQ(report.rejected_faces, 0u);
  return std::move(mesh.topology);
}

//! Sphere of \p radius around the origin, level \p level subdivision (#V = 10·4^level + 2).
inline TriMesh icosphere(double radius, int level) {
  return to_trimesh(make_icosphere(radius, level));
}

//! The same sphere with every face's corner order reversed: normals point inward.
inline TriMesh inward_icosphere(double radius, int level) {
  IndexedMesh m = make_icosphere(radius, level);
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  return to_trimesh(m);
}

inline IndexRange all_vertices(const TriMesh& mesh) {
  return {0, static_cast<std::uint32_t>(mesh.n_vertices())};
}

inline Eigen::Vector3d position(const TriMesh& mesh, std::size_t id) {
  return to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(id))));
}

//! Uniform in [−1, 1) from the raw 64-bit Mersenne Twister output (whose sequence the standard
//! fixes), so the noise is the same with every standard library.
class Noise {
 public:
  explicit Noise(std::uint64_t seed) : engine_(seed) {}
  double symmetric() { return static_cast<double>(engine_() >> 11) * 0x1.0p-52 - 1.0; }

 private:
  std::mt19937_64 engine_;
};

//! Scales each vertex's distance from the origin by (1 + amplitude·u), u uniform in [−1, 1).
inline void add_radial_noise(TriMesh& mesh, double amplitude, std::uint64_t seed) {
  Noise noise(seed);
  for (auto v : mesh.vertices()) mesh.set_point(v, mesh.point(v) * (1.0 + amplitude * noise.symmetric()));
}

//! Moves each vertex of a sphere of \p radius around the origin by a random tangential offset
//! of length ≤ \p amplitude and projects it back onto the sphere: an irregular sphere.
inline void jitter_on_sphere(TriMesh& mesh, double radius, double amplitude, std::uint64_t seed) {
  Noise noise(seed);
  for (auto v : mesh.vertices()) {
    const Eigen::Vector3d p = to_eigen(mesh.point(v));
    Eigen::Vector3d d(noise.symmetric(), noise.symmetric(), noise.symmetric());
    const Eigen::Vector3d n = p.normalized();
    d -= d.dot(n) * n;
    const Eigen::Vector3d moved = p + amplitude / std::sqrt(3.0) * d;
    mesh.set_point(v, to_openmesh(radius * moved.normalized()));
  }
}

//! RMS of (|P| − radius) over the vertices: distance to the true sphere.
inline double rms_sphere_distance(const TriMesh& mesh, double radius) {
  double sum = 0.0;
  for (auto v : mesh.vertices()) {
    const double d = mesh.point(v).norm() - radius;
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(mesh.n_vertices()));
}

struct EdgeSpread {
  double mean = 0.0;
  double stddev = 0.0;
};

inline EdgeSpread edge_spread(const TriMesh& mesh) {
  double sum = 0.0, sum2 = 0.0;
  for (auto e : mesh.edges()) {
    const double l = mesh.calc_edge_length(e);
    sum += l;
    sum2 += l * l;
  }
  const double n = static_cast<double>(mesh.n_edges());
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean))};
}

}  // namespace mvflow::test
