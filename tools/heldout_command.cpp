// `mvflow heldout SCENE MESH --views i,j`: the held-out-view error (SPEC §8) — scores a mesh on
// photographs that neither its refinement (`mvflow refine --exclude-views i,j`) nor its colouring saw.

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>

#include "engine/model/error.h"
#include <tbb/task_arena.h>

#include "engine/model/parallel.h"
#include "io/atomic_write.h"
#include "io/image_io.h"
#include "io/mask_files.h"
#include "io/mesh_io.h"
#include "io/scene_io.h"
#include "stages/eval/heldout_error.h"
#include "stages/flow/silhouette.h"
#include "tools/commands.h"

namespace mvflow::cli {

namespace {

namespace fs = std::filesystem;

struct HeldoutArguments {
  std::string scene;
  std::string mesh;
  std::vector<int> views;
  std::string json;
  std::string output;
  std::string masks;
  std::vector<float> background{0.0f};
  double error_scale = 0.25;
  SilhouetteOptions silhouette;
  HeldoutOptions options;
  int threads = 0;
};

// +inf and NaN have no JSON number: null stands for them (PSNR of identical images, no scored pixel).
nlohmann::json number_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

nlohmann::json metrics_json(const HeldoutMetrics& m) {
  return {{"mae", number_or_null(m.mae())},   {"psnr_db", number_or_null(m.psnr())},
          {"mse", number_or_null(m.mse())},   {"silhouette_disagreement", m.silhouette_disagreement()},
          {"union_pixels", m.union_pixels},   {"disagreeing_pixels", m.disagreeing_pixels},
          {"unseen_pixels", m.unseen_pixels}, {"scored_pixels", m.scored_pixels}};
}

nlohmann::json options_json(const HeldoutArguments& args, const HeldoutOptions& o) {
  nlohmann::json silhouette = {{"dilate", args.silhouette.dilate}};
  if (args.masks.empty()) {
    silhouette["source"] = "threshold";
    silhouette["threshold"] = args.silhouette.threshold;
  } else {
    silhouette["source"] = "masks";
    silhouette["masks"] = args.masks;
  }
  return {{"supersample", o.supersample},
          {"background", {o.background.x(), o.background.y(), o.background.z()}},
          {"max_view_angle_degrees", o.colouring.max_angle_degrees},
          {"ray_offset", o.colouring.ray_offset},
          {"real_silhouette", silhouette},
          {"error_scale", args.error_scale},
          {"threads", args.threads}};
}

std::string format_psnr(double psnr) {
  return std::isinf(psnr) ? "inf" : fmt::format("{:.2f}", psnr);
}

int run_heldout(const HeldoutArguments& args, spdlog::logger& log) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  // The outputs first: a location that could not be written stops the run before any work.
  const fs::path json_file = !args.json.empty()     ? fs::path(args.json)
                             : !args.output.empty() ? fs::path(args.output) / "heldout.json"
                                                    : fs::path();
  if (!args.output.empty()) io::prepare_output_folder(args.output);
  if (!json_file.empty()) io::check_writable(json_file);
  const Scene scene = io::load_scene(args.scene);
  MeshBuildReport build;
  const Mesh mesh = io::load_mesh(args.mesh, &build);
  if (mesh.n_faces() == 0) throw InputError(args.mesh, 0, "the mesh has no faces to render");
  if (build.rejected_faces > 0)
    log.warn("{}: {} face(s) would make the mesh non-manifold and are not rendered", args.mesh,
             build.rejected_faces);
  HeldoutOptions options = args.options;
  options.background = args.background.size() == 3
                           ? Eigen::Vector3f(args.background[0], args.background[1], args.background[2])
                           : Eigen::Vector3f::Constant(args.background[0]);
  const HeldoutRenderer renderer(scene, mesh, args.views, options);
  const double setup_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  log.info("scoring {} on {} held-out view(s), coloured from {} view(s)", args.mesh,
           renderer.held_out().size(), renderer.colouring_views().size());

  // The real silhouettes first, so that a missing or mis-sized mask stops the run before any work.
  std::vector<Mask> real_silhouettes;
  for (int view : renderer.held_out()) {
    const auto i = static_cast<std::size_t>(view);
    real_silhouettes.push_back(
        args.masks.empty() ? threshold_silhouette(scene.image(i), args.silhouette)
                           : dilate_mask(mask_from_image(io::read_mask_image(io::find_mask_file(args.masks, scene.views[i], i),
                                                                            scene.views[i], i)),
                                         args.silhouette.dilate));
  }

