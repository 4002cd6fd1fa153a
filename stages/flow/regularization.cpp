#include "stages/flow/regularization.h"

#include <cmath>

#include "engine/model/one_ring.h"
#include "engine/model/option_check.h"
#include "stages/flow/commit.h"
#include "stages/flow/normals.h"

namespace mvflow {

void RegularizationOptions::check() const {
  require_option(strength > 0.0 && strength <= 1.0, "strength", strength, "(0, 1]");
  require_option(steps >= 0, "steps", steps, ">= 0");
}

void regularize_tangential(const TriMesh& mesh, IndexRange vertices, const VertexFields& fields,
                           const RegularizationOptions& options,
                           std::vector<Eigen::Vector3d>& new_positions) {
  options.check();
  detail::check_range(vertices, mesh.n_vertices(), "regularize_tangential");
  MVFLOW_CHECK(fields.size() == mesh.n_vertices() && fields.normal.size() == mesh.n_vertices(),
               "regularize_tangential: fields are not sized for the mesh");
  MVFLOW_CHECK(new_positions.size() == mesh.n_vertices(),
               "regularize_tangential: buffer is not sized for the mesh");
  for (std::uint32_t id = vertices.begin; id < vertices.end; ++id) {
    const auto v = detail::handle(id);
    const Eigen::Vector3d p = detail::point(mesh, v);
    new_positions[id] = p;
    if (!(fields.defined[id] & kNormalDefined) || mesh.is_boundary(v)) continue;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int m = 0;
    for (auto it = mesh.cvv_iter(v); it.is_valid(); ++it, ++m) sum += detail::point(mesh, *it) - p;
    if (m == 0) continue;
    const Eigen::Vector3d u = sum / m;  // (1/m) Σ Q_j − P, summed as differences for precision
    const Eigen::Vector3d& n = fields.normal[id];
    new_positions[id] = p + options.strength * (u - u.dot(n) * n);
  }
}

void apply_regularization(TriMesh& mesh, const RegularizationOptions& options) {
  options.check();
  const IndexRange all{0, static_cast<std::uint32_t>(mesh.n_vertices())};
  VertexFields fields;
  fields.resize(mesh.n_vertices(), 0);
  std::vector<Eigen::Vector3d> buffer(mesh.n_vertices());
  for (int step = 0; step < options.steps; ++step) {
    compute_normals(mesh, all, fields);
    regularize_tangential(mesh, all, fields, options, buffer);
    commit_positions(mesh, all, buffer);
  }
}

}  // namespace mvflow
