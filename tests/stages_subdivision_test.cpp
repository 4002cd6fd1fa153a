// Subdivision (thesis 3.4.1, B.2): Loop, modified Loop and modified Butterfly, whole-mesh and on
// selected faces, and the `mvflow subdivide` command.

#include <gtest/gtest.h>

#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/ModifiedButterFlyT.hh>

#include <algorithm>
#include <bit>
#include <cstring>
#include <set>

#include "engine/model/error.h"
#include "engine/model/mesh_stats.h"
#include "engine/model/option_check.h"
#include "io/mesh_io.h"
#include "stages/topology/subdivision.h"
#include "stages_meshes.h"
#include "test_support.h"

namespace mvflow {
namespace {

using test::to_trimesh;
using Scheme = SubdivisionScheme;
constexpr Scheme kSchemes[] = {Scheme::Loop, Scheme::ModifiedLoop, Scheme::Butterfly};

//! The cube [−1, 1]³, each face split into two triangles, faces outward.
IndexedMesh cube() {
  IndexedMesh m;
  for (int i = 0; i < 8; ++i) m.positions.emplace_back(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return m;
}

//! The regular tetrahedron (valence-3 vertices everywhere).
IndexedMesh tetrahedron() {
  IndexedMesh m;
  m.positions = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  m.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  return m;
}

MeshStats stats_of(const TriMesh& mesh) {
  Mesh m;
  m.topology = mesh;
  return compute_mesh_stats(m);
}

TriMesh run(const TriMesh& mesh, Scheme scheme, int iterations, const std::vector<std::uint8_t>* selected = nullptr) {
  SubdivisionOptions options;
  options.scheme = scheme;
  options.iterations = iterations;
  return subdivide(mesh, options, selected);
}

std::set<std::pair<int, int>> edge_set(const TriMesh& mesh) {
  std::set<std::pair<int, int>> edges;
  for (auto e : mesh.edges()) {
    const int a = mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
    const int b = mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
    edges.insert({std::min(a, b), std::max(a, b)});
  }
  return edges;
}

//! Largest distance between same-id vertices; the meshes must also have the same edges.
double compare_by_id(const TriMesh& a, const TriMesh& b) {
  EXPECT_EQ(a.n_vertices(), b.n_vertices());
  EXPECT_EQ(a.n_faces(), b.n_faces());
  EXPECT_EQ(edge_set(a), edge_set(b));
  double worst = 0.0;
  for (auto v : a.vertices())
    worst = std::max(worst, (to_eigen(a.point(v)) - to_eigen(b.point(TriMesh::VertexHandle(v.idx())))).norm());
  return worst;
}

//! Largest distance between a vertex of \p a and its nearest vertex of \p b, when nearest
//! vertices pair the two meshes one to one and carry the edges of \p a onto those of \p b
//! (for several steps, where the two implementations number vertices differently).
double compare_by_nearest(const TriMesh& a, const TriMesh& b) {
  EXPECT_EQ(a.n_vertices(), b.n_vertices());
  std::vector<int> match(a.n_vertices(), -1);
  double worst = 0.0;
  for (auto v : a.vertices()) {
    double best = 1e300;
    for (auto w : b.vertices()) {
      const double d = (a.point(v) - b.point(w)).norm();
      if (d < best) best = d, match[v.idx()] = w.idx();
    }
    worst = std::max(worst, best);
  }
  EXPECT_EQ(std::set<int>(match.begin(), match.end()).size(), b.n_vertices());
  std::set<std::pair<int, int>> mapped;
  for (const auto& [x, y] : edge_set(a)) mapped.insert({std::min(match[x], match[y]), std::max(match[x], match[y])});
  EXPECT_EQ(mapped, edge_set(b));
  return worst;
}

bool identical(const TriMesh& a, const TriMesh& b) {
  const auto pa = positions_of(a), pb = positions_of(b);
  return pa.size() == pb.size() && std::memcmp(pa.data(), pb.data(), pa.size() * sizeof(pa[0])) == 0 &&
         triangles_of(a) == triangles_of(b);
}

// ---------------------------------------------------------------------------------------------
// Options and contracts

TEST(SubdivisionOptions, DefaultsAreValidAndBadValuesRejected) {
  SubdivisionOptions options;
  EXPECT_NO_THROW(options.check());
  EXPECT_EQ(options.scheme, Scheme::Loop);
  EXPECT_EQ(options.iterations, 1);
  EXPECT_EQ(options.sharp_angle_degrees, 30.0);
  options.iterations = -1;
  EXPECT_THROW(options.check(), OptionError);
  options = {};
  options.sharp_angle_degrees = 181;
  EXPECT_THROW(options.check(), OptionError);
  const TriMesh mesh = to_trimesh(test::octahedron());
  options.iterations = -1;
  EXPECT_THROW(subdivide(mesh, options), Error);
  const std::vector<std::uint8_t> wrong_size(3, 1);
  EXPECT_THROW(subdivide(mesh, {}, &wrong_size), Error);
  // Zero iterations: a copy.
  options = {};
  options.iterations = 0;
  EXPECT_TRUE(identical(subdivide(mesh, options), mesh));
}

// ---------------------------------------------------------------------------------------------
// Agreement with OpenMesh's uniform subdividers on the whole mesh: after one step by vertex id
// (edge e's new vertex is #V + e in both) with the same edges; after two by nearest vertex.

TEST(Subdivision, LoopEqualsOpenMeshLoopT) {
  // Both use Loop's β; closed meshes of valence 3..6 and an open grid (boundary masks).
  for (const IndexedMesh& input : {make_icosphere(1.0, 1), test::torus(8, 6), tetrahedron(), make_grid(2.0, 4)}) {
    const TriMesh mesh = to_trimesh(input);
    TriMesh reference = mesh;
    OpenMesh::Subdivider::Uniform::LoopT<TriMesh> openmesh_loop;
    openmesh_loop.attach(reference);
    openmesh_loop(1);
    EXPECT_LT(compare_by_id(run(mesh, Scheme::Loop, 1), reference), 1e-12);
    openmesh_loop(1);
    openmesh_loop.detach();
    EXPECT_LT(compare_by_nearest(run(mesh, Scheme::Loop, 2), reference), 1e-12);
  }
}

TEST(Subdivision, ButterflyEqualsOpenMeshModifiedButterfly) {
  // Valences 3 (tetrahedron), 4 (octahedron), 5 and 6 (icosphere), boundaries (grid).
  for (const IndexedMesh& input :
       {make_icosphere(1.0, 1), test::octahedron(), tetrahedron(), test::torus(8, 6), make_grid(2.0, 4)}) {
    const TriMesh mesh = to_trimesh(input);
    TriMesh reference = mesh;
    OpenMesh::Subdivider::Uniform::ModifiedButterflyT<TriMesh> openmesh_butterfly;
    openmesh_butterfly.attach(reference);
    openmesh_butterfly(1);
    EXPECT_LT(compare_by_id(run(mesh, Scheme::Butterfly, 1), reference), 1e-12);
    openmesh_butterfly(1);
    openmesh_butterfly.detach();
    EXPECT_LT(compare_by_nearest(run(mesh, Scheme::Butterfly, 2), reference), 1e-12);
  }
}

// ---------------------------------------------------------------------------------------------
// Topology, for every scheme

TEST(Subdivision, ClosedManifoldStaysSoWithFourTimesTheFaces) {
  for (const IndexedMesh& input : {make_icosphere(1.0, 1), test::torus(8, 6), cube(), test::octahedron()}) {
    const TriMesh mesh = to_trimesh(input);
    const MeshStats before = stats_of(mesh);
    for (Scheme scheme : kSchemes) {
      const TriMesh once = run(mesh, scheme, 1);
      EXPECT_EQ(once.n_vertices(), mesh.n_vertices() + mesh.n_edges());  // ids 0..V+E−1, all used
      const TriMesh result = run(mesh, scheme, 2);
      const MeshStats after = stats_of(result);
      EXPECT_EQ(after.faces, 16 * before.faces);
      EXPECT_TRUE(after.is_closed());
      EXPECT_TRUE(after.is_manifold());
      EXPECT_EQ(after.isolated_vertices, 0u);
      EXPECT_EQ(after.euler_characteristic, before.euler_characteristic);
      EXPECT_EQ(after.components, before.components);
    }
  }
}

TEST(Subdivision, OpenMeshKeepsItsBoundary) {
  const TriMesh mesh = to_trimesh(make_grid(1.0, 3));
  const MeshStats before = stats_of(mesh);
  for (Scheme scheme : kSchemes) {
    const MeshStats after = stats_of(run(mesh, scheme, 2));
    EXPECT_EQ(after.faces, 16 * before.faces);
    EXPECT_EQ(after.boundary_loops, 1u);
    EXPECT_EQ(after.boundary_edges, 4 * before.boundary_edges);
    EXPECT_EQ(after.euler_characteristic, before.euler_characteristic);
  }
}

TEST(Subdivision, SameInputSameOutput) {
  const TriMesh mesh = to_trimesh(test::torus(7, 5));
  std::vector<std::uint8_t> selected(mesh.n_faces(), 0);
  for (std::size_t f = 0; f < selected.size(); f += 3) selected[f] = 1;
  for (Scheme scheme : kSchemes) {
    EXPECT_TRUE(identical(run(mesh, scheme, 2), run(mesh, scheme, 2)));
    EXPECT_TRUE(identical(run(mesh, scheme, 2, &selected), run(mesh, scheme, 2, &selected)));
  }
}

// ---------------------------------------------------------------------------------------------
// Loop

double min_radius(const TriMesh& mesh) {
  double r = 1e300;
  for (auto v : mesh.vertices()) r = std::min(r, mesh.point(v).norm());
  return r;
}
double max_radius(const TriMesh& mesh) {
  double r = 0;
  for (auto v : mesh.vertices()) r = std::max(r, mesh.point(v).norm());
  return r;
}

TEST(Subdivision, LoopOfAnIcosphereApproachesTheSphere) {
  // All Loop weights are positive, so every new vertex is a convex combination of old ones and
  // stays inside the unit ball: r ≤ 1. Loop approximates, so it shrinks, by about a quarter to
  // a third of the squared edge length e²: the limit position of a regular vertex is
  // p/2 + Σ q_j/12, whose radius with 6 neighbours at chord e on the unit sphere is
  // 1/2 + (1 − e²/2)/2 = 1 − e²/4; points between vertices shrink a little more. Expected band:
  // e²/5 ≤ 1 − r_min ≤ e²/2 with e the input's mean edge. Measured 1 − r_min after 3 steps:
  // 0.0892 (level 1), 0.0252 (level 2), 0.0066 (level 3), i.e. 0.29–0.33 e².
  const double measured[] = {0.0892, 0.0252, 0.0066};
  for (int level = 1; level <= 3; ++level) {
    const TriMesh mesh = test::icosphere(1.0, level);
    const double e = stats_of(mesh).mean_edge;
    const TriMesh result = run(mesh, Scheme::Loop, 3);
    const double shrink = 1.0 - min_radius(result);
    EXPECT_LE(max_radius(result), 1.0 + 1e-12);
    EXPECT_GE(shrink, e * e / 5.0) << "level " << level;
    EXPECT_LE(shrink, e * e / 2.0) << "level " << level;
    EXPECT_NEAR(shrink, measured[level - 1], 0.0001) << "level " << level;
  }
}

// ---------------------------------------------------------------------------------------------
// Modified Loop

TEST(Subdivision, CubeEdgesByAngle) {
  const TriMesh mesh = to_trimesh(cube());
  const auto sharp = sharp_edges_by_angle(mesh, 30.0);
  int count = 0;
  for (auto e : mesh.edges()) {
    const auto a = to_eigen(mesh.point(mesh.from_vertex_handle(mesh.halfedge_handle(e, 0))));
    const auto b = to_eigen(mesh.point(mesh.to_vertex_handle(mesh.halfedge_handle(e, 0))));
    const bool cube_edge = (a - b).norm() < 2.0 + 1e-12;  // face diagonals are 2√2 long
    EXPECT_EQ(sharp[e.idx()] != 0, cube_edge);
    count += sharp[e.idx()];
  }
  EXPECT_EQ(count, 12);
  // 90° dihedral: sharp below 90°, smooth above.
  int at_100 = 0;
  for (auto s : sharp_edges_by_angle(mesh, 100.0)) at_100 += s;
  EXPECT_EQ(at_100, 0);
}

//! Which of the cube's six face planes (axis·2 + (side > 0)) a vertex lies on, as a bit set.
using Planes = unsigned;

TEST(Subdivision, ModifiedLoopKeepsTheCubeSharp) {
  // The planes of each vertex are followed combinatorially (the new vertex of edge e in a
  // whole-mesh step is #V + e, and lies on the planes common to both endpoints), and then the
  // geometry is checked: corners (3 planes) exact, cube-edge vertices (2 planes) on the edge's
  // line, face vertices (1 plane) on the face's plane, to 1e-12.
  const TriMesh input = to_trimesh(cube());
  TriMesh mesh = input;
  std::vector<Planes> planes;
  for (auto v : mesh.vertices()) {
    Planes p = 0;
    for (int axis = 0; axis < 3; ++axis) p |= 1u << (2 * axis + (mesh.point(v)[axis] > 0 ? 1 : 0));
    planes.push_back(p);
  }
  auto sharp = sharp_edges_by_angle(mesh, 30.0);
  for (int step = 0; step < 3; ++step) {
    std::vector<std::uint8_t> next_sharp;
    TriMesh next = modified_loop_subdivide(mesh, sharp, nullptr, &next_sharp);
    ASSERT_EQ(next.n_vertices(), mesh.n_vertices() + mesh.n_edges());
    for (auto e : mesh.edges()) {
      const int a = mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
      const int b = mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
      planes.push_back(planes[a] & planes[b]);
      ASSERT_NE(planes.back(), 0u);
    }
    mesh = std::move(next);
    sharp = std::move(next_sharp);
  }
  int corners = 0, on_edges = 0, on_faces = 0;
  for (auto v : mesh.vertices()) {
    const Planes p = planes[v.idx()];
    const auto point = mesh.point(v);
    const int count = std::popcount(p);
    if (count == 3) {
      ++corners;
      EXPECT_EQ(point, input.point(v));  // the original corner, bit for bit
    }
    on_edges += count == 2;
    on_faces += count == 1;
    for (int plane = 0; plane < 6; ++plane)
      if (p & (1u << plane)) {
        EXPECT_NEAR(point[plane / 2], plane % 2 ? 1.0 : -1.0, 1e-12) << "vertex " << v.idx();
      }
  }
  EXPECT_EQ(corners, 8);
  EXPECT_EQ(on_edges, 12 * 7);  // 8 segments per cube edge after 3 steps
  EXPECT_EQ(on_faces, static_cast<int>(mesh.n_vertices()) - 8 - 12 * 7);
  // Sharp tags: the 12 cube edges in 8 pieces each.
  EXPECT_EQ(std::count(sharp.begin(), sharp.end(), 1), 12 * 8);

  // Plain Loop rounds the cube: its corners move inward by a visible amount.
  const TriMesh loop = run(input, Scheme::Loop, 3);
  for (int v = 0; v < 8; ++v) EXPECT_LT(loop.point(TriMesh::VertexHandle(v)).norm(), std::sqrt(3.0) - 0.3);
  // The same through subdivide() with the default options.
  SubdivisionOptions options;
  options.scheme = Scheme::ModifiedLoop;
  options.iterations = 3;
  EXPECT_TRUE(identical(subdivide(input, options), mesh));
}

TEST(Subdivision, ModifiedLoopOnASmoothMeshIsLoop) {
  // A level-3 icosphere has dihedral angles of about 9°: no sharp edge, so modified Loop = Loop.
  const TriMesh mesh = test::icosphere(1.0, 3);
  EXPECT_TRUE(identical(run(mesh, Scheme::ModifiedLoop, 1), run(mesh, Scheme::Loop, 1)));
  // With a 0° threshold every edge is sharp: every vertex a corner, new vertices midpoints.
  SubdivisionOptions options;
  options.scheme = Scheme::ModifiedLoop;
  options.sharp_angle_degrees = 0.0;
  const TriMesh flat = subdivide(test::icosphere(1.0, 1), options);
  for (auto v : flat.vertices())
    if (v.idx() < 42) {
      EXPECT_NEAR(flat.point(v).norm(), 1.0, 1e-15);
    }
}

// ---------------------------------------------------------------------------------------------
// Modified Butterfly

TEST(Subdivision, ButterflyInterpolatesTheOldVertices) {
  for (const IndexedMesh& input : {make_icosphere(1.0, 1), test::torus(8, 6), make_grid(1.0, 3), cube()}) {
    const TriMesh mesh = to_trimesh(input);
    const TriMesh result = run(mesh, Scheme::Butterfly, 1);
    for (auto v : mesh.vertices()) EXPECT_EQ(result.point(v), mesh.point(v));
  }
}

TEST(Subdivision, ButterflyKeepsPlanesPlanar) {
  // A tilted plane z = 0.3x − 0.7y + 0.1: every stencil is affine, so it stays planar.
  IndexedMesh grid = make_grid(1.0, 4);
  for (auto& p : grid.positions) p.z() = 0.3 * p.x() - 0.7 * p.y() + 0.1;
  const TriMesh result = run(to_trimesh(grid), Scheme::Butterfly, 2);
  for (auto v : result.vertices()) {
    const auto p = result.point(v);
    EXPECT_NEAR(p[2], 0.3 * p[0] - 0.7 * p[1] + 0.1, 1e-12);
  }
}

TEST(Subdivision, ButterflyReproducesCubicsOnARegularGrid) {
  // The 8-point butterfly stencil has cubic precision: sampled from a cubic height field, its new
  // vertices on edges far enough from the border (full stencil) lie on the same cubic.
  auto f = [](double x, double y) { return 0.5 * x * x * x - x * x * y + 0.25 * y * y + 0.3 * x * y - y + 2.0; };
  IndexedMesh grid = make_grid(1.0, 8);
  for (auto& p : grid.positions) p.z() = f(p.x(), p.y());
  const TriMesh mesh = to_trimesh(grid);
  const TriMesh result = run(mesh, Scheme::Butterfly, 1);
  int checked = 0;
  for (auto e : mesh.edges()) {
    const auto a = mesh.point(mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)));
    const auto b = mesh.point(mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)));
    const auto mid = (a + b) * 0.5;
    const double margin = 2.0 / 8.0 - 1e-9;  // two cells: the wings are interior
    if (std::min({a[0], a[1], b[0], b[1]}) < margin || std::max({a[0], a[1], b[0], b[1]}) > 1.0 - margin) continue;
    const auto p = result.point(TriMesh::VertexHandle(static_cast<int>(mesh.n_vertices()) + e.idx()));
    EXPECT_NEAR(p[0], mid[0], 1e-12);
    EXPECT_NEAR(p[1], mid[1], 1e-12);
    EXPECT_NEAR(p[2], f(mid[0], mid[1]), 1e-12);
    ++checked;
  }
  EXPECT_GT(checked, 40);
}

