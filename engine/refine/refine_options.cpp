#include "engine/refine/refine_options.h"

#include "engine/model/error.h"

namespace mvflow {

void RefineOptions::check() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw InputError(std::string("option out of range: ") + what);
  };
  require(visibility.check(), "visibility (max angle in (0, 90], patch, ray offset, max views 0 or >= 2)");
  require(photo.check(), "photo consistency / Savitzky-Golay (k even >= 2, order, patch 1..7, noise floor in [0, 1], "
                         "drop views 0..64, min views >= 2)");
  require(unobserved.check(), "unobserved speed (rings >= 1)");
  require(unobserved_displacement.check(), "observed view angle in (0, 90]");
  require(speed.check(), "velocity");
  require(cfl > 0 && cfl <= 10, "cfl (0, 10]");
  require(speed_quantile > 0 && speed_quantile <= 1, "speed quantile (0, 1]");
  require(smoothing.check(), "smoothing (lambda*dt in (0,1), steps >= 0, Taubin pass band >= 0 with mu < 1)");
  require(regularization.check(), "regularization (strength in (0,1], steps >= 0)");
  require(stopping.check(), "stopping (epsilon, iterations, lookback, tolerance)");
  require(remeshing.check(), "remeshing factors");
  require(adaptive.check(), "adaptive refinement thresholds (min growth in [0, 1))");
  require(untangling.check(), "untangling (rounds >= 0, ring >= 0, steps >= 1, fraction in (0, 1])");
  require(block_size >= 1, "block size >= 1");
  require(image_levels >= 0 && image_levels <= 4, "image levels 0..4");
  require(silhouettes.check(), "silhouettes (threshold in [0, 1), dilation >= 0)");
  require(rims.check(), "silhouette rims (angle in (0, 90), dead zone >= 0 below the search distance <= 64 pixels, "
                        "step in (0, 1], ray offset >= 0, holes in [0, 1])");
  require(photo.photo.half_patch == visibility.half_patch, "the visibility patch must equal the photo patch");
  for (int view : excluded_views) require(view >= 0, "excluded views are 0-based indices");
}

RefineOptions default_preset() { return RefineOptions{}; }

RefineOptions thesis_preset() {
  RefineOptions options;
  options.visibility.max_angle_degrees = 90.0;
  options.visibility.preferred_angle_degrees = 90.0;
  options.curvature.area = CurvatureArea::Barycentric;
  options.stopping.epsilon_percent = 0.3;
  options.stopping.max_iterations = 100;
  options.stopping.median_move_tolerance = 0.002;
  options.speed_quantile = 1.0;
  options.local_step = false;
  options.step_control = false;
  options.adaptive.min_edge_pixels = 0.0;
  options.adaptive.min_growth = 0.0;
  options.untangling.max_rounds = 0;
  options.smoothing.taubin_pass_band = 0.0;
  options.refinement_schedule = RefinementSchedule::EveryIteration;
  options.stopping.test = ConvergenceTest::EachLookback;
  options.rims.fit = RimFit::Off;
  return options;
}

RefineOptions preset(const std::string& name) {
  if (name == "default") return default_preset();
  if (name == "thesis") return thesis_preset();
  throw InputError("unknown preset '" + name + "' (expected default or thesis)");
}

}  // namespace mvflow
