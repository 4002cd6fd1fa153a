// Loop and modified Loop masks (declared in stages/topology/subdivision.h, shared step in
// stages/topology/subdivision_refine.h).

#include <array>
#include <cmath>
#include <numbers>

#include "stages/topology/subdivision.h"
#include "stages/topology/subdivision_refine.h"

namespace mvflow::subdivision_detail {

namespace {

using Point = TriMesh::Point;

//! Loop's weight β(n) of each neighbour of an interior vertex of valence n (Loop 1987).
double loop_beta(std::size_t n) {
  const double t = 3.0 / 8.0 + 0.25 * std::cos(2.0 * std::numbers::pi / static_cast<double>(n));
  return (5.0 / 8.0 - t * t) / static_cast<double>(n);
}

bool is_sharp(const TriMesh& mesh, TriMesh::EdgeHandle e, const std::vector<std::uint8_t>& sharp) {
  return sharp[e.idx()] || mesh.is_boundary(e);
}

//! Smooth and dart vertices: Loop's mask; crease: (1, 6, 1)/8 along the crease; corner: stays.
Point loop_vertex(const TriMesh& mesh, TriMesh::VertexHandle v, const std::vector<std::uint8_t>& sharp) {
  const Point p = mesh.point(v);
  Point sum(0, 0, 0);
  std::array<Point, 2> crease;
  std::size_t n = 0, s = 0;
  for (auto h : mesh.voh_range(v)) {
    const Point q = mesh.point(mesh.to_vertex_handle(h));
    sum += q;
    ++n;
    if (is_sharp(mesh, mesh.edge_handle(h), sharp)) {
      if (s < 2) crease[s] = q;
      ++s;
    }
  }
  if (s >= 3 || n == 0) return p;
  if (s == 2) return (p * 6.0 + crease[0] + crease[1]) * 0.125;
  const double beta = loop_beta(n);
  return p * (1.0 - static_cast<double>(n) * beta) + sum * beta;
}

//! Sharp and boundary edges: the midpoint; smooth edges: 3/8·(a + b) + 1/8·(c + d).
Point loop_edge(const TriMesh& mesh, TriMesh::EdgeHandle e, const std::vector<std::uint8_t>& sharp) {
  const auto h = mesh.halfedge_handle(e, 0);
  const auto o = mesh.halfedge_handle(e, 1);
  const Point ab = mesh.point(mesh.to_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(o));
  if (is_sharp(mesh, e, sharp)) return ab * 0.5;
  const Point cd = mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h))) +
                   mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(o)));
  return ab * (3.0 / 8.0) + cd * (1.0 / 8.0);
}

}  // namespace

StepOutput loop_step(const TriMesh& mesh, const std::vector<std::uint8_t>& sharp,
                     const std::vector<std::uint8_t>* selected, bool hand_on_sharp) {
  const VertexRule even = [&sharp](const TriMesh& m, TriMesh::VertexHandle v) { return loop_vertex(m, v, sharp); };
  const EdgeRule odd = [&sharp](const TriMesh& m, TriMesh::EdgeHandle e) { return loop_edge(m, e, sharp); };
  return refine(mesh, selected, hand_on_sharp ? &sharp : nullptr, even, odd);
}

}  // namespace mvflow::subdivision_detail
