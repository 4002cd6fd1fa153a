// Unobserved vertices following the observed surface (stages/flow/unobserved_displacement.h), against
// surfaces whose answer is known: a constant offset, a linear ramp, a sphere.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "engine/model/error.h"
#include "stages/synth/synth_cameras.h"
#include "stages/flow/unobserved_displacement.h"
#include "stages_meshes.h"

namespace mvflow {
namespace {

using namespace test;

// A flat patch of (side+1)² vertices in z = 0, rows shifted by half a cell and spaced √3/2 apart
// so that every triangle is equilateral (cotangent weights 1/√3 each: none clamped).
struct FlatPatch {
  TriMesh mesh;
  std::vector<TriMesh::VertexHandle> grid;
  int side = 12;
  TriMesh::VertexHandle at(int i, int j) const { return grid[static_cast<std::size_t>(j * (side + 1) + i)]; }
  bool inner(int i, int j) const { return i >= 3 && j >= 3 && i <= side - 3 && j <= side - 3; }
};

FlatPatch equilateral_patch() {
  FlatPatch p;
  const double h = std::sqrt(3.0) / 2;
  for (int j = 0; j <= p.side; ++j)
    for (int i = 0; i <= p.side; ++i) p.grid.push_back(p.mesh.add_vertex({0.1 * (i + 0.5 * (j % 2)), 0.1 * h * j, 0.0}));
  for (int j = 0; j < p.side; ++j)
    for (int i = 0; i < p.side; ++i) {
      const auto a = p.at(i, j), b = p.at(i + 1, j), c = p.at(i, j + 1), d = p.at(i + 1, j + 1);
      if (j % 2 == 0) {
        p.mesh.add_face(a, b, c);
        p.mesh.add_face(b, d, c);
      } else {
        p.mesh.add_face(a, d, c);
        p.mesh.add_face(a, b, d);
      }
    }
  return p;
}

std::vector<Eigen::Vector3d> positions(const TriMesh& mesh) {
  std::vector<Eigen::Vector3d> p;
  for (auto v : mesh.vertices()) p.push_back(to_eigen(mesh.point(v)));
  return p;
}

TEST(UnobservedDisplacement, FollowsAConstantOffsetExactly) {
  // The observed part moved 0.05 up from where the flow started; the unobserved middle did not
  // move at all. It follows by 0.05, to rounding, whatever the cotangent weights.
  FlatPatch patch = equilateral_patch();
  const std::vector<Eigen::Vector3d> reference = positions(patch.mesh);
  std::vector<std::uint8_t> free(patch.mesh.n_vertices(), 0);
  for (int j = 0; j <= patch.side; ++j)
    for (int i = 0; i <= patch.side; ++i) {
      if (patch.inner(i, j)) {
        free[static_cast<std::size_t>(patch.at(i, j).idx())] = 1;
      } else {
        patch.mesh.set_point(patch.at(i, j), patch.mesh.point(patch.at(i, j)) + OpenMesh::Vec3d(0, 0, 0.05));
      }
    }
  const DisplacementResult result = spread_displacement(patch.mesh, reference, free);
  EXPECT_EQ(result.moved_vertices, 49u);
  EXPECT_EQ(result.skipped_vertices, 0u);
  for (auto v : patch.mesh.vertices()) {
    EXPECT_NEAR(patch.mesh.point(v)[2], 0.05, 1e-12) << "vertex " << v.idx();
    EXPECT_NEAR(patch.mesh.point(v)[0], reference[static_cast<std::size_t>(v.idx())].x(), 1e-15);
  }
}

TEST(UnobservedDisplacement, FollowsALinearRampExactly) {
  // Observed displacement 0.2·x + 0.1·y: the harmonic interpolation of a linear function on a
  // planar mesh with cotangent weights is that function (linear precision).
  FlatPatch patch = equilateral_patch();
  const std::vector<Eigen::Vector3d> reference = positions(patch.mesh);
  std::vector<std::uint8_t> free(patch.mesh.n_vertices(), 0);
  auto ramp = [](const Eigen::Vector3d& p) { return 0.2 * p.x() + 0.1 * p.y(); };
  for (int j = 0; j <= patch.side; ++j)
    for (int i = 0; i <= patch.side; ++i) {
      const auto v = patch.at(i, j);
      if (patch.inner(i, j)) {
        free[static_cast<std::size_t>(v.idx())] = 1;
        patch.mesh.set_point(v, patch.mesh.point(v) + OpenMesh::Vec3d(0, 0, -0.3));  // wherever it went
      } else {
        patch.mesh.set_point(v, patch.mesh.point(v) + OpenMesh::Vec3d(0, 0, ramp(to_eigen(patch.mesh.point(v)))));
      }
    }
  spread_displacement(patch.mesh, reference, free);
  for (auto v : patch.mesh.vertices())
    EXPECT_NEAR(patch.mesh.point(v)[2], ramp(reference[static_cast<std::size_t>(v.idx())]), 1e-12) << v.idx();
}

TEST(UnobservedDisplacement, BringsAnUnobservedSphereCapBackWithTheRest) {
  // The flow started on a sphere of radius 1.04; the observed part reached the unit sphere and
  // slid along it too (as regularization moves vertices), the cap below 60° south stayed where
  // it started. The cap follows to within a twentieth of its 0.04 error. (Measured along each
  // vertex's own starting normal instead of to the starting surface, the slide of 0.1 radian at
  // the cap's border would read as 1 − cos 0.1 ≈ 0.005 of extra inward displacement.)
  TriMesh mesh = icosphere(1.0, 4);
  const double cap_sine = -std::sin(60.0 * std::numbers::pi / 180.0);
  std::vector<Eigen::Vector3d> reference;
  std::vector<std::uint8_t> cap(mesh.n_vertices(), 0);
  for (auto v : mesh.vertices()) {
    const Eigen::Vector3d p = to_eigen(mesh.point(v));
    reference.push_back(1.04 * p);
    cap[static_cast<std::size_t>(v.idx())] = p.y() < cap_sine;
    if (cap[static_cast<std::size_t>(v.idx())]) {
      mesh.set_point(v, to_openmesh(1.04 * p));
    } else {  // slid by 0.2 radian around the y axis, on the unit sphere
      mesh.set_point(v, to_openmesh(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) * p));
    }
  }
  const DisplacementResult result = spread_displacement(mesh, reference, cap);
  EXPECT_GT(result.moved_vertices, 100u);
  double error = 0.0;
  for (auto v : mesh.vertices())
    if (cap[static_cast<std::size_t>(v.idx())]) error += std::abs(mesh.point(v).norm() - 1.0);
  error /= static_cast<double>(result.moved_vertices);
  EXPECT_LT(error, 0.002);
}

TEST(UnobservedDisplacement, LeavesARegionWithNothingObservedAsItIs) {
  TriMesh mesh = icosphere(1.0, 2);
  const std::vector<Eigen::Vector3d> reference = positions(mesh);
  for (auto v : mesh.vertices()) mesh.set_point(v, mesh.point(v) * 1.1);
  const TriMesh before = mesh;
  const std::vector<std::uint8_t> all(mesh.n_vertices(), 1);
  const DisplacementResult result = spread_displacement(mesh, reference, all);
  EXPECT_EQ(result.moved_vertices, 0u);
  EXPECT_EQ(result.skipped_vertices, mesh.n_vertices());
  for (auto v : mesh.vertices()) EXPECT_EQ(mesh.point(v), before.point(v));
}

TEST(UnobservedDisplacement, RefusesInputsOfTheWrongSize) {
  TriMesh mesh = icosphere(1.0, 1);
  const std::vector<Eigen::Vector3d> reference = positions(mesh);
  const std::vector<std::uint8_t> flags(3, 1);
  EXPECT_THROW(spread_displacement(mesh, reference, flags), Error);
  std::vector<Eigen::Vector3d> short_reference(reference.begin(), reference.end() - 1);
  EXPECT_THROW(spread_displacement(mesh, short_reference, std::vector<std::uint8_t>(mesh.n_vertices(), 0)), Error);
}

TEST(UnobservedDisplacement, ExtendsTheReferenceByEdgeMidpoints) {
  std::vector<Eigen::Vector3d> reference = {{0, 0, 0}, {2, 0, 0}, {0, 4, 0}};
  const std::vector<std::array<std::uint32_t, 2>> parents = {{0, 1}, {1, 2}};
  extend_reference(reference, parents);
  ASSERT_EQ(reference.size(), 5u);
  EXPECT_EQ(reference[3], Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(reference[4], Eigen::Vector3d(1, 2, 0));
  const std::vector<std::array<std::uint32_t, 2>> bad = {{0, 9}};
  EXPECT_THROW(extend_reference(reference, bad), Error);
}

// Fields where every vertex has a speed except those below \p sine on the y axis, each seeing
// the one \p camera.
VertexFields fields_with_speed_above(const TriMesh& mesh, double sine) {
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 1);
  for (auto v : mesh.vertices()) {
    const auto i = static_cast<std::size_t>(v.idx());
    fields.normal[i] = to_eigen(mesh.point(v)).normalized();
    fields.defined[i] = kNormalDefined;
    if (mesh.point(v)[1] >= sine) fields.defined[i] |= kSpeedDefined;
    fields.visible_views[i] = 0;
    fields.visible_count[i] = 1;
  }
  return fields;
}

TEST(UnobservedDisplacement, UnobservedAreTheVerticesWithoutSpeedGrownByTheErodedRings) {
  const TriMesh mesh = icosphere(1.0, 3);
  const VertexFields fields = fields_with_speed_above(mesh, -0.5);
  std::vector<Camera> cameras = {look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 60, 64, 48)};
  std::vector<Image> images(1, Image(64, 48));
  const std::vector<PhotoView> views = make_photo_views(cameras, {&images[0]});
  UnobservedDisplacementOptions options;
  options.erode_rings = 0;
  const std::vector<std::uint8_t> exact = poorly_observed_vertices(mesh, views, fields, options);
  options.erode_rings = 1;
  const std::vector<std::uint8_t> grown = poorly_observed_vertices(mesh, views, fields, options);
  for (auto v : mesh.vertices()) {
    const auto i = static_cast<std::size_t>(v.idx());
    EXPECT_EQ(exact[i], fields.defined[i] & kSpeedDefined ? 0 : 1);
    bool near_unobserved = exact[i];
    for (auto w : mesh.vv_range(v)) near_unobserved = near_unobserved || exact[static_cast<std::size_t>(w.idx())];
    EXPECT_EQ(grown[i], near_unobserved ? 1 : 0);
  }
  // Within 60° of the normal: only the vertices facing the camera on +z count as observed.
  options.erode_rings = 0;
  options.observed_angle_degrees = 60.0;
  const std::vector<std::uint8_t> facing = poorly_observed_vertices(mesh, views, fields, options);
  for (auto v : mesh.vertices()) {
    const auto i = static_cast<std::size_t>(v.idx());
    const Eigen::Vector3d p = to_eigen(mesh.point(v));
    const double cosine = fields.normal[i].dot((Eigen::Vector3d(0, 0, 5) - p).normalized());
    if (std::abs(cosine - 0.5) < 1e-9) continue;  // on the 60° circle
    EXPECT_EQ(facing[i], exact[i] || cosine < 0.5 ? 1 : 0) << i;
  }
  // The observed set before the erosion is the complement, with either angle.
  for (const double angle : {60.0, 90.0}) {
    options.observed_angle_degrees = angle;
    const std::vector<std::uint8_t> observed = observed_vertices(mesh, views, fields, options);
    const std::vector<std::uint8_t> poor = poorly_observed_vertices(mesh, views, fields, options);
    for (std::size_t i = 0; i < observed.size(); ++i) EXPECT_EQ(observed[i], 1 - poor[i]) << i << " at " << angle;
    // Into a reused buffer (the refiner's per-iteration count): stale, longer contents are replaced.
    std::vector<std::uint8_t> reused(observed.size() + 7, 1);
    observed_vertices(mesh, views, fields, options, reused);
    EXPECT_EQ(reused, observed) << angle;
  }
}

