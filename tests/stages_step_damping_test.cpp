// Per-vertex step damping and momentum and the net move along the normal (issue 12: convergence
// that tells drift from progress): hand-made speeds, an analytic stiff case, and spheres moved by
// known amounts.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "stages/flow/net_move.h"
#include "stages/flow/speed.h"  // compute_local_edges, median_of
#include "stages/flow/step_damping.h"
#include "stages/flow/step_momentum.h"
#include "stages/flow/stopping.h"
#include "stages_meshes.h"

namespace mvflow {
namespace {

using test::all_vertices;
using test::icosphere;

// One vertex at height x on the z axis whose speed is the photo term alone, F = −(∇g·N)N with
// ∇g = k·x·N (N = +z, g = 0): the flow of the energy k·x²/2, whose forward Euler step
// x ← (1 − dt·k)·x diverges for dt·k > 2.
struct StiffVertex {
  VertexFields fields;
  double x = 1.0;
  explicit StiffVertex() { fields.resize(1, 0); fields.normal[0] = Eigen::Vector3d::UnitZ(); }
  void set_speed(double k) {
    fields.photo_gradient[0] = k * x * fields.normal[0];
    fields.speed[0] = -fields.photo_gradient[0].dot(fields.normal[0]) * fields.normal[0];
    fields.defined[0] = kSpeedDefined;
  }
};

TEST(StepDamping, OptionsAreChecked) {
  EXPECT_NO_THROW(StepDampingOptions{}.check());
  EXPECT_THROW((StepDampingOptions{.shrink = 1.0}).check(), OptionError);
  EXPECT_THROW((StepDampingOptions{.shrink = 0.0}).check(), OptionError);
  EXPECT_THROW((StepDampingOptions{.grow = 0.9}).check(), OptionError);
  EXPECT_THROW((StepDampingOptions{.min_scale = 0.0}).check(), OptionError);
  EXPECT_THROW((StepDampingOptions{.min_scale = 1.5}).check(), OptionError);
}

TEST(StepDamping, AReversalHalvesTheScaleAndAKeptDirectionGrowsItBackToOne) {
  VertexFields fields;
  fields.resize(3, 0);
  for (int v = 0; v < 3; ++v) {
    fields.normal[v] = Eigen::Vector3d::UnitX();
    fields.defined[v] = kSpeedDefined;
  }
  StepDampingState state;
  state.reset(3);
  const StepDampingOptions options;
  // Vertex 0 alternates, vertex 1 keeps its direction, vertex 2 loses its speed at step 3.
  const double expected_alternating[] = {1.0, 0.5, 0.25, 0.125, 0.125, 0.125};
  for (int step = 0; step < 6; ++step) {
    fields.speed[0] = (step % 2 ? -1.0 : 1.0) * Eigen::Vector3d::UnitX();
    fields.speed[1] = 2.0 * Eigen::Vector3d::UnitX();
    fields.speed[2] = (step % 2 ? -1.0 : 1.0) * Eigen::Vector3d::UnitX();
    fields.defined[2] = step == 3 ? 0 : kSpeedDefined;
    damp_speeds({0, 3}, options, fields, state);
    EXPECT_EQ(state.scale[0], expected_alternating[step]) << step;
    EXPECT_EQ(state.scale[1], 1.0) << step;  // never above the CFL step
  }
  // Vertex 2 reversed at steps 1 and 2 (0.25), had no speed at 3 (kept 0.25, forgot its
  // direction), so step 4 is no reversal and step 5 is one: 0.25 → 0.25 → 0.125.
  EXPECT_EQ(state.scale[2], 0.125);
  // A vertex that stops reversing grows back by 1.25 per iteration up to 1 (the first of these
  // steps is still a reversal against step 5's speed: 0.125·1.25^11 > 1).
  for (int step = 0; step < 12; ++step) {
    fields.speed[0] = Eigen::Vector3d::UnitX();
    damp_speeds({0, 1}, options, fields, state);
  }
  EXPECT_EQ(state.scale[0], 1.0);
  StepDampingState small;
  small.reset(2);
  EXPECT_THROW(damp_speeds({0, 3}, options, fields, small), Error);
}

TEST(StepDamping, ConvergesWhereForwardEulerDivergesAndLeavesAStableStepAlone) {
  // dt·k = 2.5: plain forward Euler multiplies x by −1.5 per step.
  const double k = 2.5, dt = 1.0;
  StiffVertex plain, damped;
  StepDampingState state;
  state.reset(1);
  for (int step = 0; step < 60; ++step) {
    plain.set_speed(k);
    plain.x += dt * plain.fields.speed[0].z();
    damped.set_speed(k);
    damp_speeds({0, 1}, StepDampingOptions{}, damped.fields, state);
    damped.x += dt * damped.fields.speed[0].z();
  }
  EXPECT_GT(std::abs(plain.x), 1e9);
  EXPECT_LT(std::abs(damped.x), 1e-6);
  // dt·k = 0.5: no reversal ever, so the damped run is the plain one, bit for bit.
  StiffVertex a, b;
  state.reset(1);
  for (int step = 0; step < 20; ++step) {
    a.set_speed(0.5);
    a.x += dt * a.fields.speed[0].z();
    b.set_speed(0.5);
    damp_speeds({0, 1}, StepDampingOptions{}, b.fields, state);
    b.x += dt * b.fields.speed[0].z();
  }
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(state.scale[0], 1.0);
}

TEST(StepDamping, TheWholeSpeedIsScaledSoItsZerosStay) {
  // F = −(g·(v + H) + ∇g·N)·N with g·(v + H) = 1, ∇g·N = 3: −4·N. After two reversals (scale
  // 0.25) the speed is −N: both terms scaled, so where F = 0 the surface stays at rest.
  VertexFields fields;
  fields.resize(1, 0);
  const Eigen::Vector3d n = Eigen::Vector3d(1, 2, 2) / 3.0;
  fields.normal[0] = n;
  fields.defined[0] = kSpeedDefined;
  StepDampingState state;
  state.reset(1);
  const Eigen::Vector3d tangent = Eigen::Vector3d(2, 1, -2) / 3.0;  // ⟂ n
  for (int step = 0; step < 3; ++step) {
    const double sign = step % 2 ? -1.0 : 1.0;
    fields.photo_gradient[0] = sign * (3.0 * n + 5.0 * tangent);
    fields.speed[0] = -sign * (1.0 + 3.0) * n;
    damp_speeds({0, 1}, StepDampingOptions{}, fields, state);
  }
  EXPECT_EQ(state.scale[0], 0.25);
  EXPECT_NEAR((fields.speed[0] - (-0.25 * (1.0 + 3.0) * n)).norm(), 0.0, 1e-15);
  // The vertex without a defined speed is left alone.
  fields.defined[0] = 0;
  fields.speed[0] = Eigen::Vector3d(7, 8, 9);
  damp_speeds({0, 1}, StepDampingOptions{}, fields, state);
  EXPECT_EQ(fields.speed[0], Eigen::Vector3d(7, 8, 9));
  EXPECT_EQ(state.normal_speed[0], 0.0);
}

TEST(StepMomentum, OptionsAreChecked) {
  EXPECT_NO_THROW(StepMomentumOptions{}.check());
  EXPECT_NO_THROW(StepMomentumOptions{.carry = 0.0}.check());
  EXPECT_THROW(StepMomentumOptions{.carry = 1.0}.check(), OptionError);
  EXPECT_THROW(StepMomentumOptions{.carry = -0.1}.check(), OptionError);
}

TEST(StepMomentum, IsTheHeavyBallOnASteadyApproach) {
  // The stiff vertex with dt·k = a = 0.05 (a slow, steady approach): plain steps multiply x by
  // 1 − a; carrying β of the last step gives x' = (1 − a)·x + β·(x − x_prev), whose roots
  // r² − (1 − a + β)·r + β = 0 are real for β = 0.5 (0.885 and 0.565), so x falls monotonically,
  // the momentum always agrees with the speed, and it is never dropped.
  const double k = 0.05, dt = 1.0, beta = 0.5;
  StiffVertex carried;
  std::vector<Eigen::Vector3d> last_step;  // empty: nothing to carry at the first step
  double x = 1.0, x_prev = 1.0;            // the recurrence, written out
  int plain_steps = 0, carried_steps = 0;
  for (double plain = 1.0; plain > 1e-3; plain *= 1.0 - dt * k) ++plain_steps;
  for (int step = 0; step < 400 && carried.x > 1e-3; ++step, ++carried_steps) {
    carried.set_speed(k);
    carry_momentum({0, 1}, StepMomentumOptions{.carry = beta}, dt, last_step, carried.fields);
    const double before = carried.x;
    carried.x += dt * carried.fields.speed[0].z();
    last_step.assign(1, (carried.x - before) * Eigen::Vector3d::UnitZ());
    const double next = (1.0 - dt * k) * x + beta * (x - x_prev);
    x_prev = x;
    x = next;
    EXPECT_NEAR(carried.x, x, 1e-12) << step;
  }
  EXPECT_EQ(plain_steps, 135);  // ⌈ln 1e−3 / ln 0.95⌉
  // The slower root, 0.885 per step, alone would take ⌈ln 1e−3 / ln 0.885⌉ = 57; the first step
  // has no momentum and the faster root's share decays first: 59 (the recurrence run alone).
  EXPECT_EQ(carried_steps, 59);
}

TEST(StepMomentum, OpposingMomentumIsDroppedAndARestingVertexStaysAtRest) {
  VertexFields fields;
  fields.resize(4, 0);
  const Eigen::Vector3d n = Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Vector3d tangent = Eigen::Vector3d(2, 1, -2) / 3.0;  // ⟂ n
  for (int v = 0; v < 4; ++v) {
    fields.normal[v] = n;
    fields.defined[v] = kSpeedDefined;
    fields.speed[v] = 2.0 * n + tangent;
  }
  fields.defined[3] = 0;
  const std::vector<Eigen::Vector3d> last_step = {0.3 * n + 5.0 * tangent,  // agrees: 0.5·0.3/0.1 along n
                                                  -0.3 * n + tangent,       // opposes the speed: dropped
                                                  4.0 * tangent,            // at rest along the normal
                                                  0.3 * n};                 // no defined speed
  carry_momentum({0, 4}, StepMomentumOptions{.carry = 0.5}, 0.1, last_step, fields);
  EXPECT_NEAR((fields.speed[0] - ((2.0 + 1.5) * n + tangent)).norm(), 0.0, 1e-14);
  for (int v = 1; v < 4; ++v) EXPECT_EQ(fields.speed[v], Eigen::Vector3d(2.0 * n + tangent)) << v;
  // Nothing to carry, or carry 0: the speeds stay bit for bit.
  VertexFields same = fields;
  carry_momentum({0, 4}, StepMomentumOptions{.carry = 0.5}, 0.1, {}, same);
  carry_momentum({0, 4}, StepMomentumOptions{.carry = 0.0}, 0.1, last_step, same);
  for (int v = 0; v < 4; ++v) EXPECT_EQ(same.speed[v], fields.speed[v]);
  EXPECT_THROW(carry_momentum({0, 4}, StepMomentumOptions{}, 0.0, last_step, fields), Error);
  EXPECT_THROW(carry_momentum({0, 4}, StepMomentumOptions{}, 0.1, {Eigen::Vector3d::Zero()}, fields), Error);
  EXPECT_THROW(carry_momentum({0, 5}, StepMomentumOptions{}, 0.1, last_step, fields), Error);
}

// Fields for \p mesh with outward sphere normals, a speed everywhere and the shortest edges.
VertexFields sphere_fields(const TriMesh& mesh) {
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    fields.normal[v] = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v)))).normalized();
    fields.defined[v] = kSpeedDefined;
  }
  compute_local_edges(mesh, all_vertices(mesh), fields);
  return fields;
}

