#pragma once
// When the flow stops (thesis 5.3.3; SPEC §4).

#include <cstddef>
#include <limits>
#include <vector>

namespace mvflow {

enum class StopReason {
  Continue,       //!< keep iterating
  Converged,      //!< Σg changed by less than ε % against each of the last `lookback` iterations
  StepSmall,      //!< the median vertex move fell below τ·e_min
  Settled,        //!< the median net move along the normal over `lookback` iterations fell below τ_net
  MaxIterations,  //!< the iteration budget is used up
};

//! "continue", "converged", "step-small", "settled" or "max-iterations" (for reports).
const char* to_string(StopReason reason);

//! Whether \p reason is a stopping rule's (Converged, StepSmall or Settled): the stops a
//! refinement, the finest resolution's wait or running on may take up; not Continue, not the budget.
bool is_rule_stop(StopReason reason);

//! How "Σg no longer changes" is tested.
enum class ConvergenceTest {
  //! Thesis 5.3.3: |100 − 100·G_i/G_{i−l}| < ε for every l = 1..lookback. Never fires while Σg
  //! alternates between two values, as it does once the fastest vertices step across the
  //! minimum of g and back.
  EachLookback,
  //! No improvement: the lowest g_i = G_i/n_i (Σg per vertex with defined g, so that a change of
  //! the vertex count does not count as a change of the surface) of the last `lookback`
  //! iterations is not ε % below the lowest before them,
  //! 100 − 100·min(g_{i−w+1..i})/min(g_1..g_{i−w}) < ε with w = lookback (early stopping with
  //! patience w). An alternation around a level no longer lowers the minimum, so it stops.
  NoImprovement,
};

struct StoppingOptions {
  //! ε in percent (see ConvergenceTest); > 0. 0.3 (the thesis's experiments).
  double epsilon_percent = 0.3;
  //! NoImprovement; EachLookback in the thesis preset. README, "Defaults and differences".
  ConvergenceTest test = ConvergenceTest::NoImprovement;
  //! No stop (Converged, StepSmall or Settled) before this many completed iterations (since the start
  //! or the last restart); ≥ lookback + 1, so that every G compared exists. 10 (thesis 5.3.3).
  int min_iterations = 10;
  //! Stop after this many completed iterations at the latest, counted over the coarse-to-fine
  //! levels; ≥ min_iterations. 200; the thesis's 100 (thesis preset) is for one resolution, and
  //! with the levels the peanut scene's coarse level alone needs 66 iterations of real progress
  //! (README, "Defaults and differences").
  int max_iterations = 200;
  //! Number of previous iterations Σg is compared with; ≥ 1. 5 (thesis 5.3.3).
  int lookback = 5;
  //! τ: StepSmall when median_P |Δt·F(P)| / e_min < τ; ≥ 0 (0 disables). 0 (off): with the step
  //! damping a reversing vertex's steps shrink, so the per-iteration move falls below any τ while
  //! the rest of the surface still progresses (the settled rule replaces it). The thesis preset
  //! keeps SPEC §4's 0.002 (it replaces the thesis's absolute "step size below 1e−5").
  double median_move_tolerance = 0.0;
  //! τ_net: Settled when the median over the moving vertices of their net move along the normal
  //! over the last `lookback` iterations, divided by their shortest edge (NetNormalMove), is below
  //! it; ≥ 0 (0 disables; thesis preset). 0.0025: on five synthetic scenes the runs end in 43–117
  //! iterations instead of 77–124, the mean error within 5 % of the previous rules' and the 90 %
  //! accuracy better on four (README, "Convergence").
  double settled_tolerance = 0.0025;
  //! σ_q: for photographs whose noise σ (estimate_views_noise, stages/flow/image_noise.h) is above
  //! it, the settled rule uses settled_tolerance·√(σ/σ_q) (settled_tolerance_for_noise): image
  //! noise keeps moving the surface by more than the flow on clean photographs does (the median
  //! net move levels off at 0.004–0.01 of the edge with σ ≈ 0.006, where clean runs fall below
  //! 0.0025), so without it noisy runs end only by the Σg rule. ≥ 0 (0 disables). 0.002: above
  //! what clean images read (synthetic renders 0.0007 at 640×480 and up to 0.0018 at 320×240, the
  //! dino and temple photographs 0.0008 and 0.0006), below noisy renders (0.003 and 0.0058 with
  //! σ = 0.005 and 0.01 per channel); issue 12's item 5 then holds on 8 of 12 unit spheres instead
  //! of 5 at a mean error 1.006× on the noisy scenes (README, "Convergence").
  double settled_noise_reference = 0.002;
  //! At the finest resolution (no refinement left to make) a Converged stop waits while the
  //! surface's move persists from one window of `lookback` iterations to the next
  //! (NetNormalMove::last_persistence() > 0, holds_at_finest), for at most persistence_wait times
  //! the iterations the level ran to its first stop: there Σg per vertex is mostly the few
  //! vertices of high g, flat within their noise while a creeping region still closes in (w4: the
  //! Σg rule stopped at persistence 0.14 with running on 30 more iterations 14 % better), while a
  //! surface jittering about its minimum (every unit sphere) has persistence below 0; the limit
  //! keeps photographs, whose tail creeps for 100 iterations and more, inside the budget. ≥ 0 (0:
  //! no wait, the thesis preset). 1: README, "Convergence".
  double persistence_wait = 1.0;
  //! At the finest resolution a stop by any rule (Converged, StepSmall, Settled) waits until the
  //! level has run this many iterations: there the settled rule fired at its 10-iteration minimum
  //! while the vertices the photographs hardly see (no g: a cap seen at grazing angles) still
  //! closed in, 2 % of the vertices carrying two thirds of what running on gained (the bumpy
  //! sphere 0.00135 → 0.00129 in the next 5 iterations, 0.00126 after 20, 0.00125 after 60). A
  //! held stop is still the level's first stop for persistence_wait, whose limit counts from it.
  //! With RefinementSchedule::EveryIteration, which has no levels, the whole run counts. ≥ 0 (0: no
  //! minimum, the thesis preset). 15: 32 scenes × 3 runs 0.996× the error, worse on none, the
  //! longest unit-sphere run 55 iterations; 20 reached 60, issue 12's limit (README,
  //! "Convergence", session 41).
  int finest_min_iterations = 15;
  //! At the finest resolution a Settled stop waits while the surface's move persists, as a
  //! Converged stop does (persistence_wait), for at most settled_wait times the iterations the
  //! level ran to its first stop: on small rigs the whole surface creeps at a fraction of the
  //! settled tolerance (l1, l2: median net move 0.0012–0.0020 of an edge at persistence +0.5,
  //! Σg per vertex falling 10–20 % per five iterations). ≥ 0 (0: no wait, the thesis preset).
  //! 3: README, "Convergence", session 41.
  double settled_wait = 3.0;
  //! The run's result is the mean of the positions of its last average_last iterations (one
  //! topology): at a stop many vertices step back and forth about the minimum of g from one
  //! iteration to the next (the error of w1's stop and the next iteration 0.00118 / 0.00114 /
  //! 0.00119 …), and the mean of two iterates cancels that (0.00110). Fewer iterations of the last
  //! topology and images (a refinement or a switch to finer images just before the end), or an
  //! untangling the flow went on from among them: the last positions. In [1, 2·lookback + 1];
  //! 1 = the last iterate (the thesis preset). README, "Convergence".
  int average_last = 2;
  //! Running on, the yardstick of "converged" (issue 12's item 4: a stop is no worse than running
  //! on): after the run would end converged, step-small or settled, this many more iterations
  //! with every stopping rule off and nothing refined, then the run ends with the status of that
  //! stop (the report marks it "run on (…)"); the iteration budget does not bound them, so every
  //! stop is compared with the same number of iterations more. In [0, 1000000] (0: none, the default).
  //! README, "Convergence".
  int run_on = 0;

