#include "engine/refine/refine_options.h"

#include "engine/model/error.h"
#include "engine/model/option_check.h"

namespace mvflow {

void RefineOptions::check() const {
  // Each stage checks its own options, where their ranges are written; a failing field is named by
  // its path (smoothing.lambda_dt), which the command line maps back to its flag. The photo
  // options come before the visibility's: the patch's range is theirs.
  check_member(photo, "photo");
  check_member(visibility, "visibility");
  check_member(unobserved, "unobserved");
  check_member(unobserved_displacement, "unobserved_displacement");
  check_member(implausible_speed, "implausible_speed");
  check_member(speed, "speed");
  require_option(cfl > 0 && cfl <= 10, "cfl", cfl, "(0, 10]");
  require_option(speed_quantile > 0 && speed_quantile <= 1, "speed_quantile", speed_quantile, "(0, 1]");
  check_member(damping, "damping");
  check_member(momentum, "momentum");
  check_member(smoothing, "smoothing");
  check_member(regularization, "regularization");
  check_member(stopping, "stopping");
  check_member(remeshing, "remeshing");
  check_member(adaptive, "adaptive");
  check_member(untangling, "untangling");
  require_option(block_size >= 1, "block_size", block_size, ">= 1");
  require_option(image_levels >= 0 && image_levels <= 4, "image_levels", image_levels, "[0, 4]");
  check_member(far, "far");
  check_member(denoise, "denoise");
  check_member(silhouettes, "silhouettes");
  check_member(rims, "rims");
  require_option(visibility.half_patch == photo.photo.half_patch, "visibility.half_patch", visibility.half_patch,
                 "photo.photo.half_patch (" + std::to_string(photo.photo.half_patch) + ")");
  for (int view : excluded_views) require_option(view >= 0, "excluded_views", view, ">= 0 (0-based view indices)");
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
  options.stopping.settled_tolerance = 0.0;
  options.stopping.settled_noise_reference = 0.0;
  options.stopping.persistence_wait = 0.0;
  options.stopping.finest_min_iterations = 0;
  options.stopping.settled_wait = 0.0;
  options.stopping.average_last = 1;
  options.damping.enabled = false;
  options.momentum.carry = 0.0;
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
  options.unobserved_displacement.spread = UnobservedSpread::Off;
  options.unobserved_displacement.implausible_g_ratio = 0.0;
  options.implausible_speed.rings = 0;
  options.photo.photo.surface_patch = SurfacePatchUse::Off;
  options.denoise.use = DenoiseUse::Off;
  options.far.g_ratio = 0.0;
  return options;
}

RefineOptions accurate_preset() {
  RefineOptions options = default_preset();
  options.photo.photo.surface_patch = SurfacePatchUse::On;
  // Surface-patch runs move more steadily: at 0.0025 the median net move falls below the settled
  // tolerance while a minority (the peanut's waist) is still arriving.
  options.stopping.settled_tolerance = 0.001;
  return options;
}

namespace {

// Every preset, in the order help texts list them: the one list preset() and preset_names() read.
struct NamedPreset {
  const char* name;
  RefineOptions (*make)();
};
constexpr NamedPreset kPresets[] = {{"default", default_preset}, {"accurate", accurate_preset}, {"thesis", thesis_preset}};

}  // namespace

const std::vector<std::string>& preset_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> list;
    for (const NamedPreset& preset : kPresets) list.emplace_back(preset.name);
    return list;
  }();
  return names;
}

RefineOptions preset(const std::string& name) {
  for (const NamedPreset& known : kPresets)
    if (name == known.name) return known.make();
  std::string expected;
  for (const NamedPreset& known : kPresets) expected += (expected.empty() ? "" : ", ") + std::string(known.name);
  throw InputError("unknown preset '" + name + "' (expected one of: " + expected + ")");
}

}  // namespace mvflow
