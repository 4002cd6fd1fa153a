// Crossing faces and their removal: self_intersecting_pairs against an independent brute-force
// predicate (signed volumes instead of Möller–Trumbore, every pair instead of a grid), and
// untangle on spheres with pleats pushed into them.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <set>
#include <utility>
#include <vector>

#include "engine/model/error.h"
#include "stages/topology/self_intersections.h"
#include "stages/topology/untangling.h"
#include "stages_meshes.h"

namespace mvflow {
namespace {

using Pairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;
using Corners = std::array<Eigen::Vector3d, 3>;

double orient(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  return (b - a).cross(c - a).dot(d - a);
}

// Segment pq passes through the interior of triangle abc: p and q strictly on opposite sides of
// its plane, and the line pq strictly inside the three edges' wedges (same sign of all three).
bool segment_through(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Corners& t) {
  const double sp = orient(t[0], t[1], t[2], p), sq = orient(t[0], t[1], t[2], q);
  if (!(sp * sq < 0)) return false;
  const double e0 = orient(p, q, t[0], t[1]), e1 = orient(p, q, t[1], t[2]), e2 = orient(p, q, t[2], t[0]);
  return (e0 > 0 && e1 > 0 && e2 > 0) || (e0 < 0 && e1 < 0 && e2 < 0);
}

Pairs brute_force_pairs(const TriMesh& mesh) {
  std::vector<Corners> corners;
  std::vector<std::array<int, 3>> ids;
  for (auto f : mesh.faces()) {
    Corners c;
    std::array<int, 3> id{};
    int k = 0;
    for (auto v : mesh.fv_range(f)) {
      c[k] = to_eigen(mesh.point(v));
      id[k++] = v.idx();
    }
    corners.push_back(c);
    ids.push_back(id);
  }
  Pairs pairs;
  for (std::uint32_t f = 0; f < corners.size(); ++f)
    for (std::uint32_t g = f + 1; g < corners.size(); ++g) {
      bool shared = false;
      for (int a : ids[f])
        for (int b : ids[g]) shared |= a == b;
      if (shared) continue;
      bool cross = false;
      for (int k = 0; k < 3 && !cross; ++k)
        cross = segment_through(corners[f][k], corners[f][(k + 1) % 3], corners[g]) ||
                segment_through(corners[g][k], corners[g][(k + 1) % 3], corners[f]);
      if (cross) pairs.emplace_back(f, g);
    }
  return pairs;
}

// A pleat: vertex v of a unit icosphere is pushed `tangential` mean edges along the surface
// and `inward` mean edges below it, so the fan of faces stretched behind it dives under the
// faces it passed.
void pleat(TriMesh& mesh, int v, double tangential, double inward) {
  const double edge = test::edge_spread(mesh).mean;
  const Eigen::Vector3d p = test::position(mesh, static_cast<std::size_t>(v));
  const Eigen::Vector3d n = p.normalized();
  const Eigen::Vector3d t = n.cross(Eigen::Vector3d::UnitZ().cross(n).norm() > 0.1 ? Eigen::Vector3d::UnitZ()
                                                                                   : Eigen::Vector3d::UnitX())
                                .normalized();
  mesh.set_point(TriMesh::VertexHandle(v), to_openmesh(p + tangential * edge * t - inward * edge * n));
}

// Vertices within `rings` vertex rings of the given faces' corners.
std::set<int> near(const TriMesh& mesh, const Pairs& pairs, int rings) {
  std::set<int> in;
  for (const auto& [f, g] : pairs)
    for (const std::uint32_t face : {f, g})
      for (auto v : mesh.fv_range(TriMesh::FaceHandle(static_cast<int>(face)))) in.insert(v.idx());
  for (int r = 0; r < rings; ++r) {
    std::set<int> grown = in;
    for (int v : in)
      for (auto w : mesh.vv_range(TriMesh::VertexHandle(v))) grown.insert(w.idx());
    in.swap(grown);
  }
  return in;
}

TEST(SelfIntersections, EqualBruteForceOnPleatedSpheres) {
  std::size_t crossing_meshes = 0;
  for (const double tangential : {0.0, 1.2, 2.0, 3.0})
    for (const double inward : {0.0, 0.3, 0.8}) {
      TriMesh mesh = test::icosphere(1.0, 2);
      pleat(mesh, 17, tangential, inward);
      pleat(mesh, 101, tangential, inward);
      const Pairs expected = brute_force_pairs(mesh);
      EXPECT_EQ(self_intersecting_pairs(mesh), expected) << tangential << " " << inward;
      EXPECT_EQ(count_self_intersections(mesh), expected.size());
      crossing_meshes += !expected.empty();
      std::printf("[measured] pleat %.1f / %.1f edges: %zu crossing pairs\n", tangential, inward, expected.size());
    }
  std::printf("[measured] %zu of 12 pleated spheres have crossing faces\n", crossing_meshes);
  EXPECT_GE(crossing_meshes, 3u);  // the comparison covers crossings, not only clean meshes
  EXPECT_TRUE(self_intersecting_pairs(test::icosphere(1.0, 3)).empty());
}

TEST(Untangling, RemovesPleatsAndMovesOnlyVerticesNearThem) {
  const UntanglingOptions options;
  for (const auto& [tangential, inward] : {std::pair{2.0, 0.3}, std::pair{3.0, 0.3}, std::pair{2.5, 0.4}}) {
    TriMesh mesh = test::icosphere(1.0, 3);
    pleat(mesh, 40, tangential, inward);
    pleat(mesh, 500, tangential, inward);
    const TriMesh before = mesh;
    const Pairs crossing = self_intersecting_pairs(mesh);
    ASSERT_FALSE(crossing.empty()) << tangential;

    const UntanglingResult r = untangle(mesh, options);
    std::printf("[measured] pleat %.1f / %.1f edges: %zu -> %zu crossing pairs in %d rounds, %zu vertices smoothed\n",
                tangential, inward, r.crossing_pairs_before, r.crossing_pairs_after, r.rounds, r.smoothed_vertices);
    EXPECT_EQ(r.crossing_pairs_before, crossing.size());
    EXPECT_EQ(r.crossing_pairs_after, 0u);
    EXPECT_EQ(brute_force_pairs(mesh).size(), 0u);
    EXPECT_GE(r.rounds, 1);
    // Nothing moves beyond the largest region the rounds may use (ring + rounds − 1 rings, and
    // the crossing faces of later rounds lie within the earlier regions' reach: one ring more).
    const std::set<int> reach = near(before, crossing, options.ring + r.rounds);
    for (auto v : mesh.vertices()) {
      if (!reach.count(v.idx())) {
        EXPECT_EQ(mesh.point(v), before.point(v)) << v.idx();
      }
    }
    EXPECT_LT(reach.size(), mesh.n_vertices() / 4);
    EXPECT_EQ(mesh.n_faces(), before.n_faces());
  }
}

TEST(Untangling, LeavesAMeshWithoutCrossingsBitForBit) {
  TriMesh mesh = test::icosphere(1.0, 3);
  test::add_radial_noise(mesh, 0.01, 3);
  const TriMesh before = mesh;
  const UntanglingResult r = untangle(mesh);
  EXPECT_EQ(r.crossing_pairs_before, 0u);
  EXPECT_EQ(r.rounds, 0);
  EXPECT_EQ(positions_of(mesh), positions_of(before));
}

TEST(Untangling, NeverMovesBoundaryVertices) {
  // An icosphere opened around a vertex two rings from the pleat, so that the untangled region
  // reaches the hole's rim.
  const TriMesh closed = test::icosphere(1.0, 3);
  const int pleated = 40;
  std::set<int> ring1, ring2;
  for (auto w : closed.vv_range(TriMesh::VertexHandle(pleated))) ring1.insert(w.idx());
  for (int v : ring1)
    for (auto w : closed.vv_range(TriMesh::VertexHandle(v)))
      if (w.idx() != pleated && !ring1.count(w.idx())) ring2.insert(w.idx());
  const int removed = *ring2.begin();
  IndexedMesh indexed = make_icosphere(1.0, 3);
  std::erase_if(indexed.triangles, [&](const auto& t) { return std::find(t.begin(), t.end(), removed) != t.end(); });
  TriMesh mesh = test::to_trimesh(indexed);
  pleat(mesh, pleated, 2.5, 0.4);
  const TriMesh before = mesh;
  const std::size_t crossing = count_self_intersections(mesh);
  ASSERT_GT(crossing, 0u);

  const UntanglingResult r = untangle(mesh);
  std::printf("[measured] open sphere: %zu -> %zu crossing pairs in %d rounds\n", r.crossing_pairs_before,
              r.crossing_pairs_after, r.rounds);
  std::size_t boundary = 0, boundary_in_reach = 0;
  const std::set<int> reach = near(before, self_intersecting_pairs(before), UntanglingOptions{}.ring + r.rounds);
  for (auto v : mesh.vertices()) {
    if (!mesh.is_boundary(v)) continue;
    ++boundary;
    boundary_in_reach += reach.count(v.idx());
    EXPECT_EQ(mesh.point(v), before.point(v)) << v.idx();
  }
  EXPECT_GT(boundary, 0u);
  EXPECT_GT(boundary_in_reach, 0u);  // the test would pass trivially if the rim were out of reach
  EXPECT_LT(r.crossing_pairs_after, r.crossing_pairs_before);
}

TEST(Untangling, ChecksItsOptionsAndZeroRoundsChangesNothing) {
  TriMesh mesh = test::icosphere(1.0, 3);
  pleat(mesh, 40, 3.0, 0.3);
  ASSERT_GT(count_self_intersections(mesh), 0u);
  const TriMesh before = mesh;
  const UntanglingResult none = untangle(mesh, {.max_rounds = 0});
  EXPECT_EQ(none.rounds, 0);
  EXPECT_EQ(none.crossing_pairs_after, none.crossing_pairs_before);
  EXPECT_GT(none.crossing_pairs_before, 0u);
  EXPECT_EQ(positions_of(mesh), positions_of(before));
  EXPECT_THROW(untangle(mesh, {.steps = 0}), Error);
  EXPECT_THROW(untangle(mesh, {.fraction = 1.5}), Error);
  EXPECT_THROW(untangle(mesh, {.max_rounds = -1}), Error);
  EXPECT_THROW(untangle(mesh, {.ring = -1}), Error);
}

}  // namespace
}  // namespace mvflow
