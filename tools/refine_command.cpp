// `mvflow refine SCENE --mesh INIT -o OUT`: the main job.

#include <unistd.h>

#include <cstdio>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "engine/error.h"
#include "engine/refiner.h"
#include "io/atomic_write.h"
#include "io/mesh_io.h"
#include "io/report_io.h"
#include "io/scene_io.h"
#include "stages/photo_kernel.h"
#include "tools/commands.h"
#include "tools/interrupt.h"

namespace mvflow::cli {

namespace {

struct RefineArguments {
  std::string scene;
  std::string mesh;
  std::string output;
  std::string report;
  std::string preset = "default";
  std::string engine = "graph";
  bool ascii = false;
  bool no_remeshing = false;
  bool no_adaptive = false;
  std::string step;               // "local" or "global"; empty: the preset's
  std::string step_control;       // "on" or "off"; empty: the preset's
  std::string refine_when;        // "iteration" or "converged"; empty: the preset's
  std::string convergence;        // "each-lookback" or "no-improvement"; empty: the preset's
  std::string normalize;          // "on" or "off"; empty: the preset's
  std::string fill_unobserved;    // "on" or "off"; empty: the preset's
  std::string spread_unobserved;  // "on" or "off"; empty: the preset's
  int threads = 0;
  RefineOptions options;          // values given on the command line override the preset
};

nlohmann::json options_json(const RefineOptions& o, const std::string& preset) {
  return {{"preset", preset},
          {"engine", o.engine == EngineKind::Graph ? "graph" : "sequential"},
          {"block_size", o.block_size},
          {"velocity", o.speed.velocity},
          {"cfl", o.cfl},
          {"speed_quantile", o.speed_quantile},
          {"local_step", o.local_step},
          {"step_control", o.step_control},
          {"patch", 2 * o.photo.photo.half_patch + 1},
          {"savitzky_golay_k", o.photo.savitzky_golay.k},
          {"savitzky_golay_order", o.photo.savitzky_golay.order},
          {"max_view_angle_degrees", o.visibility.max_angle_degrees},
          {"max_views", o.visibility.max_views},
          {"image_levels", o.image_levels},
          {"preferred_view_angle_degrees", o.visibility.preferred_angle_degrees},
          {"min_views", o.visibility.min_views},
          {"photo_normalize", o.photo.photo.normalize},
          {"photo_noise_floor", o.photo.photo.noise_floor},
          {"drop_views", o.photo.photo.drop_views},
          {"drop_min_views", o.photo.photo.min_views},
          {"fill_unobserved", o.unobserved.fill},
          {"spread_unobserved", o.unobserved_displacement.enabled},
          {"observed_view_angle_degrees", o.unobserved_displacement.observed_angle_degrees},
          {"observed_erode_rings", o.unobserved_displacement.erode_rings},
          {"weak_view_angle_degrees", o.unobserved.weak_angle_degrees},
          {"curvature_area", o.curvature.area == CurvatureArea::Mixed ? "mixed" : "barycentric"},
          {"smoothing_lambda_dt", o.smoothing.lambda_dt},
          {"smoothing_steps", o.smoothing.steps},
          {"smoothing_taubin_pass_band", o.smoothing.taubin_pass_band},
          {"regularization_strength", o.regularization.strength},
          {"regularization_steps", o.regularization.steps},
          {"epsilon_percent", o.stopping.epsilon_percent},
          {"min_iterations", o.stopping.min_iterations},
          {"max_iterations", o.stopping.max_iterations},
          {"median_move_tolerance", o.stopping.median_move_tolerance},
          {"global_remeshing", o.global_remeshing},
          {"adaptive_refinement", o.adaptive_refinement},
          {"adaptive_curvature_factor", o.adaptive.curvature_factor},
          {"adaptive_min_edge_pixels", o.adaptive.min_edge_pixels},
          {"adaptive_min_growth", o.adaptive.min_growth},
          {"untangle_rounds", o.untangling.max_rounds},
          {"refine_when", o.refinement_schedule == RefinementSchedule::EveryIteration ? "iteration" : "converged"},
          {"convergence_test", o.stopping.test == ConvergenceTest::EachLookback ? "each-lookback" : "no-improvement"},
          {"excluded_views", o.excluded_views},
          {"keep_inside_silhouettes", o.keep_inside_silhouettes},
          {"silhouette_threshold", o.silhouettes.threshold},
          {"silhouette_dilate", o.silhouettes.dilate}};
}

// Starts from the preset and applies every option the user gave.
RefineOptions resolve_options(const RefineArguments& args, CLI::App& command) {
  RefineOptions options = preset(args.preset);
  const RefineOptions& given = args.options;
  auto set = [&](const char* name, auto& target, const auto& value) {
    if (command.count(name) > 0) target = value;
  };
  set("--block-size", options.block_size, given.block_size);
  set("--velocity", options.speed.velocity, given.speed.velocity);
  set("--cfl", options.cfl, given.cfl);
  set("--speed-quantile", options.speed_quantile, given.speed_quantile);
  set("--silhouette-threshold", options.silhouettes.threshold, given.silhouettes.threshold);
  set("--silhouette-dilate", options.silhouettes.dilate, given.silhouettes.dilate);
  if (command.count("--keep-inside-silhouettes") > 0) options.keep_inside_silhouettes = true;

  set("--refine-min-pixels", options.adaptive.min_edge_pixels, given.adaptive.min_edge_pixels);
  set("--refine-curvature", options.adaptive.curvature_factor, given.adaptive.curvature_factor);
  set("--refine-min-growth", options.adaptive.min_growth, given.adaptive.min_growth);
  set("--untangle-rounds", options.untangling.max_rounds, given.untangling.max_rounds);
  set("--max-view-angle", options.visibility.max_angle_degrees, given.visibility.max_angle_degrees);
  set("--smoothing", options.smoothing.lambda_dt, given.smoothing.lambda_dt);
  set("--smoothing-steps", options.smoothing.steps, given.smoothing.steps);
  set("--taubin-pass-band", options.smoothing.taubin_pass_band, given.smoothing.taubin_pass_band);
  set("--regularization", options.regularization.strength, given.regularization.strength);
  set("--regularization-steps", options.regularization.steps, given.regularization.steps);
  set("--epsilon", options.stopping.epsilon_percent, given.stopping.epsilon_percent);
  set("--max-iterations", options.stopping.max_iterations, given.stopping.max_iterations);
  set("--min-iterations", options.stopping.min_iterations, given.stopping.min_iterations);
  set("--step-tolerance", options.stopping.median_move_tolerance, given.stopping.median_move_tolerance);
  set("--sg-k", options.photo.savitzky_golay.k, given.photo.savitzky_golay.k);
  set("--max-views", options.visibility.max_views, given.visibility.max_views);
  set("--image-levels", options.image_levels, given.image_levels);
  set("--preferred-view-angle", options.visibility.preferred_angle_degrees, given.visibility.preferred_angle_degrees);
  set("--min-views", options.visibility.min_views, given.visibility.min_views);
  set("--noise-floor", options.photo.photo.noise_floor, given.photo.photo.noise_floor);
  set("--drop-views", options.photo.photo.drop_views, given.photo.photo.drop_views);
  set("--drop-min-views", options.photo.photo.min_views, given.photo.photo.min_views);
  if (!args.normalize.empty()) options.photo.photo.normalize = args.normalize == "on";
  if (!args.fill_unobserved.empty()) options.unobserved.fill = args.fill_unobserved == "on";
  if (!args.spread_unobserved.empty()) options.unobserved_displacement.enabled = args.spread_unobserved == "on";
  set("--weak-view-angle", options.unobserved.weak_angle_degrees, given.unobserved.weak_angle_degrees);
  set("--observed-erode", options.unobserved_displacement.erode_rings, given.unobserved_displacement.erode_rings);
  set("--observed-view-angle", options.unobserved_displacement.observed_angle_degrees,
      given.unobserved_displacement.observed_angle_degrees);
  set("--sg-order", options.photo.savitzky_golay.order, given.photo.savitzky_golay.order);
  if (command.count("--patch") > 0) {
    options.photo.photo.half_patch = given.photo.photo.half_patch;
    options.visibility.half_patch = given.photo.photo.half_patch;
  }
  if (args.no_remeshing) options.global_remeshing = false;
  if (args.no_adaptive) options.adaptive_refinement = false;
  if (!args.step.empty()) options.local_step = args.step == "local";
  if (!args.step_control.empty()) options.step_control = args.step_control == "on";
  if (!args.refine_when.empty())
    options.refinement_schedule =
        args.refine_when == "iteration" ? RefinementSchedule::EveryIteration : RefinementSchedule::AtConvergence;
  if (!args.convergence.empty())
    options.stopping.test =
        args.convergence == "each-lookback" ? ConvergenceTest::EachLookback : ConvergenceTest::NoImprovement;
  options.excluded_views = given.excluded_views;
  options.engine = args.engine == "sequential" ? EngineKind::Sequential : EngineKind::Graph;
  return options;
}

int run_refine(const RefineArguments& args, const RefineOptions& options, spdlog::logger& log) {
  install_interrupt_handlers();
  // Before the scene is read: a refinement that cannot write its result is not started.
  io::check_writable(args.output);
  if (!args.report.empty()) io::check_writable(args.report);
  const Scene scene = io::load_scene(args.scene);
  std::string mesh_file = args.mesh;
  if (mesh_file.empty() && scene.mesh_file) mesh_file = scene.mesh_file->string();
  if (mesh_file.empty()) throw InputError(args.scene, 0, "no initial mesh: pass --mesh FILE or put init.ply in the scene folder");
  MeshBuildReport build;
  const Mesh initial = io::load_mesh(mesh_file, &build);
  if (build.rejected_faces > 0)
    throw InputError(mesh_file, "face", build.first_rejected.front(),
                     "makes the mesh non-manifold (" + std::to_string(build.rejected_faces) +
                         " such faces); the flow needs a manifold mesh");

  std::shared_ptr<spdlog::logger> shared_log(&log, [](spdlog::logger*) {});  // borrowed, not owned
  RefineControl control;
  control.threads = args.threads;
  control.logger = shared_log;
  control.cancel = &interrupt_requested();
  const bool live = isatty(fileno(stderr)) != 0;
  control.on_progress = [live](const RefineProgress& p) {
    if (live)
      std::fprintf(stderr, "\r\033[K%s: iteration %d/%d, %zu vertices, Σg/vertex %.5g", p.stage, p.iteration,
                   p.max_iterations, p.vertices, p.sum_g_per_vertex);
  };
  log.info("refining {} ({} vertices) with {} views of {}", mesh_file, initial.n_vertices(), scene.size(),
           scene.folder.string());
  const RefineResult result = refine_mesh(scene, initial, options, control);
  if (live) std::fprintf(stderr, "\r\033[K");
  const RefineSummary& s = result.summary;
  if (s.status == RefineStatus::Cancelled) {
    log.warn("interrupted after {} iterations: nothing written", s.iterations.size());
    return kInterrupted;
  }
  if (!args.report.empty()) {
    const nlohmann::json inputs = {{"scene", scene.folder.string()}, {"mesh", mesh_file}, {"views", scene.size()},
                                   {"photo_kernel", detail::active_photo_kernel().name},
                                   {"threads", args.threads}};
    io::write_report(args.report, s, inputs, options_json(options, args.preset));
  }
  if (s.status == RefineStatus::Failed) throw Error(s.message);
  io::MeshWriteOptions write;
  write.binary = !args.ascii;
  io::write_mesh(args.output, to_indexed(result.mesh), write);
  fmt::print("refined    {} → {} vertices in {} iterations, {:.2f} s ({})\n", s.initial_vertices, s.final_vertices,
             s.iterations.size(), s.seconds, to_string(s.status));
  fmt::print("Σg/vertex  {:.6g} → {:.6g}\n", s.initial_sum_g_per_vertex, s.final_sum_g_per_vertex);
  fmt::print("mesh       {} ({} self-intersecting face pairs; {} removed by untangling during the run)\n", args.output,
             s.self_intersections, s.untangled_pairs);
  if (!args.report.empty()) fmt::print("report     {}\n", args.report);
  return kOk;
}

}  // namespace

void add_refine_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<RefineArguments>();
  CLI::App* c = app.add_subcommand("refine", "Refine a mesh toward the photo-consistent surface (the main job)");
  RefineOptions& o = args->options;
  c->add_option("scene", args->scene, "Scene folder, or a camera file inside one")->required();
  c->add_option("--mesh", args->mesh, "Initial mesh (default: the scene's init.*)");
  c->add_option("-o,--output", args->output, "Refined mesh (PLY with colour and quality = g; format by extension)")
      ->required();
  c->add_option("--report", args->report, "JSON report (per iteration and per stage)");
  c->add_option("--preset", args->preset, "Parameter set: default or thesis (exactly the thesis's B.7 values)")
      ->check(CLI::IsMember({"default", "thesis"}))
      ->capture_default_str();
  c->add_option("--threads", args->threads, "Worker threads (0 = all cores)")->check(CLI::NonNegativeNumber)->capture_default_str();
  c->add_option("--engine", args->engine, "graph (TBB flow graph) or sequential (reference loop, one thread)")
      ->check(CLI::IsMember({"graph", "sequential"}))
      ->capture_default_str();
  c->add_option("--block-size", o.block_size, "Vertices per block (graph node)")->check(CLI::PositiveNumber)->capture_default_str();
  c->add_option("--velocity", o.speed.velocity, "Balloon velocity v of the speed g(v+H)")->capture_default_str();
  c->add_option("--cfl", o.cfl, "CFL factor of the time step")->capture_default_str();
  c->add_option("--speed-quantile", o.speed_quantile,
                "Quantile of |F| that sets the time step (1 = max, the thesis); faster vertices move the CFL distance")
      ->capture_default_str();
  c->add_option("--patch", o.photo.photo.half_patch, "Patch half size (2 = 5×5)")->check(CLI::Range(1, 7))->capture_default_str();
  c->add_option("--sg-k", o.photo.savitzky_golay.k, "Savitzky–Golay k (window k+1 samples per axis)")->capture_default_str();
  c->add_option("--sg-order", o.photo.savitzky_golay.order, "Savitzky–Golay polynomial order")->capture_default_str();
  c->add_option("--max-view-angle", o.visibility.max_angle_degrees, "Views beyond this angle to the normal are not used (degrees)")
      ->capture_default_str();
  c->add_option("--max-views", o.visibility.max_views,
                "Keep only this many visible views per vertex, those closest to the normal (0 = all, else >= 2)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  c->add_option("--preferred-view-angle", o.visibility.preferred_angle_degrees,
                "Views beyond this angle to the normal (up to --max-view-angle) only top a vertex's views up to "
                "--min-views, the closest first (degrees)")
      ->check(CLI::Range(0.001, 90.0))
      ->capture_default_str();
  c->add_option("--min-views", o.visibility.min_views, "See --preferred-view-angle")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  c->add_option("--image-levels", o.image_levels,
                "Start on the photographs halved this many times, one level finer each time the flow settles")
      ->check(CLI::Range(0, 4))
      ->capture_default_str();
  c->add_option("--normalize", args->normalize,
                "Per-view gain/bias normalisation of the patches before the variance (on/off)")
      ->check(CLI::IsMember({"on", "off"}));
  c->add_option("--noise-floor", o.photo.photo.noise_floor,
                "Normalisation: contrast floor σ₀ on [0,1] values (flat patches are not stretched beyond it)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  c->add_option("--drop-views", o.photo.photo.drop_views,
                "Drop up to this many outlier views per vertex (the patches farthest from the mean)")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  c->add_option("--drop-min-views", o.photo.photo.min_views, "... while more than this many views remain")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  c->add_option("--spread-unobserved", args->spread_unobserved,
                "Vertices without g or ∇g take the observed surface's displacement (harmonic, along the starting "
                "normal) when the flow converges at a resolution and at the end (on/off; default off)")
      ->check(CLI::IsMember({"on", "off"}));
  c->add_option("--observed-view-angle", o.unobserved_displacement.observed_angle_degrees,
                "--spread-unobserved on: a vertex counts as observed when it has a speed and a view within this angle "
                "of its normal (degrees)")
      ->check(CLI::Range(0.001, 90.0))
      ->capture_default_str();
  c->add_option("--observed-erode", o.unobserved_displacement.erode_rings,
                "--spread-unobserved on: shrink the observed set by this many rings before following it")
      ->check(CLI::Range(0, 100))
      ->capture_default_str();
  c->add_option("--fill-unobserved", args->fill_unobserved,
                "Vertices without g or ∇g move with their observed neighbours (on/off)")
      ->check(CLI::IsMember({"on", "off"}));
  c->add_option("--weak-view-angle", o.unobserved.weak_angle_degrees,
                "--fill-unobserved on: a vertex whose views all lie beyond this angle to its normal follows its "
                "neighbours too (degrees; 90 = only vertices without g or ∇g)")
      ->check(CLI::Range(0.001, 90.0))
      ->capture_default_str();
  c->add_option("--smoothing", o.smoothing.lambda_dt, "Curvature-normal smoothing λ·dt per step")->capture_default_str();
  c->add_option("--smoothing-steps", o.smoothing.steps, "Smoothing steps per iteration")->capture_default_str();
  c->add_option("--taubin-pass-band", o.smoothing.taubin_pass_band,
                "Taubin k_PB: each smoothing step is followed by one with −μ = −λ/(1 − k_PB·λ), so smoothing does "
                "not shrink the surface (0 = off, the thesis)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  c->add_option("--regularization", o.regularization.strength, "Tangential regularization C per step")->capture_default_str();
  c->add_option("--regularization-steps", o.regularization.steps, "Regularization steps per iteration")->capture_default_str();
  c->add_option("--epsilon", o.stopping.epsilon_percent, "Stop when Σg changes less than this (percent) over 5 iterations")
      ->capture_default_str();
  c->add_option("--min-iterations", o.stopping.min_iterations, "No stop before this iteration")->capture_default_str();
  c->add_option("--max-iterations", o.stopping.max_iterations, "Stop after this many iterations")->capture_default_str();
  c->add_option("--step-tolerance", o.stopping.median_move_tolerance, "Stop when the median move is below this × e_min")
      ->capture_default_str();
  c->add_flag("--no-remeshing", args->no_remeshing, "Skip the global split/collapse before the flow");
  c->add_option("--refine-min-pixels", o.adaptive.min_edge_pixels,
                "Adaptive refinement leaves faces with an edge shorter than this many pixels at the object")
      ->capture_default_str();
  c->add_option("--refine-curvature", o.adaptive.curvature_factor,
                "Adaptive refinement marks vertices whose curvature-normal length exceeds this × e_S")
      ->capture_default_str();
  c->add_option("--untangle-rounds", o.untangling.max_rounds,
                "Rounds of fold removal (smoothing around crossing faces) before each refinement and at the end; "
                "0 disables (thesis preset)")
      ->capture_default_str();
  c->add_option("--refine-min-growth", o.adaptive.min_growth,
                "A refinement that would add fewer than this fraction of the vertices is not done (coarse to fine, "
                "the run then ends; thesis preset: 0)")
      ->capture_default_str();
  c->add_option("--refine-when", args->refine_when,
                "Adaptive refinement before every iteration (the thesis) or when the flow has converged at the "
                "current resolution (default: converged; thesis preset: iteration)")
      ->check(CLI::IsMember({"iteration", "converged"}));
  c->add_option("--convergence", args->convergence,
                "Σg convergence test: each-lookback (the thesis: every one of the last 5 changes below ε) or "
                "no-improvement (the best Σg of the last 5 iterations is not ε below the best before; default)")
      ->check(CLI::IsMember({"each-lookback", "no-improvement"}));
  c->add_option("--step", args->step,
                "CFL bound: local (Δt from the mean edge, each vertex moves at most cfl/(2√3) of its own shortest "
                "edge; default) or global (the thesis: every vertex within cfl/(2√3) of the mesh's shortest edge)")
      ->check(CLI::IsMember({"local", "global"}));
  c->add_option("--step-control", args->step_control,
                "Halve the steps after an iteration that raised Σg/vertex, grow them back after one that lowered it")
      ->check(CLI::IsMember({"on", "off"}));
  c->add_flag("--keep-inside-silhouettes", o.keep_inside_silhouettes,
               "Keep the surface inside the visual hull of the used views' silhouettes (photographs on a dark "
               "background)");
  c->add_option("--silhouette-threshold", o.silhouettes.threshold,
                "Silhouettes for --keep-inside-silhouettes: largest channel above this (on [0,1])")
      ->capture_default_str();
  c->add_option("--silhouette-dilate", o.silhouettes.dilate, "... dilated by this many pixels")->capture_default_str();

  c->add_flag("--no-adaptive", args->no_adaptive, "Skip adaptive refinement between iterations");
  c->add_option("--exclude-views", o.excluded_views, "0-based views not to use (held out)")->delimiter(',');
  c->add_flag("--ascii", args->ascii, "Write PLY as ASCII");
  c->callback([args, c, &runner] {
    const RefineOptions options = resolve_options(*args, *c);
    runner = [args, options](spdlog::logger& log) { return run_refine(*args, options, log); };
  });
}

}  // namespace mvflow::cli
