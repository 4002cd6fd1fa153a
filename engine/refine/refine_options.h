#pragma once
// Every parameter of a refinement, one nested Options struct per stage (their defaults and
// ranges are documented where each stage is declared), plus presets as functions.

#include <cstddef>
#include <string>
#include <vector>

#include "stages/topology/adaptive_refinement.h"
#include "stages/flow/curvature.h"
#include "stages/flow/far_vertices.h"
#include "stages/flow/image_denoise.h"
#include "stages/flow/implausible_speed.h"
#include "stages/flow/photo_gradient.h"
#include "stages/flow/regularization.h"
#include "stages/topology/remeshing.h"
#include "stages/flow/silhouette.h"
#include "stages/flow/silhouette_rims.h"
#include "stages/flow/smoothing.h"
#include "stages/flow/speed.h"
#include "stages/flow/step_damping.h"
#include "stages/flow/step_momentum.h"
#include "stages/flow/stopping.h"
#include "stages/flow/unobserved_displacement.h"
#include "stages/flow/unobserved_speed.h"
#include "stages/topology/untangling.h"
#include "stages/flow/visibility.h"

namespace mvflow {

//! How an iteration's stages are scheduled. Both give bit-identical results.
enum class EngineKind {
  Graph,      //!< one oneTBB flow graph per iteration, nodes per vertex block (SPEC §6)
  Sequential  //!< the same per-block stage functions in a plain loop on the calling thread
};

//! When adaptive refinement runs.
enum class RefinementSchedule {
  EveryIteration,  //!< before every iteration but the first (thesis §5.3.4)
  //! Coarse to fine: when the flow has converged at the current resolution (the Converged or
  //! StepSmall rule fires), then the stopping rules start afresh; the run ends (with that rule's
  //! status) when they fire and refinement adds nothing or is declined as too small
  //! (AdaptiveRefinementOptions::min_growth). README, "Defaults and differences".
  AtConvergence,
};

struct RefineOptions {
  CurvatureOptions curvature;
  VisibilityOptions visibility;
  PhotoGradientOptions photo;          //!< Savitzky–Golay window and the photo-consistency patch
  SpeedOptions speed;                  //!< balloon velocity v
  //! Whether vertices without g or ∇g move with their observed neighbours (default: no).
  UnobservedSpeedOptions unobserved;
  //! Whether the poorly observed vertices take the observed surface's displacement when the
  //! flow has converged at a resolution and at the end (default: yes; thesis preset: no).
  UnobservedDisplacementOptions unobserved_displacement;
  //! The speed of a region of implausibly high g (unobserved_displacement.implausible_g_ratio,
  //! where the rims are not fitted) averaged over its rings (default: 8 rings; thesis preset: off).
  ImplausibleSpeedOptions implausible_speed;
  //! Δt = cfl·(e/2)/(√3·|F|_q), e the mean edge (local_step) or e_min (SPEC §4; thesis 1)
  double cfl = 1.0;
  //! q, the quantile of |F| over the moving vertices that sets Δt; in (0, 1]. 1 = max|F|, the
  //! thesis's CFL rule. Below 1, vertices faster than |F|_q move only their CFL distance along F
  //! (cfl/(2√3) of their own shortest edge with local_step, of e_min without).
  double speed_quantile = 0.9;
  //! Local CFL: Δt uses the mean edge instead of the shortest, and each vertex moves at most
  //! cfl/(2√3) of its own shortest edge, so one short edge slows only its own vertices. false:
  //! the thesis's global rule (every vertex moves at most cfl·e_min/(2√3)).
  bool local_step = true;
  //! Step control: when an iteration finds Σg/vertex higher than the one before (on the same
  //! mesh), the last step overshot, so the steps are halved; after a decrease they grow back by
  //! 1.25× up to the CFL step. false: always the CFL step (the thesis).
  bool step_control = false;
  //! Per-vertex step damping (stages/flow/step_damping.h): on by default; off in the thesis preset.
  StepDampingOptions damping;
  //! Per-vertex step momentum (stages/flow/step_momentum.h): β = 0.7 by default; 0 in the thesis preset.
  StepMomentumOptions momentum;
  SmoothingOptions smoothing;
  RegularizationOptions regularization;
  StoppingOptions stopping;
  bool global_remeshing = true;        //!< split/collapse once before the flow (SPEC §5)
  RemeshingOptions remeshing;
  bool adaptive_refinement = true;     //!< quadrisect high-curvature regions between iterations
  AdaptiveRefinementOptions adaptive;

