#include "stages/flow/speed.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/model/one_ring.h"
#include "engine/model/option_check.h"

namespace mvflow {
namespace {

constexpr std::uint8_t speed_inputs = kPhotoDefined | kGradientDefined | kNormalDefined | kCurvatureDefined;

}  // namespace

void SpeedOptions::check() const {
  require_option(std::isfinite(velocity), "velocity", velocity, "a finite number");
}

void compute_speed(IndexRange vertices, const SpeedOptions& options, VertexFields& fields) {
  options.check();
  detail::check_range(vertices, fields.size(), "compute_speed");
  for (std::uint32_t id = vertices.begin; id < vertices.end; ++id) {
    fields.speed[id] = Eigen::Vector3d::Zero();
    fields.defined[id] &= static_cast<std::uint8_t>(~(kSpeedDefined | kSpeedFilled));
    if ((fields.defined[id] & speed_inputs) != speed_inputs) continue;
    const Eigen::Vector3d& n = fields.normal[id];
    const double g = fields.photo_consistency[id];
    const double normal_speed =
        g * (options.velocity + fields.mean_curvature[id]) + fields.photo_gradient[id].dot(n);
    const Eigen::Vector3d f = -normal_speed * n;
    if (!f.allFinite()) continue;
    fields.speed[id] = f;
    fields.defined[id] |= kSpeedDefined;
  }
}

BlockPartial reduce_block(IndexRange vertices, const VertexFields& fields) {
  detail::check_range(vertices, fields.size(), "reduce_block");
  BlockPartial partial;
  for (std::uint32_t id = vertices.begin; id < vertices.end; ++id) {
    if (fields.defined[id] & kSpeedDefined)
      partial.max_speed = std::max(partial.max_speed, fields.speed[id].norm());
    if (fields.defined[id] & kPhotoDefined) {
      partial.sum_g += fields.photo_consistency[id];
      ++partial.defined_g;
    }
  }
  return partial;
}

BlockPartial combine(const std::vector<BlockPartial>& partials) {
  BlockPartial total;
  for (const BlockPartial& p : partials) {
    total.max_speed = std::max(total.max_speed, p.max_speed);
    total.sum_g += p.sum_g;
    total.defined_g += p.defined_g;
  }
  return total;
}

double cfl_time_step(double shortest_edge, double max_speed, double cfl) {
  MVFLOW_CHECK(shortest_edge > 0.0 && std::isfinite(shortest_edge),
               "cfl_time_step: shortest edge must be > 0");
  MVFLOW_CHECK(max_speed >= 0.0 && std::isfinite(max_speed),
               "cfl_time_step: max speed must be finite and >= 0");
  MVFLOW_CHECK(cfl > 0.0 && std::isfinite(cfl), "cfl_time_step: cfl must be > 0");
  if (max_speed == 0.0) return 0.0;
  return cfl * (0.5 * shortest_edge) / (std::sqrt(3.0) * max_speed);
}

void compute_local_edges(const TriMesh& mesh, IndexRange vertices, VertexFields& fields) {
  detail::check_range(vertices, mesh.n_vertices(), "compute_local_edges");
  MVFLOW_CHECK(fields.local_edge.size() == mesh.n_vertices(), "compute_local_edges: fields are not sized for the mesh");
  for (std::uint32_t id = vertices.begin; id < vertices.end; ++id) {
    double shortest = std::numeric_limits<double>::infinity();
    for (auto h = mesh.cvoh_iter(detail::handle(id)); h.is_valid(); ++h)
      shortest = std::min(shortest, mesh.calc_edge_length(*h));
    fields.local_edge[id] = shortest;
  }
}

void move_vertices(TriMesh& mesh, IndexRange vertices, const VertexFields& fields, double dt, const MoveLimit& limit,
                   const SilhouetteConstraint* inside, std::vector<double>* moved) {
  MVFLOW_CHECK(dt >= 0.0 && std::isfinite(dt), "move_vertices: dt must be finite and >= 0");
  MVFLOW_CHECK(limit.distance > 0.0 && limit.local_edge_fraction >= 0.0, "move_vertices: invalid move limit");
  detail::check_range(vertices, mesh.n_vertices(), "move_vertices");
  MVFLOW_CHECK(fields.size() == mesh.n_vertices(), "move_vertices: fields are not sized for the mesh");
  MVFLOW_CHECK(!moved || moved->size() == mesh.n_vertices(), "move_vertices: moved is not sized for the mesh");
  for (std::uint32_t id = vertices.begin; id < vertices.end; ++id) {
    const auto v = detail::handle(id);
    if (moved) (*moved)[id] = 0.0;
    if (!(fields.defined[id] & (kSpeedDefined | kSpeedFilled)) || mesh.is_boundary(v)) continue;
    Eigen::Vector3d step = dt * fields.speed[id];
    double longest = limit.distance;
    if (limit.local_edge_fraction > 0.0) longest = std::min(longest, limit.local_edge_fraction * fields.local_edge[id]);
    const double length = step.norm();
    if (length > longest) step *= longest / length;
    const Eigen::Vector3d from = to_eigen(mesh.point(v));
    const Eigen::Vector3d to = inside ? inside->limit_move(from, from + step) : from + step;
    mesh.set_point(v, to_openmesh(to));
    if (moved) (*moved)[id] = (to - from).norm();
  }
}

namespace {

std::vector<double> moving_speeds(const TriMesh& mesh, const VertexFields& fields) {
  MVFLOW_CHECK(fields.size() == mesh.n_vertices(), "speeds: fields are not sized for the mesh");
  std::vector<double> speeds;
  speeds.reserve(fields.size());
  for (std::uint32_t id = 0; id < fields.size(); ++id)
    if ((fields.defined[id] & kSpeedDefined) && !mesh.is_boundary(detail::handle(id)))
      speeds.push_back(fields.speed[id].norm());
  return speeds;
}

}  // namespace

double speed_quantile(const TriMesh& mesh, const VertexFields& fields, double quantile) {
  MVFLOW_CHECK(quantile > 0.0 && quantile <= 1.0, "speed_quantile: quantile must be in (0, 1]");
  std::vector<double> speeds = moving_speeds(mesh, fields);
  if (speeds.empty()) return 0.0;
  const auto rank = static_cast<std::size_t>(std::ceil(quantile * static_cast<double>(speeds.size()))) - 1;
  const auto nth = speeds.begin() + static_cast<std::ptrdiff_t>(std::min(rank, speeds.size() - 1));
  std::nth_element(speeds.begin(), nth, speeds.end());
  return *nth;
}

double median_of(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t upper = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(upper), values.end());
  if (values.size() % 2 == 1) return values[upper];
  // Even count: mean of the two middle values; the lower one is the max of the lower half.
  const double lower = *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(upper));
  return 0.5 * (lower + values[upper]);
}

double median_speed(const TriMesh& mesh, const VertexFields& fields) { return median_of(moving_speeds(mesh, fields)); }

}  // namespace mvflow