TEST(UnobservedDisplacement, VerticesOnTheSilhouettesCountAsObservedAndAreNotEroded) {
  const TriMesh mesh = icosphere(1.0, 3);
  const VertexFields fields = fields_with_speed_above(mesh, -0.5);
  std::vector<Camera> cameras = {look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 60, 64, 48)};
  std::vector<Image> images(1, Image(64, 48));
  const std::vector<PhotoView> views = make_photo_views(cameras, {&images[0]});
  UnobservedDisplacementOptions options;  // erode_rings = 1
  const std::vector<std::uint8_t> without = poorly_observed_vertices(mesh, views, fields, options);
  // The silhouettes observe a band of the unobserved region and the ring just outside it.
  std::vector<std::uint8_t> on_silhouette(mesh.n_vertices(), 0);
  for (auto v : mesh.vertices()) {
    const double y = mesh.point(v)[1];
    on_silhouette[static_cast<std::size_t>(v.idx())] = (y > -0.75 && y < -0.6) || (y >= -0.5 && y < -0.4);
  }
  const std::vector<std::uint8_t> with = poorly_observed_vertices(mesh, views, fields, options, on_silhouette);
  std::size_t cleared = 0;
  for (std::size_t i = 0; i < with.size(); ++i) {
    EXPECT_EQ(with[i], on_silhouette[i] ? 0 : without[i]) << i;
    cleared += without[i] && on_silhouette[i];
  }
  EXPECT_GT(cleared, 10u);  // the band and the eroded ring, not an empty test
  EXPECT_THROW(poorly_observed_vertices(mesh, views, fields, options, std::vector<std::uint8_t>(3, 0)), Error);
}

