// mvflow_bench: the end-to-end performance table. Renders synthetic scenes of growing size in
// memory (never timed), refines each with 1 and 2 threads and with the flow graph and the
// sequential path, and writes per-stage seconds per iteration, iteration seconds, whole-
// refinement seconds and peak memory as a text table, CSV and JSON. Also the thesis-sized suite
// and the OpenMVS-sized case (--suite). Validates what it measures unless --no-validate: every
// configuration of a scene must give the same mesh bit for bit (and the complete refinements of
// the suites must lower Σg per vertex, or the radial error).
// perf/README.md has the latest table and the command that made it.

#include <CLI/CLI.hpp>

#include <iostream>
#include <map>
#include <optional>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "perf/bench_runs.h"
#include "perf/bench_scene.h"
#include "perf/bench_table.h"
#include "perf/openmvs_case.h"
#include "perf/peak_memory.h"
#include "perf/thesis_suite.h"
#include "stages/flow/photo_kernel.h"

namespace mvflow::perf {
namespace {

// {1k, 10k, 100k} vertices × {8, 16, 32} views × {640×480, 1920×1080}.
std::vector<std::string> full_grid() {
  std::vector<std::string> sizes;
  for (const char* vertices : {"1k", "10k", "100k"})
    for (const char* views : {"8", "16", "32"})
      for (const char* image : {"640x480", "1920x1080"})
        sizes.push_back(std::string(vertices) + "/" + views + "/" + image);
  return sizes;
}

Row row_of(const Measurement& m) {
  Row row;
  row["scene"] = m.scene;
  row["engine"] = m.config.engine == EngineKind::Graph ? "graph" : "sequential";
  row["threads"] = m.config.threads;
  row["iteration_s"] = m.iteration_seconds;
  for (std::size_t s = 0; s < kStageCount; ++s)
    if (s != static_cast<std::size_t>(Stage::Refinement)) row[std::string(kStageNames[s]) + "_s"] = m.stage_seconds[s];
  row["photo_share"] = m.photo_share;
  row["refine_s"] = m.refine_seconds;
  row["refine_iterations"] = m.refine_iterations;
  row["refine_vertices"] = m.refine_vertices;
  row["refine_status"] = m.refine_status;
  row["g_start"] = m.initial_g_per_vertex;
  row["g_end"] = m.final_g_per_vertex;
  row["peak_MB"] = static_cast<double>(m.peak_bytes) / (1 << 20);
  row["peak_reset"] = m.peak_reset;
  row["load"] = load_average();
  return row;
}

// Same scene, other configuration: the meshes must be identical (SPEC §6).
void validate(const Measurement& m, const Measurement& first) {
  if (m.fixed_hash != first.fixed_hash)
    throw Error(m.scene + ": " + m.config.name() + " and " + first.config.name() +
                " gave different meshes after the fixed iterations");
  if (m.refine_hash != first.refine_hash)
    throw Error(m.scene + ": " + m.config.name() + " and " + first.config.name() +
                " gave different meshes after the whole refinement");
}

std::vector<Row> run_grid(const std::vector<std::string>& sizes, const std::vector<RunConfig>& configs,
                          const RunSettings& settings, int supersample, bool check) {
  std::vector<Row> rows;
  for (const std::string& size : sizes) {
    SceneSpec spec = SceneSpec::parse(size);
    spec.supersample = supersample;
    std::cerr << "scene " << spec.label() << ": rendering ..." << std::flush;
    const BenchScene scene = make_bench_scene(spec);
    std::cerr << " " << scene.seconds << " s\n";
    std::optional<Measurement> first;
    for (const RunConfig& config : configs) {
      const Measurement m = measure(scene, config, settings);
      if (check && first) validate(m, *first);
      if (!first) first = m;
      std::cerr << "  " << config.name() << ": iteration " << m.iteration_seconds << " s, whole refinement "
                << m.refine_seconds << " s, peak " << m.peak_bytes / (1 << 20) << " MB\n";
      rows.push_back(row_of(m));
    }
  }
  return rows;
}

std::vector<RunConfig> configurations(const std::vector<int>& threads, const std::vector<std::string>& engines) {
  std::vector<RunConfig> configs;
  for (const std::string& engine : engines)
    for (const int t : threads) {
      if (engine != "graph" && engine != "sequential") throw InputError("engine must be graph or sequential");
      configs.push_back({t, engine == "graph" ? EngineKind::Graph : EngineKind::Sequential});
    }
  return configs;
}

int run(int argc, char** argv) {
  CLI::App app{"mvflow_bench: end-to-end timing and peak memory of mvflow on synthetic scenes"};
  std::vector<std::string> suites{"grid"};
  std::vector<std::string> sizes;
  bool quick = false;
  std::vector<int> threads{1, 2};
  std::vector<std::string> engines{"graph", "sequential"};
  RunSettings settings;
  int supersample = 1;
  std::string csv_prefix, json_path;
  bool no_validate = false;
  std::vector<std::string> models;
  app.add_option("--suite", suites, "grid (scenes of growing size), thesis (the thesis's four models), openmvs "
                                    "(the peer's sphere); several allowed")
      ->delimiter(',')
      ->check(CLI::IsMember({"grid", "thesis", "openmvs"}))
      ->capture_default_str();
  app.add_option("--sizes", sizes, "Grid scenes VERTICES/VIEWS/WIDTHxHEIGHT, comma separated (default: 1k, 10k, "
                                   "100k × 8, 16, 32 views × 640x480, 1920x1080)")
      ->delimiter(',');
  app.add_flag("--quick", quick, "A small grid: 1k/8/640x480 and 10k/16/640x480");
  app.add_option("--threads", threads, "Thread counts")->delimiter(',')->capture_default_str();
  app.add_option("--engines", engines, "graph, sequential")->delimiter(',')->capture_default_str();
  app.add_option("--iterations", settings.timed_iterations, "Fixed-topology iterations per configuration (>= 6; the "
                                                            "first is not averaged)")
      ->check(CLI::Range(6, 1000))
      ->capture_default_str();
  app.add_option("--refine-iterations", settings.refine_iterations, "Cap on the whole refinement's iterations (>= 6)")
      ->check(CLI::Range(6, 1000))
      ->capture_default_str();
  app.add_flag("--no-refine", [&](std::int64_t) { settings.whole_refinement = false; },
               "Skip the whole refinement (fixed-topology iterations only)");
  std::string surface_patch = to_string(settings.surface_patch);
  app.add_option("--surface-patch", surface_patch,
                 "Grid suite: patches on the surface at oblique vertices (the default), everywhere (on) or nowhere "
                 "(off), as refine --surface-patch")
      ->check(CLI::IsMember({"off", "oblique", "on"}))
      ->capture_default_str();
  app.add_option("--supersample", supersample, "Rays per pixel N×N when rendering the grid scenes")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  app.add_option("--models", models, "Thesis suite: bag, nefertiti, frog, clown (default all)")->delimiter(',');
  app.add_option("--csv", csv_prefix, "Write PREFIX_SUITE.csv per suite");
  app.add_option("--json", json_path, "Write every table and the machine as JSON");
  app.add_flag("--no-validate", no_validate, "Do not check that every configuration gives the same mesh (nor that "
                                             "the suites' refinements lower Σg or the error)");
  CLI11_PARSE(app, argc, argv);
  settings.surface_patch = surface_patch_use_from_string(surface_patch);
  if (quick && sizes.empty()) sizes = {"1k/8/640x480", "10k/16/640x480"};
  if (sizes.empty()) sizes = full_grid();
  // Before the runs, which take minutes to hours: an unwritable output is known at once.
  if (!json_path.empty()) io::check_writable(json_path);
  if (!csv_prefix.empty())
    for (const std::string& suite : suites) io::check_writable(csv_prefix + "_" + suite + ".csv");

  nlohmann::ordered_json document;
  document["command"] = [&] {
    std::string line;
    for (int i = 0; i < argc; ++i) line += (i ? " " : "") + std::string(argv[i]);
    return line;
  }();
  document["machine"] = machine_description();
  document["photo_kernel"] = photo_kernel_summary();  // MVFLOW_KERNEL=baseline|avx2|avx512 forces one
  document["surface_patch"] = surface_patch;
  document["peak_memory_reset"] = reset_peak_memory();
  std::map<std::string, std::vector<Row>> tables;
  for (const std::string& suite : suites) {
    if (suite == "grid")
      tables[suite] = run_grid(sizes, configurations(threads, engines), settings, supersample, !no_validate);
    else if (suite == "thesis")
      tables[suite] = run_thesis_suite({.threads = threads, .models = models}, !no_validate);
    else
      tables[suite] = run_openmvs_case({}, !no_validate);
  }
  document["load_average_1min_after"] = load_average();
  std::cout << "machine: " << document["machine"].dump() << "\n";
  for (const auto& [suite, rows] : tables) {
    std::cout << "\n" << suite << "\n";
    print_table(std::cout, rows);
    document["suites"][suite] = rows;
    if (!csv_prefix.empty()) write_csv(csv_prefix + "_" + suite + ".csv", rows);
  }
  // Through a temporary file renamed into place, as every mvflow output: an interrupted or failed
  // write leaves the previous JSON whole.
  if (!json_path.empty())
    io::write_atomically(json_path, false, [&](std::ostream& out) { out << document.dump(2) << "\n"; });
  return 0;
}

}  // namespace
}  // namespace mvflow::perf

int main(int argc, char** argv) {
  try {
    return mvflow::perf::run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "mvflow_bench: " << e.what() << "\n";
    return 1;
  }
}
