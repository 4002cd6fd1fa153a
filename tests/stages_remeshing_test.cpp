// Global remeshing (SPEC §5, thesis 5.3.2): one pass of splits above b_u = 2 e_S, one pass of
// collapses below b_l = 0.8 e_S, keeping the mesh closed (or its boundary fixed), manifold,
// of the same topology, and without fold-overs.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/mesh_stats.h"
#include "engine/model/option_check.h"
#include "stages/topology/remeshing.h"
#include "stages/topology/self_intersections.h"  // the input check only
#include "stages_meshes.h"
#include "test_support.h"

namespace mvflow {
namespace {

using test::to_trimesh;

MeshStats stats_of(const TriMesh& mesh) {
  Mesh m;
  m.topology = mesh;
  return compute_mesh_stats(m);
}

//! The level-\p level icosphere of radius 1 with its vertices slid along the meridians,
//! θ' = θ + a·sin θ (θ the angle from +z): the northern cap is stretched by up to 1 + a, the
//! southern one compressed to 1 − a, all vertices stay on the unit sphere.
TriMesh warped_sphere(int level, double a) {
  IndexedMesh m = make_icosphere(1.0, level);
  for (auto& p : m.positions) {
    const double theta = std::acos(std::clamp(p.z(), -1.0, 1.0));
    const double phi = std::atan2(p.y(), p.x());
    const double t = theta + a * std::sin(theta);
    p = Eigen::Vector3d(std::sin(t) * std::cos(phi), std::sin(t) * std::sin(phi), std::cos(t));
  }
  return to_trimesh(m);
}

struct EdgeCensus {
  double shortest = 0.0, longest = 0.0;
  std::size_t total = 0, too_long = 0, too_short = 0;
  double outside_fraction() const { return static_cast<double>(too_long + too_short) / static_cast<double>(total); }
};

EdgeCensus census(const TriMesh& mesh, double lower, double upper) {
  EdgeCensus c;
  c.shortest = INFINITY;
  for (auto e : mesh.edges()) {
    const double l = mesh.calc_edge_length(e);
    c.shortest = std::min(c.shortest, l);
    c.longest = std::max(c.longest, l);
    ++c.total;
    c.too_long += l > upper;
    c.too_short += l < lower;
  }
  return c;
}

Eigen::Vector3d face_cross(const TriMesh& mesh, TriMesh::FaceHandle f, Eigen::Vector3d* centroid = nullptr) {
  std::array<Eigen::Vector3d, 3> p;
  int k = 0;
  for (auto v = mesh.cfv_iter(f); v.is_valid(); ++v) p[k++] = to_eigen(mesh.point(*v));
  if (centroid) *centroid = (p[0] + p[1] + p[2]) / 3.0;
  return (p[1] - p[0]).cross(p[2] - p[0]);
}

//! min over faces of |cross| / (longest edge)²: twice the area over the longest edge squared,
//! √3/2 for an equilateral triangle, 0 for a degenerate one.
double worst_face_shape(const TriMesh& mesh) {
  double worst = INFINITY;
  for (auto f : mesh.faces()) {
    double longest2 = 0.0;
    for (auto e = mesh.cfe_iter(f); e.is_valid(); ++e) longest2 = std::max(longest2, mesh.calc_edge_sqr_length(*e));
    worst = std::min(worst, face_cross(mesh, f).norm() / longest2);
  }
  return worst;
}

//! min over faces of the cosine between the unit face normal and the direction from the origin
//! to the face centroid: positive everywhere means no face of a sphere is folded over.
double worst_radial_cosine(const TriMesh& mesh) {
  double worst = INFINITY;
  for (auto f : mesh.faces()) {
    Eigen::Vector3d centroid;
    const Eigen::Vector3d n = face_cross(mesh, f, &centroid).normalized();
    worst = std::min(worst, n.dot(centroid.normalized()));
  }
  return worst;
}

//! Ids are 0..#V−1 with no deleted element, every vertex has a face and a finite position.
void expect_contiguous_and_finite(const TriMesh& mesh) {
  EXPECT_FALSE(mesh.has_vertex_status());  // released again by remesh_edges
  std::size_t count = 0;
  for (auto v : mesh.vertices()) {
    EXPECT_EQ(static_cast<std::size_t>(v.idx()), count);
    EXPECT_TRUE(std::isfinite(mesh.point(v)[0]) && std::isfinite(mesh.point(v)[1]) &&
                std::isfinite(mesh.point(v)[2]));
    ++count;
  }
  EXPECT_EQ(count, mesh.n_vertices());
  const MeshStats s = stats_of(mesh);
  EXPECT_EQ(s.isolated_vertices, 0u);
  EXPECT_EQ(s.vertices, mesh.n_vertices());
}

TEST(RemeshingOptions, DefaultsAreTheThesisValuesAndValid) {
  const RemeshingOptions options;
  EXPECT_NO_THROW(options.check());
  EXPECT_EQ(options.split_factor, 2.0);     // b_u = 2 e_S, thesis B.7
  EXPECT_EQ(options.collapse_factor, 0.8);  // b_l = 4/5 e_S, thesis B.7
  EXPECT_THROW((RemeshingOptions{.split_factor = 1.5, .collapse_factor = 0.8}).check(), OptionError);
  EXPECT_THROW((RemeshingOptions{.split_factor = 2.0, .collapse_factor = 0.0}).check(), OptionError);
  EXPECT_THROW((RemeshingOptions{.split_factor = NAN, .collapse_factor = 0.8}).check(), OptionError);
  TriMesh mesh = test::icosphere(1.0, 1);
  EXPECT_THROW(remesh_edges(mesh, 0.0), Error);
  EXPECT_THROW(remesh_edges(mesh, INFINITY), Error);
  EXPECT_THROW(remesh_edges(mesh, 0.1, RemeshingOptions{.split_factor = 1.0}), Error);
}

TEST(Remeshing, MeshWithinBoundsIsUntouched) {
  TriMesh mesh = test::icosphere(1.0, 2);
  const auto before = positions_of(mesh);
  const auto faces = triangles_of(mesh);
  const RemeshingResult r = remesh_edges(mesh, stats_of(mesh).shortest_edge);  // the pipeline's e_S
  EXPECT_EQ(r.splits, 0u);
  EXPECT_EQ(r.collapses, 0u);
  EXPECT_EQ(r.rejected_collapses, 0u);
  EXPECT_EQ(positions_of(mesh), before);
  EXPECT_EQ(triangles_of(mesh), faces);
}

// The warped sphere has edges from 0.2× to 1.8× the icosphere's (about 10× range). e_S = 0.6 ×
// the icosphere's mean edge puts the stretched north above b_u and the compressed south below b_l.
class WarpedSphere : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh = warped_sphere(4, 0.8);
    const MeshStats s = stats_of(test::icosphere(1.0, 4));
    reference_edge = 0.6 * s.mean_edge;
    lower = 0.8 * reference_edge;
    upper = 2.0 * reference_edge;
  }
  TriMesh mesh;
  double reference_edge = 0.0, lower = 0.0, upper = 0.0;
};

