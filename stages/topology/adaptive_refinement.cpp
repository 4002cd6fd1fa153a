#include "stages/topology/adaptive_refinement.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/model/mesh_stats.h"
#include "engine/model/error.h"
#include "stages/topology/mesh_edit.h"
#include "engine/model/one_ring.h"

namespace mvflow {

bool AdaptiveRefinementOptions::check() const {
  return std::isfinite(curvature_factor) && std::isfinite(min_edge_relative) && std::isfinite(min_edge_pixels) &&
         curvature_factor > 0.0 && min_edge_relative >= 0.0 && min_edge_pixels >= 0.0 && min_growth >= 0.0 &&
         min_growth < 1.0;
}

namespace {

using VertexHandle = TriMesh::VertexHandle;
using HalfedgeHandle = TriMesh::HalfedgeHandle;
using Triangle = std::array<VertexHandle, 3>;

//! The three halfedges of face \p f in order: halfedge k runs from corner k to corner k+1.
std::array<HalfedgeHandle, 3> face_halfedges(const TriMesh& mesh, TriMesh::FaceHandle f) {
  const HalfedgeHandle h0 = mesh.halfedge_handle(f);
  const HalfedgeHandle h1 = mesh.next_halfedge_handle(h0);
  return {h0, h1, mesh.next_halfedge_handle(h1)};
}

//! The red/green marks of one call: per face (1 = red) and per edge (1 = split), flat arrays
//! indexed by id (std::uint8_t, never std::vector<bool>).
struct Marks {
  std::vector<std::uint8_t> red;
  std::vector<std::uint8_t> split;
};

void make_red(const TriMesh& mesh, TriMesh::FaceHandle f, Marks& marks) {
  marks.red[f.idx()] = 1;
  for (auto e = mesh.cfe_iter(f); e.is_valid(); ++e) marks.split[e->idx()] = 1;
}

int split_edges_of(const TriMesh& mesh, TriMesh::FaceHandle f, const Marks& marks) {
  int count = 0;
  for (auto e = mesh.cfe_iter(f); e.is_valid(); ++e) count += marks.split[e->idx()];
  return count;
}

//! Marks the red faces around high-curvature vertices (step 1); returns the marked vertex count.
std::size_t mark_red(const TriMesh& mesh, const VertexFields& fields, double threshold, double min_edge,
                     Marks& marks) {
  std::size_t marked = 0;
  for (auto v : mesh.vertices()) {
    const auto id = static_cast<std::size_t>(v.idx());
    if (!(fields.defined[id] & kCurvatureDefined) || !(fields.curvature_normal_length[id] > threshold)) continue;
    ++marked;
    for (auto f = mesh.cvf_iter(v); f.is_valid(); ++f) {
      if (marks.red[f->idx()]) continue;
      bool long_enough = true;
      for (auto e = mesh.cfe_iter(*f); e.is_valid(); ++e) long_enough &= mesh.calc_edge_length(*e) > min_edge;
      if (long_enough) make_red(mesh, *f, marks);
    }
  }
  return marked;
}

//! Promotes faces with ≥ 2 split edges to red until none is left (step 2); returns how many.
std::size_t close_red(const TriMesh& mesh, Marks& marks) {
  std::size_t promoted = 0;
  for (bool changed = true; changed;) {
    changed = false;
    for (auto f : mesh.faces()) {
      if (marks.red[f.idx()] || split_edges_of(mesh, f, marks) < 2) continue;
      make_red(mesh, f, marks);
      ++promoted;
      changed = true;
    }
  }
  return promoted;
}

}  // namespace

RefinementResult refine_adaptively(TriMesh& mesh, const VertexFields& fields, double reference_edge,
                                   const AdaptiveRefinementOptions& options, double pixel_size) {
  MVFLOW_CHECK(pixel_size >= 0.0 && std::isfinite(pixel_size), "refine_adaptively: pixel size must be >= 0");
  MVFLOW_CHECK(options.check(), "refine_adaptively: invalid AdaptiveRefinementOptions");
  MVFLOW_CHECK(std::isfinite(reference_edge) && reference_edge > 0.0,
               "refine_adaptively: the reference edge e_S must be positive and finite");
  MVFLOW_CHECK(fields.defined.size() == mesh.n_vertices() &&
                   fields.curvature_normal_length.size() == mesh.n_vertices(),
               "refine_adaptively: fields are not sized for the mesh");

  RefinementResult result;
  Marks marks{std::vector<std::uint8_t>(mesh.n_faces(), 0), std::vector<std::uint8_t>(mesh.n_edges(), 0)};
  const double threshold = options.curvature_factor * reference_edge;
  const double min_edge =
      std::max(options.min_edge_relative * bounding_box_of(mesh).diagonal(), options.min_edge_pixels * pixel_size);
  result.marked_vertices = mark_red(mesh, fields, threshold, min_edge, marks);
  result.promoted_faces = close_red(mesh, marks);
  const auto split_edges = static_cast<std::size_t>(std::count(marks.split.begin(), marks.split.end(), 1));
  if (split_edges > 0 && static_cast<double>(split_edges) < options.min_growth * static_cast<double>(mesh.n_vertices())) {
    result.promoted_faces = 0;
    result.declined = split_edges;
    return result;
  }

  // Midpoints, appended in edge-id order.
  std::vector<VertexHandle> midpoint(mesh.n_edges());
  for (auto e : mesh.edges()) {
    if (!marks.split[e.idx()]) continue;
    const auto h = mesh.halfedge_handle(e, 0);
    const auto mid = 0.5 * (mesh.point(mesh.from_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(h)));
    midpoint[e.idx()] = mesh.add_vertex(mid);
    result.parents.push_back({static_cast<std::uint32_t>(mesh.from_vertex_handle(h).idx()),
                              static_cast<std::uint32_t>(mesh.to_vertex_handle(h).idx())});
    ++result.new_vertices;
  }
  if (result.new_vertices == 0) return result;

  // The children of every refined face, in face-id order, corners counter-clockwise as the parent's.
  std::vector<TriMesh::FaceHandle> refined;
  std::vector<Triangle> children;
  for (auto f : mesh.faces()) {
    const auto h = face_halfedges(mesh, f);
    std::array<VertexHandle, 3> c, m;
    int split = 0, first_split = 0;
    for (int k = 0; k < 3; ++k) {
      c[k] = mesh.from_vertex_handle(h[k]);
      const int e = mesh.edge_handle(h[k]).idx();
      m[k] = midpoint[e];
      if (marks.split[e] && split++ == 0) first_split = k;
    }
    if (split == 0) continue;
    refined.push_back(f);
    if (marks.red[f.idx()]) {
      assert(split == 3);
      ++result.red_faces;
      children.push_back({c[0], m[0], m[2]});
      children.push_back({c[1], m[1], m[0]});
      children.push_back({c[2], m[2], m[1]});
      children.push_back({m[0], m[1], m[2]});
    } else {
      assert(split == 1);  // close_red promoted every face with more
      ++result.green_faces;
      const int k = first_split;
      children.push_back({c[k], m[k], c[(k + 2) % 3]});
      children.push_back({m[k], c[(k + 1) % 3], c[(k + 2) % 3]});
    }
  }

  const detail::StatusScope status(mesh);
  for (const auto f : refined) mesh.delete_face(f, false);  // keep vertices: their ids must not change
  for (const auto& t : children) {
    const auto f = mesh.add_face(t[0], t[1], t[2]);
    MVFLOW_CHECK(f.is_valid(), "refine_adaptively: OpenMesh rejected a child face (internal error)");
  }
  mesh.garbage_collection();
  return result;
}

}  // namespace mvflow