void scale_sphere(TriMesh& mesh, double factor) {
  for (auto v : mesh.vertices()) mesh.set_point(v, mesh.point(v) * factor);
}

// A copy of \p base scaled by \p factor about the origin.
TriMesh scaled(const TriMesh& base, double factor) {
  TriMesh mesh = base;
  scale_sphere(mesh, factor);
  return mesh;
}

TEST(NetNormalMove, IsTheRadialGrowthOverTheWindowInShortestEdges) {
  TriMesh mesh = icosphere(1.0, 3);
  const VertexFields fields = sphere_fields(mesh);
  NetNormalMove net(5);
  // The radius grows by 0.001 per iteration: after 5 iterations each vertex has moved 0.005
  // along its normal; the median of 0.005 / (shortest edge at the final radius) is known.
  double radius = 1.0;
  for (int i = 0; i < 5; ++i) {
    EXPECT_TRUE(std::isnan(net.record(mesh, fields))) << i;  // fewer than 6 positions
    scale_sphere(mesh, (radius + 0.001) / radius);
    radius += 0.001;
  }
  std::vector<double> expected;
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) expected.push_back(0.005 / fields.local_edge[v]);
  EXPECT_NEAR(net.record(mesh, fields), median_of(expected), 1e-9);
  // The tail: rank ⌈0.9·n⌉ of the ascending ratios, taken here by a full sort.
  std::sort(expected.begin(), expected.end());
  const auto rank = static_cast<std::size_t>(std::ceil(0.9 * static_cast<double>(expected.size()))) - 1;
  EXPECT_NEAR(net.last_tail(), expected[rank], 1e-9);
  EXPECT_GT(net.last_tail(), median_of(expected));  // the shortest edges vary over an icosphere
  // An oscillation around one radius, ±0.001 in turn. Over an even window of 4 it cancels, though
  // every single step is 0.002 long.
  const TriMesh base = mesh;
  NetNormalMove even(4);
  for (int i = 0; i < 12; ++i) {
    for (auto v : mesh.vertices()) mesh.set_point(v, base.point(v) * (1.0 + (i % 2 ? -0.001 : 0.001)));
    const double value = even.record(mesh, fields);
    if (i >= 4) {
      EXPECT_NEAR(value, 0.0, 1e-12) << i;
      EXPECT_NEAR(even.last_tail(), 0.0, 1e-12) << i;
    } else {
      EXPECT_TRUE(std::isnan(value)) << i;
      EXPECT_TRUE(std::isnan(even.last_tail())) << i;
    }
  }
  // reset() forgets the positions: NaN again.
  even.reset();
  EXPECT_TRUE(std::isnan(even.last_tail()));
  EXPECT_TRUE(std::isnan(even.record(mesh, fields)));
  // A vertex count change without reset is refused.
  TriMesh other = icosphere(1.0, 2);
  EXPECT_THROW(even.record(other, sphere_fields(other)), Error);
  EXPECT_THROW(NetNormalMove(0), Error);
}

