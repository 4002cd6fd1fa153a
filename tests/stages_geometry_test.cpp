// Normals and mean curvature (SPEC §3): analytic answers on spheres and planes, degenerate
// input, and independence from the vertex block size.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "engine/model/error.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/curvature.h"
#include "stages/flow/normals.h"
#include "stages_meshes.h"

namespace mvflow {
namespace {

using test::all_vertices;
using test::icosphere;
using test::position;

VertexFields geometry(const TriMesh& mesh, const CurvatureOptions& options = {}) {
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  compute_normals(mesh, all_vertices(mesh), fields);
  compute_mean_curvature(mesh, all_vertices(mesh), fields, options);
  return fields;
}

// Normals and curvature of each block computed together, as the per-block graph node does.
VertexFields geometry_in_blocks(const TriMesh& mesh, std::size_t block_size) {
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  for (const IndexRange block : split_into_blocks(mesh.n_vertices(), block_size)) {
    compute_normals(mesh, block, fields);
    compute_mean_curvature(mesh, block, fields);
  }
  return fields;
}

TEST(Normals, FollowTheRadiusOfASphereAndPointOutward) {
  const TriMesh mesh = icosphere(1.0, 4);
  const VertexFields fields = geometry(mesh);
  double max_angle = 0.0;
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    ASSERT_TRUE(fields.defined[v] & kNormalDefined) << v;
    const Eigen::Vector3d p = position(mesh, v);
    EXPECT_NEAR(fields.normal[v].norm(), 1.0, 1e-12);
    EXPECT_GT(fields.normal[v].dot(p), 0.0) << v;
    const double c = std::clamp(fields.normal[v].dot(p.normalized()), -1.0, 1.0);
    max_angle = std::max(max_angle, std::acos(c) * 180.0 / std::numbers::pi);
  }
  std::printf("[measured] level-4 icosphere: max angle to radial normal %.4g deg\n", max_angle);
  EXPECT_LT(max_angle, 0.5);
}

TEST(Normals, InwardFacesGiveInwardNormals) {
  const TriMesh mesh = test::inward_icosphere(1.0, 2);
  const VertexFields fields = geometry(mesh);
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) EXPECT_LT(fields.normal[v].dot(position(mesh, v)), 0.0);
}

TEST(Normals, DegenerateFaceOrIsolatedVertexIsUndefinedNotNaN) {
  TriMesh mesh = icosphere(1.0, 2);
  // Put P on the midpoint of the opposite edge Q–R of one of its faces: that face has zero area.
  const auto f = *mesh.faces().begin();
  auto h = mesh.halfedge_handle(f);
  const auto p = mesh.from_vertex_handle(h), q = mesh.to_vertex_handle(h);
  const auto r = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
  mesh.set_point(p, 0.5 * (mesh.point(q) + mesh.point(r)));
  const auto isolated = mesh.add_vertex({2.0, 0.0, 0.0});
  const VertexFields fields = geometry(mesh);
  std::size_t undefined = 0;
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    EXPECT_TRUE(fields.normal[v].allFinite());
    EXPECT_TRUE(std::isfinite(fields.mean_curvature[v]));
    EXPECT_TRUE(std::isfinite(fields.curvature_normal_length[v]));
    if (!(fields.defined[v] & kNormalDefined)) {
      ++undefined;
      EXPECT_EQ(fields.normal[v], Eigen::Vector3d::Zero());
      EXPECT_FALSE(fields.defined[v] & kCurvatureDefined);
    }
  }
  for (TriMesh::VertexHandle v : {p, q, r, TriMesh::VertexHandle(isolated)})
    EXPECT_FALSE(fields.defined[v.idx()] & kNormalDefined) << v.idx();
  EXPECT_EQ(undefined, 4u);  // the degenerate face's three corners and the isolated vertex
}

// Twice the Voronoi area around P for non-obtuse faces (Meyer et al. 2003), from angles:
// Σ over faces (P, Q, R) of (|PQ|² cot R + |PR|² cot Q) / 4.
double twice_voronoi_area(const TriMesh& mesh, TriMesh::VertexHandle v) {
  const Eigen::Vector3d p = to_eigen(mesh.point(v));
  auto cot = [](const Eigen::Vector3d& at, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return 1.0 / std::tan(std::acos((a - at).normalized().dot((b - at).normalized())));
  };
  double sum = 0.0;
  for (auto h : mesh.voh_range(v)) {
    const Eigen::Vector3d q = to_eigen(mesh.point(h.to())), r = to_eigen(mesh.point(h.next().to()));
    sum += ((q - p).squaredNorm() * cot(r, p, q) + (r - p).squaredNorm() * cot(q, p, r)) / 4.0;
  }
  return sum;
}