TEST(Subdivision, ButterflyOnAnIcosphereIsRounderThanMidpoints) {
  // Level-1 icosphere (valences 5 and 6): every new vertex is closer to the unit sphere than the
  // midpoint of its edge.
  const TriMesh mesh = test::icosphere(1.0, 1);
  const TriMesh result = run(mesh, Scheme::Butterfly, 1);
  for (auto e : mesh.edges()) {
    const auto a = mesh.point(mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)));
    const auto b = mesh.point(mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)));
    const double midpoint_error = std::abs(((a + b) * 0.5).norm() - 1.0);
    const auto p = result.point(TriMesh::VertexHandle(static_cast<int>(mesh.n_vertices()) + e.idx()));
    EXPECT_LT(std::abs(p.norm() - 1.0), midpoint_error) << "edge " << e.idx();
  }
}

// ---------------------------------------------------------------------------------------------
// Selected faces (thesis B.2)

std::vector<std::uint8_t> faces_near_north_pole(const TriMesh& mesh, double min_z) {
  std::vector<std::uint8_t> selected(mesh.n_faces(), 0);
  for (auto f : mesh.faces()) {
    double z = 0;
    for (auto v : mesh.fv_range(f)) z += mesh.point(v)[2] / 3.0;
    selected[f.idx()] = z > min_z ? 1 : 0;
  }
  return selected;
}

