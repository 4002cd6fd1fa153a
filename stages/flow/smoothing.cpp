#include "stages/flow/smoothing.h"

#include <cmath>

#include "engine/model/one_ring.h"
#include "engine/model/option_check.h"
#include "stages/flow/commit.h"

namespace mvflow {

void SmoothingOptions::check() const {
  require_option(lambda_dt > 0.0 && lambda_dt < 1.0, "lambda_dt", lambda_dt, "(0, 1)");
  require_option(steps >= 0, "steps", steps, ">= 0");
  require_option(taubin_pass_band >= 0.0, "taubin_pass_band", taubin_pass_band, ">= 0");
  // μ = λ/(1 − k·λ) must lie in (0, 1): a negative μ would shrink a second time.
  require_option(taubin_pass_band * lambda_dt < 1.0 && taubin_mu() < 1.0, "taubin_pass_band", taubin_pass_band,
                 "< 1/lambda_dt − 1 (Taubin's mu = lambda/(1 − k·lambda) below 1)");
}

namespace {

// P' = P + factor·(centroid − P) for the vertices of the range (smooth_curvature_normal).
void step_toward_centroid(const TriMesh& mesh, IndexRange vertices, double factor,
                          std::vector<Eigen::Vector3d>& new_positions) {
  detail::check_range(vertices, mesh.n_vertices(), "smooth_curvature_normal");
  MVFLOW_CHECK(new_positions.size() == mesh.n_vertices(),
               "smooth_curvature_normal: buffer is not sized for the mesh");
  for (std::uint32_t id = vertices.begin; id < vertices.end; ++id) {
    const auto v = detail::handle(id);
    const Eigen::Vector3d p = detail::point(mesh, v);
    new_positions[id] = p;
    const detail::CotangentRing ring = detail::cotangent_ring(mesh, v);
    if (ring.neighbours == 0 || ring.boundary) continue;
    Eigen::Vector3d to_centroid = ring.weighted_difference / ring.weight_sum;
    // Single weights c_j go negative at obtuse angles, but each face (P, Q, R) adds
    // cot Q + cot R = sin P / (sin Q sin R) > 0 to Σ c_j, so the sum fails (≤ 0, inf, NaN) only
    // with (near-)degenerate faces. Then the cotangent centroid is noise or infinitely far:
    // use the uniform centroid, which always lies inside the one ring.
    if (ring.degenerate || !(ring.weight_sum > 0.0) || !to_centroid.allFinite())
      to_centroid = ring.uniform_difference / ring.neighbours;
    new_positions[id] = p + factor * to_centroid;
  }
}

}  // namespace

void smooth_curvature_normal(const TriMesh& mesh, IndexRange vertices, const SmoothingOptions& options,
                             std::vector<Eigen::Vector3d>& new_positions) {
  options.check();
  step_toward_centroid(mesh, vertices, options.lambda_dt, new_positions);
}

void inflate_curvature_normal(const TriMesh& mesh, IndexRange vertices, const SmoothingOptions& options,
                              std::vector<Eigen::Vector3d>& new_positions) {
  options.check();
  MVFLOW_CHECK(options.taubin_pass_band > 0.0, "inflate_curvature_normal: needs a Taubin pass band > 0");
  step_toward_centroid(mesh, vertices, -options.taubin_mu(), new_positions);
}

void apply_smoothing(TriMesh& mesh, const SmoothingOptions& options) {
  options.check();
  const IndexRange all{0, static_cast<std::uint32_t>(mesh.n_vertices())};
  std::vector<Eigen::Vector3d> buffer(mesh.n_vertices());
  for (int step = 0; step < options.steps; ++step) {
    smooth_curvature_normal(mesh, all, options, buffer);
    commit_positions(mesh, all, buffer);
    if (options.taubin_pass_band > 0.0) {
      inflate_curvature_normal(mesh, all, options, buffer);
      commit_positions(mesh, all, buffer);
    }
  }
}

}  // namespace mvflow