TEST_F(WarpedSphere, StaysClosedManifoldSameTopologyNoFoldOver) {
  const MeshStats before = stats_of(mesh);
  const EdgeCensus initial = census(mesh, lower, upper);
  const RemeshingResult r = remesh_edges(mesh, reference_edge);
  const MeshStats after = stats_of(mesh);
  std::printf("[measured] edges %zu: %.4f..%.4f (ratio %.1f), %zu > b_u = %.4f, %zu < b_l = %.4f\n", initial.total,
              initial.shortest, initial.longest, initial.longest / initial.shortest, initial.too_long, upper,
              initial.too_short, lower);
  std::printf("[measured] splits %zu, collapses %zu, rejected %zu (boundary %zu, topology %zu, fold-over %zu, "
              "long edge %zu); vertices %zu -> %zu\n",
              r.splits, r.collapses, r.rejected_collapses, r.rejected_boundary, r.rejected_topology,
              r.rejected_fold_over, r.rejected_long_edge, before.vertices, after.vertices);
  EXPECT_GT(initial.longest / initial.shortest, 8.0);
  EXPECT_EQ(r.splits, initial.too_long);  // one pass over the edges too long at the start
  EXPECT_GT(r.collapses, 0u);
  EXPECT_EQ(after.boundary_edges, 0u);
  EXPECT_EQ(after.non_manifold_vertices, 0u);
  EXPECT_EQ(after.components, 1u);
  EXPECT_EQ(after.euler_characteristic, before.euler_characteristic);
  EXPECT_EQ(after.genus, 0);
  EXPECT_EQ(after.vertices, before.vertices + r.splits - r.collapses);
  EXPECT_GT(worst_face_shape(mesh), 1e-3);  // no degenerate face (equilateral: 0.87)
  EXPECT_GT(worst_radial_cosine(mesh), 0.0);  // no face folded over
  expect_contiguous_and_finite(mesh);
}