TEST(Subdivision, SelectedPatchLeavesTheRestUntouched) {
  const TriMesh mesh = test::icosphere(1.0, 2);
  const MeshStats before = stats_of(mesh);
  const auto selected = faces_near_north_pole(mesh, 0.7);
  ASSERT_GT(std::count(selected.begin(), selected.end(), 1), 5);
  const auto input_triangles = triangles_of(mesh);
  for (Scheme scheme : kSchemes)
    for (int iterations : {1, 2}) {
      const TriMesh result = run(mesh, scheme, iterations, &selected);
      const MeshStats after = stats_of(result);
      EXPECT_TRUE(after.is_closed());
      EXPECT_TRUE(after.is_manifold());
      EXPECT_EQ(after.isolated_vertices, 0u);
      EXPECT_EQ(after.euler_characteristic, before.euler_characteristic);
      EXPECT_GT(after.faces, before.faces);
      // Faces far from the patch: same vertex ids, positions bit for bit.
      std::set<std::array<std::uint32_t, 3>> output;
      for (auto t : triangles_of(result)) {
        std::sort(t.begin(), t.end());
        output.insert(t);
      }
      int far = 0;
      for (auto f : mesh.faces()) {
        double z = 1.0;
        for (auto v : mesh.fv_range(f)) z = std::min(z, mesh.point(v)[2]);
        if (z > 0.2) continue;
        ++far;
        auto t = input_triangles[f.idx()];
        std::sort(t.begin(), t.end());
        EXPECT_TRUE(output.contains(t)) << "face " << f.idx();
        for (auto v : mesh.fv_range(f)) EXPECT_EQ(result.point(v), mesh.point(v));
      }
      EXPECT_GT(far, 100);
    }
}

