#include "stages/flow/unobserved_displacement.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <Eigen/Geometry>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "engine/model/camera.h"
#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "engine/model/surface_query.h"
#include "stages/flow/speed.h"  // median_g_where

namespace mvflow {

void UnobservedDisplacementOptions::check() const {
  require_option(observed_angle_degrees > 0 && observed_angle_degrees <= 90, "observed_angle_degrees",
                 observed_angle_degrees, "(0, 90]");
  require_option(erode_rings >= 0 && erode_rings <= 100, "erode_rings", erode_rings, "[0, 100]");
  require_option(hardly_observed_fraction >= 0 && hardly_observed_fraction <= 1, "hardly_observed_fraction",
                 hardly_observed_fraction, "[0, 1]");
  require_option(first_hardly_observed_fraction >= 0 && first_hardly_observed_fraction <= 1,
                 "first_hardly_observed_fraction", first_hardly_observed_fraction, "[0, 1]");
  require_option(implausible_g_ratio == 0.0 || (implausible_g_ratio > 1.0 && std::isfinite(implausible_g_ratio)),
                 "implausible_g_ratio", implausible_g_ratio, "0 (off) or > 1 and finite");
}

namespace {

// Cotangent weights are clamped into this range: the lower end keeps every edge in the system
// (it stays positive definite where angles near 90° or beyond give a weight near 0 or below), the
// upper end bounds what a nearly degenerate triangle can contribute.
constexpr double kMinWeight = 0.01;
constexpr double kMaxWeight = 1e3;

Eigen::Vector3d position(const TriMesh& mesh, TriMesh::VertexHandle v) { return to_eigen(mesh.point(v)); }

// cot of the angle at r in the triangle (p, q, r).
double cot_at(const Eigen::Vector3d& r, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d a = p - r, b = q - r;
  return a.dot(b) / a.cross(b).norm();
}

// Half the cotangent sum of the angles opposite edge e of the mesh placed at \p at, clamped (see
// kMinWeight).
double edge_weight(const TriMesh& mesh, std::span<const Eigen::Vector3d> at, TriMesh::EdgeHandle e) {
  double sum = 0.0;
  for (int side = 0; side < 2; ++side) {
    const TriMesh::HalfedgeHandle h = mesh.halfedge_handle(e, side);
    if (!mesh.face_handle(h).is_valid()) continue;
    auto p = [&](TriMesh::VertexHandle v) { return at[static_cast<std::size_t>(v.idx())]; };
    sum += cot_at(p(mesh.to_vertex_handle(mesh.next_halfedge_handle(h))), p(mesh.from_vertex_handle(h)),
                  p(mesh.to_vertex_handle(h)));
  }
  const double w = 0.5 * sum;
  return std::isfinite(w) ? std::clamp(w, kMinWeight, kMaxWeight) : kMaxWeight;
}

// Area-weighted vertex normals of the mesh's faces placed at \p at (unit length; zero where
// every face around a vertex is degenerate).
std::vector<Eigen::Vector3d> normals_at(const TriMesh& mesh, std::span<const Eigen::Vector3d> at) {
  std::vector<Eigen::Vector3d> normal(mesh.n_vertices(), Eigen::Vector3d::Zero());
  for (auto f : mesh.faces()) {
    auto fv = mesh.cfv_iter(f);
    const auto a = static_cast<std::size_t>((*fv).idx()), b = static_cast<std::size_t>((*++fv).idx()),
               c = static_cast<std::size_t>((*++fv).idx());
    const Eigen::Vector3d twice_area = (at[b] - at[a]).cross(at[c] - at[a]);
    normal[a] += twice_area, normal[b] += twice_area, normal[c] += twice_area;
  }
  for (Eigen::Vector3d& n : normal) {
    const double length = n.norm();
    n = length > 0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
  }
  return normal;
}

// Clears the free vertices whose connected free region has no fixed neighbour; returns how many.
std::size_t drop_unanchored(const TriMesh& mesh, std::vector<std::uint8_t>& is_free) {
  const std::size_t n = is_free.size();
  std::vector<std::uint8_t> seen(n, 0);
  std::vector<int> members, stack;
  std::size_t dropped = 0;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (!is_free[seed] || seen[seed]) continue;
    members.clear();
    stack.assign(1, static_cast<int>(seed));
    seen[seed] = 1;
    bool anchored = false;
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      members.push_back(v);
      for (auto w : mesh.vv_range(TriMesh::VertexHandle(v))) {
        const auto j = static_cast<std::size_t>(w.idx());
        if (!is_free[j]) {
          anchored = true;
        } else if (!seen[j]) {
          seen[j] = 1;
          stack.push_back(w.idx());
        }
      }
    }
    if (anchored) continue;
    for (int v : members) is_free[static_cast<std::size_t>(v)] = 0;
    dropped += members.size();
  }
  return dropped;
}