  //! Coarse-to-fine images: the flow starts on the photographs halved this many times
  //! (stages/flow/image_pyramid.h) and moves one level finer each time it has settled; adaptive
  //! refinement (with either schedule) waits for the full resolution; 0 = full resolution
  //! throughout (the thesis). 0..4.
  int image_levels = 0;
  //! Far vertices (stages/flow/far_vertices.h): at the first resolution, a vertex whose g is
  //! g_ratio × the median reads half-resolution photographs until it comes near or the first
  //! resolution ends (when that is the run's last, e.g. --no-adaptive, a far vertex ends on them).
  //! On by default (g_ratio 300); off in the thesis preset, whenever image_levels > 0 (every
  //! vertex starts on coarser images then) and when an image is smaller than 16 × 16 pixels.
  FarVertexOptions far;
  //! Noisy photographs blurred before the whole-pixel image patches read them, just enough to
  //! bring their estimated noise to a reference (stages/flow/image_denoise.h); the surface patches
  //! read them as given (a blur in the image smears an oblique view along the surface), and with
  //! surface patches everywhere nothing is blurred. The settled rule then uses the reference's
  //! tolerance. Auto by default, off in the thesis preset (README, "Convergence").
  DenoiseOptions denoise;

  RefinementSchedule refinement_schedule = RefinementSchedule::AtConvergence;  //!< thesis: EveryIteration
  //! Folds removed where the flow has settled: before each coarse-to-fine refinement (then the
  //! curvature is recomputed, so that the marks do not follow a removed fold) and at the end of
  //! the run (with either schedule). max_rounds 0 (the thesis preset) disables.
  UntanglingOptions untangling;
  //! Vertices per block (one graph node per block and stage). 128: on the default scene (800
  //! vertices) 1024 left one block and no speed-up from a second thread; at 10k vertices 64, 128
  //! and 512 gave the same time (README, "Performance").
  std::size_t block_size = 128;
  EngineKind engine = EngineKind::Graph;
  std::vector<int> excluded_views;     //!< 0-based view indices the refinement must not use
  //! Keep the surface inside the visual hull of the used views' silhouettes (thresholded from
  //! their images; SilhouetteConstraint). Off by default and in the thesis: it needs photographs
  //! whose background separates from the object.
  bool keep_inside_silhouettes = false;
  //! How the silhouettes are thresholded; 0.19 (Middlebury) with a 3-pixel dilation so that
  //! calibration error does not cut into the object.
  SilhouetteOptions silhouettes{.threshold = 0.19, .dilate = 3};
  //! Fit the surface's rims to the silhouettes (stages/flow/silhouette_rims.h), thresholded at
  //! silhouettes.threshold without the dilation: by default when every view's border is dark
  //! (README, "Defaults and differences"); off in the thesis preset.
  SilhouetteRimOptions rims;

  //! Runs every stage's check() and checks the fields of its own.
  //! \throw OptionError naming the first field out of range by its path ("smoothing.lambda_dt"),
  //! its value and its valid values.
  void check() const;
};

//! SPEC's defaults (this struct's initializers).
RefineOptions default_preset();
//! Exactly the thesis's parameters (appendix B.7, SPEC §9): grazing views up to 90°, the
//! barycentric curvature area, ε = 0.3 %.
RefineOptions thesis_preset();
//! The default preset with surface patches (PhotoConsistencyOptions::surface_patch) and the
//! settled tolerance 0.001: lower error on 11 of 15 textured scenes and on both photograph sets,
//! 1.2–1.8× the time of a default run with the AVX-512 build, 1.8–2.5× with AVX2 (README "Surface patches").
RefineOptions accurate_preset();
//! The presets' names, in the order help texts list them: default, accurate, thesis.
const std::vector<std::string>& preset_names();
//! The preset named `name` (one of preset_names()). \throw InputError otherwise.
RefineOptions preset(const std::string& name);

}  // namespace mvflow
