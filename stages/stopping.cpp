#include "stages/stopping.h"

#include <cmath>
#include <limits>

#include "engine/error.h"

namespace mvflow {

const char* to_string(StopReason reason) {
  switch (reason) {
    case StopReason::Continue:
      return "continue";
    case StopReason::Converged:
      return "converged";
    case StopReason::StepSmall:
      return "step-small";
    case StopReason::MaxIterations:
      return "max-iterations";
  }
  return "unknown";
}

bool StoppingOptions::check() const {
  return epsilon_percent > 0.0 && std::isfinite(epsilon_percent) && lookback >= 1 &&
         min_iterations >= lookback + 1 && max_iterations >= min_iterations && median_move_tolerance >= 0.0 &&
         std::isfinite(median_move_tolerance);
}

StoppingCriterion::StoppingCriterion(StoppingOptions options) : options_(options) {
  MVFLOW_CHECK(options_.check(), "StoppingCriterion: invalid StoppingOptions");
  history_.reserve(static_cast<std::size_t>(options_.max_iterations));
}

double StoppingCriterion::change_percent(std::size_t lag) const {
  const double current = history_.back();
  const double previous = history_[history_.size() - 1 - lag];
  if (previous == 0.0) return current == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  return std::abs(100.0 - 100.0 * current / previous);
}

std::vector<double> StoppingCriterion::last_changes_percent() const {
  std::vector<double> changes;
  for (std::size_t lag = 1; lag <= static_cast<std::size_t>(options_.lookback) && lag < history_.size();
       ++lag)
    changes.push_back(change_percent(lag));
  return changes;
}

StopReason StoppingCriterion::add_iteration(double sum_g, double median_move_over_emin) {
  history_.push_back(sum_g);
  const std::size_t i = history_.size();
  if (i >= static_cast<std::size_t>(options_.min_iterations)) {
    bool converged = true;  // min_iterations > lookback, so every G_{i−l} exists
    for (std::size_t lag = 1; lag <= static_cast<std::size_t>(options_.lookback) && converged; ++lag)
      converged = change_percent(lag) < options_.epsilon_percent;  // NaN (a NaN Σg) never converges
    if (converged) return StopReason::Converged;
    if (median_move_over_emin < options_.median_move_tolerance) return StopReason::StepSmall;
  }
  if (i >= static_cast<std::size_t>(options_.max_iterations)) return StopReason::MaxIterations;
  return StopReason::Continue;
}

}  // namespace mvflow