TEST(Subdivision, RedGreenClosureCounts) {
  const TriMesh mesh = test::icosphere(1.0, 2);
  const std::size_t F = mesh.n_faces();
  // One face: it gives 4, its three neighbours 2 each (green).
  std::vector<std::uint8_t> one(F, 0);
  one[0] = 1;
  EXPECT_EQ(run(mesh, Scheme::Loop, 1, &one).n_faces(), F - 4 + 4 + 3 * 2);
  // Two faces both next to a third: the third has two split edges and turns red; the strip of
  // three red faces has five green neighbours.
  std::vector<TriMesh::FaceHandle> around;
  for (auto g : mesh.ff_range(TriMesh::FaceHandle(0))) around.push_back(g);
  std::vector<std::uint8_t> two(F, 0);
  two[around[0].idx()] = two[around[1].idx()] = 1;
  EXPECT_EQ(run(mesh, Scheme::Loop, 1, &two).n_faces(), F - 3 - 5 + 3 * 4 + 5 * 2);
  // Everything selected: the whole-mesh result, bit for bit.
  const std::vector<std::uint8_t> all(F, 1);
  for (Scheme scheme : kSchemes) EXPECT_TRUE(identical(run(mesh, scheme, 2, &all), run(mesh, scheme, 2)));
}

