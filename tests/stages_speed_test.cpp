// Speed, block reductions, CFL step and Euler move (SPEC §3, §4).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "stages/flow/speed.h"
#include "stages_meshes.h"

namespace mvflow {
namespace {

constexpr std::uint8_t all_inputs = kPhotoDefined | kGradientDefined | kNormalDefined | kCurvatureDefined;

VertexFields hand_made_fields() {
  VertexFields fields;
  fields.resize(2, 0);
  fields.normal[0] = Eigen::Vector3d(0, 0, 1);
  fields.photo_consistency[0] = 2.0;
  fields.mean_curvature[0] = 3.0;
  fields.photo_gradient[0] = Eigen::Vector3d(1.0, 2.0, 0.5);
  fields.normal[1] = Eigen::Vector3d(0.6, 0.0, 0.8);
  fields.photo_consistency[1] = 0.25;
  fields.mean_curvature[1] = -4.0;
  fields.photo_gradient[1] = Eigen::Vector3d(-1.0, 7.0, 2.0);
  fields.defined[0] = fields.defined[1] = all_inputs;
  return fields;
}

TEST(SpeedOptions, DefaultIsTheThesisInitialSpeed) {
  EXPECT_NO_THROW(SpeedOptions{}.check());
  EXPECT_EQ(SpeedOptions{}.velocity, 0.001);
  EXPECT_THROW(SpeedOptions{.velocity = std::nan("")}.check(), OptionError);
}

TEST(Speed, FollowsTheFlowEquation) {
  VertexFields fields = hand_made_fields();
  compute_speed({0, 2}, {}, fields);
  // Vertex 0: g(v+H) + ∇g·N = 2·3.001 + 0.5 = 6.502, F = −6.502 N.
  EXPECT_TRUE(fields.defined[0] & kSpeedDefined);
  EXPECT_NEAR((fields.speed[0] - Eigen::Vector3d(0, 0, -6.502)).norm(), 0.0, 1e-14);
  // Vertex 1: 0.25·(0.001 − 4) + (−1·0.6 + 7·0 + 2·0.8) = −0.99975 + 1.0 = 0.00025.
  const double normal_speed = 0.25 * (0.001 - 4.0) + (-1.0 * 0.6 + 2.0 * 0.8);
  EXPECT_NEAR((fields.speed[1] - (-normal_speed) * Eigen::Vector3d(0.6, 0.0, 0.8)).norm(), 0.0, 1e-15);
  // Moves along −N when g > 0 on a convex surface with a flat g (shrinks).
  fields.photo_gradient[0].setZero();
  compute_speed({0, 1}, {.velocity = 0.0}, fields);
  EXPECT_NEAR(fields.speed[0].z(), -6.0, 1e-15);
}

TEST(Speed, IsZeroAndUndefinedWhenAnyInputIsMissing) {
  for (const std::uint8_t missing : {kPhotoDefined, kGradientDefined, kNormalDefined, kCurvatureDefined}) {
    VertexFields fields = hand_made_fields();
    fields.defined[0] = static_cast<std::uint8_t>((all_inputs | kSpeedDefined) & ~missing);
    fields.speed[0] = Eigen::Vector3d(9, 9, 9);  // stale value from an earlier iteration
    compute_speed({0, 2}, {}, fields);
    EXPECT_EQ(fields.speed[0], Eigen::Vector3d::Zero());
    EXPECT_FALSE(fields.defined[0] & kSpeedDefined);
    EXPECT_TRUE(fields.defined[1] & kSpeedDefined);
  }
  VertexFields fields = hand_made_fields();
  fields.photo_consistency[0] = std::numeric_limits<double>::infinity();
  compute_speed({0, 1}, {}, fields);
  EXPECT_EQ(fields.speed[0], Eigen::Vector3d::Zero());
  EXPECT_FALSE(fields.defined[0] & kSpeedDefined);
}

VertexFields random_fields(std::size_t n) {
  VertexFields fields;
  fields.resize(n, 0);
  test::Noise noise(42);
  for (std::size_t v = 0; v < n; ++v) {
    fields.photo_consistency[v] = 1.0 + noise.symmetric();
    fields.speed[v] = Eigen::Vector3d(noise.symmetric(), noise.symmetric(), noise.symmetric());
    fields.defined[v] = (v % 5 ? kPhotoDefined : 0) | (v % 3 ? kSpeedDefined : 0);
  }
  return fields;
}

TEST(Reduction, CombinesPartialsInBlockOrder) {
  const VertexFields fields = random_fields(1000);
  const auto blocks = split_into_blocks(1000, 64);
  std::vector<BlockPartial> partials;
  for (const IndexRange b : blocks) partials.push_back(reduce_block(b, fields));
  const BlockPartial total = combine(partials);
  // The same partial list always gives the same value.
  const BlockPartial again = combine(partials);
  EXPECT_EQ(total.sum_g, again.sum_g);
  EXPECT_EQ(total.max_speed, again.max_speed);
  // It equals a plain sequential sum over the same block structure: each block's g in id
  // order, then the block sums in block order.
  double sum = 0.0, max_speed = 0.0;
  std::size_t count = 0;
  for (const IndexRange b : blocks) {
    double block_sum = 0.0;
    for (std::uint32_t v = b.begin; v < b.end; ++v) {
      if (fields.defined[v] & kPhotoDefined) block_sum += fields.photo_consistency[v], ++count;
      if (fields.defined[v] & kSpeedDefined) max_speed = std::max(max_speed, fields.speed[v].norm());
    }
    sum += block_sum;
  }
  EXPECT_EQ(total.sum_g, sum);
  EXPECT_EQ(total.max_speed, max_speed);
  EXPECT_EQ(total.defined_g, count);
  EXPECT_EQ(count, 800u);
  // Other block sizes: the max and count are exact, the sum equal up to rounding.
  for (const std::size_t size : {1u, 7u, 1000u}) {
    std::vector<BlockPartial> other;
    for (const IndexRange b : split_into_blocks(1000, size)) other.push_back(reduce_block(b, fields));
    const BlockPartial t = combine(other);
    EXPECT_EQ(t.max_speed, total.max_speed);
    EXPECT_EQ(t.defined_g, total.defined_g);
    EXPECT_NEAR(t.sum_g, total.sum_g, 1e-12 * total.sum_g);
  }
  EXPECT_EQ(combine({}).sum_g, 0.0);
}

TEST(Cfl, FastestVertexMovesCflTimesHalfTheShortestEdgeOverRootThree) {
  for (const double cfl : {1.0, 0.5}) {
    const double e_min = 0.1, max_speed = 3.0;
    const double dt = cfl_time_step(e_min, max_speed, cfl);
    EXPECT_NEAR(dt * max_speed, cfl * e_min / (2.0 * std::sqrt(3.0)), 1e-16);
  }
  EXPECT_EQ(cfl_time_step(0.1, 0.0), 0.0);
  EXPECT_THROW(cfl_time_step(0.0, 1.0), Error);
  EXPECT_THROW(cfl_time_step(0.1, -1.0), Error);
  EXPECT_THROW(cfl_time_step(0.1, std::numeric_limits<double>::infinity()), Error);
  EXPECT_THROW(cfl_time_step(0.1, 1.0, 0.0), Error);
}

TEST(Move, AppliesEulerStepToDefinedInteriorVerticesOnly) {
  TriMesh mesh = test::to_trimesh(make_grid(1.0, 4));
  const TriMesh before = mesh;
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    fields.speed[v] = Eigen::Vector3d(0.0, 0.0, 1.0 + static_cast<double>(v));
    fields.defined[v] = v == 12 ? 0 : kSpeedDefined;  // 12 is the centre: interior, undefined
  }
  // Moving in blocks of 7 is the same as moving everything at once.
  for (const IndexRange b : split_into_blocks(mesh.n_vertices(), 7)) move_vertices(mesh, b, fields, 0.25);
  std::size_t moved = 0;
  for (auto v : mesh.vertices()) {
    const auto id = static_cast<std::size_t>(v.idx());
    if (mesh.is_boundary(v) || id == 12) {
      EXPECT_EQ(mesh.point(v), before.point(v)) << id;
    } else {
      ++moved;
      EXPECT_EQ(mesh.point(v)[2], 0.25 * (1.0 + static_cast<double>(id)));
      EXPECT_EQ(mesh.point(v)[0], before.point(v)[0]);
    }
  }
  EXPECT_EQ(moved, 8u);
  EXPECT_THROW(move_vertices(mesh, test::all_vertices(mesh), fields, -1.0), Error);
  // The median over moving vertices: interior ids 6,7,8,11,13,16,17,18 → speeds id+1.
  EXPECT_EQ(median_speed(mesh, fields), 0.5 * (12.0 + 14.0));
}

TEST(Move, LimitsEachVertexToADistanceOrAFractionOfItsOwnShortestEdge) {
  // make_grid(1.0, 4): a 5×5 grid of spacing 0.25 (every vertex's shortest edge), interior
  // vertices 6..8, 11..13, 16..18; speeds grow with the id.
  TriMesh mesh = test::to_trimesh(make_grid(1.0, 4));
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    fields.speed[v] = Eigen::Vector3d(0.0, 0.0, 1.0 + static_cast<double>(v));
    fields.defined[v] = kSpeedDefined;
  }
  compute_local_edges(mesh, test::all_vertices(mesh), fields);
  for (auto v : mesh.vertices()) {  // against an independent walk over the edges
    double shortest = std::numeric_limits<double>::infinity();
    for (auto e : mesh.edges())
      if (mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)) == v || mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)) == v)
        shortest = std::min(shortest, mesh.calc_edge_length(e));
    EXPECT_DOUBLE_EQ(fields.local_edge[static_cast<std::size_t>(v.idx())], shortest);
  }
  const TriMesh before = mesh;
  TriMesh by_distance = mesh;
  const double dt = 0.01;  // dt·|F| = 0.07 .. 0.19 for the interior ids
  move_vertices(mesh, test::all_vertices(mesh), fields, dt, MoveLimit{.local_edge_fraction = 0.4});  // 0.1
  move_vertices(by_distance, test::all_vertices(by_distance), fields, dt, MoveLimit{.distance = 0.12});
  for (auto v : mesh.vertices()) {
    if (mesh.is_boundary(v)) continue;
    const double free_move = dt * (1.0 + v.idx());
    EXPECT_DOUBLE_EQ(mesh.point(v)[2] - before.point(v)[2], std::min(free_move, 0.4 * 0.25)) << v.idx();
    EXPECT_DOUBLE_EQ(by_distance.point(v)[2] - before.point(v)[2], std::min(free_move, 0.12)) << v.idx();
  }
  EXPECT_THROW(move_vertices(mesh, test::all_vertices(mesh), fields, dt, MoveLimit{.distance = 0.0}), Error);
}

TEST(Speed, QuantileOfTheMovingVertices) {
  TriMesh mesh = test::to_trimesh(make_grid(1.0, 4));
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    fields.speed[v] = Eigen::Vector3d(1.0 + static_cast<double>(v), 0.0, 0.0);
    fields.defined[v] = kSpeedDefined;
  }
  // Interior speeds (id + 1), sorted: 7 8 9 12 13 14 17 18 19 (n = 9; boundary vertices never
  // move).
  EXPECT_EQ(speed_quantile(mesh, fields, 1.0), 19.0);
  EXPECT_EQ(speed_quantile(mesh, fields, 0.9), 19.0);   // rank ceil(8.1) − 1 = 8
  EXPECT_EQ(speed_quantile(mesh, fields, 0.75), 17.0);  // rank ceil(6.75) − 1 = 6
  EXPECT_EQ(speed_quantile(mesh, fields, 0.5), 13.0);   // rank ceil(4.5) − 1 = 4
  EXPECT_EQ(speed_quantile(mesh, fields, 0.01), 7.0);
  EXPECT_THROW(speed_quantile(mesh, fields, 0.0), Error);
}

}  // namespace
}  // namespace mvflow
