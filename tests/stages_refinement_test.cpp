// Adaptive refinement (SPEC §5, thesis 5.3.1, figure 5.1, B.7): faces around vertices with a
// large mean-curvature normal are quadrisected (red), their neighbours bisected (green), so the
// mesh stays conforming, of the same topology, and unchanged away from the marked region.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <set>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/mesh_stats.h"
#include "engine/model/option_check.h"
#include "stages/flow/curvature.h"
#include "stages/flow/normals.h"
#include "stages/topology/adaptive_refinement.h"
#include "stages_meshes.h"
#include "test_support.h"

namespace mvflow {
namespace {

using Triangle = std::array<std::uint32_t, 3>;

MeshStats stats_of(const TriMesh& mesh) {
  Mesh m;
  m.topology = mesh;
  return compute_mesh_stats(m);
}

VertexFields curvature_of(const TriMesh& mesh) {
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  compute_normals(mesh, test::all_vertices(mesh), fields);
  compute_mean_curvature(mesh, test::all_vertices(mesh), fields);
  return fields;
}

double total_area(const TriMesh& mesh) {
  double area = 0.0;
  for (const auto& t : triangles_of(mesh)) {
    const Eigen::Vector3d a = test::position(mesh, t[0]), b = test::position(mesh, t[1]),
                          c = test::position(mesh, t[2]);
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

//! A face as its corners rotated so the smallest id comes first (orientation kept).
Triangle canonical(Triangle t) {
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

std::set<Triangle> face_set(const TriMesh& mesh) {
  std::set<Triangle> faces;
  for (const auto& t : triangles_of(mesh)) faces.insert(canonical(t));
  return faces;
}

bool has_edge(const TriMesh& mesh, std::uint32_t a, std::uint32_t b) {
  return mesh.find_halfedge(TriMesh::VertexHandle(static_cast<int>(a)), TriMesh::VertexHandle(static_cast<int>(b)))
      .is_valid();
}

//! The level-3 icosphere of radius 1 with its topmost vertex pushed out to radius 1.3: a spike
//! whose apex and one ring have a large curvature normal, the rest a sphere's.
struct Bump {
  TriMesh mesh;
  std::uint32_t apex = 0;
  double reference_edge = 0.0;  // e_S: the shortest edge of the sphere before the bump
};

Bump bumped_sphere() {
  Bump bump;
  bump.mesh = test::icosphere(1.0, 3);
  bump.reference_edge = stats_of(bump.mesh).shortest_edge;
  for (auto v : bump.mesh.vertices())
    if (bump.mesh.point(v)[2] > bump.mesh.point(TriMesh::VertexHandle(static_cast<int>(bump.apex)))[2])
      bump.apex = static_cast<std::uint32_t>(v.idx());
  const auto apex = TriMesh::VertexHandle(static_cast<int>(bump.apex));
  bump.mesh.set_point(apex, bump.mesh.point(apex) * 1.3);
  return bump;
}

//! The faces the marking rule selects, recomputed here: around a vertex over the threshold, with
//! every edge longer than the minimum.
std::vector<Triangle> marked_faces(const TriMesh& mesh, const VertexFields& fields, double threshold, double min_edge) {
  std::set<Triangle> marked;
  for (auto v : mesh.vertices()) {
    const auto id = static_cast<std::size_t>(v.idx());
    if (!(fields.defined[id] & kCurvatureDefined) || fields.curvature_normal_length[id] <= threshold) continue;
    for (auto f = mesh.cvf_iter(v); f.is_valid(); ++f) {
      bool long_enough = true;
      for (auto e = mesh.cfe_iter(*f); e.is_valid(); ++e) long_enough &= mesh.calc_edge_length(*e) > min_edge;
      if (!long_enough) continue;
      Triangle t{};
      int k = 0;
      for (auto c = mesh.cfv_iter(*f); c.is_valid(); ++c) t[k++] = static_cast<std::uint32_t>(c->idx());
      marked.insert(canonical(t));
    }
  }
  return {marked.begin(), marked.end()};
}

// Every refinement done, however small: the geometric tests below refine a few faces of a sphere.
constexpr AdaptiveRefinementOptions kEveryRefinement{.min_growth = 0.0};

TEST(AdaptiveRefinementOptions, DefaultsAreTheThesisValuesAndValid) {
  const AdaptiveRefinementOptions options;
  EXPECT_NO_THROW(options.check());
  EXPECT_EQ(options.curvature_factor, 0.5);     // tolerance e_S / 2, thesis B.7
  EXPECT_EQ(options.min_edge_relative, 1e-3);   // thesis B.4's 1e-3, relative (SPEC §9)
  EXPECT_EQ(options.min_growth, 0.1);           // not the thesis's (0): README, "Defaults and differences"
  EXPECT_THROW((AdaptiveRefinementOptions{.curvature_factor = 0.0}).check(), OptionError);
  EXPECT_THROW((AdaptiveRefinementOptions{.min_edge_relative = -1.0, .min_growth = 0.0}).check(), OptionError);
  EXPECT_THROW((AdaptiveRefinementOptions{.curvature_factor = NAN}).check(), OptionError);
  TriMesh mesh = test::icosphere(1.0, 1);
  const VertexFields fields = curvature_of(mesh);
  EXPECT_THROW(refine_adaptively(mesh, fields, 0.0), Error);
  EXPECT_THROW(refine_adaptively(mesh, VertexFields{}, 0.1), Error);
}

TEST(AdaptiveRefinement, SmoothSphereBelowTheThresholdIsUntouched) {
  // Level 3: |Σ c_j (Q_j − P)|/2 ≈ 2·A·H ≈ 0.04 per vertex, below e_S/2 ≈ 0.05.
  TriMesh mesh = test::icosphere(1.0, 3);
  const VertexFields fields = curvature_of(mesh);
  const auto positions = positions_of(mesh);
  const auto faces = triangles_of(mesh);
  const RefinementResult r = refine_adaptively(mesh, fields, stats_of(mesh).shortest_edge, kEveryRefinement);
  EXPECT_EQ(r.marked_vertices, 0u);
  EXPECT_EQ(r.red_faces + r.green_faces + r.new_vertices, 0u);
  EXPECT_EQ(positions_of(mesh), positions);
  EXPECT_EQ(triangles_of(mesh), faces);
}

class BumpedSphere : public ::testing::Test {
 protected:
  void SetUp() override {
    bump = bumped_sphere();
    fields = curvature_of(bump.mesh);
    threshold = 0.5 * bump.reference_edge;
    min_edge = 1e-3 * stats_of(bump.mesh).bounding_box.diagonal();
  }
  Bump bump;
  VertexFields fields;
  double threshold = 0.0, min_edge = 0.0;
};

TEST_F(BumpedSphere, RefinesOnlyTheMarkedRegionAndItsClosure) {
  TriMesh& mesh = bump.mesh;
  const MeshStats before = stats_of(mesh);
  const auto old_positions = positions_of(mesh);
  const auto old_faces = triangles_of(mesh);
  const double old_area = total_area(mesh);
  const std::vector<Triangle> marked = marked_faces(mesh, fields, threshold, min_edge);
  std::set<std::uint32_t> region;  // the corners of the marked faces
  for (const auto& t : marked) region.insert(t.begin(), t.end());

  const RefinementResult r = refine_adaptively(mesh, fields, bump.reference_edge, kEveryRefinement);
  const MeshStats after = stats_of(mesh);
  std::printf("[measured] marked vertices %zu, marked faces %zu, red %zu (promoted %zu), green %zu, new vertices "
              "%zu; faces %zu -> %zu\n",
              r.marked_vertices, marked.size(), r.red_faces, r.promoted_faces, r.green_faces, r.new_vertices,
              before.faces, after.faces);
  EXPECT_GT(r.marked_vertices, 0u);
  EXPECT_LT(r.marked_vertices, 10u);  // the apex and its ring, not the sphere
  EXPECT_GE(r.red_faces, marked.size());
  EXPECT_GT(r.green_faces, 0u);

  // Conforming, manifold, same topology; counts add up.
  EXPECT_EQ(after.boundary_edges, 0u);
  EXPECT_EQ(after.non_manifold_vertices, 0u);
  EXPECT_EQ(after.isolated_vertices, 0u);
  EXPECT_EQ(after.components, 1u);
  EXPECT_EQ(after.euler_characteristic, before.euler_characteristic);
  EXPECT_EQ(after.genus, 0);
  EXPECT_EQ(after.vertices, before.vertices + r.new_vertices);
  EXPECT_EQ(after.faces, before.faces + 3 * r.red_faces + r.green_faces);
  EXPECT_EQ(after.edges, before.edges + r.new_vertices + 3 * r.red_faces + r.green_faces);

  // Old vertices keep their ids and positions; the children lie in their parents' planes.
  const auto new_positions = positions_of(mesh);
  EXPECT_TRUE(std::equal(old_positions.begin(), old_positions.end(), new_positions.begin()));
  EXPECT_NEAR(total_area(mesh), old_area, 1e-12 * old_area);

  // Every marked face is quadrisected: none of its edges survives.
  for (const auto& t : marked)
    for (int k = 0; k < 3; ++k) EXPECT_FALSE(has_edge(mesh, t[k], t[(k + 1) % 3]));
  // Faces that are gone all touch the marked region (its faces and their vertex one ring); every
  // other face is still there, with the same corners.
  const std::set<Triangle> now = face_set(mesh);
  std::size_t kept = 0, refined = 0;
  for (const auto& t : old_faces) {
    if (now.count(canonical(t))) {
      ++kept;
      continue;
    }
    ++refined;
    EXPECT_TRUE(region.count(t[0]) || region.count(t[1]) || region.count(t[2]))
        << "refined face " << t[0] << " " << t[1] << " " << t[2] << " is outside the closure";
  }
  EXPECT_EQ(refined, r.red_faces + r.green_faces);
  EXPECT_EQ(kept, before.faces - refined);
}

TEST_F(BumpedSphere, MinimumGrowthDeclinesASmallRefinementAndChangesNothing) {
  TriMesh reference = bump.mesh;
  const RefinementResult all = refine_adaptively(reference, fields, bump.reference_edge, kEveryRefinement);
  ASSERT_GT(all.new_vertices, 0u);
  const double growth = static_cast<double>(all.new_vertices) / static_cast<double>(bump.mesh.n_vertices());

  TriMesh declined = bump.mesh;  // just above the growth: declined, the mesh untouched
  const RefinementResult none =
      refine_adaptively(declined, fields, bump.reference_edge, {.min_growth = growth * 1.0001});
  EXPECT_EQ(none.declined, all.new_vertices);
  EXPECT_EQ(none.new_vertices + none.red_faces + none.green_faces + none.promoted_faces, 0u);
  EXPECT_EQ(none.marked_vertices, all.marked_vertices);
  EXPECT_EQ(triangles_of(declined), triangles_of(bump.mesh));
  EXPECT_EQ(positions_of(declined), positions_of(bump.mesh));

  TriMesh accepted = bump.mesh;  // just below the growth: done, exactly as without a minimum
  const RefinementResult done = refine_adaptively(accepted, fields, bump.reference_edge, {.min_growth = growth * 0.9999});
  EXPECT_EQ(done.declined, 0u);
  EXPECT_EQ(done.new_vertices, all.new_vertices);
  EXPECT_EQ(triangles_of(accepted), triangles_of(reference));
  EXPECT_EQ(positions_of(accepted), positions_of(reference));

  for (const double bad : {-0.1, 1.0, std::nan("")}) EXPECT_THROW(AdaptiveRefinementOptions{.min_growth = bad}.check(), OptionError) << bad;
}

TEST_F(BumpedSphere, MinimumEdgeBlocksRefinement) {
  // Per marked face its shortest edge, relative to the bounding-box diagonal: a minimum at or
  // above the largest of these blocks every face, one below the smallest blocks none.
  const double diagonal = stats_of(bump.mesh).bounding_box.diagonal();
  double smallest = INFINITY, largest = 0.0;
  for (const auto& t : marked_faces(bump.mesh, fields, threshold, 0.0)) {
    double shortest = INFINITY;
    for (int k = 0; k < 3; ++k)
      shortest = std::min(shortest, (test::position(bump.mesh, t[k]) - test::position(bump.mesh, t[(k + 1) % 3])).norm());
    smallest = std::min(smallest, shortest / diagonal);
    largest = std::max(largest, shortest / diagonal);
  }
  std::printf("[measured] marked faces' shortest edges: %.4f..%.4f of the diagonal\n", smallest, largest);

  TriMesh blocked = bump.mesh;
  const RefinementResult none =
      refine_adaptively(blocked, fields, bump.reference_edge, {.min_edge_relative = largest * 1.0001, .min_growth = 0.0});
  EXPECT_GT(none.marked_vertices, 0u);
  EXPECT_EQ(none.red_faces + none.green_faces + none.new_vertices, 0u);
  EXPECT_EQ(triangles_of(blocked), triangles_of(bump.mesh));
  EXPECT_EQ(positions_of(blocked), positions_of(bump.mesh));

  // The same floor given in pixels: min_edge_pixels × pixel_size blocks exactly like the
  // relative floor of the same length.
  TriMesh blocked_by_pixels = bump.mesh;
  const double pixel_size = largest * 1.0001 * diagonal / 5.0;
  const RefinementResult none_by_pixels =
      refine_adaptively(blocked_by_pixels, fields, bump.reference_edge, {.min_edge_pixels = 5.0, .min_growth = 0.0}, pixel_size);
  EXPECT_EQ(none_by_pixels.red_faces + none_by_pixels.new_vertices, 0u);
  TriMesh pixels_between = bump.mesh;
  const RefinementResult some_by_pixels = refine_adaptively(
      pixels_between, fields, bump.reference_edge, {.min_edge_pixels = 5.0, .min_growth = 0.0}, 0.5 * (smallest + largest) * diagonal / 5.0);
  EXPECT_EQ(some_by_pixels.red_faces - some_by_pixels.promoted_faces,
            marked_faces(bump.mesh, fields, threshold, 0.5 * (smallest + largest) * diagonal).size());
  EXPECT_THROW(refine_adaptively(pixels_between, fields, bump.reference_edge, {}, -1.0), Error);

  TriMesh partly = bump.mesh;  // between: only the faces whose edges are all long enough
  const double between = 0.5 * (smallest + largest);
  const RefinementResult some =
      refine_adaptively(partly, fields, bump.reference_edge, {.min_edge_relative = between, .min_growth = 0.0});
  const auto expected = marked_faces(bump.mesh, fields, threshold, between * diagonal);
  EXPECT_EQ(some.red_faces - some.promoted_faces, expected.size());  // marked directly

  TriMesh allowed = bump.mesh;  // below all: refined as with the default 1e-3
  const RefinementResult all =
      refine_adaptively(allowed, fields, bump.reference_edge, {.min_edge_relative = smallest * 0.9999, .min_growth = 0.0});
  TriMesh by_default = bump.mesh;
  const RefinementResult reference = refine_adaptively(by_default, fields, bump.reference_edge, kEveryRefinement);
  std::printf("[measured] red faces: %zu blocked, %zu between, %zu below all, %zu by default\n", none.red_faces,
              some.red_faces, all.red_faces, reference.red_faces);
  EXPECT_GT(all.red_faces, 0u);
  EXPECT_EQ(all.red_faces, reference.red_faces);
  EXPECT_EQ(triangles_of(allowed), triangles_of(by_default));
}

TEST_F(BumpedSphere, IsDeterministicAndUnitFree) {
  TriMesh copy = bump.mesh;
  TriMesh scaled = bump.mesh;
  for (auto v : scaled.vertices()) scaled.set_point(v, scaled.point(v) * 1000.0);
  const VertexFields scaled_fields = curvature_of(scaled);
  const RefinementResult a = refine_adaptively(bump.mesh, fields, bump.reference_edge, kEveryRefinement);
  const RefinementResult b = refine_adaptively(copy, fields, bump.reference_edge, kEveryRefinement);
  const RefinementResult c = refine_adaptively(scaled, scaled_fields, 1000.0 * bump.reference_edge, kEveryRefinement);
  EXPECT_EQ(a.red_faces, b.red_faces);
  EXPECT_EQ(a.green_faces, b.green_faces);
  EXPECT_EQ(positions_of(bump.mesh), positions_of(copy));
  EXPECT_EQ(triangles_of(bump.mesh), triangles_of(copy));
  // Both thresholds are relative (e_S and the bounding box): a mesh in millimetres refines alike.
  EXPECT_EQ(a.red_faces, c.red_faces);
  EXPECT_EQ(a.green_faces, c.green_faces);
  EXPECT_EQ(triangles_of(bump.mesh), triangles_of(scaled));
}

TEST_F(BumpedSphere, RepeatedRefinementStaysConformingAndStops) {
  // As the engine does between iterations: recompute the curvature, refine, again. The apex's
  // curvature normal shrinks with its ring, so refinement stops on its own.
  TriMesh& mesh = bump.mesh;
  const double area = total_area(mesh);
  int rounds = 0;
  for (; rounds < 12; ++rounds) {
    const RefinementResult r = refine_adaptively(mesh, curvature_of(mesh), bump.reference_edge, kEveryRefinement);
    if (r.new_vertices == 0) break;
    const MeshStats s = stats_of(mesh);
    EXPECT_EQ(s.boundary_edges, 0u);
    EXPECT_EQ(s.non_manifold_vertices, 0u);
    EXPECT_EQ(s.euler_characteristic, 2);
  }
  const MeshStats s = stats_of(mesh);
  std::printf("[measured] refinement rounds until none: %d, vertices %zu, shortest edge %.4g (e_S %.4g)\n", rounds,
              s.vertices, s.shortest_edge, bump.reference_edge);
  EXPECT_LT(rounds, 12);
  EXPECT_NEAR(total_area(mesh), area, 1e-12 * area);
}

// Thesis figure 5.1 on a flat grid: the six faces around a marked interior vertex are quadrisected
// and the six faces sharing an edge with that hexagon bisected; nothing else changes.
TEST(AdaptiveRefinement, FigureFiveOneOnAGrid) {
  TriMesh mesh = test::to_trimesh(make_grid(1.0, 6));
  const MeshStats before = stats_of(mesh);
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  const std::uint32_t centre = 3 * 7 + 3;  // (3, 3) of the 7×7 grid vertices
  ASSERT_EQ(mesh.valence(TriMesh::VertexHandle(static_cast<int>(centre))), 6u);
  fields.defined[centre] = kCurvatureDefined;
  fields.curvature_normal_length[centre] = 1.0;
  const double area = total_area(mesh);
  const RefinementResult r = refine_adaptively(mesh, fields, 0.1, kEveryRefinement);
  const MeshStats after = stats_of(mesh);
  EXPECT_EQ(r.marked_vertices, 1u);
  EXPECT_EQ(r.red_faces, 6u);
  EXPECT_EQ(r.promoted_faces, 0u);
  EXPECT_EQ(r.green_faces, 6u);
  EXPECT_EQ(r.new_vertices, 12u);  // 6 spokes + 6 rim edges
  EXPECT_EQ(after.faces, before.faces + 3 * 6 + 6);
  EXPECT_EQ(after.boundary_edges, before.boundary_edges);  // the grid's border only: conforming inside
  EXPECT_EQ(after.boundary_loops, 1u);
  EXPECT_EQ(after.euler_characteristic, before.euler_characteristic);
  EXPECT_EQ(after.non_manifold_vertices, 0u);
  EXPECT_NEAR(total_area(mesh), area, 1e-12 * area);
  for (auto f : mesh.faces()) {  // all still facing +z
    const auto n = mesh.calc_face_normal(f);
    EXPECT_GT(n[2], 0.0);
  }
}

// Two marked vertices two steps apart: faces between their hexagons get two split edges and are
// promoted to red (never split 1 → 3); the result is conforming.
TEST(AdaptiveRefinement, FacesWithTwoSplitEdgesArePromotedToRed) {
  TriMesh mesh = test::to_trimesh(make_grid(1.0, 8));
  const MeshStats before = stats_of(mesh);
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  for (const std::uint32_t v : {3u * 9 + 2, 3u * 9 + 4}) {
    fields.defined[v] = kCurvatureDefined;
    fields.curvature_normal_length[v] = 1.0;
  }
  const double area = total_area(mesh);
  const RefinementResult r = refine_adaptively(mesh, fields, 0.1, kEveryRefinement);
  const MeshStats after = stats_of(mesh);
  std::printf("[measured] two marked vertices: red %zu (promoted %zu), green %zu, new vertices %zu\n", r.red_faces,
              r.promoted_faces, r.green_faces, r.new_vertices);
  EXPECT_GT(r.promoted_faces, 0u);
  EXPECT_EQ(after.faces, before.faces + 3 * r.red_faces + r.green_faces);
  EXPECT_EQ(after.boundary_edges, before.boundary_edges);
  EXPECT_EQ(after.euler_characteristic, before.euler_characteristic);
  EXPECT_EQ(after.non_manifold_vertices, 0u);
  EXPECT_NEAR(total_area(mesh), area, 1e-12 * area);
  // No T-junction: every new vertex is interior with valence 5 (red on one side, green on the other) or 6 (red on both).
  for (std::size_t id = before.vertices; id < mesh.n_vertices(); ++id) {
    const auto v = TriMesh::VertexHandle(static_cast<int>(id));
    EXPECT_FALSE(mesh.is_boundary(v));
    EXPECT_TRUE(mesh.valence(v) == 5 || mesh.valence(v) == 6) << mesh.valence(v);
  }
}

TEST(AdaptiveRefinement, AtTheBoundaryOfAnOpenMesh) {
  // A marked vertex next to the border: its red faces split border edges, which have no face
  // beyond them to close; the border stays one loop on the square.
  TriMesh mesh = test::to_trimesh(make_grid(1.0, 6));
  const MeshStats before = stats_of(mesh);
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  const std::uint32_t v = 1 * 7 + 1;
  fields.defined[v] = kCurvatureDefined;
  fields.curvature_normal_length[v] = 1.0;
  const double area = total_area(mesh);
  const RefinementResult r = refine_adaptively(mesh, fields, 0.1, kEveryRefinement);
  const MeshStats after = stats_of(mesh);
  EXPECT_EQ(r.red_faces, 6u);
  EXPECT_GT(after.boundary_edges, before.boundary_edges);
  EXPECT_EQ(after.boundary_loops, 1u);
  EXPECT_EQ(after.euler_characteristic, before.euler_characteristic);
  EXPECT_EQ(after.non_manifold_vertices, 0u);
  EXPECT_NEAR(total_area(mesh), area, 1e-12 * area);
  for (auto u : mesh.vertices()) {
    if (!mesh.is_boundary(u)) continue;
    const auto p = mesh.point(u);
    EXPECT_TRUE(p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0) << p;
  }
}

}  // namespace
}  // namespace mvflow