TEST(Subdivision, SelectedFacesSmoothOnlyInside) {
  // Loop on a cap of faces: old vertices with an unselected face keep their position (a cap on
  // an icosphere needs no red closure faces); those inside the cap move.
  const TriMesh mesh = test::icosphere(1.0, 2);
  const auto selected = faces_near_north_pole(mesh, 0.5);
  const TriMesh result = run(mesh, Scheme::Loop, 1, &selected);
  int moved = 0, kept = 0;
  for (auto v : mesh.vertices()) {
    bool all_selected = true;
    for (auto f : mesh.vf_range(v)) all_selected = all_selected && selected[f.idx()];
    if (all_selected) {
      moved += result.point(v) != mesh.point(v);
    } else if (result.point(v) == mesh.point(v)) {
      ++kept;
    } else {
      // Only closure faces can have turned red; none do around a cap on an icosphere.
      ADD_FAILURE() << "vertex " << v.idx() << " outside the selection moved";
    }
  }
  EXPECT_GT(moved, 3);
  EXPECT_GT(kept, 100);
}

// ---------------------------------------------------------------------------------------------
// The command

TEST(SubdivideCommand, WholeMeshQuadruplesTheFaces) {
  test::ScratchFolder folder;
  io::write_mesh(folder / "oct.off", test::octahedron());
  for (const std::string scheme : {"loop", "modloop", "butterfly"}) {
    const auto out = folder / ("out-" + scheme + ".ply");
    const test::CommandResult r = test::run_mvflow("subdivide " + (folder / "oct.off").string() + " --scheme " +
                                                   scheme + " --iterations 2 -o " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(io::read_mesh(out).triangles.size(), 8u * 16u);
  }
}

TEST(SubdivideCommand, FacesFileSelectsFaces) {
  test::ScratchFolder folder;
  io::write_mesh(folder / "oct.off", test::octahedron());
  test::write_text(folder / "faces.txt", "# one face\n  0  # the first\n");
  const test::CommandResult r =
      test::run_mvflow("subdivide " + (folder / "oct.off").string() + " --scheme butterfly --faces " +
                       (folder / "faces.txt").string() + " -o " + (folder / "out.obj").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(io::read_mesh(folder / "out.obj").triangles.size(), 8u - 4u + 4u + 3u * 2u);
}

TEST(SubdivideCommand, BadFaceIndexExitsOneNamingFileLineAndIndex) {
  test::ScratchFolder folder;
  io::write_mesh(folder / "oct.off", test::octahedron());
  test::write_text(folder / "faces.txt", "0 1\n# comment\n2 99\n");
  test::write_text(folder / "out.ply", "keep");
  const test::CommandResult r =
      test::run_mvflow("subdivide " + (folder / "oct.off").string() + " --scheme loop --faces " +
                       (folder / "faces.txt").string() + " -o " + (folder / "out.ply").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("faces.txt:3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("99"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("8 faces"), std::string::npos) << r.output;
  EXPECT_EQ(test::read_text(folder / "out.ply"), "keep");
  // Not a number at all.
  test::write_text(folder / "faces.txt", "0\nseven\n");
  const test::CommandResult r2 =
      test::run_mvflow("subdivide " + (folder / "oct.off").string() + " --scheme loop --faces " +
                       (folder / "faces.txt").string() + " -o " + (folder / "out.ply").string());
  EXPECT_EQ(r2.exit_code, 1) << r2.output;
  EXPECT_NE(r2.output.find("faces.txt:2"), std::string::npos) << r2.output;
}

TEST(SubdivideCommand, UsageErrorsExitTwo) {
  test::ScratchFolder folder;
  io::write_mesh(folder / "oct.off", test::octahedron());
  const std::string mesh = (folder / "oct.off").string(), out = (folder / "out.ply").string();
  EXPECT_EQ(test::run_mvflow("subdivide " + mesh + " --scheme catmull -o " + out).exit_code, 2);
  EXPECT_EQ(test::run_mvflow("subdivide " + mesh + " -o " + out).exit_code, 2);  // --scheme is required
  EXPECT_EQ(test::run_mvflow("subdivide " + mesh + " --scheme loop --iterations -1 -o " + out).exit_code, 2);
  EXPECT_EQ(test::run_mvflow("subdivide --help").exit_code, 0);
}

}  // namespace
}  // namespace mvflow
