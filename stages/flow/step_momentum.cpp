#include "stages/flow/step_momentum.h"

#include <cmath>

#include "engine/model/error.h"
#include "engine/model/one_ring.h"
#include "engine/model/option_check.h"

namespace mvflow {

void StepMomentumOptions::check() const {
  require_option(carry >= 0.0 && carry < 1.0, "carry", carry, "[0, 1)");
}

void carry_momentum(IndexRange vertices, const StepMomentumOptions& options, double time_step,
                    const std::vector<Eigen::Vector3d>& last_step, VertexFields& fields) {
  detail::check_range(vertices, fields.size(), "carry_momentum");
  MVFLOW_CHECK(time_step > 0.0 && std::isfinite(time_step), "carry_momentum: time_step must be finite and > 0");
  MVFLOW_CHECK(last_step.empty() || last_step.size() == fields.size(),
               "carry_momentum: last_step is not sized for the fields");
  if (options.carry == 0.0 || last_step.empty()) return;
  for (std::uint32_t v = vertices.begin; v < vertices.end; ++v) {
    if (!(fields.defined[v] & kSpeedDefined)) continue;
    const Eigen::Vector3d& normal = fields.normal[v];
    const double carried = last_step[v].dot(normal);
    if (carried * fields.speed[v].dot(normal) > 0.0) fields.speed[v] += (options.carry * carried / time_step) * normal;
  }
}

}  // namespace mvflow
