#include "stages/topology/subdivision.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <Eigen/Geometry>

#include "engine/model/error.h"
#include "engine/model/one_ring.h"
#include "engine/model/option_check.h"
#include "stages/topology/red_green.h"
#include "stages/topology/subdivision_refine.h"

namespace mvflow {

namespace subdivision_detail {

namespace {

using VertexHandle = TriMesh::VertexHandle;
using EdgeHandle = TriMesh::EdgeHandle;
using FaceHandle = TriMesh::FaceHandle;
using HalfedgeHandle = TriMesh::HalfedgeHandle;

//! Which faces are quadrisected ("red"), which edges split, and where smoothing may act.
struct RefinementPlan {
  std::vector<std::uint8_t> red;           //!< #F
  std::vector<std::int64_t> edge_vertex;   //!< #E: id of the edge's new vertex, −1 if not split
  std::vector<std::uint8_t> edge_smooth;   //!< #E: split and every face of the edge red
  std::vector<std::uint8_t> vertex_moves;  //!< #V: has faces, all of them red
  std::size_t new_vertices = 0;
};

RefinementPlan plan_refinement(const TriMesh& mesh, const std::vector<std::uint8_t>* selected) {
  RefinementPlan plan;
  plan.red = selected ? *selected : std::vector<std::uint8_t>(mesh.n_faces(), 1);
  if (selected) detail::close_red_faces(mesh, plan.red);
  plan.edge_vertex.assign(mesh.n_edges(), -1);
  plan.edge_smooth.assign(mesh.n_edges(), 0);
  for (auto e : mesh.edges()) {
    if (!detail::edge_is_split(mesh, e, plan.red)) continue;
    plan.edge_vertex[e.idx()] = static_cast<std::int64_t>(mesh.n_vertices() + plan.new_vertices++);
    bool all_red = true;
    for (int side = 0; side < 2; ++side) {
      const FaceHandle f = mesh.face_handle(mesh.halfedge_handle(e, side));
      if (f.is_valid() && !plan.red[f.idx()]) all_red = false;
    }
    plan.edge_smooth[e.idx()] = all_red ? 1 : 0;
  }
  plan.vertex_moves.assign(mesh.n_vertices(), 0);
  for (auto v : mesh.vertices()) {
    bool any = false, all_red = true;
    for (auto f : mesh.vf_range(v)) {
      any = true;
      if (!plan.red[f.idx()]) all_red = false;
    }
    plan.vertex_moves[v.idx()] = any && all_red ? 1 : 0;
  }
  return plan;
}

std::vector<TriMesh::Point> new_positions(const TriMesh& mesh, const RefinementPlan& plan, const VertexRule& even,
                                          const EdgeRule& odd) {
  std::vector<TriMesh::Point> points(mesh.n_vertices() + plan.new_vertices);
  for (auto v : mesh.vertices()) points[v.idx()] = plan.vertex_moves[v.idx()] ? even(mesh, v) : mesh.point(v);
  for (auto e : mesh.edges()) {
    const std::int64_t id = plan.edge_vertex[e.idx()];
    if (id < 0) continue;
    // Outside the quadrisected region the surface keeps its shape: split at the midpoint.
    points[id] = plan.edge_smooth[e.idx()]
                     ? odd(mesh, e)
                     : (mesh.point(mesh.from_vertex_handle(mesh.halfedge_handle(e, 0))) +
                        mesh.point(mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)))) * 0.5;
  }
  return points;
}

//! Adds the children of the face with corners \p v and new vertices \p m (red_green.h) to \p out;
//! returns how many.
int add_children(TriMesh& out, const detail::Corners& v, const detail::Corners& m) {
  const detail::ChildFaces children = detail::child_faces(v, m);
  MVFLOW_CHECK(children.count > 0, "subdivide: red-green closure left a face with two split edges");
  for (int k = 0; k < children.count; ++k) {
    const detail::Corners& t = children.faces[k];
    const auto f = out.add_face(VertexHandle(t[0]), VertexHandle(t[1]), VertexHandle(t[2]));
    MVFLOW_CHECK(f.is_valid(), "subdivide: the refined mesh is not manifold (is the input?)");
  }
  return children.count;
}

TriMesh build_refined(const TriMesh& mesh, const RefinementPlan& plan, const std::vector<TriMesh::Point>& points,
                      const std::vector<std::uint8_t>* selected, std::vector<std::uint8_t>& child_selected) {
  TriMesh out;
  out.reserve(points.size(), mesh.n_edges() * 2 + mesh.n_faces() * 3, mesh.n_faces() * 4);
  for (const auto& p : points) out.add_vertex(p);
  const QuietOpenMesh quiet;
  for (auto f : mesh.faces()) {
    // Corners in OpenMesh's face-vertex order (as triangles_of), so untouched faces stay as they were.
    const HalfedgeHandle h2 = mesh.halfedge_handle(f);
    const HalfedgeHandle h0 = mesh.next_halfedge_handle(h2);
    const HalfedgeHandle h1 = mesh.next_halfedge_handle(h0);
    const detail::Corners v{mesh.from_vertex_handle(h0).idx(), mesh.from_vertex_handle(h1).idx(),
                            mesh.from_vertex_handle(h2).idx()};
    auto new_vertex = [&](HalfedgeHandle h) { return static_cast<int>(plan.edge_vertex[mesh.edge_handle(h).idx()]); };
    const detail::Corners m{new_vertex(h0), new_vertex(h1), new_vertex(h2)};
    const int children = add_children(out, v, m);
    if (selected) child_selected.insert(child_selected.end(), children, (*selected)[f.idx()]);
  }
  return out;
}

//! The tags of \p sharp (#E of \p mesh) moved onto the edges of \p out: both halves of a split
//! sharp edge are sharp.
std::vector<std::uint8_t> hand_on_sharp(const TriMesh& mesh, const RefinementPlan& plan,
                                        const std::vector<std::uint8_t>& sharp, const TriMesh& out) {
  std::vector<std::uint8_t> result(out.n_edges(), 0);
  auto tag = [&](int a, std::int64_t b) {
    const auto h = out.find_halfedge(VertexHandle(a), VertexHandle(static_cast<int>(b)));
    MVFLOW_CHECK(h.is_valid(), "subdivide: lost a sharp edge while refining");
    result[out.edge_handle(h).idx()] = 1;
  };
  for (auto e : mesh.edges()) {
    if (!sharp[e.idx()]) continue;
    const int a = mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
    const int b = mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
    const std::int64_t m = plan.edge_vertex[e.idx()];
    if (m < 0) {
      tag(a, b);
    } else {
      tag(a, m);
      tag(b, m);
    }
  }
  return result;
}

}  // namespace

