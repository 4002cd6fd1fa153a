// Vertex order for locality: the renumbering keeps the surface (same points, same oriented
// triangles up to the renumbering), is a permutation, is its own fixed point, and puts the one
// rings into the same vertex blocks where a shuffled order scatters them.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include <OpenMesh/Tools/Utils/MeshCheckerT.hh>

#include "engine/model/error.h"
#include "stages/topology/vertex_order.h"
#include "stages_meshes.h"

namespace mvflow {
namespace {

using Triangle = std::array<std::uint32_t, 3>;

// The triangles with each one's lowest corner first (a rotation: orientation kept), as a set.
std::set<Triangle> oriented_triangles(const TriMesh& mesh, const std::vector<std::uint32_t>* new_of_old = nullptr) {
  std::set<Triangle> triangles;
  for (Triangle t : triangles_of(mesh)) {
    if (new_of_old)
      for (auto& corner : t) corner = (*new_of_old)[corner];
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    triangles.insert(t);
  }
  return triangles;
}

// The share of edges whose two ends lie in the same block of 128 consecutive ids (the engine's
// default block size).
double same_block_edges(const TriMesh& mesh) {
  std::size_t same = 0;
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    same += mesh.from_vertex_handle(h).idx() / 128 == mesh.to_vertex_handle(h).idx() / 128;
  }
  return static_cast<double>(same) / static_cast<double>(mesh.n_edges());
}

// An icosphere whose vertex ids are shuffled by a fixed permutation.
TriMesh shuffled_icosphere(int level) {
  IndexedMesh sphere = make_icosphere(1.0, level);
  std::vector<std::uint32_t> to(sphere.positions.size());
  std::iota(to.begin(), to.end(), 0u);
  test::Noise noise(7);
  for (std::size_t i = to.size(); i > 1; --i)
    std::swap(to[i - 1], to[static_cast<std::size_t>((noise.symmetric() + 1.0) / 2.0 * static_cast<double>(i)) % i]);
  IndexedMesh shuffled = sphere;
  for (std::size_t v = 0; v < to.size(); ++v) shuffled.positions[to[v]] = sphere.positions[v];
  for (auto& t : shuffled.triangles)
    for (auto& corner : t) corner = to[corner];
  return test::to_trimesh(shuffled);
}

TEST(VertexOrder, KeepsTheSurfaceAndRenumbersByAPermutation) {
  TriMesh mesh = shuffled_icosphere(4);
  const TriMesh before = mesh;
  const std::vector<std::uint32_t> new_of_old = order_vertices_by_locality(mesh);
  ASSERT_EQ(new_of_old.size(), before.n_vertices());
  std::vector<std::uint32_t> sorted = new_of_old;
  std::sort(sorted.begin(), sorted.end());
  for (std::uint32_t v = 0; v < sorted.size(); ++v) ASSERT_EQ(sorted[v], v) << "not a permutation";

  ASSERT_EQ(mesh.n_vertices(), before.n_vertices());
  ASSERT_EQ(mesh.n_faces(), before.n_faces());
  for (std::uint32_t v = 0; v < new_of_old.size(); ++v)
    EXPECT_EQ(test::position(mesh, new_of_old[v]), test::position(before, v)) << "vertex " << v;
  EXPECT_EQ(oriented_triangles(mesh), oriented_triangles(before, &new_of_old));
  EXPECT_EQ(mesh.n_edges(), before.n_edges());
  for (auto v : mesh.vertices()) EXPECT_FALSE(mesh.is_boundary(v));
  // Every link consistent: next/prev, opposites, each vertex's and face's halfedge.
  EXPECT_TRUE(OpenMesh::Utils::MeshCheckerT<TriMesh>(mesh).check());
}

TEST(VertexOrder, PutsOneRingsIntoTheSameBlocks) {
  TriMesh mesh = shuffled_icosphere(5);  // 10 242 vertices, 80 blocks
  const double shuffled = same_block_edges(mesh);
  order_vertices_by_locality(mesh);
  const double ordered = same_block_edges(mesh);
  EXPECT_LT(shuffled, 0.05);
  EXPECT_GT(ordered, 0.6) << "shuffled " << shuffled;
}

// The triangles in face order, each with its lowest corner first.
std::vector<Triangle> rotated_triangles(const TriMesh& mesh) {
  std::vector<Triangle> triangles = triangles_of(mesh);
  for (Triangle& t : triangles) std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return triangles;
}

TEST(VertexOrder, IsItsOwnFixedPointAndIndependentOfTheInputOrder) {
  TriMesh a = shuffled_icosphere(3);
  TriMesh b = test::icosphere(1.0, 3);
  order_vertices_by_locality(a);
  order_vertices_by_locality(b);
  // The order depends on the positions only: both numberings of the same sphere end the same,
  // the faces sorted by their corners (lowest first).
  EXPECT_EQ(positions_of(a), positions_of(b));
  const std::vector<Triangle> faces = rotated_triangles(a);
  EXPECT_EQ(faces, rotated_triangles(b));
  EXPECT_TRUE(std::is_sorted(faces.begin(), faces.end()));
  // Ordering an ordered mesh changes nothing.
  const std::vector<Triangle> before = triangles_of(a);
  const std::vector<std::uint32_t> again = order_vertices_by_locality(a);
  for (std::uint32_t v = 0; v < again.size(); ++v) ASSERT_EQ(again[v], v);
  EXPECT_EQ(triangles_of(a), before);
}

TEST(VertexOrder, LeavesAMeshWithOtherPropertiesUntouched) {
  TriMesh mesh = shuffled_icosphere(2);
  mesh.request_vertex_status();  // a property the renumbering would not carry along
  const std::vector<Eigen::Vector3d> before = positions_of(mesh);
  EXPECT_TRUE(order_vertices_by_locality(mesh).empty());
  EXPECT_EQ(positions_of(mesh), before);
  mesh.release_vertex_status();  // released, it carries nothing: renumbered again
  EXPECT_EQ(order_vertices_by_locality(mesh).size(), before.size());
}

TEST(VertexOrder, LeavesAMeshWithANonFiniteVertexUntouched) {
  TriMesh mesh = shuffled_icosphere(2);
  mesh.set_point(TriMesh::VertexHandle(5), OpenMesh::Vec3d(std::nan(""), 0.0, 0.0));
  const std::vector<Triangle> before = triangles_of(mesh);
  EXPECT_TRUE(order_vertices_by_locality(mesh).empty());
  EXPECT_EQ(triangles_of(mesh), before);
  EXPECT_TRUE(std::isnan(mesh.point(TriMesh::VertexHandle(5))[0]));
}

TEST(VertexOrder, KeepsAnOpenMeshOpenAndAnEmptyMeshEmpty) {
  IndexedMesh grid;  // a 3×3 grid of vertices, 8 triangles, with a border
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) grid.positions.emplace_back(x, y, 0.0);
  for (std::uint32_t y = 0; y < 2; ++y)
    for (std::uint32_t x = 0; x < 2; ++x) {
      const std::uint32_t v = 3 * y + x;
      grid.triangles.push_back({v, v + 1, v + 4});
      grid.triangles.push_back({v, v + 4, v + 3});
    }
  TriMesh mesh = test::to_trimesh(grid);
  const TriMesh before = mesh;
  const std::vector<std::uint32_t> new_of_old = order_vertices_by_locality(mesh);
  ASSERT_EQ(new_of_old.size(), 9u);
  EXPECT_EQ(oriented_triangles(mesh), oriented_triangles(before, &new_of_old));
  EXPECT_TRUE(OpenMesh::Utils::MeshCheckerT<TriMesh>(mesh).check());
  for (std::uint32_t v = 0; v < 9; ++v)
    EXPECT_EQ(mesh.is_boundary(TriMesh::VertexHandle(static_cast<int>(new_of_old[v]))),
              before.is_boundary(TriMesh::VertexHandle(static_cast<int>(v))));

  TriMesh empty;
  EXPECT_TRUE(order_vertices_by_locality(empty).empty());
  EXPECT_EQ(empty.n_vertices(), 0u);
}

TEST(VertexOrder, RenumbersAPerVertexArray) {
  std::vector<std::string> names{"a", "b", "c", "d"};
  renumber_vertices(names, {2, 0, 3, 1});
  EXPECT_EQ(names, (std::vector<std::string>{"b", "d", "a", "c"}));
  EXPECT_THROW(renumber_vertices(names, {0, 1}), Error);
}

}  // namespace
}  // namespace mvflow