TEST_F(WarpedSphere, OnePassLeavesFewEdgesOutsideTheBoundsAndASecondPassFewer) {
  const EdgeCensus initial = census(mesh, lower, upper);
  remesh_edges(mesh, reference_edge);
  const EdgeCensus first = census(mesh, lower, upper);
  const RemeshingResult again = remesh_edges(mesh, reference_edge);
  const EdgeCensus second = census(mesh, lower, upper);
  std::printf("[measured] outside [b_l, b_u]: initially %zu of %zu (%.1f %%), after one pass %zu long + %zu short of "
              "%zu (%.2f %%), after two %zu + %zu of %zu (%.2f %%); edges %.4f..%.4f after one pass\n",
              initial.too_long + initial.too_short, initial.total, 100 * initial.outside_fraction(), first.too_long,
              first.too_short, first.total, 100 * first.outside_fraction(), second.too_long, second.too_short,
              second.total, 100 * second.outside_fraction(), first.shortest, first.longest);
  std::printf("[measured] second pass: splits %zu, collapses %zu, rejected %zu\n", again.splits, again.collapses,
              again.rejected_collapses);
  // One pass cannot guarantee the bounds (stages/topology/remeshing.h): the midpoint-to-corner edges of a
  // split may still exceed b_u and rejected or revisited collapses leave edges below b_l.
  // Measured: 52.8 % outside before, 5.5 % (672 long, 19 short) after one pass, 0.08 % after two.
  EXPECT_LT(first.outside_fraction(), 0.07);
  EXPECT_LT(first.outside_fraction(), 0.15 * initial.outside_fraction());
  EXPECT_LT(first.longest, 1.5 * upper);  // measured 1.36 b_u: medians, not halves (none was > 2 b_u)
  EXPECT_LT(second.too_long + second.too_short, first.too_long + first.too_short);
  EXPECT_LT(second.outside_fraction(), 0.005);
  EXPECT_EQ(stats_of(mesh).euler_characteristic, 2);
  EXPECT_GT(worst_radial_cosine(mesh), 0.0);
}

TEST_F(WarpedSphere, EdgesStillTooLongAfterOnePassAreAllNewMidpointEdges) {
  // Without collapses nothing is deleted, so the split vertices are exactly the ids ≥ #V before.
  const std::size_t old_vertices = mesh.n_vertices();
  const RemeshingResult r = remesh_edges(mesh, reference_edge, {.split_factor = 2.0, .collapse_factor = 1e-6});
  EXPECT_EQ(r.collapses, 0u);
  std::size_t too_long = 0, at_a_midpoint = 0;
  for (auto e : mesh.edges()) {
    if (!(mesh.calc_edge_length(e) > upper)) continue;
    ++too_long;
    const auto h = mesh.halfedge_handle(e, 0);
    const auto a = static_cast<std::size_t>(mesh.from_vertex_handle(h).idx());
    const auto b = static_cast<std::size_t>(mesh.to_vertex_handle(h).idx());
    at_a_midpoint += (a >= old_vertices) != (b >= old_vertices);  // midpoint to an old corner
  }
  std::printf("[measured] without collapses: %zu of %zu edges > b_u, %zu of them midpoint-to-corner\n", too_long,
              mesh.n_edges(), at_a_midpoint);
  EXPECT_GT(too_long, 0u);
  EXPECT_EQ(at_a_midpoint, too_long);
}

TEST_F(WarpedSphere, IsDeterministic) {
  TriMesh copy = mesh;
  remesh_edges(mesh, reference_edge);
  remesh_edges(copy, reference_edge);
  EXPECT_EQ(positions_of(mesh), positions_of(copy));
  EXPECT_EQ(triangles_of(mesh), triangles_of(copy));
}

TEST(Remeshing, ManyReferenceEdgesKeepAJitteredSphereValid) {
  // From e_S far below the edges (everything split) to far above (b_l ≥ 1.6× the mean edge: most
  // edges are collapse candidates, far beyond the pipeline's use, where e_S is the shortest edge).
  const double mean = stats_of(test::icosphere(1.0, 3)).mean_edge;
  for (const double factor : {0.3, 0.5, 0.8, 1.2, 2.0, 3.0}) {
    TriMesh mesh = warped_sphere(3, 0.6);
    test::jitter_on_sphere(mesh, 1.0, 0.1 * mean, 7);
    ASSERT_EQ(count_self_intersections(mesh), 0u);
    ASSERT_GT(worst_radial_cosine(mesh), 0.0);
    for (int pass = 0; pass < 2; ++pass) {
      const RemeshingResult r = remesh_edges(mesh, factor * mean);
      const MeshStats s = stats_of(mesh);
      SCOPED_TRACE(::testing::Message() << "e_S = " << factor << " × mean edge, pass " << pass);
      std::printf("[measured] e_S %.1f×mean pass %d: splits %zu, collapses %zu, rejected %zu, vertices %zu, worst "
                  "radial cosine %.3f, worst shape %.4f\n",
                  factor, pass, r.splits, r.collapses, r.rejected_collapses, s.vertices, worst_radial_cosine(mesh),
                  worst_face_shape(mesh));
      EXPECT_EQ(s.boundary_edges, 0u);
      EXPECT_EQ(s.non_manifold_vertices, 0u);
      EXPECT_EQ(s.euler_characteristic, 2);
      EXPECT_EQ(s.components, 1u);
      EXPECT_GT(worst_face_shape(mesh), 1e-4);
      // Within the intended range every face still faces outward. Beyond it (a sphere decimated
      // to ~100 vertices) slivers with all corners within 3 % of the sphere can tilt past 90°
      // from the radial direction: measured down to −0.26 there.
      if (factor <= 1.2) {
        EXPECT_GT(worst_radial_cosine(mesh), 0.0);
      }
      expect_contiguous_and_finite(mesh);
    }
  }
}

