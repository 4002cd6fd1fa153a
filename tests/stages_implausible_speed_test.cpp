// The speed of a region of implausibly high g averaged over its rings
// (stages/flow/implausible_speed.h), against fields whose answer is known.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/primitives.h"
#include "stages/flow/implausible_speed.h"

namespace mvflow {
namespace {

// A 12 × 12 grid in z = 0: every inner vertex's ring is centrally symmetric (its six neighbours
// come in opposite pairs), so a one-ring mean of a linear field is the field at the vertex.
struct Grid {
  TriMesh mesh = build_mesh(make_grid(1.2, 12), "grid").topology;
  VertexFields fields;
  std::vector<std::uint8_t> flagged;
  Grid() {
    fields.resize(mesh.n_vertices(), 1);
    flagged.assign(mesh.n_vertices(), 0);
    for (auto v : mesh.vertices()) fields.defined[v.idx()] = kSpeedDefined;
  }
  Eigen::Vector3d at(TriMesh::VertexHandle v) const { return to_eigen(mesh.point(v)); }
  // The square [0.4, 0.8]², far enough (≥ 4 rings) from the border for two rounds.
  bool central(TriMesh::VertexHandle v) const {
    const Eigen::Vector3d p = at(v);
    return p.x() > 0.35 && p.x() < 0.85 && p.y() > 0.35 && p.y() < 0.85;
  }
};

Eigen::Vector3d linear_speed(const Eigen::Vector3d& p) { return Eigen::Vector3d(0.0, 0.0, 0.25 + 0.5 * p.x() - 0.75 * p.y()); }

TEST(ImplausibleSpeed, KeepsTheRegionsCommonMotionAndAveragesItsNoise) {
  Grid grid;
  // A linear field everywhere, and on the flagged square a noise of ±1 that alternates from one
  // vertex to the next along x: the sign noise of the background showing through.
  std::size_t flagged = 0;
  for (auto v : grid.mesh.vertices()) {
    const auto i = static_cast<std::size_t>(v.idx());
    grid.fields.speed[i] = linear_speed(grid.at(v));
    if (grid.central(v)) {
      grid.flagged[i] = 1;
      ++flagged;
      const int column = static_cast<int>(std::lround(grid.at(v).x() / 0.1));
      grid.fields.speed[i].z() += column % 2 == 0 ? 1.0 : -1.0;
    }
  }
  const VertexFields before = grid.fields;
  ImplausibleSpeedOptions options;
  options.rings = 2;
  EXPECT_EQ(average_implausible_speeds(grid.mesh, grid.flagged, options, grid.fields), flagged);
  double worst_noise = 0.0;
  for (auto v : grid.mesh.vertices()) {
    const auto i = static_cast<std::size_t>(v.idx());
    if (!grid.flagged[i]) {
      EXPECT_EQ(grid.fields.speed[i], before.speed[i]) << i;  // untouched, to the bit
      continue;
    }
    worst_noise = std::max(worst_noise, std::abs(grid.fields.speed[i].z() - linear_speed(grid.at(v)).z()));
  }
  // A closed one-ring holds 3 values of the vertex's sign and 4 of the other (the neighbours along
  // x and on the diagonal lie in the next columns), so a round leaves −1/7 of the noise and two
  // 1/49; at the square's edge, whose outer neighbours carry none, 5/49 (0.102) at most.
  EXPECT_LT(worst_noise, 0.103);
  EXPECT_GT(worst_noise, 0.0);

  // Without noise the linear field comes back (each ring is symmetric, so each round keeps it).
  Grid clean;
  for (auto v : clean.mesh.vertices()) {
    clean.fields.speed[v.idx()] = linear_speed(clean.at(v));
    clean.flagged[v.idx()] = clean.central(v);
  }
  average_implausible_speeds(clean.mesh, clean.flagged, options, clean.fields);
  for (auto v : clean.mesh.vertices())
    EXPECT_NEAR(clean.fields.speed[v.idx()].z(), linear_speed(clean.at(v)).z(), 1e-14) << v.idx();
}

// One round by hand: the mean over the vertex and its neighbours with a speed, as the round
// found them (a flagged neighbour's too, not its new mean); a neighbour without one (its speed
// NaN here) is skipped; 0 rings change nothing.
TEST(ImplausibleSpeed, OneRoundIsTheMeanOverTheNeighboursWithASpeed) {
  Grid grid;
  TriMesh::VertexHandle centre;
  for (auto v : grid.mesh.vertices())
    if ((grid.at(v) - Eigen::Vector3d(0.6, 0.6, 0.0)).norm() < 1e-9) centre = v;
  ASSERT_TRUE(centre.is_valid());
  for (auto v : grid.mesh.vertices()) grid.fields.speed[v.idx()] = Eigen::Vector3d(0, 0, 10.0 * v.idx());
  grid.flagged[centre.idx()] = 1;
  std::vector<int> neighbours;
  for (auto w : grid.mesh.vv_range(centre)) neighbours.push_back(w.idx());
  ASSERT_EQ(neighbours.size(), 6u);
  grid.fields.defined[neighbours[0]] = 0;
  grid.fields.speed[neighbours[0]] = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double expected = 10.0 * centre.idx();
  for (std::size_t k = 1; k < neighbours.size(); ++k) expected += 10.0 * neighbours[k];
  expected /= 6.0;
  // A flagged neighbour: its mean reads the centre's speed before the round.
  const auto other = TriMesh::VertexHandle(neighbours[1]);
  grid.flagged[other.idx()] = 1;
  double other_expected = 0.0;
  int other_count = 0;
  for (const auto v : {other, centre}) {
    other_expected += 10.0 * v.idx();
    ++other_count;
  }
  for (auto w : grid.mesh.vv_range(other))
    if (w != centre && grid.fields.defined[w.idx()] & kSpeedDefined) {
      other_expected += 10.0 * w.idx();
      ++other_count;
    }
  other_expected /= other_count;

  VertexFields off = grid.fields;
  ImplausibleSpeedOptions options;
  options.rings = 0;
  EXPECT_EQ(average_implausible_speeds(grid.mesh, grid.flagged, options, off), 0u);
  EXPECT_EQ(off.speed[centre.idx()].z(), 10.0 * centre.idx());
  options.rings = 1;
  EXPECT_EQ(average_implausible_speeds(grid.mesh, grid.flagged, options, grid.fields), 2u);
  EXPECT_NEAR(grid.fields.speed[centre.idx()].z(), expected, 1e-12);
  EXPECT_NEAR(grid.fields.speed[other.idx()].z(), other_expected, 1e-12);

  options.rings = -1;
  EXPECT_THROW(options.check(), Error);
  options.rings = 17;
  EXPECT_THROW(options.check(), Error);
  options.rings = 1;
  const std::vector<std::uint8_t> short_flags(3, 0);
  EXPECT_THROW(average_implausible_speeds(grid.mesh, short_flags, options, grid.fields), Error);
}

}  // namespace
}  // namespace mvflow