TEST(NetNormalMove, PersistenceIsTheShareOfTheLastWindowsMoveThatCarriesOn) {
  const TriMesh base = icosphere(1.0, 3);
  const VertexFields fields = sphere_fields(base);
  const auto at_radius = [&](double radius) { return scaled(base, radius); };
  // A creep slowing geometrically, r_i = 1 + 0.01·(1 − q^i): over one window of 5 every vertex
  // moves q^5 times its move over the window before, so Σ a·b / Σ b² = q^5 whatever the edges.
  constexpr double q = 0.9;
  NetNormalMove net(5);
  for (int i = 0; i <= 12; ++i) {
    net.record(at_radius(1.0 + 0.01 * (1.0 - std::pow(q, i))), fields);
    if (i < 10) {
      EXPECT_TRUE(std::isnan(net.last_persistence())) << i;  // fewer than 2·5 + 1 positions
    } else {
      EXPECT_NEAR(net.last_persistence(), std::pow(q, 5), 1e-9) << i;
    }
  }
  // A steady creep carries all of it on.
  NetNormalMove steady(5);
  for (int i = 0; i <= 10; ++i) steady.record(at_radius(1.0 + 0.001 * i), fields);
  EXPECT_NEAR(steady.last_persistence(), 1.0, 1e-9);
  // Back and forth by ±0.001 in turn: over an odd window each vertex ends on the other side of
  // where the window before ended, by as much: −1.
  NetNormalMove jitter(5);
  for (int i = 0; i <= 11; ++i) {
    jitter.record(at_radius(1.0 + (i % 2 ? -0.001 : 0.001)), fields);
    if (i >= 10) {
      EXPECT_NEAR(jitter.last_persistence(), -1.0, 1e-9) << i;
    }
  }
  // Nothing moved in the earlier window: no share to speak of (NaN), and reset() forgets.
  NetNormalMove still(1);
  still.record(base, fields);
  still.record(base, fields);
  still.record(at_radius(1.001), fields);
  EXPECT_TRUE(std::isnan(still.last_persistence()));
  still.record(at_radius(1.002), fields);
  EXPECT_NEAR(still.last_persistence(), 1.0, 1e-9);
  still.reset();
  EXPECT_TRUE(std::isnan(still.last_persistence()));
  // After a reset two windows are needed again, though the ring still holds older positions.
  still.record(at_radius(1.003), fields);
  still.record(at_radius(1.004), fields);
  EXPECT_TRUE(std::isnan(still.last_persistence()));
  still.record(at_radius(1.005), fields);
  EXPECT_NEAR(still.last_persistence(), 1.0, 1e-9);
}

