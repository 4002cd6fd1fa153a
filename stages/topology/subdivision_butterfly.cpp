// Modified Butterfly masks (Zorin, Schröder, Sweldens 1996; declared in stages/topology/subdivision.h,
// shared step in stages/topology/subdivision_refine.h).

#include <cmath>
#include <numbers>

#include "stages/topology/subdivision.h"
#include "stages/topology/subdivision_refine.h"

namespace mvflow::subdivision_detail {

namespace {

using Point = TriMesh::Point;
using HalfedgeHandle = TriMesh::HalfedgeHandle;

//! Zorin's weight s_j of the j-th neighbour of an extraordinary vertex of valence K (the vertex
//! itself weighs 3/4).
double zorin_weight(std::size_t K, std::size_t j) {
  if (K == 3) return j == 0 ? 5.0 / 12.0 : -1.0 / 12.0;
  if (K == 4) return j == 0 ? 3.0 / 8.0 : j == 2 ? -1.0 / 8.0 : 0.0;
  const double angle = 2.0 * std::numbers::pi * static_cast<double>(j) / static_cast<double>(K);
  return (0.25 + std::cos(angle) + 0.5 * std::cos(2.0 * angle)) / static_cast<double>(K);
}

//! The stencil of the interior vertex v = from(h), neighbours counted from q_0 = to(h).
Point extraordinary_stencil(const TriMesh& mesh, HalfedgeHandle h) {
  const auto v = mesh.from_vertex_handle(h);
  const std::size_t K = mesh.valence(v);
  Point p = mesh.point(v) * 0.75;
  for (std::size_t j = 0; j < K; ++j, h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h)))
    p += mesh.point(mesh.to_vertex_handle(h)) * zorin_weight(K, j);
  return p;
}

//! The wing vertex across the edge of \p h (the corner opposite it in the other face), or its
//! reflection x + y − opposite when that edge is a boundary edge.
Point wing(const TriMesh& mesh, HalfedgeHandle h) {
  const HalfedgeHandle o = mesh.opposite_halfedge_handle(h);
  if (!mesh.is_boundary(o)) return mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(o)));
  return mesh.point(mesh.from_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(h)) -
         mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
}

//! Regular case: 1/2·(a + b) + 1/8·(c + d) − 1/16·(w1 + w2 + w3 + w4).
Point butterfly_stencil(const TriMesh& mesh, HalfedgeHandle h) {
  const HalfedgeHandle o = mesh.opposite_halfedge_handle(h);
  const Point ab = mesh.point(mesh.from_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(h));
  const Point cd = mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h))) +
                   mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(o)));
  const Point wings = wing(mesh, mesh.next_halfedge_handle(h)) + wing(mesh, mesh.prev_halfedge_handle(h)) +
                      wing(mesh, mesh.next_halfedge_handle(o)) + wing(mesh, mesh.prev_halfedge_handle(o));
  return ab * 0.5 + cd * 0.125 - wings * 0.0625;
}

//! Boundary edge: the 4-point rule (−1, 9, 9, −1)/16 along the boundary.
Point four_point(const TriMesh& mesh, TriMesh::EdgeHandle e) {
  HalfedgeHandle h = mesh.halfedge_handle(e, 0);
  if (!mesh.is_boundary(h)) h = mesh.opposite_halfedge_handle(h);
  const Point ab = mesh.point(mesh.from_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(h));
  const Point outer = mesh.point(mesh.from_vertex_handle(mesh.prev_halfedge_handle(h))) +
                      mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
  return ab * (9.0 / 16.0) - outer * (1.0 / 16.0);
}

bool extraordinary(const TriMesh& mesh, TriMesh::VertexHandle v) {
  return !mesh.is_boundary(v) && mesh.valence(v) != 6;
}

Point butterfly_edge(const TriMesh& mesh, TriMesh::EdgeHandle e) {
  if (mesh.is_boundary(e)) return four_point(mesh, e);
  const HalfedgeHandle h = mesh.halfedge_handle(e, 0);
  const HalfedgeHandle o = mesh.halfedge_handle(e, 1);
  const auto a = mesh.from_vertex_handle(h);
  const auto b = mesh.to_vertex_handle(h);
  // Valence < 3 (two faces glued along all edges) has no stencil: split at the midpoint.
  if (mesh.valence(a) < 3 || mesh.valence(b) < 3) return (mesh.point(a) + mesh.point(b)) * 0.5;
  const bool xa = extraordinary(mesh, a), xb = extraordinary(mesh, b);
  if (!xa && !xb) return butterfly_stencil(mesh, h);
  if (xa && xb) return (extraordinary_stencil(mesh, h) + extraordinary_stencil(mesh, o)) * 0.5;
  return extraordinary_stencil(mesh, xa ? h : o);
}

}  // namespace

StepOutput butterfly_step(const TriMesh& mesh, const std::vector<std::uint8_t>* selected) {
  const VertexRule even = [](const TriMesh& m, TriMesh::VertexHandle v) { return m.point(v); };
  const EdgeRule odd = [](const TriMesh& m, TriMesh::EdgeHandle e) { return butterfly_edge(m, e); };
  return refine(mesh, selected, nullptr, even, odd);
}

}  // namespace mvflow::subdivision_detail