// A region of implausibly high g counts as not observed; a single such vertex does not. The median
// is the one of the vertices with a speed (40 % of the sphere here; the others' g is 0, so the
// median over every vertex would be 0 and flag nothing).
TEST(UnobservedDisplacement, ARegionOfImplausiblyHighGIsNotObserved) {
  const TriMesh mesh = icosphere(1.0, 3);
  VertexFields fields = fields_with_speed_above(mesh, 0.2);
  const auto y = [&](auto v) { return mesh.point(v)[1]; };
  // The single vertex: the one nearest (0.8, 0.45, 0.4), well outside the cap.
  TriMesh::VertexHandle single;
  double nearest = 1e9;
  for (auto v : mesh.vertices()) {
    const double d = (to_eigen(mesh.point(v)) - Eigen::Vector3d(0.8, 0.45, 0.4)).norm();
    if (d < nearest) nearest = d, single = v;
  }
  for (auto v : mesh.vertices())
    if (fields.defined[v.idx()] & kSpeedDefined) fields.photo_consistency[v.idx()] = y(v) > 0.7 || v == single ? 1000.0 : 1.0;
  std::vector<Camera> cameras = {look_at({0, 5, 0}, {0, 0, 0}, {0, 0, 1}, 60, 64, 48)};
  std::vector<Image> images(1, Image(64, 48));
  const std::vector<PhotoView> views = make_photo_views(cameras, {&images[0]});
  UnobservedDisplacementOptions options;
  options.erode_rings = 0;
  options.implausible_g_ratio = 300.0;
  const std::vector<std::uint8_t> implausible = implausible_g_vertices(mesh, fields, options.implausible_g_ratio);
  const std::vector<std::uint8_t> observed = observed_vertices(mesh, views, fields, options);
  std::size_t inside_cap = 0;
  for (auto v : mesh.vertices()) {
    const auto i = static_cast<std::size_t>(v.idx());
    // The cap's vertices whose whole ring lies in the cap too.
    bool ring_in_cap = y(v) > 0.7;
    for (auto w : mesh.vv_range(v)) ring_in_cap = ring_in_cap && y(w) > 0.7;
    inside_cap += ring_in_cap;
    EXPECT_EQ(implausible[i], ring_in_cap ? 1 : 0) << i << " at y = " << y(v);
    EXPECT_EQ(observed[i], (fields.defined[i] & kSpeedDefined) && !ring_in_cap ? 1 : 0) << i;
  }
  EXPECT_GT(inside_cap, 10u);
  EXPECT_EQ(implausible[static_cast<std::size_t>(single.idx())], 0);
  // A neighbour without a speed does not count: the ring just outside the cap loses its speeds.
  VertexFields border = fields;
  for (auto v : mesh.vertices()) {
    bool next_to_cap = false;
    for (auto w : mesh.vv_range(v)) next_to_cap = next_to_cap || y(w) > 0.7;
    if (y(v) <= 0.7 && next_to_cap) border.defined[v.idx()] &= static_cast<std::uint8_t>(~kSpeedDefined);
  }
  const std::vector<std::uint8_t> whole_cap = implausible_g_vertices(mesh, border, 300.0);
  for (auto v : mesh.vertices()) EXPECT_EQ(whole_cap[v.idx()], y(v) > 0.7 ? 1 : 0) << v.idx();
  // Off, or a threshold at the cap's g: nothing.
  for (const double ratio : {0.0, 1000.0}) {
    const std::vector<std::uint8_t> none = implausible_g_vertices(mesh, fields, ratio);
    EXPECT_EQ(std::count(none.begin(), none.end(), 1), 0) << ratio;
  }
  options.implausible_g_ratio = 1.0;
  EXPECT_THROW(options.check(), Error);
  EXPECT_THROW(implausible_g_vertices(icosphere(1.0, 1), fields, 300.0), Error);
  EXPECT_THROW(implausible_g_vertices(mesh, fields, 0.5), Error);
}

