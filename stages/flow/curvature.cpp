#include "stages/flow/curvature.h"

#include <cmath>

#include "engine/model/one_ring.h"

namespace mvflow {

void compute_mean_curvature(const TriMesh& mesh, IndexRange vertices, VertexFields& fields,
                            const CurvatureOptions& options) {
  detail::check_range(vertices, mesh.n_vertices(), "compute_mean_curvature");
  MVFLOW_CHECK(fields.size() == mesh.n_vertices() && fields.normal.size() == mesh.n_vertices() &&
                   fields.mean_curvature.size() == mesh.n_vertices() &&
                   fields.curvature_normal_length.size() == mesh.n_vertices(),
               "compute_mean_curvature: fields are not sized for the mesh");
  constexpr auto clear_curvature_bit = static_cast<std::uint8_t>(~kCurvatureDefined);
  for (std::uint32_t id = vertices.begin; id < vertices.end; ++id) {
    fields.mean_curvature[id] = 0.0;
    fields.curvature_normal_length[id] = 0.0;
    fields.defined[id] &= clear_curvature_bit;
    if (!(fields.defined[id] & kNormalDefined)) continue;
    const detail::CotangentRing ring = detail::cotangent_ring(mesh, detail::handle(id));
    if (ring.neighbours == 0 || ring.degenerate || ring.boundary) continue;
    // Barycentric: A = (1/3) Σ area = (1/6) Σ |cross|, so 1/(2A) = 3 / Σ |cross|.
    const double inverse_double_area = options.area == CurvatureArea::Barycentric ? 3.0 / ring.double_area_sum
                                                                                  : 0.5 / ring.mixed_area;
    const Eigen::Vector3d laplace = inverse_double_area * ring.weighted_difference;
    const double h = -0.5 * laplace.dot(fields.normal[id]);
    const double length = 0.5 * ring.weighted_difference.norm();
    if (!std::isfinite(h) || !std::isfinite(length)) continue;
    fields.mean_curvature[id] = h;
    fields.curvature_normal_length[id] = length;
    fields.defined[id] |= kCurvatureDefined;
  }
}

}  // namespace mvflow