// The mean of the last positions: on a sphere stepping 1.01 / 0.99 / 1.01 … in turn, the mean of
// the last two is the unit sphere, of the last three the sphere of radius (1.01 + 0.99 + 1.01)/3.
TEST(NetNormalMove, TheMeanOfTheLastPositionsCancelsABackAndForth) {
  const TriMesh base = icosphere(1.0, 2);
  const VertexFields fields = sphere_fields(base);
  const auto at_radius = [&](double radius) { return scaled(base, radius); };
  NetNormalMove net(2);  // a ring of 5 positions
  std::vector<Eigen::Vector3d> mean;
  EXPECT_FALSE(net.mean_of_last(1, mean));
  for (int i = 0; i < 7; ++i) {
    net.record(at_radius(i % 2 ? 0.99 : 1.01), fields);
    EXPECT_EQ(net.mean_of_last(2, mean), i >= 1) << i;
  }
  // The last recorded (i = 6) is at 1.01, the one before at 0.99.
  ASSERT_TRUE(net.mean_of_last(2, mean));
  ASSERT_EQ(mean.size(), base.n_vertices());
  for (auto v : base.vertices()) EXPECT_NEAR((mean[v.idx()] - to_eigen(base.point(v))).norm(), 0.0, 1e-15);
  ASSERT_TRUE(net.mean_of_last(3, mean));
  for (auto v : base.vertices())
    EXPECT_NEAR((mean[v.idx()] - to_eigen(base.point(v)) * (1.01 + 0.99 + 1.01) / 3).norm(), 0.0, 1e-15);
  ASSERT_TRUE(net.mean_of_last(1, mean));
  for (auto v : base.vertices()) EXPECT_NEAR((mean[v.idx()] - to_eigen(base.point(v)) * 1.01).norm(), 0.0, 1e-15);
  EXPECT_THROW(net.mean_of_last(0, mean), Error);
  EXPECT_THROW(net.mean_of_last(6, mean), Error);  // more than the ring holds
  // After a reset (a new topology) only what was recorded since counts; mean stays as it was.
  net.reset();
  net.record(at_radius(1.0), fields);
  const std::vector<Eigen::Vector3d> before = mean;
  EXPECT_FALSE(net.mean_of_last(2, mean));
  EXPECT_EQ(mean, before);
  EXPECT_THROW((StoppingOptions{.average_last = 0}).check(), OptionError);
  EXPECT_THROW((StoppingOptions{.lookback = 5, .average_last = 12}).check(), OptionError);
  EXPECT_NO_THROW((StoppingOptions{.lookback = 5, .average_last = 11}).check());
}

}  // namespace
}  // namespace mvflow
