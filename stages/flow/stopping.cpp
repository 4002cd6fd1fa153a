#include "stages/flow/stopping.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/model/error.h"
#include "engine/model/option_check.h"

namespace mvflow {

bool is_rule_stop(StopReason reason) {
  return reason == StopReason::Converged || reason == StopReason::StepSmall || reason == StopReason::Settled;
}

const char* to_string(StopReason reason) {
  switch (reason) {
    case StopReason::Continue:
      return "continue";
    case StopReason::Converged:
      return "converged";
    case StopReason::StepSmall:
      return "step-small";
    case StopReason::Settled:
      return "settled";
    case StopReason::MaxIterations:
      return "max-iterations";
  }
  return "unknown";
}

void StoppingOptions::check() const {
  require_option(epsilon_percent > 0.0 && std::isfinite(epsilon_percent), "epsilon_percent", epsilon_percent,
                 "> 0 and finite");
  require_option(lookback >= 1, "lookback", lookback, ">= 1");
  require_option(min_iterations >= lookback + 1, "min_iterations", min_iterations, ">= lookback + 1 (" + std::to_string(lookback + 1) + ")");
  require_option(max_iterations >= min_iterations, "max_iterations", max_iterations,
                 ">= min_iterations (" + std::to_string(min_iterations) + ")");
  require_option(median_move_tolerance >= 0.0 && std::isfinite(median_move_tolerance), "median_move_tolerance",
                 median_move_tolerance, ">= 0 and finite");
  require_option(settled_tolerance >= 0.0 && std::isfinite(settled_tolerance), "settled_tolerance", settled_tolerance,
                 ">= 0 and finite");
  require_option(finest_min_iterations >= 0, "finest_min_iterations", finest_min_iterations, ">= 0");
  require_option(settled_wait >= 0.0 && std::isfinite(settled_wait), "settled_wait", settled_wait, ">= 0 and finite");
  require_option(persistence_wait >= 0.0 && std::isfinite(persistence_wait), "persistence_wait", persistence_wait,
                 ">= 0 and finite");
  // Bounded so that max_iterations + run_on (the progress's bound) stays an int.
  require_option(run_on >= 0 && run_on <= 1000000, "run_on", run_on, "in [0, 1000000]");
  const long long ring = 2LL * lookback + 1;  // NetNormalMove's positions
  require_option(average_last >= 1 && average_last <= ring, "average_last", average_last,
                 "in [1, 2·lookback + 1] (" + std::to_string(ring) + ")");
  require_option(settled_noise_reference >= 0.0 && std::isfinite(settled_noise_reference), "settled_noise_reference",
                 settled_noise_reference, ">= 0 and finite");
}

double settled_tolerance_for_noise(const StoppingOptions& options, double image_noise) {
  if (!(options.settled_noise_reference > 0.0) || !(image_noise > options.settled_noise_reference))
    return options.settled_tolerance;
  return options.settled_tolerance * std::sqrt(image_noise / options.settled_noise_reference);
}

bool holds_at_finest(const StoppingOptions& options, StopReason reason, double persistence,
                     std::size_t level_iterations, std::size_t first_stop) {
  if (is_rule_stop(reason) && level_iterations < static_cast<std::size_t>(options.finest_min_iterations)) return true;
  double wait = 0.0;
  if (reason == StopReason::Converged) wait = options.persistence_wait;
  if (reason == StopReason::Settled) wait = options.settled_wait;
  return wait > 0.0 && persistence > 0.0 &&  // false for NaN
         static_cast<double>(level_iterations) < (1.0 + wait) * static_cast<double>(first_stop);
}

bool FinestResolutionWait::wait(const StoppingOptions& options, StopReason reason, double persistence,
                                std::size_t level_iterations, bool budget_left) {
  if (!reached_) first_stop_ = level_iterations;
  reached_ = true;
  return budget_left && holds_at_finest(options, reason, persistence, level_iterations, first_stop_);
}

StoppingCriterion::StoppingCriterion(StoppingOptions options) : options_(options) {
  options_.check();
  history_.reserve(static_cast<std::size_t>(options_.max_iterations));
}

namespace {

double relative_change_percent(double current, double previous) {
  if (previous == 0.0) return current == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  return std::abs(100.0 - 100.0 * current / previous);
}

}  // namespace

double StoppingCriterion::change_percent(std::size_t lag) const {
  return relative_change_percent(history_.back(), history_[history_.size() - 1 - lag]);
}

bool StoppingCriterion::converged() const {
  const auto w = static_cast<std::size_t>(options_.lookback);
  if (options_.test == ConvergenceTest::NoImprovement) {
    // A NaN in the window holds convergence off; earlier NaNs are skipped.
    const std::vector<double>& g = history_per_vertex_;
    const auto split = g.end() - static_cast<std::ptrdiff_t>(w);  // ≥ 1 value before it
    if (std::any_of(split, g.end(), [](double x) { return std::isnan(x); })) return false;
    const double recent = *std::min_element(split, g.end());
    double earlier = std::numeric_limits<double>::infinity();
    for (auto it = g.begin(); it != split; ++it)
      if (*it < earlier) earlier = *it;  // false for NaN
    if (std::isinf(earlier)) return false;
    if (earlier == 0.0) return true;  // nothing left to improve
    return 100.0 - 100.0 * recent / earlier < options_.epsilon_percent;
  }
  for (std::size_t lag = 1; lag <= w; ++lag)
    if (!(change_percent(lag) < options_.epsilon_percent)) return false;
  return true;
}

void StoppingCriterion::restart() {
  before_restart_ += history_.size();
  history_.clear();
  history_per_vertex_.clear();
}

std::vector<double> StoppingCriterion::last_changes_percent() const {
  std::vector<double> changes;
  for (std::size_t lag = 1; lag <= static_cast<std::size_t>(options_.lookback) && lag < history_.size();
       ++lag)
    changes.push_back(change_percent(lag));
  return changes;
}

StopReason StoppingCriterion::add_iteration(double sum_g, double median_move_over_emin, std::size_t vertices_with_g,
                                            double net_move_over_edge) {
  history_.push_back(sum_g);
  history_per_vertex_.push_back(vertices_with_g > 0 ? sum_g / static_cast<double>(vertices_with_g) : sum_g);
  if (history_.size() >= static_cast<std::size_t>(options_.min_iterations)) {
    if (converged()) return StopReason::Converged;
    if (median_move_over_emin < options_.median_move_tolerance) return StopReason::StepSmall;
    if (net_move_over_edge < options_.settled_tolerance) return StopReason::Settled;  // false for NaN
  }
  if (iterations() >= static_cast<std::size_t>(options_.max_iterations)) return StopReason::MaxIterations;
  return StopReason::Continue;
}

}  // namespace mvflow
