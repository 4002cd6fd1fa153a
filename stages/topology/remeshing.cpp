#include "stages/topology/remeshing.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "engine/model/error.h"
#include "engine/model/one_ring.h"
#include "engine/model/option_check.h"
#include "stages/topology/mesh_edit.h"

namespace mvflow {

void RemeshingOptions::check() const {
  require_option(collapse_factor > 0.0 && std::isfinite(collapse_factor), "collapse_factor", collapse_factor,
                 "> 0 and finite");
  require_option(split_factor >= 2.0 * collapse_factor && std::isfinite(split_factor), "split_factor", split_factor,
                 ">= 2 × collapse_factor and finite");
}

namespace {

using VertexHandle = TriMesh::VertexHandle;
using HalfedgeHandle = TriMesh::HalfedgeHandle;

void split_long_edges(TriMesh& mesh, double upper, RemeshingResult& result) {
  // The edges too long at the start, each split once (SPEC §5: one pass), longest first (ties in
  // id order): when several edges of a face are long, the first split joins the midpoint to the
  // opposite corner, and that median is shortest for the longest edge; the later splits of the
  // face's other edges join their midpoints to the first midpoint instead.
  std::vector<std::pair<double, int>> long_edges;
  for (auto e : mesh.edges())
    if (const double l = mesh.calc_edge_length(e); l > upper) long_edges.emplace_back(-l, e.idx());
  std::sort(long_edges.begin(), long_edges.end());
  for (const auto& [negative_length, id] : long_edges) {
    // Splitting keeps e's handle (as one half) and only adds elements, so the handles still
    // waiting in long_edges stay valid.
    detail::split_at_midpoint(mesh, TriMesh::EdgeHandle(id));
    ++result.splits;
  }
}

void collapse_short_edges(TriMesh& mesh, double lower, double upper, RemeshingResult& result) {
  // Collapses only delete, so the ids below n_edges() at the start cover every edge of the pass.
  const auto n_edges = static_cast<int>(mesh.n_edges());
  for (int id = 0; id < n_edges; ++id) {
    const TriMesh::EdgeHandle e(id);
    if (mesh.status(e).deleted() || !(mesh.calc_edge_length(e) < lower)) continue;
    HalfedgeHandle h = mesh.halfedge_handle(e, 0);
    VertexHandle from = mesh.from_vertex_handle(h), to = mesh.to_vertex_handle(h);
    const bool from_boundary = mesh.is_boundary(from), to_boundary = mesh.is_boundary(to);
    if (mesh.is_boundary(e) || (from_boundary && to_boundary)) {
      ++result.rejected_boundary;
      continue;
    }
    // OpenMesh's collapse removes the from-vertex and keeps the to-vertex: keep the boundary end.
    if (from_boundary) {
      h = mesh.opposite_halfedge_handle(h);
      std::swap(from, to);
    }
    if (!mesh.is_collapse_ok(h)) {
      ++result.rejected_topology;
      continue;
    }
    const Eigen::Vector3d target = (from_boundary || to_boundary)
                                       ? detail::point(mesh, to)
                                       : 0.5 * (detail::point(mesh, from) + detail::point(mesh, to));
    const Eigen::Vector3d ring_normal = detail::area_normal(mesh, from) + detail::area_normal(mesh, to);
    // Unflipped also against both rings' normal before the collapse: that stops a face from turning
    // over in several steps of < 90° each (seen when most edges of a sphere were candidates).
    using detail::CollapseVerdict;
    CollapseVerdict verdict = detail::check_collapse_ring(mesh, from, to, target, upper, &ring_normal);
    if (verdict == CollapseVerdict::Ok) verdict = detail::check_collapse_ring(mesh, to, from, target, upper, &ring_normal);
    if (verdict != CollapseVerdict::Ok) {
      ++(verdict == CollapseVerdict::FoldOver ? result.rejected_fold_over : result.rejected_long_edge);
      continue;
    }
    mesh.collapse(h);
    mesh.set_point(to, to_openmesh(target));
    ++result.collapses;
  }
  result.rejected_collapses =
      result.rejected_boundary + result.rejected_topology + result.rejected_fold_over + result.rejected_long_edge;
}

}  // namespace

RemeshingResult remesh_edges(TriMesh& mesh, double reference_edge, const RemeshingOptions& options) {
  options.check();
  MVFLOW_CHECK(std::isfinite(reference_edge) && reference_edge > 0.0,
               "remesh_edges: the reference edge e_S must be positive and finite");
  const double upper = options.split_factor * reference_edge;
  const double lower = options.collapse_factor * reference_edge;
  RemeshingResult result;
  const detail::StatusScope status(mesh);
  split_long_edges(mesh, upper, result);
  collapse_short_edges(mesh, lower, upper, result);
  if (result.collapses > 0) mesh.garbage_collection();
  return result;
}

}  // namespace mvflow