  fmt::print("{:>5}  {:<24} {:>9} {:>9} {:>11} {:>8} {:>8}\n", "view", "image", "MAE", "PSNR dB",
             "silhouette", "unseen", "seconds");
  HeldoutMetrics all;
  nlohmann::json per_view = nlohmann::json::array();
  for (std::size_t k = 0; k < renderer.held_out().size(); ++k) {
    const auto view_start = Clock::now();
    const int view = renderer.held_out()[k];
    const std::string image_name =
        fs::path(scene.views[static_cast<std::size_t>(view)].image_name).filename().string();
    const Image& photograph = scene.image(static_cast<std::size_t>(view));
    const Mask& real = real_silhouettes[k];
    const HeldoutRendering rendering = renderer.render(view);
    const HeldoutMetrics m = compare_with_photograph(rendering, photograph, real);
    const double seconds = std::chrono::duration<double>(Clock::now() - view_start).count();
    all += m;
    nlohmann::json entry = metrics_json(m);
    entry["view"] = view;
    entry["image"] = image_name;
    entry["seconds"] = seconds;
    if (!args.output.empty()) {
      const fs::path panel = fs::path(args.output) / fmt::format("heldout_{:03d}.png", view);
      io::write_png(panel, heldout_panel(photograph, rendering, real, args.error_scale));
      entry["panel"] = panel.string();
    }
    per_view.push_back(entry);
    fmt::print("{:>5}  {:<24} {:>9.5f} {:>9} {:>11.5f} {:>7.2f}% {:>8.2f}\n", view, image_name, m.mae(),
               format_psnr(m.psnr()), m.silhouette_disagreement(),
               m.union_pixels ? 100.0 * m.unseen_pixels / m.union_pixels : 0.0, seconds);
  }
  fmt::print("{:>5}  {:<24} {:>9.5f} {:>9} {:>11.5f} {:>7.2f}%\n", "all", "", all.mae(),
             format_psnr(all.psnr()), all.silhouette_disagreement(),
             all.union_pixels ? 100.0 * all.unseen_pixels / all.union_pixels : 0.0);

  if (!json_file.empty()) {
    const nlohmann::json report = {{"inputs",
                                    {{"scene", scene.folder.string()},
                                     {"mesh", args.mesh},
                                     {"scene_views", scene.size()},
                                     {"held_out_views", renderer.held_out()},
                                     {"colouring_views", renderer.colouring_views()}}},
                                   {"options", options_json(args, options)},
                                   {"views", per_view},
                                   {"all", metrics_json(all)},
                                   {"setup_seconds", setup_seconds},
                                   {"seconds", std::chrono::duration<double>(Clock::now() - start).count()}};
    io::write_atomically(json_file, false, [&](std::ostream& out) { out << report.dump(2) << '\n'; });
    log.info("wrote {}", json_file.string());
  }
  return kOk;
}

}  // namespace

void add_heldout_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<HeldoutArguments>();
  CLI::App* c = app.add_subcommand(
      "heldout",
      "Held-out-view error: colour a mesh from the other views, render it into views it never saw, "
      "compare with their photographs");
  c->add_option("scene", args->scene, "Scene folder, or a camera file inside one")->required();
  c->add_option("mesh", args->mesh,
                "Mesh to score (refined without these views: mvflow refine --exclude-views)")
      ->required();
  c->add_option("--views", args->views,
                "0-based views to score (comma-separated); none of them colours the mesh")
      ->required()
      ->delimiter(',');
  c->add_option("--json", args->json, "JSON summary (default with -o: DIR/heldout.json)");
  c->add_option("-o,--output", args->output,
                "Folder for heldout_NNN.png: photograph | rendering | error map");
  auto* threshold =
      c->add_option("--threshold", args->silhouette.threshold,
                    "Real silhouette: pixels whose largest channel exceeds this (black background)")
          ->check(CLI::Range(0.0, 0.999999))
          ->capture_default_str();
  c->add_option("--masks", args->masks,
                "Real silhouettes from mask images (non-zero = object) named as the photographs")
      ->check(CLI::ExistingDirectory)
      ->excludes(threshold);
  c->add_option("--dilate", args->silhouette.dilate,
                "Dilate the real silhouette by a disc of this radius (pixels)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  c->add_option("--background", args->background,
                "Rendered value where the mesh is missed: one grey or R,G,B on [0,1]")
      ->delimiter(',')
      ->expected(1, 3)
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  c->add_option("--supersample", args->options.supersample, "N: N×N rays per pixel")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  c->add_option("--max-view-angle", args->options.colouring.max_angle_degrees,
                "Views beyond this angle to the surface normal do not colour a point (degrees)")
      ->check(CLI::Range(1e-6, 90.0))
      ->capture_default_str();
  c->add_option("--error-scale", args->error_scale,
                "Error map: this mean absolute error shows as full yellow")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  c->add_option("--threads", args->threads,
                "Threads (0 = all cores); the result does not depend on it")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  c->callback([args, &runner] {
    if (args->background.size() == 2)
      throw CLI::ValidationError("--background", "give one grey value or R,G,B");
    runner = [args](spdlog::logger& log) {
      tbb::task_arena arena(args->threads > 0 ? args->threads : tbb::task_arena::automatic);
      return parallel::execute(arena, [&] { return run_heldout(*args, log); });
    };
  });
}

}  // namespace mvflow::cli