TEST(Remeshing, TorusKeepsGenusOne) {
  // Torus radii 2 and 1, 24×12: edges from 0.26 (inner equator) to ~0.95 (outer diagonals).
  TriMesh mesh = to_trimesh(test::torus(24, 12));
  const MeshStats before = stats_of(mesh);
  const double reference_edge = 0.4;  // b_u = 0.8: outer edges split; b_l = 0.32: inner ones collapse
  const RemeshingResult r = remesh_edges(mesh, reference_edge);
  const MeshStats after = stats_of(mesh);
  std::printf("[measured] torus: edges %.3f..%.3f -> %.3f..%.3f, splits %zu, collapses %zu, rejected %zu\n",
              before.shortest_edge, before.longest_edge, after.shortest_edge, after.longest_edge, r.splits,
              r.collapses, r.rejected_collapses);
  EXPECT_GT(r.splits, 0u);
  EXPECT_GT(r.collapses, 0u);
  EXPECT_EQ(before.genus, 1);
  EXPECT_EQ(after.genus, 1);
  EXPECT_EQ(after.euler_characteristic, 0);
  EXPECT_EQ(after.boundary_edges, 0u);
  EXPECT_EQ(after.non_manifold_vertices, 0u);
  EXPECT_EQ(after.components, 1u);
  EXPECT_GT(worst_face_shape(mesh), 1e-3);
  expect_contiguous_and_finite(mesh);
}

TEST(Remeshing, OpenGridKeepsItsBoundaryVerticesInPlace) {
  // A 12×12 grid on [0,1]² with x ↦ x²: cells from 0.007 wide (left) to 0.16 (right).
  IndexedMesh grid = make_grid(1.0, 12);
  for (auto& p : grid.positions) p.x() = p.x() * p.x();
  TriMesh mesh = to_trimesh(grid);
  const MeshStats before = stats_of(mesh);
  std::vector<Eigen::Vector3d> boundary;
  for (auto v : mesh.vertices())
    if (mesh.is_boundary(v)) boundary.push_back(to_eigen(mesh.point(v)));
  const RemeshingResult r = remesh_edges(mesh, 0.07);  // b_u = 0.14, b_l = 0.056
  const MeshStats after = stats_of(mesh);
  std::printf("[measured] grid: edges %.4f..%.4f -> %.4f..%.4f, splits %zu, collapses %zu, rejected %zu (boundary "
              "%zu)\n",
              before.shortest_edge, before.longest_edge, after.shortest_edge, after.longest_edge, r.splits,
              r.collapses, r.rejected_collapses, r.rejected_boundary);
  EXPECT_GT(r.splits, 0u);
  EXPECT_GT(r.collapses, 0u);
  EXPECT_GT(r.rejected_boundary, 0u);
  // Every boundary vertex is still there, at exactly its old position.
  std::vector<Eigen::Vector3d> now;
  for (auto v : mesh.vertices()) now.push_back(to_eigen(mesh.point(v)));
  for (const auto& p : boundary)
    EXPECT_NE(std::find(now.begin(), now.end(), p), now.end()) << p.transpose();
  // New boundary vertices (split boundary edges) lie on the square's border; the boundary is one loop.
  for (auto v : mesh.vertices()) {
    if (!mesh.is_boundary(v)) continue;
    const auto p = mesh.point(v);
    EXPECT_TRUE(p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0) << p;
  }
  EXPECT_EQ(after.boundary_loops, 1u);
  EXPECT_EQ(after.euler_characteristic, before.euler_characteristic);
  EXPECT_EQ(after.non_manifold_vertices, 0u);
  for (auto f : mesh.faces()) EXPECT_GT(face_cross(mesh, f).z(), 0.0);  // no fold-over: normals stay +z
  EXPECT_GT(worst_face_shape(mesh), 1e-3);
  expect_contiguous_and_finite(mesh);
}

TEST(Remeshing, KeepsTheCallersStatusRequests) {
  TriMesh mesh = warped_sphere(3, 0.8);
  mesh.request_vertex_status();
  remesh_edges(mesh, 0.6 * stats_of(test::icosphere(1.0, 3)).mean_edge);
  EXPECT_TRUE(mesh.has_vertex_status());
  EXPECT_FALSE(mesh.has_face_status());
}

}  // namespace
}  // namespace mvflow