StepOutput refine(const TriMesh& mesh, const std::vector<std::uint8_t>* selected,
                  const std::vector<std::uint8_t>* sharp, const VertexRule& even, const EdgeRule& odd) {
  const RefinementPlan plan = plan_refinement(mesh, selected);
  const std::vector<TriMesh::Point> points = new_positions(mesh, plan, even, odd);
  StepOutput out;
  out.mesh = build_refined(mesh, plan, points, selected, out.selected);
  if (sharp) out.sharp = hand_on_sharp(mesh, plan, *sharp, out.mesh);
  return out;
}

std::vector<std::uint8_t> boundary_edges(const TriMesh& mesh) {
  std::vector<std::uint8_t> flags(mesh.n_edges(), 0);
  for (auto e : mesh.edges()) flags[e.idx()] = mesh.is_boundary(e) ? 1 : 0;
  return flags;
}

}  // namespace subdivision_detail

void SubdivisionOptions::check() const {
  require_option(iterations >= 0, "iterations", iterations, ">= 0");
  require_option(sharp_angle_degrees >= 0.0 && sharp_angle_degrees <= 180.0, "sharp_angle_degrees",
                 sharp_angle_degrees, "[0, 180]");
}

std::vector<std::uint8_t> sharp_edges_by_angle(const TriMesh& mesh, double angle_degrees) {
  std::vector<std::uint8_t> sharp = subdivision_detail::boundary_edges(mesh);
  const double limit = angle_degrees * std::numbers::pi / 180.0;
  auto unit_normal = [&mesh](TriMesh::FaceHandle f, Eigen::Vector3d& n) {
    std::array<Eigen::Vector3d, 3> p;
    int i = 0;
    for (auto v : mesh.fv_range(f)) p[i++] = to_eigen(mesh.point(v));
    const Eigen::Vector3d cross = (p[1] - p[0]).cross(p[2] - p[0]);
    if (detail::is_degenerate(p[0], p[1], p[2], cross)) return false;
    n = cross.normalized();
    return true;
  };
  for (auto e : mesh.edges()) {
    if (sharp[e.idx()]) continue;
    Eigen::Vector3d n0, n1;
    if (!unit_normal(mesh.face_handle(mesh.halfedge_handle(e, 0)), n0) ||
        !unit_normal(mesh.face_handle(mesh.halfedge_handle(e, 1)), n1))
      continue;
    const double angle = std::acos(std::clamp(n0.dot(n1), -1.0, 1.0));
    sharp[e.idx()] = angle > limit ? 1 : 0;
  }
  return sharp;
}