// With the default mixed Voronoi area H is 1/r within 2 % at every vertex. SPEC §3 (the thesis)
// divides by the barycentric area instead: around the 12 valence-5 vertices of an icosphere the
// faces are smaller than that area assumes and H there is ~14.5 % high at every level (it does
// not converge under refinement), while the valence-6 vertices stay within 2 %. The test pins
// both, and checks the mixed area against the angle-based Voronoi formula written out here.
TEST(MeanCurvature, IsOneOverTheRadiusOnSpheres) {
  CurvatureOptions barycentric;
  barycentric.area = CurvatureArea::Barycentric;
  for (const int level : {3, 4}) {
    for (const double radius : {0.5, 1.0, 2.0}) {
      const TriMesh mesh = icosphere(radius, level);
      const VertexFields mixed = geometry(mesh);
      const VertexFields thesis = geometry(mesh, barycentric);
      double max_mixed = 0.0, max_regular = 0.0, max_irregular = 0.0, max_voronoi = 0.0, sum_error = 0.0;
      std::size_t irregular = 0;
      for (auto v : mesh.vertices()) {
        const auto id = v.idx();
        ASSERT_TRUE(mixed.defined[id] & kCurvatureDefined) << id;
        ASSERT_TRUE(thesis.defined[id] & kCurvatureDefined) << id;
        max_mixed = std::max(max_mixed, std::abs(mixed.mean_curvature[id] * radius - 1.0));
        const double error = std::abs(thesis.mean_curvature[id] * radius - 1.0);
        sum_error += error;
        if (mesh.valence(v) == 6) {
          max_regular = std::max(max_regular, error);
        } else {
          ASSERT_EQ(mesh.valence(v), 5u);
          ++irregular;
          max_irregular = std::max(max_irregular, error);
        }
        // |Σ c_j (Q_j − P)| / 2 = A·|L| = 2·A·H, so H_voronoi = length / (2·A_voronoi); all
        // icosphere faces are acute, where the mixed area is the Voronoi area (the length also
        // holds the small tangential part of the Laplacian, hence 1e-4 and not rounding).
        const double h_voronoi = thesis.curvature_normal_length[id] / twice_voronoi_area(mesh, v);
        max_voronoi = std::max(max_voronoi, std::abs(h_voronoi - mixed.mean_curvature[id]) * radius);
      }
      const double mean_error = sum_error / static_cast<double>(mesh.n_vertices());
      std::printf(
          "[measured] level %d r=%.1f: |H·r − 1| mixed area max %.3g%%; barycentric valence-6 max %.3g%%, "
          "valence-5 max %.3g%%, mean %.3g%%\n",
          level, radius, 100 * max_mixed, 100 * max_regular, 100 * max_irregular, 100 * mean_error);
      EXPECT_EQ(irregular, 12u);
      EXPECT_LT(max_mixed, 0.02) << "level " << level << " radius " << radius;
      EXPECT_LT(max_voronoi, 1e-4) << "level " << level << " radius " << radius;
      EXPECT_LT(max_regular, 0.02) << "level " << level << " radius " << radius;
      EXPECT_GT(max_irregular, 0.10) << "the barycentric area's known bias at valence 5";
      EXPECT_LT(max_irregular, 0.16) << "level " << level << " radius " << radius;
      EXPECT_LT(mean_error, 0.005) << "level " << level << " radius " << radius;
    }
  }
}

TEST(MeanCurvature, IsNegativeWithInwardNormals) {
  const TriMesh mesh = test::inward_icosphere(2.0, 3);
  const VertexFields fields = geometry(mesh);
  for (auto v : mesh.vertices())
    EXPECT_NEAR(fields.mean_curvature[v.idx()], -0.5, (mesh.valence(v) == 6 ? 0.02 : 0.16) * 0.5);
}

TEST(MeanCurvature, CurvatureNormalLengthMatchesHTimesArea) {
  // |Σ c_j (Q_j − P)| / 2 = A·|L| with L = (1/2A) Σ c_j (Q_j − P) = −2HN when L is along N
  // (on a sphere it is radial), so the stored length is 2·A·|H| with A = one third of the face
  // areas around P, computed here with OpenMesh's own face areas.
  const TriMesh mesh = icosphere(1.0, 3);
  CurvatureOptions barycentric;
  barycentric.area = CurvatureArea::Barycentric;
  const VertexFields fields = geometry(mesh, barycentric);
  double max_ratio_error = 0.0;
  for (auto v : mesh.vertices()) {
    double area = 0.0;
    for (auto f : mesh.vf_range(v)) area += mesh.calc_face_area(f) / 3.0;
    const double expected = 2.0 * area * std::abs(fields.mean_curvature[v.idx()]);
    // Equal up to the tangential part of L, which is tiny on a sphere.
    max_ratio_error =
        std::max(max_ratio_error, std::abs(fields.curvature_normal_length[v.idx()] / expected - 1.0));
  }
  std::printf("[measured] level-3 sphere: |curvature normal length / (2A|H|) - 1| max %.3g\n",
              max_ratio_error);
  EXPECT_LT(max_ratio_error, 1e-3);
}