// The poor set grown by rings (a vertex becomes poor when one of its one ring is), then the
// vertices on the silhouettes cleared: the observed set eroded.
std::vector<std::uint8_t> grow_by_rings(const TriMesh& mesh, std::vector<std::uint8_t> poor, int rings,
                                        std::span<const std::uint8_t> on_silhouette) {
  std::vector<std::uint8_t> next;
  for (int ring = 0; ring < rings; ++ring) {
    next = poor;
    for (auto v : mesh.vertices())
      for (auto w : mesh.vv_range(v))
        if (poor[static_cast<std::size_t>(w.idx())]) {
          next[static_cast<std::size_t>(v.idx())] = 1;
          break;
        }
    poor.swap(next);
  }
  for (std::size_t v = 0; v < on_silhouette.size(); ++v)
    if (on_silhouette[v]) poor[v] = 0;
  return poor;
}

}  // namespace

std::vector<std::uint8_t> observed_vertices(const TriMesh& mesh, const std::vector<PhotoView>& views,
                                            const VertexFields& fields,
                                            const UnobservedDisplacementOptions& options) {
  std::vector<std::uint8_t> observed;
  observed_vertices(mesh, views, fields, options, observed);
  return observed;
}

void observed_vertices(const TriMesh& mesh, const std::vector<PhotoView>& views, const VertexFields& fields,
                       const UnobservedDisplacementOptions& options, std::vector<std::uint8_t>& observed) {
  options.check();
  MVFLOW_CHECK(fields.size() == mesh.n_vertices(), "observed_vertices: fields not sized for the mesh");
  const double cos_observed = std::cos(options.observed_angle_degrees * std::numbers::pi / 180.0);
  const std::vector<std::uint8_t> implausible = implausible_g_vertices(mesh, fields, options.implausible_g_ratio);
  observed.assign(fields.size(), 0);
  for (std::uint32_t v = 0; v < fields.size(); ++v) {
    if (!(fields.defined[v] & kSpeedDefined) || implausible[v]) continue;
    if (options.observed_angle_degrees >= 90.0) {
      observed[v] = 1;
      continue;
    }
    const Eigen::Vector3d p = position(mesh, TriMesh::VertexHandle(static_cast<int>(v)));
    for (const std::uint16_t id : fields.visible(v)) {
      const Eigen::Vector3d to_camera = views[id].camera->centre() - p;
      if (fields.normal[v].dot(to_camera) >= cos_observed * to_camera.norm()) {
        observed[v] = 1;
        break;
      }
    }
  }
}

std::vector<std::uint8_t> implausible_g_vertices(const TriMesh& mesh, const VertexFields& fields, double ratio) {
  MVFLOW_CHECK(fields.size() == mesh.n_vertices(), "implausible_g_vertices: fields not sized for the mesh");
  MVFLOW_CHECK(ratio == 0.0 || (ratio > 1.0 && std::isfinite(ratio)), "implausible_g_vertices: ratio must be 0 or > 1");
  const std::size_t n = fields.size();
  std::vector<std::uint8_t> implausible(n, 0);
  if (ratio == 0.0) return implausible;
  const double above = ratio * median_g_where(fields, [&](std::size_t v) { return (fields.defined[v] & kSpeedDefined) != 0; });
  if (!(above > 0.0)) return implausible;
  std::vector<std::uint8_t> high(n, 0);
  for (std::size_t v = 0; v < n; ++v)
    high[v] = (fields.defined[v] & kSpeedDefined) && fields.photo_consistency[v] > above;
  for (std::size_t v = 0; v < n; ++v) {
    if (!high[v]) continue;
    bool ring_high = true;
    for (auto w : mesh.vv_range(TriMesh::VertexHandle(static_cast<int>(v))))
      if ((fields.defined[w.idx()] & kSpeedDefined) && !high[w.idx()]) ring_high = false;
    implausible[v] = ring_high;
  }
  return implausible;
}

std::vector<std::uint8_t> poorly_observed_vertices(const TriMesh& mesh, const std::vector<PhotoView>& views,
                                                   const VertexFields& fields,
                                                   const UnobservedDisplacementOptions& options,
                                                   std::span<const std::uint8_t> on_silhouette) {
  MVFLOW_CHECK(on_silhouette.empty() || on_silhouette.size() == fields.size(),
               "poorly_observed_vertices: the silhouette flags are not sized for the mesh");
  std::vector<std::uint8_t> poor = observed_vertices(mesh, views, fields, options);
  for (std::uint8_t& flag : poor) flag = !flag;
  return grow_by_rings(mesh, poor, options.erode_rings, on_silhouette);
}