TriMesh loop_subdivide(const TriMesh& mesh, const std::vector<std::uint8_t>* selected_faces) {
  MVFLOW_CHECK(!selected_faces || selected_faces->size() == mesh.n_faces(),
               "loop_subdivide: selected_faces needs one flag per face");
  return subdivision_detail::loop_step(mesh, subdivision_detail::boundary_edges(mesh), selected_faces, false).mesh;
}

TriMesh modified_loop_subdivide(const TriMesh& mesh, const std::vector<std::uint8_t>& sharp_edges,
                                const std::vector<std::uint8_t>* selected_faces,
                                std::vector<std::uint8_t>* next_sharp_edges) {
  MVFLOW_CHECK(sharp_edges.size() == mesh.n_edges(), "modified_loop_subdivide: sharp_edges needs one flag per edge");
  MVFLOW_CHECK(!selected_faces || selected_faces->size() == mesh.n_faces(),
               "modified_loop_subdivide: selected_faces needs one flag per face");
  subdivision_detail::StepOutput out = subdivision_detail::loop_step(mesh, sharp_edges, selected_faces, true);
  if (next_sharp_edges) *next_sharp_edges = std::move(out.sharp);
  return std::move(out.mesh);
}

TriMesh butterfly_subdivide(const TriMesh& mesh, const std::vector<std::uint8_t>* selected_faces) {
  MVFLOW_CHECK(!selected_faces || selected_faces->size() == mesh.n_faces(),
               "butterfly_subdivide: selected_faces needs one flag per face");
  return subdivision_detail::butterfly_step(mesh, selected_faces).mesh;
}

TriMesh subdivide(const TriMesh& mesh, const SubdivisionOptions& options,
                  const std::vector<std::uint8_t>* selected_faces) {
  using namespace subdivision_detail;
  options.check();
  MVFLOW_CHECK(!selected_faces || selected_faces->size() == mesh.n_faces(),
               "subdivide: selected_faces needs one flag per face (" + std::to_string(mesh.n_faces()) + ")");
  StepOutput state{mesh, selected_faces ? *selected_faces : std::vector<std::uint8_t>{}, {}};
  if (options.scheme == SubdivisionScheme::ModifiedLoop)
    state.sharp = sharp_edges_by_angle(mesh, options.sharp_angle_degrees);
  for (int i = 0; i < options.iterations; ++i) {
    const std::vector<std::uint8_t>* selected = selected_faces ? &state.selected : nullptr;
    switch (options.scheme) {
      case SubdivisionScheme::Loop: state = loop_step(state.mesh, boundary_edges(state.mesh), selected, false); break;
      case SubdivisionScheme::ModifiedLoop: state = loop_step(state.mesh, state.sharp, selected, true); break;
      case SubdivisionScheme::Butterfly: state = butterfly_step(state.mesh, selected); break;
    }
  }
  return std::move(state.mesh);
}

}  // namespace mvflow
