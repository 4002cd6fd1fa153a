// `mvflow refine SCENE --mesh INIT -o OUT`: the main job.

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "engine/model/error.h"
#include "engine/refine/refiner.h"
#include "io/atomic_write.h"
#include "io/mesh_io.h"
#include "io/report_io.h"
#include "io/scene_io.h"
#include "io/vertex_fields_io.h"
#include "stages/flow/photo_kernel.h"
#include "tools/commands.h"
#include "tools/interrupt.h"
#include "tools/refine_option_table.h"

namespace mvflow::cli {

namespace {

struct RefineArguments {
  std::string scene;
  std::string mesh;
  std::string output;
  std::string report;
  std::string masks;
  std::string dump_fields;
  std::string preset = "default";
  bool ascii = false;
  int threads = 0;
};

// A folder for --dump-fields: created if missing, and refused if it holds another run's dumps,
// whose later iterations would otherwise sit beside this run's as if they were its own.
void prepare_dump_folder(const std::filesystem::path& folder) {
  io::prepare_output_folder(folder);
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    if (entry.path().filename().string().starts_with("iteration_") && entry.path().extension() == ".ply")
      throw IoError(folder, "holds per-vertex dumps of another run (" + entry.path().filename().string() +
                                "): give an empty or new folder to --dump-fields");
}

// Writes each iteration's dump; a failure (a full disk) ends the dumps with a warning, not the run:
// they are a diagnostic, the refined mesh is the result.
std::function<void(const IterationVertexFields&)> dump_writer(const std::filesystem::path& folder,
                                                               spdlog::logger& log) {
  return [folder, &log, failed = false](const IterationVertexFields& state) mutable {
    if (failed) return;
    try {
      io::write_vertex_fields(folder / io::vertex_fields_file_name(state.iteration), state);
    } catch (const IoError& error) {
      failed = true;
      log.warn("{}: no more per-vertex dumps after iteration {}; the refinement goes on", error.what(),
               state.iteration - 1);
    }
  };
}

int run_refine(const RefineArguments& args, const RefineOptions& options, spdlog::logger& log) {
  install_interrupt_handlers();
  // Before the scene is read: a refinement that cannot write its result is not started.
  io::check_writable(args.output);
  if (!args.report.empty()) io::check_writable(args.report);
  if (!args.dump_fields.empty()) prepare_dump_folder(args.dump_fields);
  const Scene scene = io::load_scene(args.scene, {.mask_folder = args.masks});
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
      std::fprintf(stderr, "\r\033[K%s: iteration %d/%d, %zu vertices, Σg/vertex %.5g", to_string(p.stage), p.iteration,
                   p.max_iterations, p.vertices, p.sum_g_per_vertex);
  };
  if (!args.dump_fields.empty()) control.on_vertex_fields = dump_writer(args.dump_fields, log);
  log.info("refining {} ({} vertices) with {} views of {}", mesh_file, initial.n_vertices(), scene.size(),
           scene.folder.string());
  const RefineResult result = refine_mesh(scene, initial, options, control);
  if (live) std::fprintf(stderr, "\r\033[K");
  const RefineSummary& s = result.summary;
  if (s.status == RefineStatus::Cancelled) {
    log.warn("interrupted after {} iterations: nothing written{}", s.iterations.size(),
             args.dump_fields.empty() ? "" : " but the per-vertex dumps in " + args.dump_fields);
    return kInterrupted;
  }
  if (!args.report.empty()) {
    const nlohmann::json inputs = {{"scene", scene.folder.string()}, {"mesh", mesh_file}, {"views", scene.size()},
                                   {"masks", args.masks.empty() ? nlohmann::json() : nlohmann::json(args.masks)},
                                   {"photo_kernel", detail::active_photo_kernel().name},
                                   {"threads", args.threads}};
    io::write_report(args.report, s, inputs, refine_options_json(options, args.preset));
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
  c->add_option("scene", args->scene, "Scene folder, or a camera file inside one")->required();
  c->add_option("--mesh", args->mesh, "Initial mesh (default: the scene's init.*)");
  c->add_option("-o,--output", args->output, "Refined mesh (PLY with colour and quality = g; format by extension)")
      ->required();
  c->add_option("--report", args->report, "JSON report (per iteration and per stage)");
  c->add_option("--dump-fields", args->dump_fields,
                "Folder (created if missing) for one PLY per iteration, iteration_NNNN.ply: the surface after the "
                "iteration with each vertex's normal, g, H, grad g along N, speed along N, damping scale, move, "
                "defined bits, views and patch kind (README \"Formats\"); about 125 bytes per vertex and iteration; "
                "refused if it holds another run's dumps");
  c->add_option("--masks", args->masks,
                "Folder of silhouette masks, one per view named after its photograph (object: any channel > 0): the "
                "rims are fitted to them (with --fit-silhouettes auto or on) and anchor the unobserved spread, and "
                "--keep-inside-silhouettes uses them, instead of thresholded photographs");
  c->add_option("--preset", args->preset,
                "Parameter set: default, accurate (surface patches, --settle-tolerance 0.001: lower error, "
                "1.2-1.8x the time with AVX-512, 1.8-2.5x with AVX2) or thesis (exactly the thesis's B.7 values)")
      ->check(CLI::IsMember(preset_names()))
      ->capture_default_str();
  c->add_option("--threads", args->threads, "Worker threads (0 = all cores)")->check(CLI::NonNegativeNumber)->capture_default_str();
  add_refine_options(*c);  // every RefineOptions field, from tools/refine_option_table
  c->add_flag("--ascii", args->ascii, "Write PLY as ASCII");
  c->callback([args, c, &runner] {
    const RefineOptions options = resolve_refine_options(args->preset, *c);
    runner = [args, options](spdlog::logger& log) { return run_refine(*args, options, log); };
  });
}

}  // namespace mvflow::cli