TEST(MeanCurvature, IsZeroOnAPlaneEvenWhenIrregular) {
  TriMesh mesh = test::to_trimesh(make_grid(1.0, 8));
  // Move interior vertices within the plane: cotangent weights have linear precision, so
  // Σ c_j (Q_j − P) = 0 for any planar interior vertex, regular or not.
  test::Noise noise(7);
  for (auto v : mesh.vertices())
    if (!mesh.is_boundary(v))
      mesh.set_point(
          v, mesh.point(v) + OpenMesh::Vec3d(0.03 * noise.symmetric(), 0.03 * noise.symmetric(), 0.0));
  const VertexFields fields = geometry(mesh);
  std::size_t interior = 0;
  double max_length = 0.0;
  for (auto v : mesh.vertices()) {
    const auto id = v.idx();
    EXPECT_TRUE(fields.defined[id] & kNormalDefined);
    EXPECT_NEAR(fields.normal[id].z(), 1.0, 1e-15);
    if (mesh.is_boundary(v)) {
      EXPECT_FALSE(fields.defined[id] & kCurvatureDefined) << "boundary vertices have no curvature";
      continue;
    }
    ++interior;
    ASSERT_TRUE(fields.defined[id] & kCurvatureDefined);
    EXPECT_NEAR(fields.mean_curvature[id], 0.0, 1e-12);
    max_length = std::max(max_length, fields.curvature_normal_length[id]);
  }
  EXPECT_EQ(interior, 49u);
  std::printf("[measured] jittered plane: max curvature normal length %.3g\n", max_length);
  EXPECT_LT(max_length, 1e-12);
}

TEST(MeanCurvature, DegenerateFaceIsUndefinedEvenWithANormal) {
  TriMesh mesh = icosphere(1.0, 2);
  const auto h = mesh.halfedge_handle(*mesh.faces().begin());
  const auto p = mesh.from_vertex_handle(h);
  const auto q = mesh.to_vertex_handle(h), r = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
  mesh.set_point(p, 0.5 * (mesh.point(q) + mesh.point(r)));
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  // A normal from elsewhere (e.g. the previous iteration) must not make H defined.
  fields.normal[p.idx()] = Eigen::Vector3d::UnitZ();
  fields.defined[p.idx()] = kNormalDefined | kCurvatureDefined;
  fields.mean_curvature[p.idx()] = 123.0;
  compute_mean_curvature(mesh, {static_cast<std::uint32_t>(p.idx()), static_cast<std::uint32_t>(p.idx() + 1)},
                         fields);
  EXPECT_FALSE(fields.defined[p.idx()] & kCurvatureDefined);
  EXPECT_EQ(fields.mean_curvature[p.idx()], 0.0);
  EXPECT_EQ(fields.curvature_normal_length[p.idx()], 0.0);
}

TEST(Geometry, ResultsDoNotDependOnTheBlockSize) {
  TriMesh mesh = icosphere(1.0, 3);
  test::add_radial_noise(mesh, 0.02, 11);
  const VertexFields reference = geometry(mesh);
  for (const std::size_t block_size : {1u, 7u, 64u}) {
    const VertexFields blocked = geometry_in_blocks(mesh, block_size);
    for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
      for (int a = 0; a < 3; ++a) EXPECT_EQ(blocked.normal[v][a], reference.normal[v][a]);
      EXPECT_EQ(blocked.mean_curvature[v], reference.mean_curvature[v]);
      EXPECT_EQ(blocked.curvature_normal_length[v], reference.curvature_normal_length[v]);
      EXPECT_EQ(blocked.defined[v], reference.defined[v]);
    }
  }
}

TEST(Geometry, RejectsRangesOutsideTheMeshAndUnsizedFields) {
  const TriMesh mesh = icosphere(1.0, 1);
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  EXPECT_THROW(compute_normals(mesh, {0, static_cast<std::uint32_t>(mesh.n_vertices() + 1)}, fields), Error);
  VertexFields small;
  small.resize(3, 0);
  EXPECT_THROW(compute_normals(mesh, {0, 3}, small), Error);
  EXPECT_THROW(compute_mean_curvature(mesh, {0, 3}, small), Error);
}

}  // namespace
}  // namespace mvflow
