#include "stages/hull/neck_cutting.h"

#include <algorithm>
#include <array>
#include <optional>
#include <vector>

#include "engine/model/error.h"
#include "stages/hull/mesh_cleanup.h"

namespace mvflow {

namespace {

using VertexHandle = TriMesh::VertexHandle;
using HalfedgeHandle = TriMesh::HalfedgeHandle;

//! A loop a → b → x → a of edges that bounds no face.
using Loop = std::array<VertexHandle, 3>;

//! The first short edge (a, b) with a common neighbour x of a and b other than the two
//! vertices opposite the edge, as the loop (a, b, x).
std::optional<Loop> find_thin_loop(const TriMesh& mesh, double max_edge) {
  std::vector<VertexHandle> ring;
  for (const auto e : mesh.edges()) {
    if (!(mesh.calc_edge_length(e) < max_edge)) continue;
    const HalfedgeHandle h = mesh.halfedge_handle(e, 0);
    const VertexHandle a = mesh.from_vertex_handle(h), b = mesh.to_vertex_handle(h);
    const VertexHandle c = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
    const VertexHandle d = mesh.to_vertex_handle(mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h)));
    ring.clear();
    for (auto v = mesh.cvv_iter(a); v.is_valid(); ++v) ring.push_back(*v);
    for (auto v = mesh.cvv_iter(b); v.is_valid(); ++v)
      if (*v != c && *v != d && std::find(ring.begin(), ring.end(), *v) != ring.end()) return Loop{a, b, *v};
  }
  return std::nullopt;
}

//! The faces on the left of the loop at its vertex \p v, which the loop enters from \p previous
//! and leaves towards \p next: those met turning counter-clockwise around v from the edge
//! v → next to the edge v → previous.
std::vector<int> left_faces(const TriMesh& mesh, VertexHandle previous, VertexHandle v, VertexHandle next) {
  std::vector<int> faces;
  HalfedgeHandle h = mesh.find_halfedge(v, next);
  do {
    faces.push_back(mesh.face_handle(h).idx());
    h = mesh.opposite_halfedge_handle(mesh.prev_halfedge_handle(h));  // next outgoing edge, counter-clockwise
  } while (mesh.to_vertex_handle(h) != previous);
  return faces;
}

IndexedMesh cut_along(const TriMesh& mesh, const Loop& loop) {
  IndexedMesh cut;
  cut.positions = positions_of(mesh);
  cut.triangles = triangles_of(mesh);
  std::array<std::uint32_t, 3> left_copy{};
  for (int i = 0; i < 3; ++i) {
    const VertexHandle v = loop[i];
    left_copy[i] = static_cast<std::uint32_t>(cut.positions.size());
    cut.positions.push_back(cut.positions[v.idx()]);
    for (const int f : left_faces(mesh, loop[(i + 2) % 3], v, loop[(i + 1) % 3]))
      for (auto& corner : cut.triangles[f])
        if (corner == static_cast<std::uint32_t>(v.idx())) corner = left_copy[i];
  }
  // The faces on the right hold the half-edges b → a, a → x, x → b; the ones on the left
  // a → b, b → x, x → a. Each cap runs the other way round its hole.
  const auto a = static_cast<std::uint32_t>(loop[0].idx()), b = static_cast<std::uint32_t>(loop[1].idx()),
             x = static_cast<std::uint32_t>(loop[2].idx());
  cut.triangles.push_back({a, b, x});
  cut.triangles.push_back({left_copy[0], left_copy[2], left_copy[1]});
  return cut;
}

}  // namespace

std::size_t cut_thin_necks(TriMesh& mesh, double max_edge, std::size_t max_cuts) {
  std::size_t cuts = 0;
  while (cuts < max_cuts) {
    const std::optional<Loop> loop = find_thin_loop(mesh, max_edge);
    if (!loop) break;
    MeshBuildReport report;
    Mesh rebuilt = build_mesh(largest_component(cut_along(mesh, *loop)), "neck cut", &report);
    MVFLOW_CHECK(report.rejected_faces == 0, "cut_thin_necks: the cut surface is not manifold");
    mesh = std::move(rebuilt.topology);
    ++cuts;
  }
  return cuts;
}

}  // namespace mvflow