// Auto without fitted rims spreads only what the flow hardly observed: a vertex stays free when it
// had a speed in at most fraction × iterations of them (on the boundary, kept).
TEST(UnobservedDisplacement, HardlyObservedAreThoseWithASpeedInAtMostTheFraction) {
  const int iterations = 20;
  std::vector<std::uint32_t> counts;
  for (std::uint32_t c = 0; c <= 20; ++c) counts.push_back(c);
  for (const double fraction : {0.0, 0.25, 0.5, 1.0}) {
    std::vector<std::uint8_t> poor(counts.size(), 1);
    poor[3] = 0;  // not poorly observed: stays observed whatever its count
    keep_hardly_observed(poor, counts, iterations, fraction);
    for (std::size_t v = 0; v < counts.size(); ++v)
      EXPECT_EQ(poor[v], v != 3 && counts[v] <= fraction * iterations ? 1 : 0) << fraction << " " << v;
  }
  std::vector<std::uint8_t> poor(counts.size(), 1);
  keep_hardly_observed(poor, counts, iterations, 0.25);
  EXPECT_EQ(std::count(poor.begin(), poor.end(), 1), 6);  // 0, 1, ..., 5 of 20 iterations
  EXPECT_THROW(keep_hardly_observed(poor, std::vector<std::uint32_t>(3, 0), iterations, 0.25), Error);
}

}  // namespace
}  // namespace mvflow
