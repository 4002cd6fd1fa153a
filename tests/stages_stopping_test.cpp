// The stopping rule (SPEC §4): hand-made Σg sequences.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "stages/flow/stopping.h"

namespace mvflow {
namespace {

constexpr double large_move = 1.0;  // far above τ: only the Σg rule or the budget can fire

// The thesis's test (every one of the last five changes below ε) with the thesis preset's budget
// and SPEC §4's step tolerance.
StoppingOptions each_lookback() {
  return StoppingOptions{.epsilon_percent = 0.3, .test = ConvergenceTest::EachLookback, .max_iterations = 100,
                         .median_move_tolerance = 0.002, .settled_tolerance = 0.0};
}

// Feeds \p g and returns the iteration (1-based) at which the criterion stopped, 0 if never.
std::pair<std::size_t, StopReason> run(const std::vector<double>& g, double move = large_move,
                                       StoppingOptions options = each_lookback()) {
  StoppingCriterion criterion(options);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const StopReason reason = criterion.add_iteration(g[i], move);
    EXPECT_EQ(criterion.iterations(), i + 1);
    if (reason != StopReason::Continue) return {i + 1, reason};
  }
  return {0, StopReason::Continue};
}

// The refiner takes up rule stops only (refinement, the finest resolution's wait, running on): the
// budget and Continue are not among them.
TEST(Stopping, TheRulesStopsAreConvergedStepSmallAndSettled) {
  EXPECT_TRUE(is_rule_stop(StopReason::Converged));
  EXPECT_TRUE(is_rule_stop(StopReason::StepSmall));
  EXPECT_TRUE(is_rule_stop(StopReason::Settled));
  EXPECT_FALSE(is_rule_stop(StopReason::Continue));
  EXPECT_FALSE(is_rule_stop(StopReason::MaxIterations));
}

TEST(StoppingOptions, DefaultsFollowTheThesisButForTheTestTheBudgetAndTheMoveRules) {
  const StoppingOptions o;
  EXPECT_NO_THROW(o.check());
  EXPECT_EQ(o.test, ConvergenceTest::NoImprovement);
  EXPECT_EQ(o.epsilon_percent, 0.3);
  EXPECT_EQ(o.settled_tolerance, 0.0025);
  EXPECT_EQ(o.settled_noise_reference, 0.002);
  EXPECT_EQ(o.min_iterations, 10);
  EXPECT_EQ(o.max_iterations, 200);
  EXPECT_EQ(o.lookback, 5);
  EXPECT_EQ(o.median_move_tolerance, 0.0);
  EXPECT_THROW((StoppingOptions{.settled_tolerance = -1.0}).check(), OptionError);
  EXPECT_THROW((StoppingOptions{.settled_tolerance = INFINITY}).check(), OptionError);
  EXPECT_THROW((StoppingOptions{.epsilon_percent = 0.0}).check(), OptionError);
  EXPECT_THROW((StoppingOptions{.min_iterations = 5}).check(), OptionError);  // needs lookback + 1
  EXPECT_THROW((StoppingOptions{.max_iterations = 9}).check(), OptionError);
  EXPECT_THROW(StoppingCriterion(StoppingOptions{.lookback = 0}), Error);
  EXPECT_STREQ(to_string(StopReason::Converged), "converged");
  EXPECT_STREQ(to_string(StopReason::StepSmall), "step-small");
  EXPECT_STREQ(to_string(StopReason::Settled), "settled");
  EXPECT_STREQ(to_string(StopReason::MaxIterations), "max-iterations");
  EXPECT_STREQ(to_string(StopReason::Continue), "continue");
}

TEST(Stopping, NeverBeforeIterationTenEvenWhenConstant) {
  EXPECT_EQ(run(std::vector<double>(30, 5.0)), std::make_pair(std::size_t{10}, StopReason::Converged));
  // All-zero Σg (every view agrees) counts as no change.
  EXPECT_EQ(run(std::vector<double>(30, 0.0)), std::make_pair(std::size_t{10}, StopReason::Converged));
}

TEST(Stopping, AtTheFirstIterationWhereAllFiveChangesAreBelowEpsilon) {
  // Σg falls 1 % per iteration up to iteration 20, then stays: at 24 the change against G_19
  // is still 1 %, at 25 all of G_20..G_24 equal G_25.
  std::vector<double> g;
  for (int i = 1; i <= 40; ++i) g.push_back(1000.0 * std::pow(0.99, std::min(i, 20)));
  EXPECT_EQ(run(g), std::make_pair(std::size_t{25}, StopReason::Converged));
  // 0.05 % per iteration: the lag-5 change is 0.25 % < 0.3 % from the start, so iteration 10.
  g.clear();
  for (int i = 1; i <= 40; ++i) g.push_back(1000.0 * std::pow(0.9995, i));
  EXPECT_EQ(run(g), std::make_pair(std::size_t{10}, StopReason::Converged));
  // 0.07 % per iteration: lag 5 is ≈ 0.349 % ≥ 0.3 %: never converges, the budget ends it.
  g.clear();
  for (int i = 1; i <= 120; ++i) g.push_back(1000.0 * std::pow(0.9993, i));
  EXPECT_EQ(run(g), std::make_pair(std::size_t{100}, StopReason::MaxIterations));
  // One drop of 0.5 % at iteration 8 holds convergence off until G_7 leaves the window: at 12
  // the lag-5 change (against G_7) is 0.5 %, at 13 every G_{i−l} is G_8 = 99.5.
  g.assign(40, 100.0);
  for (std::size_t i = 7; i < g.size(); ++i) g[i] = 99.5;
  EXPECT_EQ(run(g), std::make_pair(std::size_t{13}, StopReason::Converged));
}

TEST(Stopping, AtMaxIterationsAtTheLatest) {
  std::vector<double> g;
  for (int i = 1; i <= 150; ++i) g.push_back(i % 2 ? 100.0 : 110.0);
  EXPECT_EQ(run(g), std::make_pair(std::size_t{100}, StopReason::MaxIterations));
  StoppingOptions short_run = each_lookback();
  short_run.max_iterations = 12;
  EXPECT_EQ(run(g, large_move, short_run), std::make_pair(std::size_t{12}, StopReason::MaxIterations));
  // A zero G_{i−l} with a positive G_i is an infinite change, not convergence.
  for (auto& x : g) x = 0.0;
  for (std::size_t i = 0; i < g.size(); i += 3) g[i] = 1.0;
  EXPECT_EQ(run(g), std::make_pair(std::size_t{100}, StopReason::MaxIterations));
}

TEST(Stopping, WhenTheMedianMoveIsSmallFromMinIterationsOn) {
  std::vector<double> g;
  for (int i = 1; i <= 50; ++i) g.push_back(i % 2 ? 100.0 : 110.0);  // Σg never converges
  EXPECT_EQ(run(g, 0.001), std::make_pair(std::size_t{10}, StopReason::StepSmall));
  EXPECT_EQ(run(g, 0.0), std::make_pair(std::size_t{10}, StopReason::StepSmall));  // nothing moved
  EXPECT_EQ(run(g, 0.0025).second, StopReason::Continue);  // above τ = 0.002: runs out of g
  EXPECT_EQ(run(g, std::nan("")).second, StopReason::Continue);
  // A small move at iteration 13 only.
  StoppingCriterion criterion{each_lookback()};
  for (int i = 1; i <= 12; ++i) EXPECT_EQ(criterion.add_iteration(g[i - 1], 0.5), StopReason::Continue);
  EXPECT_EQ(criterion.add_iteration(g[12], 0.0019), StopReason::StepSmall);
  // Converged wins when both fire.
  EXPECT_EQ(run(std::vector<double>(30, 5.0), 0.0), std::make_pair(std::size_t{10}, StopReason::Converged));
}

// Feeds Σg falling 1 % per iteration (never converged) with the net moves \p net, from iteration 1.
std::pair<std::size_t, StopReason> run_net(const std::vector<double>& net, StoppingOptions options = {}) {
  StoppingCriterion criterion(options);
  for (std::size_t i = 0; i < net.size(); ++i) {
    const StopReason reason = criterion.add_iteration(1000.0 * std::pow(0.99, static_cast<double>(i)), large_move, 0, net[i]);
    if (reason != StopReason::Continue) return {i + 1, reason};
  }
  return {0, StopReason::Continue};
}

TEST(Stopping, SettledWhenTheNetMoveFallsBelowTauFromMinIterationsOn) {
  // NaN for the first five iterations (no window yet), then the net move halves every iteration
  // from 0.1: below τ = 0.0025 from iteration 12 (0.1/2^6 = 0.0016; 0.0031 at 11).
  std::vector<double> net(5, std::nan(""));
  for (int i = 6; i <= 40; ++i) net.push_back(0.1 * std::pow(0.5, i - 6));
  EXPECT_EQ(run_net(net), std::make_pair(std::size_t{12}, StopReason::Settled));
  // Below τ from the start: not before min_iterations.
  EXPECT_EQ(run_net(std::vector<double>(40, 0.0)), std::make_pair(std::size_t{10}, StopReason::Settled));
  // Never on NaN, never when disabled, never at or above τ.
  EXPECT_EQ(run_net(std::vector<double>(40, std::nan(""))).second, StopReason::Continue);
  EXPECT_EQ(run_net(net, StoppingOptions{.settled_tolerance = 0.0}).second, StopReason::Continue);
  EXPECT_EQ(run_net(std::vector<double>(40, 0.0025)).second, StopReason::Continue);
}

TEST(Stopping, NoImprovementStopsAnAlternationThatEachLookbackNeverStops) {
  // Σg falls 2 % per iteration to iteration 20, then alternates ±5 % around its last level, as
  // it does once the fastest vertices step across the minimum of g and back.
  std::vector<double> g;
  for (int i = 1; i <= 20; ++i) g.push_back(100.0 * std::pow(0.98, i));
  for (int i = 21; i <= 120; ++i) g.push_back(g[19] * (i % 2 ? 1.05 : 0.95));
  EXPECT_EQ(run(g), std::make_pair(std::size_t{100}, StopReason::MaxIterations));
  // The lowest value, 0.95·G_20, comes at iteration 22 and never again: at 27 the last five
  // (23..27) have not improved on it.
  EXPECT_EQ(run(g, large_move, StoppingOptions{}), std::make_pair(std::size_t{27}, StopReason::Converged));
}

TEST(Stopping, NoImprovementWaitsForEpsilonAndRestartsWithTheResolution) {
  // 1 % lower every iteration: always an improvement beyond 0.3 % over five iterations.
  std::vector<double> g;
  for (int i = 1; i <= 60; ++i) g.push_back(1000.0 * std::pow(0.99, i));
  EXPECT_EQ(run(g, large_move, StoppingOptions{.epsilon_percent = 0.1}),
            std::make_pair(std::size_t{0}, StopReason::Continue));
  // 0.05 % per iteration: the best of the last five is 0.25 % below the best before: converged
  // as soon as the history is long enough (min_iterations = 10) with ε = 0.3 %, never with 0.1 %.
  g.clear();
  for (int i = 1; i <= 40; ++i) g.push_back(1000.0 * std::pow(0.9995, i));
  EXPECT_EQ(run(g, large_move, StoppingOptions{.epsilon_percent = 0.3}),
            std::make_pair(std::size_t{10}, StopReason::Converged));
  EXPECT_EQ(run(g, large_move, StoppingOptions{.epsilon_percent = 0.1}),
            std::make_pair(std::size_t{0}, StopReason::Continue));
  // After restart() the rules wait min_iterations again, but the budget counts on.
  StoppingCriterion criterion{StoppingOptions{.max_iterations = 25}};
  for (int i = 1; i <= 10; ++i) criterion.add_iteration(5.0, large_move);
  criterion.restart();
  EXPECT_EQ(criterion.iterations(), 10u);
  for (int i = 11; i <= 19; ++i) EXPECT_EQ(criterion.add_iteration(5.0, large_move), StopReason::Continue) << i;
  EXPECT_EQ(criterion.add_iteration(5.0, large_move), StopReason::Converged);  // 10 since the restart
  criterion.restart();
  for (int i = 21; i <= 24; ++i) EXPECT_EQ(criterion.add_iteration(5.0, large_move), StopReason::Continue) << i;
  EXPECT_EQ(criterion.add_iteration(5.0, large_move), StopReason::MaxIterations);
}

TEST(Stopping, NoImprovementComparesSumsPerVertexAndNeverConvergesOnNaN) {
  // Σg grows with the vertex count (refinement) while Σg per vertex falls 2 % per iteration: an
  // improvement, not convergence.
  StoppingCriterion criterion{StoppingOptions{}};
  for (int i = 1; i <= 30; ++i) {
    const std::size_t vertices = 1000u * static_cast<std::size_t>(i);
    EXPECT_EQ(criterion.add_iteration(static_cast<double>(vertices) * std::pow(0.98, i), large_move, vertices),
              StopReason::Continue) << i;
  }
  // A NaN at iteration 9 holds convergence off while it is among the last five (10..13).
  std::vector<double> g(30, 5.0);
  g[8] = std::nan("");
  EXPECT_EQ(run(g, large_move, StoppingOptions{}), std::make_pair(std::size_t{14}, StopReason::Converged));
}

TEST(Stopping, ReportsTheLastChanges) {
  StoppingCriterion criterion{StoppingOptions{}};
  criterion.add_iteration(100.0, 1.0);
  EXPECT_TRUE(criterion.last_changes_percent().empty());
  criterion.add_iteration(99.0, 1.0);
  criterion.add_iteration(99.0, 1.0);
  const auto changes = criterion.last_changes_percent();
  ASSERT_EQ(changes.size(), 2u);
  EXPECT_EQ(changes[0], 0.0);
  EXPECT_NEAR(changes[1], 1.0, 1e-12);
}

TEST(Stopping, TheFinestResolutionHoldsAConvergedStopWhileTheMovePersists) {
  const StoppingOptions on;
  EXPECT_EQ(on.persistence_wait, 1.0);  // the default; the thesis preset's 0 never waits
  // A level whose first stop came after 20 iterations waits up to iteration 39 of the level.
  EXPECT_TRUE(holds_at_finest(on, StopReason::Converged, 0.14, 20, 20));
  EXPECT_TRUE(holds_at_finest(on, StopReason::Converged, 0.14, 39, 20));
  EXPECT_FALSE(holds_at_finest(on, StopReason::Converged, 0.14, 40, 20));  // its patience is spent
  EXPECT_FALSE(holds_at_finest(on, StopReason::Converged, 0.0, 25, 20));   // moves that do not carry on
  EXPECT_FALSE(holds_at_finest(on, StopReason::Converged, -0.3, 25, 20));  // back and forth
  EXPECT_FALSE(holds_at_finest(on, StopReason::Converged, NAN, 25, 20));   // not yet two windows
  EXPECT_FALSE(holds_at_finest(on, StopReason::StepSmall, 0.5, 25, 20));   // past the minimum
  EXPECT_FALSE(holds_at_finest(on, StopReason::MaxIterations, 0.5, 25, 20));
  EXPECT_FALSE(holds_at_finest(on, StopReason::Continue, 0.5, 25, 20));
  const StoppingOptions half{.persistence_wait = 0.5};
  EXPECT_TRUE(holds_at_finest(half, StopReason::Converged, 0.5, 29, 20));
  EXPECT_FALSE(holds_at_finest(half, StopReason::Converged, 0.5, 30, 20));
  EXPECT_FALSE(holds_at_finest(StoppingOptions{.persistence_wait = 0.0}, StopReason::Converged, 0.5, 20, 20));
  EXPECT_THROW((StoppingOptions{.persistence_wait = -1.0}).check(), OptionError);
  EXPECT_THROW((StoppingOptions{.persistence_wait = INFINITY}).check(), OptionError);
}

TEST(Stopping, TheFinestResolutionHoldsASettledStopWhileTheMovePersistsWithItsOwnLimit) {
  const StoppingOptions on;
  EXPECT_EQ(on.settled_wait, 3.0);  // the default (the thesis preset's 0: cli_options_test)
  // A level whose first stop came after 20 iterations: a settled stop waits up to iteration 79.
  EXPECT_TRUE(holds_at_finest(on, StopReason::Settled, 0.5, 25, 20));
  EXPECT_TRUE(holds_at_finest(on, StopReason::Settled, 0.5, 79, 20));
  EXPECT_FALSE(holds_at_finest(on, StopReason::Settled, 0.5, 80, 20));
  EXPECT_FALSE(holds_at_finest(on, StopReason::Settled, -0.2, 25, 20));  // back and forth
  EXPECT_FALSE(holds_at_finest(on, StopReason::Settled, NAN, 25, 20));
  // The Σg stop keeps its own limit (persistence_wait 1: iteration 39).
  EXPECT_TRUE(holds_at_finest(on, StopReason::Converged, 0.5, 39, 20));
  EXPECT_FALSE(holds_at_finest(on, StopReason::Converged, 0.5, 40, 20));
  EXPECT_FALSE(holds_at_finest(StoppingOptions{.settled_wait = 0.0}, StopReason::Settled, 0.5, 25, 20));
  EXPECT_TRUE(holds_at_finest(StoppingOptions{.persistence_wait = 0.0}, StopReason::Settled, 0.5, 25, 20));
  EXPECT_THROW((StoppingOptions{.settled_wait = -1.0}).check(), OptionError);
  EXPECT_THROW((StoppingOptions{.settled_wait = INFINITY}).check(), OptionError);
}

TEST(Stopping, TheFinestResolutionHoldsAnyRulesStopUntilItsMinimum) {
  const StoppingOptions options;
  EXPECT_EQ(options.finest_min_iterations, 15);  // the default (the thesis preset's 0: cli_options_test)
  for (const StopReason reason : {StopReason::Converged, StopReason::StepSmall, StopReason::Settled}) {
    // Whatever the persistence: a net move that reverses does not end the minimum either.
    EXPECT_TRUE(holds_at_finest(options, reason, -0.5, 14, 14)) << to_string(reason);
    EXPECT_FALSE(holds_at_finest(options, reason, -0.5, 15, 14)) << to_string(reason);
  }
  EXPECT_FALSE(holds_at_finest(options, StopReason::MaxIterations, -0.5, 10, 10));
  EXPECT_FALSE(holds_at_finest(options, StopReason::Continue, -0.5, 10, 10));
  EXPECT_FALSE(holds_at_finest(StoppingOptions{.finest_min_iterations = 0}, StopReason::Settled, -0.5, 3, 3));
  // Past the minimum, the persistence wait decides, counted from the first stop.
  EXPECT_TRUE(holds_at_finest(options, StopReason::Converged, 0.2, 17, 10));
  EXPECT_TRUE(holds_at_finest(options, StopReason::Converged, 0.2, 19, 10));
  EXPECT_FALSE(holds_at_finest(options, StopReason::Converged, 0.2, 20, 10));
  FinestResolutionWait no_budget;  // the budget ends the run within the minimum too
  EXPECT_FALSE(no_budget.wait(options, StopReason::Settled, NAN, 10, false));
  EXPECT_THROW((StoppingOptions{.finest_min_iterations = -1}).check(), OptionError);
}

TEST(Stopping, TheFinestResolutionWaitCountsFromItsFirstStop) {
  const StoppingOptions options;  // persistence_wait 1
  FinestResolutionWait wait;
  EXPECT_FALSE(wait.reached());
  // The first stop with nothing to refine, after 20 iterations of the level: reached, and it waits.
  EXPECT_TRUE(wait.wait(options, StopReason::Converged, 0.2, 20, true));
  EXPECT_TRUE(wait.reached());
  EXPECT_EQ(wait.first_stop(), 20u);
  // Later stops keep the first stop's 20: the wait ends at iteration 40 of the level, not 60.
  EXPECT_TRUE(wait.wait(options, StopReason::Converged, 0.2, 30, true));
  EXPECT_EQ(wait.first_stop(), 20u);
  EXPECT_TRUE(wait.wait(options, StopReason::Converged, 0.2, 39, true));
  EXPECT_FALSE(wait.wait(options, StopReason::Converged, 0.2, 40, true));
  // No budget left: no wait, whatever the persistence.
  EXPECT_FALSE(wait.wait(options, StopReason::Converged, 0.2, 25, false));
  // A first stop that does not wait (settled with a move that does not carry on, or no budget) still
  // marks the finest resolution.
  FinestResolutionWait settled;
  EXPECT_FALSE(settled.wait(options, StopReason::Settled, -0.2, 16, true));
  EXPECT_TRUE(settled.reached());
  EXPECT_EQ(settled.first_stop(), 16u);
  FinestResolutionWait none;
  EXPECT_FALSE(none.wait(StoppingOptions{.persistence_wait = 0.0}, StopReason::Converged, 0.9, 15, true));
  EXPECT_TRUE(none.reached());
}

}  // namespace
}  // namespace mvflow
