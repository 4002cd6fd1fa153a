#include "tools/refine_option_table.h"

#include <algorithm>
#include <limits>
#include <type_traits>
#include <utility>

#include "engine/model/option_check.h"

namespace mvflow::cli {

namespace {

// What --help shows as each option's default.
const RefineOptions& defaults() {
  static const RefineOptions options = default_preset();
  return options;
}

// The field an entry sets, for a const or a mutable RefineOptions: a generic lambda such as
// [](auto& o) -> auto& { return o.cfl; }.
template <typename Get>
using FieldType = std::remove_cvref_t<decltype(std::declval<Get>()(std::declval<RefineOptions&>()))>;

// The valid values of \p member as RefineOptions::check states them ("(0, 10]"), found by
// checking the default preset with a value no range admits (NaN, or the lowest integer) set by
// \p spoil: each range is written once, in its stage's check(). Empty when that is accepted.
std::string valid_values(const std::string& member, const std::function<void(RefineOptions&)>& spoil) {
  RefineOptions probe = defaults();
  spoil(probe);
  try {
    probe.check();
  } catch (const OptionError& e) {
    if (e.option() == member) return e.expected();
  }
  return "";
}

template <typename T>
T outside_every_range() {
  if constexpr (std::numeric_limits<T>::has_quiet_NaN) return std::numeric_limits<T>::quiet_NaN();
  else return std::numeric_limits<T>::lowest();
}

// The help with the valid values appended, as --help shows it.
std::string with_valid_values(const std::string& help, const std::string& valid) {
  return valid.empty() ? help : help + " (valid: " + valid + ")";
}

// A numeric (or other single-value) field set from the flag's value; RefineOptions::check names
// it \p member.
template <typename Get>
RefineOptionEntry value(std::string flag, std::string key, std::string member, std::string help, Get get) {
  using T = FieldType<Get>;
  return {flag, key, {member},
          [=](CLI::App& command) {
            const std::string description =
                with_valid_values(help, valid_values(member, [get](RefineOptions& o) { get(o) = outside_every_range<T>(); }));
            return command.add_option(flag, description)
                ->type_name(CLI::detail::type_name<T>())
                ->default_str(CLI::detail::to_string(get(defaults())));
          },
          [=](const CLI::Option& given, RefineOptions& target) { get(target) = given.as<T>(); },
          [=](const RefineOptions& options) { return nlohmann::json(get(options)); }};
}

// How a choice appears in the report: by its name, or as the field's own value (bool fields).
enum class ReportAs { Name, Value };

// A field set from one of a few names. CLI11 refuses any other name; \p member (the field's path
// in RefineOptions::check) is needed only where check() can still refuse a name in combination
// with another option, so that the refusal names this flag (and --help lists the names).
template <typename Get>
RefineOptionEntry choice(std::string flag, std::string key, std::string help,
                         std::vector<std::pair<std::string, FieldType<Get>>> names, Get get,
                         ReportAs report = ReportAs::Name, std::string member = "") {
  auto name_of = [names](const FieldType<Get>& v) {
    for (const auto& [name, value] : names)
      if (value == v) return name;
    return std::string("?");
  };
  std::vector<std::string> allowed;
  for (const auto& entry : names) allowed.push_back(entry.first);
  std::string listed;
  for (const std::string& name : allowed) listed += (listed.empty() ? "" : ", ") + name;
  const std::string description = member.empty() ? help : with_valid_values(help, listed);
  std::vector<std::string> members;
  if (!member.empty()) members.push_back(member);
  return {flag, key, members,
          [=](CLI::App& command) {
            return command.add_option(flag, description)
                ->type_name("TEXT")
                ->check(CLI::IsMember(allowed))
                ->default_str(name_of(get(defaults())));
          },
          [=](const CLI::Option& given, RefineOptions& target) {
            const std::string name = given.as<std::string>();
            for (const auto& [candidate, value] : names)
              if (candidate == name) get(target) = value;
          },
          [=](const RefineOptions& options) {
            return report == ReportAs::Name ? nlohmann::json(name_of(get(options))) : nlohmann::json(get(options));
          }};
}

// "on" or "off" for a bool field, reported as the bool.
template <typename Get>
RefineOptionEntry on_off(std::string flag, std::string key, std::string help, Get get) {
  return choice(std::move(flag), std::move(key), std::move(help), {{"on", true}, {"off", false}}, get, ReportAs::Value);
}

// A flag without a value that sets a bool field to \p when_given.
template <typename Get>
RefineOptionEntry switch_flag(std::string flag, std::string key, std::string help, Get get, bool when_given) {
  return {flag, key, {}, [=](CLI::App& command) { return command.add_flag(flag, help); },
          [=](const CLI::Option&, RefineOptions& target) { get(target) = when_given; },
          [=](const RefineOptions& options) { return nlohmann::json(get(options)); }};
}

std::vector<RefineOptionEntry> make_table() {
  using R = RefineOptions;
  std::vector<RefineOptionEntry> t;
  t.push_back(choice("--engine", "engine", "graph (TBB flow graph) or sequential (reference loop, one thread)",
                     {{"graph", EngineKind::Graph}, {"sequential", EngineKind::Sequential}},
                     [](auto& o) -> auto& { return o.engine; }));
  t.push_back(value("--block-size", "block_size", "block_size", "Vertices per block (graph node)",
                    [](auto& o) -> auto& { return o.block_size; }));
  t.push_back(value("--velocity", "velocity", "speed.velocity", "Balloon velocity v of the speed g(v+H)",
                    [](auto& o) -> auto& { return o.speed.velocity; }));
  t.push_back(value("--cfl", "cfl", "cfl", "CFL factor of the time step", [](auto& o) -> auto& { return o.cfl; }));
  t.push_back(value("--speed-quantile", "speed_quantile", "speed_quantile",
                    "Quantile of |F| that sets the time step (1 = max, the thesis); faster vertices move the CFL distance",
                    [](auto& o) -> auto& { return o.speed_quantile; }));
  // The patch sets the photo consistency's and the visibility's half size together.
  t.push_back({"--patch", "patch", {"photo.photo.half_patch", "visibility.half_patch"},
               [](CLI::App& command) {
                 const std::string description =
                     with_valid_values("Patch half size (2 = 5×5)", valid_values("photo.photo.half_patch", [](R& o) {
                                         o.photo.photo.half_patch = o.visibility.half_patch = outside_every_range<int>();
                                       }));
                 return command.add_option("--patch", description)
                     ->type_name("INT")
                     ->default_str(std::to_string(defaults().photo.photo.half_patch));
               },
               [](const CLI::Option& given, R& target) {
                 target.photo.photo.half_patch = target.visibility.half_patch = given.as<int>();
               },
               [](const R& o) { return nlohmann::json(2 * o.photo.photo.half_patch + 1); }});
  t.push_back(value("--sg-k", "savitzky_golay_k", "photo.savitzky_golay.k", "Savitzky–Golay k (window k+1 samples per axis)",
                    [](auto& o) -> auto& { return o.photo.savitzky_golay.k; }));
  t.push_back(value("--sg-order", "savitzky_golay_order", "photo.savitzky_golay.order", "Savitzky–Golay polynomial order",
                    [](auto& o) -> auto& { return o.photo.savitzky_golay.order; }));
  t.push_back(choice("--curvature-area", "curvature_area",
                     "Area of the mean-curvature operator: mixed (Meyer et al.) or barycentric (the thesis)",
                     {{"mixed", CurvatureArea::Mixed}, {"barycentric", CurvatureArea::Barycentric}},
                     [](auto& o) -> auto& { return o.curvature.area; }));
  t.push_back(value("--max-view-angle", "max_view_angle_degrees", "visibility.max_angle_degrees",
                    "Views beyond this angle to the normal are not used (degrees)",
                    [](auto& o) -> auto& { return o.visibility.max_angle_degrees; }));
  t.push_back(value("--max-views", "max_views", "visibility.max_views",
                    "Keep only this many visible views per vertex, those closest to the normal (0 = all, else >= 2)",
                    [](auto& o) -> auto& { return o.visibility.max_views; }));
  t.push_back(value("--preferred-view-angle", "preferred_view_angle_degrees", "visibility.preferred_angle_degrees",
                    "Views beyond this angle to the normal (up to --max-view-angle) only top a vertex's views up to "
                    "--min-views, the closest first (degrees)",
                    [](auto& o) -> auto& { return o.visibility.preferred_angle_degrees; }));
  t.push_back(value("--min-views", "min_views", "visibility.min_views", "See --preferred-view-angle",
                    [](auto& o) -> auto& { return o.visibility.min_views; }));
  t.push_back(value("--image-levels", "image_levels", "image_levels",
                    "Start on the photographs halved this many times, one level finer each time the flow settles",
                    [](auto& o) -> auto& { return o.image_levels; }));
  t.push_back(value("--far-g-ratio", "far_g_ratio", "far.g_ratio",
                    "At the first resolution a vertex whose g exceeds this multiple of the median g reads the "
                    "photographs at half resolution until it comes near (0 = never, the thesis preset)",
                    [](auto& o) -> auto& { return o.far.g_ratio; }));
  t.push_back(value("--far-view-angle", "far_view_angle_degrees", "far.view_angle_degrees",
                    "... if one of its views lies within this angle of its normal (degrees)",
                    [](auto& o) -> auto& { return o.far.view_angle_degrees; }));
  t.push_back(value("--far-release", "far_release", "far.release",
                    "A far vertex is near again when its g falls below this fraction of --far-g-ratio times the median",
                    [](auto& o) -> auto& { return o.far.release; }));
  t.push_back(choice("--denoise", "denoise",
                     "Photographs whose estimated noise is above --denoise-reference are blurred (Gaussian) just "
                     "enough to bring it there for the whole-pixel image patches (surface patches read them as "
                     "given; with --surface-patch on nothing is blurred): auto or off (thesis preset: off)",
                     {{"auto", DenoiseUse::Auto}, {"off", DenoiseUse::Off}}, [](auto& o) -> auto& { return o.denoise.use; }));
  t.push_back(value("--denoise-reference", "denoise_noise_reference", "denoise.noise_reference",
                    "--denoise auto: the noise σ (on [0, 1]) the photographs are blurred down to",
                    [](auto& o) -> auto& { return o.denoise.noise_reference; }));
  t.push_back(on_off("--normalize", "photo_normalize",
                     "Per-view gain/bias normalisation of the patches before the variance (on/off)",
                     [](auto& o) -> auto& { return o.photo.photo.normalize; }));
  t.push_back(choice("--surface-patch", "photo_surface_patch",
                     "Patches laid on the tangent plane, the same surface points in every view, instead of whole-pixel "
                     "image patches: on, off, or oblique (at the vertices with a view beyond --surface-patch-angle)",
                     {{"off", SurfacePatchUse::Off},
                      {"oblique", SurfacePatchUse::Oblique},
                      {"on", SurfacePatchUse::On}},
                     [](auto& o) -> auto& { return o.photo.photo.surface_patch; }, ReportAs::Name,
                     "photo.photo.surface_patch"));  // on is refused with --normalize on
  t.push_back(value("--surface-patch-angle", "photo_surface_patch_angle", "photo.photo.surface_patch_angle_degrees",
                    "--surface-patch oblique: a vertex with a view farther than this from its normal (degrees) lays "
                    "its patch on the surface",
                    [](auto& o) -> auto& { return o.photo.photo.surface_patch_angle_degrees; }));
  t.push_back(value("--surface-patch-spacing", "photo_surface_patch_spacing", "photo.photo.surface_patch_spacing",
                    "--surface-patch: spacing of the patch points in pixels of the finest view",
                    [](auto& o) -> auto& { return o.photo.photo.surface_patch_spacing; }));
  t.push_back(value("--noise-floor", "photo_noise_floor", "photo.photo.noise_floor",
                    "Normalisation: contrast floor σ₀ on [0,1] values (flat patches are not stretched beyond it)",
                    [](auto& o) -> auto& { return o.photo.photo.noise_floor; }));
  t.push_back(value("--drop-views", "drop_views", "photo.photo.drop_views",
                    "Drop up to this many outlier views per vertex (the patches farthest from the mean)",
                    [](auto& o) -> auto& { return o.photo.photo.drop_views; }));
  t.push_back(value("--drop-min-views", "drop_min_views", "photo.photo.min_views", "... while more than this many views remain",
                    [](auto& o) -> auto& { return o.photo.photo.min_views; }));
  t.push_back(choice("--spread-unobserved", "spread_unobserved",
                     "Vertices without g or ∇g take the observed surface's displacement (harmonic, from the surface "
                     "the flow started on) when the flow converges at a resolution that is then refined: on, off, or "
                     "auto (all of them when the rims are fitted to silhouettes, which then count as observed, else "
                     "only the hardly observed ones, --hardly-observed; thesis preset: off)",
                     {{"off", UnobservedSpread::Off}, {"on", UnobservedSpread::On}, {"auto", UnobservedSpread::Auto}},
                     [](auto& o) -> auto& { return o.unobserved_displacement.spread; }));
  t.push_back(value("--observed-view-angle", "observed_view_angle_degrees", "unobserved_displacement.observed_angle_degrees",
                    "--spread-unobserved: a vertex counts as observed when it has a speed and a view within this "
                    "angle of its normal (degrees)",
                    [](auto& o) -> auto& { return o.unobserved_displacement.observed_angle_degrees; }));
  t.push_back(value("--observed-erode", "observed_erode_rings", "unobserved_displacement.erode_rings",
                    "--spread-unobserved: shrink the observed set by this many rings before following it",
                    [](auto& o) -> auto& { return o.unobserved_displacement.erode_rings; }));
  t.push_back(value("--implausible-g-ratio", "implausible_g_ratio", "unobserved_displacement.implausible_g_ratio",
                    "a vertex whose g and whose neighbours' g all exceed this multiple of the median g of the "
                    "vertices with a speed counts as not observed by --spread-unobserved, and its speed is averaged "
                    "(--implausible-speed-rings); not applied where the rims are fitted to silhouettes (0 = never, "
                    "the thesis preset)",
                    [](auto& o) -> auto& { return o.unobserved_displacement.implausible_g_ratio; }));
  t.push_back(value("--implausible-speed-rings", "implausible_speed_rings", "implausible_speed.rings",
                    "the speed of a vertex of implausibly high g (--implausible-g-ratio) becomes this many rounds "
                    "of one-ring means over the vertices with a speed; not where the rims are fitted (0 = its own, "
                    "the thesis preset)",
                    [](auto& o) -> auto& { return o.implausible_speed.rings; }));
  t.push_back(value("--hardly-observed", "hardly_observed_fraction", "unobserved_displacement.hardly_observed_fraction",
                    "--spread-unobserved auto without fitted rims: only vertices that had a speed in at most this "
                    "fraction of their resolution's iterations follow the observed surface",
                    [](auto& o) -> auto& { return o.unobserved_displacement.hardly_observed_fraction; }));
  t.push_back(value("--hardly-observed-first", "first_hardly_observed_fraction",
                    "unobserved_displacement.first_hardly_observed_fraction",
                    "--hardly-observed at the first resolution's convergence (the coarsest mesh)",
                    [](auto& o) -> auto& { return o.unobserved_displacement.first_hardly_observed_fraction; }));
  t.push_back(choice("--spread-unmoved", "spread_unmoved",
                     "--spread-unobserved on/auto: at the run's end the poorly observed vertices the finest resolution "
                     "never observed (no speed, or --implausible-g-ratio) follow the observed surface too, and stay: on, "
                     "off, or auto (where the rims are not fitted)",
                     {{"off", UnobservedSpread::Off}, {"on", UnobservedSpread::On}, {"auto", UnobservedSpread::Auto}},
                     [](auto& o) -> auto& { return o.unobserved_displacement.spread_unmoved; }));
  t.push_back(on_off("--fill-unobserved", "fill_unobserved",
                     "Vertices without g or ∇g move with their observed neighbours (on/off)",
                     [](auto& o) -> auto& { return o.unobserved.fill; }));
  t.push_back(value("--weak-view-angle", "weak_view_angle_degrees", "unobserved.weak_angle_degrees",
                    "--fill-unobserved on: a vertex whose views all lie beyond this angle to its normal follows its "
                    "neighbours too (degrees; 90 = only vertices without g or ∇g)",
                    [](auto& o) -> auto& { return o.unobserved.weak_angle_degrees; }));
  t.push_back(value("--smoothing", "smoothing_lambda_dt", "smoothing.lambda_dt", "Curvature-normal smoothing λ·dt per step",
                    [](auto& o) -> auto& { return o.smoothing.lambda_dt; }));
  t.push_back(value("--smoothing-steps", "smoothing_steps", "smoothing.steps", "Smoothing steps per iteration",
                    [](auto& o) -> auto& { return o.smoothing.steps; }));
  t.push_back(value("--taubin-pass-band", "smoothing_taubin_pass_band", "smoothing.taubin_pass_band",
                    "Taubin k_PB: each smoothing step is followed by one with −μ = −λ/(1 − k_PB·λ), so smoothing does "
                    "not shrink the surface (0 = off, the thesis)",
                    [](auto& o) -> auto& { return o.smoothing.taubin_pass_band; }));
  t.push_back(value("--regularization", "regularization_strength", "regularization.strength", "Tangential regularization C per step",
                    [](auto& o) -> auto& { return o.regularization.strength; }));
  t.push_back(value("--regularization-steps", "regularization_steps", "regularization.steps", "Regularization steps per iteration",
                    [](auto& o) -> auto& { return o.regularization.steps; }));
  t.push_back(value("--epsilon", "epsilon_percent", "stopping.epsilon_percent", "Stop when Σg changes less than this (percent) over 5 iterations",
                    [](auto& o) -> auto& { return o.stopping.epsilon_percent; }));
  t.push_back(value("--min-iterations", "min_iterations", "stopping.min_iterations", "No stop before this iteration",
                    [](auto& o) -> auto& { return o.stopping.min_iterations; }));
  t.push_back(value("--max-iterations", "max_iterations", "stopping.max_iterations", "Stop after this many iterations (over all resolutions)",
                    [](auto& o) -> auto& { return o.stopping.max_iterations; }));
  t.push_back(value("--step-tolerance", "median_move_tolerance", "stopping.median_move_tolerance",
                    "Stop when the median move of one iteration is below this × e_min (0 = off; thesis preset: 0.002)",
                    [](auto& o) -> auto& { return o.stopping.median_move_tolerance; }));
  t.push_back(value("--settle-tolerance", "settled_tolerance", "stopping.settled_tolerance",
                    "Stop (settled) when the median net move along the normal over the last 5 iterations is below "
                    "this × the vertex's shortest edge (0 = off, the thesis preset)",
                    [](auto& o) -> auto& { return o.stopping.settled_tolerance; }));
  t.push_back(value("--settle-noise-reference", "settled_noise_reference", "stopping.settled_noise_reference",
                    "Photographs noisier than this (σ on [0, 1], estimated from them) raise the settled tolerance by "
                    "√(σ / this), σ after --denoise (0 = off; clean renders and photographs here read 0.0006–0.0018, README "
                    "\"Convergence\")",
                    [](auto& o) -> auto& { return o.stopping.settled_noise_reference; }));
  t.push_back(value("--persistence-wait", "persistence_wait", "stopping.persistence_wait",
                    "At the finest resolution the Σg stop waits while the surface's net move along the normal "
                    "carries on from one window of iterations to the next, for at most this many times the "
                    "iterations the level ran to its first stop (0 = no wait, the thesis preset; README \"Convergence\")",
                    [](auto& o) -> auto& { return o.stopping.persistence_wait; }));
  t.push_back(value("--finest-min-iterations", "finest_min_iterations", "stopping.finest_min_iterations",
                    "At the finest resolution a stop by any rule waits until the level has run this many iterations "
                    "(0 = no minimum, the thesis preset; README \"Convergence\")",
                    [](auto& o) -> auto& { return o.stopping.finest_min_iterations; }));
  t.push_back(value("--settled-wait", "settled_wait", "stopping.settled_wait",
                    "At the finest resolution a settled stop waits while the surface's net move carries on, for at "
                    "most this many times the iterations the level ran to its first stop (0 = no wait, the thesis "
                    "preset; README \"Convergence\")",
                    [](auto& o) -> auto& { return o.stopping.settled_wait; }));
  t.push_back(value("--average-last", "average_last", "stopping.average_last",
                    "The refined mesh is the mean of the positions of the last this many iterations (of the last "
                    "topology and images), which cancels the vertices' back-and-forth about the minimum of g (1 = the last "
                    "iteration, the thesis preset; README \"Convergence\")",
                    [](auto& o) -> auto& { return o.stopping.average_last; }));
  t.push_back(value("--run-on", "run_on", "stopping.run_on",
                    "After the run would end converged, step-small or settled, this many more iterations with every stopping "
                    "rule off and nothing refined (outside the budget): whether the stop came too early (0 = none; "
                    "README \"Convergence\")",
                    [](auto& o) -> auto& { return o.stopping.run_on; }));
  t.push_back(switch_flag("--no-remeshing", "global_remeshing", "Skip the global split/collapse before the flow",
                          [](auto& o) -> auto& { return o.global_remeshing; }, false));
  t.push_back(value("--refine-min-pixels", "adaptive_min_edge_pixels", "adaptive.min_edge_pixels",
                    "Adaptive refinement leaves faces with an edge shorter than this many pixels at the object",
                    [](auto& o) -> auto& { return o.adaptive.min_edge_pixels; }));
  t.push_back(value("--refine-curvature", "adaptive_curvature_factor", "adaptive.curvature_factor",
                    "Adaptive refinement marks vertices whose curvature-normal length exceeds this × e_S",
                    [](auto& o) -> auto& { return o.adaptive.curvature_factor; }));
  t.push_back(value("--untangle-rounds", "untangle_rounds", "untangling.max_rounds",
                    "Rounds of fold removal (smoothing around crossing faces) before each refinement and at the end; "
                    "0 disables (thesis preset)",
                    [](auto& o) -> auto& { return o.untangling.max_rounds; }));
  t.push_back(value("--refine-min-growth", "adaptive_min_growth", "adaptive.min_growth",
                    "A refinement that would add fewer than this fraction of the vertices is not done (coarse to "
                    "fine, the run then ends; thesis preset: 0)",
                    [](auto& o) -> auto& { return o.adaptive.min_growth; }));
  t.push_back(choice("--refine-when", "refine_when",
                     "Adaptive refinement before every iteration (the thesis) or when the flow has converged at the "
                     "current resolution (thesis preset: iteration)",
                     {{"iteration", RefinementSchedule::EveryIteration}, {"converged", RefinementSchedule::AtConvergence}},
                     [](auto& o) -> auto& { return o.refinement_schedule; }));
  t.push_back(choice("--convergence", "convergence_test",
                     "Σg convergence test: each-lookback (the thesis: every one of the last 5 changes below ε) or "
                     "no-improvement (the best Σg of the last 5 iterations is not ε below the best before)",
                     {{"each-lookback", ConvergenceTest::EachLookback}, {"no-improvement", ConvergenceTest::NoImprovement}},
                     [](auto& o) -> auto& { return o.stopping.test; }));
  t.push_back(choice("--step", "local_step",
                     "CFL bound: local (Δt from the mean edge, each vertex moves at most cfl/(2√3) of its own "
                     "shortest edge) or global (the thesis: every vertex within cfl/(2√3) of the mesh's shortest edge)",
                     {{"local", true}, {"global", false}}, [](auto& o) -> auto& { return o.local_step; },
                     ReportAs::Value));
  t.push_back(on_off("--step-control", "step_control",
                     "Halve the steps after an iteration that raised Σg/vertex, grow them back after one that lowered it",
                     [](auto& o) -> auto& { return o.step_control; }));
  t.push_back(on_off("--damping", "step_damping",
                     "Per-vertex step damping: halve a vertex's step when its speed along the normal reverses, "
                     "grow it back toward the CFL step while it does not (thesis preset: off)",
                     [](auto& o) -> auto& { return o.damping.enabled; }));
  t.push_back(value("--momentum", "step_momentum", "momentum.carry",
                    "Per-vertex step momentum β: a vertex moving the same way along its normal as in the last "
                    "iteration carries β of that whole step into this one (0 = off, the thesis preset)",
                    [](auto& o) -> auto& { return o.momentum.carry; }));
  t.push_back(switch_flag("--keep-inside-silhouettes", "keep_inside_silhouettes",
                          "Keep the surface inside the visual hull of the used views' silhouettes (photographs on a "
                          "dark background)",
                          [](auto& o) -> auto& { return o.keep_inside_silhouettes; }, true));
  t.push_back(choice("--fit-silhouettes", "fit_silhouettes",
                     "Move the surface's rims (normal perpendicular to a view's ray, unoccluded) toward that view's "
                     "silhouette boundary, past a dead zone: on, off, or auto (on when every view's border is dark, "
                     "i.e. a background the threshold separates; thesis preset: off)",
                     {{"off", RimFit::Off}, {"on", RimFit::On}, {"auto", RimFit::Auto}},
                     [](auto& o) -> auto& { return o.rims.fit; }));
  t.push_back(value("--rim-angle", "rim_angle_degrees", "rims.rim_angle_degrees",
                    "--fit-silhouettes on: a vertex is a rim of a view within this angle of 90° between its normal "
                    "and the view's ray (degrees)",
                    [](auto& o) -> auto& { return o.rims.rim_angle_degrees; }));
  t.push_back(value("--rim-dead-zone", "rim_dead_zone_pixels", "rims.dead_zone_pixels",
                    "--fit-silhouettes on: boundaries nearer than this many pixels are left to the photo consistency",
                    [](auto& o) -> auto& { return o.rims.dead_zone_pixels; }));
  t.push_back(value("--rim-step", "rim_step", "rims.step",
                    "--fit-silhouettes on: the fraction of the distance to the boundary moved per iteration",
                    [](auto& o) -> auto& { return o.rims.step; }));
  t.push_back(value("--silhouette-threshold", "silhouette_threshold", "silhouettes.threshold",
                    "Silhouettes for --keep-inside-silhouettes and --fit-silhouettes: largest channel above this (on [0,1])",
                    [](auto& o) -> auto& { return o.silhouettes.threshold; }));
  t.push_back(value("--silhouette-dilate", "silhouette_dilate", "silhouettes.dilate", "... dilated by this many pixels",
                    [](auto& o) -> auto& { return o.silhouettes.dilate; }));
  t.push_back(switch_flag("--no-adaptive", "adaptive_refinement", "Skip adaptive refinement between iterations",
                          [](auto& o) -> auto& { return o.adaptive_refinement; }, false));
  t.push_back({"--exclude-views", "excluded_views", {"excluded_views"},
               [](CLI::App& command) {
                 return command.add_option("--exclude-views", "0-based views not to use (held out)")
                     ->type_name("INT")
                     ->expected(1, CLI::detail::expected_max_vector_size)
                     ->delimiter(',');
               },
               [](const CLI::Option& given, R& target) { target.excluded_views = given.as<std::vector<int>>(); },
               [](const R& o) { return nlohmann::json(o.excluded_views); }});
  return t;
}

}  // namespace

const std::vector<RefineOptionEntry>& refine_option_table() {
  static const std::vector<RefineOptionEntry> table = make_table();
  return table;
}

void add_refine_options(CLI::App& command) {
  for (const RefineOptionEntry& entry : refine_option_table()) entry.add(command);
}

RefineOptions resolve_refine_options(const std::string& preset_name, const CLI::App& command) {
  RefineOptions options = preset(preset_name);
  for (const RefineOptionEntry& entry : refine_option_table()) {
    const CLI::Option* given = command.get_option_no_throw(entry.flag);
    if (given && given->count() > 0) entry.apply(*given, options);
  }
  // Validated as a whole, after every flag: a range may depend on another option (Taubin's μ on λ).
  try {
    options.check();
  } catch (const OptionError& e) {
    for (const RefineOptionEntry& entry : refine_option_table())
      if (std::find(entry.members.begin(), entry.members.end(), e.option()) != entry.members.end())
        throw CLI::ValidationError(entry.flag, e.what());
    throw CLI::ValidationError(e.what());
  }
  return options;
}

nlohmann::json refine_options_json(const RefineOptions& options, const std::string& preset_name) {
  nlohmann::json json = {{"preset", preset_name}};
  for (const RefineOptionEntry& entry : refine_option_table()) json[entry.key] = entry.value(options);
  return json;
}

}  // namespace mvflow::cli
