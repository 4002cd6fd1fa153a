#include "stages/hull/isotropic_remeshing.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/one_ring.h"  // point, is_degenerate
#include "engine/model/option_check.h"
#include "engine/model/parallel.h"
#include "stages/topology/mesh_edit.h"

namespace mvflow {

namespace {

using VertexHandle = TriMesh::VertexHandle;
using HalfedgeHandle = TriMesh::HalfedgeHandle;
using EdgeHandle = TriMesh::EdgeHandle;
using detail::point;

//! True when the triangle (p, q, r) is not degenerate and faces the same side as \p reference.
bool keeps_facing(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r,
                  const Eigen::Vector3d& reference) {
  const Eigen::Vector3d normal = (q - p).cross(r - p);
  return !detail::is_degenerate(p, q, r, normal) && normal.dot(reference) > 0.0;
}

std::size_t split_long_edges(TriMesh& mesh, double high) {
  std::size_t splits = 0;
  // Halves of an edge longer than 2·high are still too long: repeat until none is (each pass at
  // least halves the longest edge, so the loop ends).
  for (bool again = true; again;) {
    again = false;
    const auto n_edges = static_cast<int>(mesh.n_edges());
    for (int id = 0; id < n_edges; ++id) {
      const EdgeHandle e(id);
      if (!(mesh.calc_edge_length(e) > high)) continue;
      detail::split_at_midpoint(mesh, e);
      ++splits;
      again = true;
    }
  }
  return splits;
}

//! Would collapsing \p h (its from-vertex merged into its to-vertex, which stays where it is)
//! keep every edge at the merged vertex ≤ \p high and every surviving face around the removed
//! vertex non-degenerate and facing the way it did?
bool collapse_keeps_shape(const TriMesh& mesh, HalfedgeHandle h, double high) {
  const VertexHandle from = mesh.from_vertex_handle(h), to = mesh.to_vertex_handle(h);
  return detail::check_collapse_ring(mesh, from, to, point(mesh, to), high) == detail::CollapseVerdict::Ok;
}

std::size_t collapse_short_edges(TriMesh& mesh, double low, double high) {
  std::size_t collapses = 0;
  const auto n_edges = static_cast<int>(mesh.n_edges());  // collapses only delete elements
  for (int id = 0; id < n_edges; ++id) {
    const EdgeHandle e(id);
    if (mesh.status(e).deleted() || !(mesh.calc_edge_length(e) < low)) continue;
    const HalfedgeHandle h01 = mesh.halfedge_handle(e, 0), h10 = mesh.halfedge_handle(e, 1);
    bool ok01 = mesh.is_collapse_ok(h01) && collapse_keeps_shape(mesh, h01, high);
    bool ok10 = mesh.is_collapse_ok(h10) && collapse_keeps_shape(mesh, h10, high);
    if (ok01 && ok10) {
      // Remove the end of lower valence (ties: the from-end of halfedge 0).
      if (mesh.valence(mesh.from_vertex_handle(h01)) <= mesh.valence(mesh.to_vertex_handle(h01))) ok10 = false;
      else ok01 = false;
    }
    if (!ok01 && !ok10) continue;
    mesh.collapse(ok01 ? h01 : h10);
    ++collapses;
  }
  if (collapses > 0) mesh.garbage_collection();
  return collapses;
}

std::size_t flip_edges(TriMesh& mesh) {
  std::size_t flips = 0;
  for (const EdgeHandle e : mesh.edges()) {
    if (mesh.is_boundary(e) || !mesh.is_flip_ok(e)) continue;
    // Faces (a0, a1, c) and (a1, a0, d); after the flip (a0, d, c) and (d, a1, c).
    const HalfedgeHandle h0 = mesh.halfedge_handle(e, 0), h1 = mesh.halfedge_handle(e, 1);
    const VertexHandle a0 = mesh.from_vertex_handle(h0), a1 = mesh.to_vertex_handle(h0);
    const VertexHandle c = mesh.to_vertex_handle(mesh.next_halfedge_handle(h0));
    const VertexHandle d = mesh.to_vertex_handle(mesh.next_halfedge_handle(h1));
    auto deviation = [&](int va0, int va1, int vc, int vd) {
      return std::abs(va0 - 6) + std::abs(va1 - 6) + std::abs(vc - 6) + std::abs(vd - 6);
    };
    const int va0 = static_cast<int>(mesh.valence(a0)), va1 = static_cast<int>(mesh.valence(a1));
    const int vc = static_cast<int>(mesh.valence(c)), vd = static_cast<int>(mesh.valence(d));
    if (deviation(va0 - 1, va1 - 1, vc + 1, vd + 1) >= deviation(va0, va1, vc, vd)) continue;
    const Eigen::Vector3d p0 = point(mesh, a0), p1 = point(mesh, a1), pc = point(mesh, c), pd = point(mesh, d);
    // Both new triangles must face the way both old ones did: no fold, no flip across a crease.
    const Eigen::Vector3d n0 = (p1 - p0).cross(pc - p0), n1 = (p0 - p1).cross(pd - p1);
    if (!keeps_facing(p0, pd, pc, n0) || !keeps_facing(p0, pd, pc, n1) || !keeps_facing(pd, p1, pc, n0) ||
        !keeps_facing(pd, p1, pc, n1))
      continue;
    mesh.flip(e);
    ++flips;
  }
  return flips;
}

//! Every vertex moves to the centroid of its neighbours, minus the move along its normal, then
//! onto the reference surface. Jacobi: all new positions from the old ones.
void relax_and_project(TriMesh& mesh, const SurfaceQuery& reference) {
  std::vector<Eigen::Vector3d> moved(mesh.n_vertices());
  parallel::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.n_vertices(), 256), [&](const auto& range) {
    for (std::size_t id = range.begin(); id < range.end(); ++id) {
      const VertexHandle v(static_cast<int>(id));
      const Eigen::Vector3d p = point(mesh, v);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int neighbours = 0;
      for (auto out = mesh.cvoh_iter(v); out.is_valid(); ++out) {
        sum += point(mesh, mesh.to_vertex_handle(*out));
        ++neighbours;
      }
      Eigen::Vector3d normal = detail::area_normal(mesh, v);  // twice the area-weighted normal
      Eigen::Vector3d target = p;
      if (neighbours > 0 && normal.norm() > 0.0) {
        normal.normalize();
        const Eigen::Vector3d step = sum / neighbours - p;
        target = p + step - normal * normal.dot(step);
      }
      moved[id] = reference.closest_point(target).point;
    }
  });
  for (std::size_t id = 0; id < moved.size(); ++id) mesh.set_point(VertexHandle(static_cast<int>(id)), to_openmesh(moved[id]));
}

}  // namespace

void IsotropicRemeshingOptions::check() const {
  require_option(target_edge > 0.0 && std::isfinite(target_edge), "target_edge", target_edge, "> 0 and finite");
  require_option(iterations >= 0, "iterations", iterations, ">= 0");
}

double edge_length_for_vertices(double area, std::size_t vertices) {
  return std::sqrt(2.0 * area / (std::sqrt(3.0) * static_cast<double>(std::max<std::size_t>(vertices, 1))));
}

IsotropicRemeshingResult remesh_isotropic(TriMesh& mesh, const SurfaceQuery& reference,
                                          const IsotropicRemeshingOptions& options) {
  options.check();
  const double low = 0.8 * options.target_edge, high = 4.0 / 3.0 * options.target_edge;
  IsotropicRemeshingResult result;
  const detail::StatusScope status(mesh);
  for (int round = 0; round < options.iterations; ++round) {
    result.splits += split_long_edges(mesh, high);
    result.collapses += collapse_short_edges(mesh, low, high);
    result.flips += flip_edges(mesh);
    relax_and_project(mesh, reference);
  }
  return result;
}

}  // namespace mvflow