  //! \throw OptionError naming the first field out of range, its value and its valid values.
  void check() const;
};

//! The settled tolerance for photographs with noise \p image_noise (σ):
//! settled_tolerance·√(σ/settled_noise_reference) when σ is above the reference, else (or with a
//! reference of 0) settled_tolerance.
double settled_tolerance_for_noise(const StoppingOptions& options, double image_noise);

//! Whether a stop at the finest resolution waits: \p reason is a rule's (Converged, StepSmall or
//! Settled) and the level's \p level_iterations are fewer than finest_min_iterations; or \p reason
//! is Converged (Settled), \p persistence (NetNormalMove::last_persistence) is above 0 (false for
//! NaN) and the level's iterations are fewer than (1 + persistence_wait)·\p first_stop ((1 +
//! settled_wait)·\p first_stop), the level's iterations at its first stop. StepSmall past the
//! minimum ends the run.
bool holds_at_finest(const StoppingOptions& options, StopReason reason, double persistence,
                     std::size_t level_iterations, std::size_t first_stop);

//! The finest resolution's wait (StoppingOptions::finest_min_iterations, persistence_wait,
//! settled_wait) over one run: the refiner asks it at every stop once a stop has found nothing
//! left to refine.
class FinestResolutionWait {
 public:
  //! A stop has found nothing left to refine: the flow is at its finest resolution, where a stop
  //! is never tried as a refinement again.
  bool reached() const { return reached_; }
  //! The level's iterations at its first stop there (0 before).
  std::size_t first_stop() const { return first_stop_; }

