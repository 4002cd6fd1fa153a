#include "stages/flow/step_damping.h"

#include <algorithm>
#include <cmath>

#include "engine/model/error.h"
#include "engine/model/one_ring.h"
#include "engine/model/option_check.h"

namespace mvflow {

void StepDampingOptions::check() const {
  require_option(shrink > 0.0 && shrink < 1.0, "shrink", shrink, "(0, 1)");
  require_option(grow >= 1.0 && std::isfinite(grow), "grow", grow, ">= 1 and finite");
  require_option(min_scale > 0.0 && min_scale <= 1.0, "min_scale", min_scale, "(0, 1]");
}

void StepDampingState::reset(std::size_t n_vertices) {
  scale.assign(n_vertices, 1.0);
  normal_speed.assign(n_vertices, 0.0);
}

void damp_speeds(IndexRange vertices, const StepDampingOptions& options, VertexFields& fields, StepDampingState& state) {
  detail::check_range(vertices, fields.size(), "damp_speeds");
  MVFLOW_CHECK(state.scale.size() == fields.size() && state.normal_speed.size() == fields.size(),
               "damp_speeds: state is not sized for the fields");
  for (std::uint32_t v = vertices.begin; v < vertices.end; ++v) {
    if (!(fields.defined[v] & kSpeedDefined)) {
      state.normal_speed[v] = 0.0;
      continue;
    }
    const double now = fields.speed[v].dot(fields.normal[v]);
    const double before = state.normal_speed[v];
    if (now * before < 0.0)
      state.scale[v] = std::max(options.min_scale, options.shrink * state.scale[v]);
    else if (now * before > 0.0)
      state.scale[v] = std::min(1.0, options.grow * state.scale[v]);
    state.normal_speed[v] = now;
    fields.speed[v] *= state.scale[v];
  }
}

}  // namespace mvflow
