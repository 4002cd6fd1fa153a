#include "stages/topology/adaptive_refinement.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/mesh_stats.h"
#include "engine/model/one_ring.h"
#include "engine/model/option_check.h"
#include "stages/topology/mesh_edit.h"
#include "stages/topology/red_green.h"

namespace mvflow {

void AdaptiveRefinementOptions::check() const {
  require_option(curvature_factor > 0.0 && std::isfinite(curvature_factor), "curvature_factor", curvature_factor,
                 "> 0 and finite");
  require_option(min_edge_relative >= 0.0 && std::isfinite(min_edge_relative), "min_edge_relative",
                 min_edge_relative, ">= 0 and finite");
  require_option(min_edge_pixels >= 0.0 && std::isfinite(min_edge_pixels), "min_edge_pixels", min_edge_pixels,
                 ">= 0 and finite");
  require_option(min_growth >= 0.0 && min_growth < 1.0, "min_growth", min_growth, "[0, 1)");
}

namespace {

using VertexHandle = TriMesh::VertexHandle;
using HalfedgeHandle = TriMesh::HalfedgeHandle;

//! The three halfedges of face \p f in order: halfedge k runs from corner k to corner k+1.
std::array<HalfedgeHandle, 3> face_halfedges(const TriMesh& mesh, TriMesh::FaceHandle f) {
  const HalfedgeHandle h0 = mesh.halfedge_handle(f);
  const HalfedgeHandle h1 = mesh.next_halfedge_handle(h0);
  return {h0, h1, mesh.next_halfedge_handle(h1)};
}

//! Marks red (\p red, #F) the faces around high-curvature vertices whose edges are all longer
//! than \p min_edge (step 1); returns the marked vertex count.
std::size_t mark_red(const TriMesh& mesh, const VertexFields& fields, double threshold, double min_edge,
                     std::vector<std::uint8_t>& red) {
  std::size_t marked = 0;
  for (auto v : mesh.vertices()) {
    const auto id = static_cast<std::size_t>(v.idx());
    if (!(fields.defined[id] & kCurvatureDefined) || !(fields.curvature_normal_length[id] > threshold)) continue;
    ++marked;
    for (auto f = mesh.cvf_iter(v); f.is_valid(); ++f) {
      if (red[f->idx()]) continue;
      bool long_enough = true;
      for (auto e = mesh.cfe_iter(*f); e.is_valid(); ++e) long_enough &= mesh.calc_edge_length(*e) > min_edge;
      if (long_enough) red[f->idx()] = 1;
    }
  }
  return marked;
}

//! #E flags: the edges of the red faces, each of which gets a midpoint.
std::vector<std::uint8_t> edges_of_red_faces(const TriMesh& mesh, const std::vector<std::uint8_t>& red) {
  std::vector<std::uint8_t> split(mesh.n_edges(), 0);
  for (auto f : mesh.faces())
    if (red[f.idx()])
      for (auto e = mesh.cfe_iter(f); e.is_valid(); ++e) split[e->idx()] = 1;
  return split;
}

}  // namespace

RefinementResult refine_adaptively(TriMesh& mesh, const VertexFields& fields, double reference_edge,
                                   const AdaptiveRefinementOptions& options, double pixel_size) {
  MVFLOW_CHECK(pixel_size >= 0.0 && std::isfinite(pixel_size), "refine_adaptively: pixel size must be >= 0");
  options.check();
  MVFLOW_CHECK(std::isfinite(reference_edge) && reference_edge > 0.0,
               "refine_adaptively: the reference edge e_S must be positive and finite");
  MVFLOW_CHECK(fields.defined.size() == mesh.n_vertices() &&
                   fields.curvature_normal_length.size() == mesh.n_vertices(),
               "refine_adaptively: fields are not sized for the mesh");

  RefinementResult result;
  std::vector<std::uint8_t> red(mesh.n_faces(), 0);
  const double threshold = options.curvature_factor * reference_edge;
  const double min_edge =
      std::max(options.min_edge_relative * bounding_box_of(mesh).diagonal(), options.min_edge_pixels * pixel_size);
  result.marked_vertices = mark_red(mesh, fields, threshold, min_edge, red);
  result.promoted_faces = detail::close_red_faces(mesh, red);  // step 2
  const std::vector<std::uint8_t> split = edges_of_red_faces(mesh, red);
  const auto split_edges = static_cast<std::size_t>(std::count(split.begin(), split.end(), 1));
  if (split_edges > 0 && static_cast<double>(split_edges) < options.min_growth * static_cast<double>(mesh.n_vertices())) {
    result.promoted_faces = 0;
    result.declined = split_edges;
    return result;
  }

  // Midpoints, appended in edge-id order.
  std::vector<int> new_vertex(mesh.n_edges(), -1);  // #E: the midpoint's id, −1 if not split
  for (auto e : mesh.edges()) {
    if (!split[e.idx()]) continue;
    const auto h = mesh.halfedge_handle(e, 0);
    new_vertex[e.idx()] = mesh.add_vertex(detail::midpoint(mesh, e)).idx();
    result.parents.push_back({static_cast<std::uint32_t>(mesh.from_vertex_handle(h).idx()),
                              static_cast<std::uint32_t>(mesh.to_vertex_handle(h).idx())});
    ++result.new_vertices;
  }
  if (result.new_vertices == 0) return result;

  // The children of every refined face, in face-id order, corners counter-clockwise as the parent's.
  std::vector<TriMesh::FaceHandle> refined;
  std::vector<detail::Corners> children;
  for (auto f : mesh.faces()) {
    const auto h = face_halfedges(mesh, f);
    detail::Corners c, m;
    for (int k = 0; k < 3; ++k) {
      c[k] = mesh.from_vertex_handle(h[k]).idx();
      m[k] = new_vertex[mesh.edge_handle(h[k]).idx()];
    }
    const detail::ChildFaces split_face = detail::child_faces(c, m);
    if (split_face.count == 1) continue;  // no split edge: the face stays
    assert(split_face.count == 4 || split_face.count == 2);  // the closure leaves no face with two
    refined.push_back(f);
    ++(split_face.count == 4 ? result.red_faces : result.green_faces);
    children.insert(children.end(), split_face.faces.begin(), split_face.faces.begin() + split_face.count);
  }

  const detail::StatusScope status(mesh);
  for (const auto f : refined) mesh.delete_face(f, false);  // keep vertices: their ids must not change
  for (const auto& t : children) {
    const auto f = mesh.add_face(VertexHandle(t[0]), VertexHandle(t[1]), VertexHandle(t[2]));
    MVFLOW_CHECK(f.is_valid(), "refine_adaptively: OpenMesh rejected a child face (internal error)");
  }
  mesh.garbage_collection();
  return result;
}

}  // namespace mvflow