  //! Called with a stop (\p reason neither Continue nor MaxIterations) that found nothing to
  //! refine, after \p level_iterations iterations of the level: the first call marks the finest
  //! resolution reached and records them as its first stop. Returns whether the stop waits:
  //! \p budget_left and holds_at_finest with that first stop.
  bool wait(const StoppingOptions& options, StopReason reason, double persistence, std::size_t level_iterations,
            bool budget_left);

 private:
  bool reached_ = false;
  std::size_t first_stop_ = 0;
};

//! The stopping test of the flow, fed once per completed iteration.
//!
//! Iterations are counted from 1: the i-th call of add_iteration reports iteration i, and
//! i is the number of completed iterations. With G_i the Σg passed at iteration i:
//!  - Converged at i ≥ min_iterations when options.test says Σg has stopped changing (a
//!    previous value 0 counts as a change of 0 if the current one is 0 too and as an infinite
//!    change otherwise);
//!  - StepSmall at i ≥ min_iterations when median_move_over_emin < τ. Like the ε rule it waits
//!    for min_iterations: the first iterations run on a freshly remeshed surface whose median
//!    move says little about convergence, and a few extra iterations cost little;
//!  - Settled at i ≥ min_iterations when net_move_over_edge < τ_net (NaN never fires);
//!  - MaxIterations at i ≥ max_iterations (counted over restarts).
//! When several fire at once the first in this list is reported. After a stop, further calls
//! keep evaluating the same rules on the longer history.
class StoppingCriterion {
 public:
  //! \throw OptionError if options.check() does.
  explicit StoppingCriterion(StoppingOptions options);

  //! Records iteration i = iterations() + 1 and returns whether to stop after it.
  //! \param sum_g               G_i = Σ g(P) over the vertices with defined g, ≥ 0.
  //! \param median_move_over_emin median over the moving vertices of their move divided by the
  //!                              edge length the CFL bound uses for them; 0 when nothing moved
  //!                              (NaN never fires).
  //! \param vertices_with_g      n_i, the vertices with defined g (NoImprovement compares G_i/n_i);
  //!                              0 when unknown: G_i itself is compared.
  //! \param net_move_over_edge    NetNormalMove::record of this iteration; NaN while unknown.
  StopReason add_iteration(double sum_g, double median_move_over_emin, std::size_t vertices_with_g = 0,
                           double net_move_over_edge = std::numeric_limits<double>::quiet_NaN());

  //! Starts the Converged, StepSmall and Settled rules afresh (after a change of the mesh's resolution Σg
  //! sums over other vertices); the iteration count for MaxIterations goes on.
  void restart();

  //! Completed iterations so far, restarts included.
  std::size_t iterations() const { return before_restart_ + history_.size(); }
  //! Completed iterations since the start or the last restart (of this resolution).
  std::size_t level_iterations() const { return history_.size(); }
  //! |100 − 100·G_i/G_{i−l}| of the last iteration for l = 1..lookback (fewer if the history
  //! is shorter), for reports.
  std::vector<double> last_changes_percent() const;
  const StoppingOptions& options() const { return options_; }

 private:
  double change_percent(std::size_t lag) const;

  bool converged() const;

  StoppingOptions options_;
  std::vector<double> history_;            // G since the start or the last restart
  std::vector<double> history_per_vertex_;  // G/n (or G where n is unknown), the same iterations
  std::size_t before_restart_ = 0;
};

}  // namespace mvflow