void keep_hardly_observed(std::vector<std::uint8_t>& poor, std::span<const std::uint32_t> speed_iterations,
                          int iterations, double fraction) {
  MVFLOW_CHECK(speed_iterations.size() == poor.size(), "keep_hardly_observed: " +
                                                           std::to_string(speed_iterations.size()) + " counts for " +
                                                           std::to_string(poor.size()) + " vertices");
  const double most = fraction * iterations;
  for (std::size_t v = 0; v < poor.size(); ++v)
    if (speed_iterations[v] > most) poor[v] = 0;
}

DisplacementResult spread_displacement(TriMesh& mesh, std::span<const Eigen::Vector3d> reference,
                                       std::span<const std::uint8_t> free) {
  const std::size_t n = mesh.n_vertices();
  MVFLOW_CHECK(reference.size() == n && free.size() == n,
               "spread_displacement: " + std::to_string(reference.size()) + " references and " +
                   std::to_string(free.size()) + " flags for " + std::to_string(n) + " vertices");
  std::vector<std::uint8_t> is_free(n, 0);
  for (auto v : mesh.vertices()) {
    const auto i = static_cast<std::size_t>(v.idx());
    is_free[i] = free[i] && !mesh.is_boundary(v);
  }
  DisplacementResult result;
  result.skipped_vertices = drop_unanchored(mesh, is_free);
  std::vector<int> row(n, -1);
  int rows = 0;
  for (std::size_t v = 0; v < n; ++v)
    if (is_free[v]) row[v] = rows++;
  result.moved_vertices = static_cast<std::size_t>(rows);
  if (rows == 0) return result;

  const std::vector<Eigen::Vector3d> normal = normals_at(mesh, reference);
  // d_j is P_j's signed distance to the reference surface, not its offset along its own starting
  // normal: an observed vertex that also slid along the surface (regularization) would otherwise
  // report a displacement too far inward by about (slide)²/(2·radius).
  std::vector<std::array<std::uint32_t, 3>> triangles;
  triangles.reserve(mesh.n_faces());
  for (auto f : mesh.faces()) {
    auto fv = mesh.cfv_iter(f);
    const auto a = static_cast<std::uint32_t>((*fv).idx()), b = static_cast<std::uint32_t>((*++fv).idx()),
               c = static_cast<std::uint32_t>((*++fv).idx());
    triangles.push_back({a, b, c});
  }
  const SurfaceQuery reference_surface(std::vector<Eigen::Vector3d>(reference.begin(), reference.end()), triangles);
  auto displacement = [&](std::size_t v) {
    const Eigen::Vector3d p = position(mesh, TriMesh::VertexHandle(static_cast<int>(v)));
    const ClosestPoint nearest = reference_surface.closest_point(p);
    const auto& t = triangles[nearest.face];
    const Eigen::Vector3d face_normal = (reference[t[1]] - reference[t[0]]).cross(reference[t[2]] - reference[t[0]]);
    return (p - nearest.point).dot(face_normal) < 0 ? -nearest.distance : nearest.distance;
  };
  // Rows of Σ_j w_ij (d_j − d_i) = 0 for the free i, negated; the fixed d_j go to the right.
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(rows);
  for (auto e : mesh.edges()) {
    const double w = edge_weight(mesh, reference, e);
    const auto a = static_cast<std::size_t>(mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)).idx());
    const auto b = static_cast<std::size_t>(mesh.to_vertex_handle(mesh.halfedge_handle(e, 1)).idx());
    for (const auto& [i, j] : {std::pair{a, b}, std::pair{b, a}}) {
      if (row[i] < 0) continue;
      triplets.emplace_back(row[i], row[i], w);
      if (row[j] >= 0) {
        triplets.emplace_back(row[i], row[j], -w);
      } else {
        rhs[row[i]] += w * displacement(j);
      }
    }
  }
  Eigen::SparseMatrix<double> system(rows, rows);
  system.setFromTriplets(triplets.begin(), triplets.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(system);
  MVFLOW_CHECK(solver.info() == Eigen::Success, "spread_displacement: the system could not be factored");
  const Eigen::VectorXd d = solver.solve(rhs);
  MVFLOW_CHECK(solver.info() == Eigen::Success && d.allFinite(), "spread_displacement: the solve failed");
  for (std::size_t v = 0; v < n; ++v)
    if (row[v] >= 0)
      mesh.set_point(TriMesh::VertexHandle(static_cast<int>(v)), to_openmesh(reference[v] + d[row[v]] * normal[v]));
  return result;
}

void extend_reference(std::vector<Eigen::Vector3d>& reference,
                      std::span<const std::array<std::uint32_t, 2>> parents) {
  const std::size_t existing = reference.size();
  for (const auto& [a, b] : parents) {
    MVFLOW_CHECK(a < existing && b < existing, "extend_reference: a parent is not an existing vertex");
    reference.push_back(0.5 * (reference[a] + reference[b]));
  }
}

}  // namespace mvflow
