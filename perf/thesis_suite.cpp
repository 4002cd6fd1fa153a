#include "perf/thesis_suite.h"

#include <algorithm>
#include <iostream>
#include <optional>

#include "engine/model/error.h"
#include "engine/refine/refiner.h"
#include "perf/bench_runs.h"
#include "perf/bench_scene.h"
#include "perf/peak_memory.h"

namespace mvflow::perf {

const std::vector<ThesisModel>& thesis_models() {
  // Tables 5.1–5.4 (rows (n)/(j) and the final row) and table 5.5.
  static const std::vector<ThesisModel> models{
      {"bag", 562, 586, 22, 28, 719, 503},
      {"nefertiti", 1699, 1770, 14, 18, 1229, 758},
      {"frog", 2870, 3151, 20, 33, 6754, 3965},
      {"clown", 2087, 2415, 16, 35, 3980, 1785},
  };
  return models;
}

std::vector<Row> run_thesis_suite(const ThesisSuiteSettings& settings, bool validate) {
  std::vector<Row> rows;
  for (const ThesisModel& model : thesis_models()) {
    if (!settings.models.empty() && std::find(settings.models.begin(), settings.models.end(), model.name) ==
                                        settings.models.end())
      continue;
    SceneSpec spec;
    spec.vertices = model.initial_vertices;
    spec.views = model.views;
    spec.width = settings.width;
    spec.height = settings.height;
    std::cerr << "thesis " << model.name << ": rendering " << spec.label() << " ...\n";
    const BenchScene scene = make_bench_scene(spec);
    std::optional<std::uint64_t> first_hash;
    for (const int threads : settings.threads) {
      RefineOptions options = thesis_preset();
      options.stopping.min_iterations = model.steps;
      options.stopping.max_iterations = model.steps;
      RefineControl control;
      control.threads = threads;
      release_free_memory();
      const bool reset = reset_peak_memory();
      const RefineResult result = refine_mesh(scene.scene, scene.initial, options, control);
      const RefineSummary& s = result.summary;
      if (s.status == RefineStatus::Failed) throw Error("thesis " + model.name + ": " + s.message);
      double gradient = 0;
      for (const IterationReport& r : s.iterations) gradient += r.stage_seconds[static_cast<int>(Stage::PhotoGradient)];
      const std::uint64_t hash = mesh_hash(result.mesh.topology);
      if (validate) {
        if (!(s.final_sum_g_per_vertex < s.initial_sum_g_per_vertex))
          throw Error("thesis " + model.name + ": Σg per vertex did not fall");
        if (!first_hash) first_hash = hash;
        if (hash != *first_hash) throw Error("thesis " + model.name + ": thread counts gave different meshes");
      }
      Row row;
      row["model"] = model.name;
      row["views"] = model.views;
      row["image"] = std::to_string(spec.width) + "x" + std::to_string(spec.height);
      row["steps"] = model.steps;
      row["thesis_vertices"] = model.final_vertices;
      row["vertices"] = std::to_string(s.initial_vertices) + "->" + std::to_string(s.final_vertices);
      row["threads"] = threads;
      row["seconds"] = s.seconds;
      row["thesis_seconds"] = model.seconds;
      row["speedup"] = model.seconds / s.seconds;
      row["gradient_seconds"] = gradient;
      row["thesis_gradient_seconds"] = model.gradient_seconds;
      row["peak_MB"] = static_cast<double>(peak_memory_bytes()) / (1 << 20);
      row["peak_reset"] = reset;
      std::cerr << "  " << threads << " thread(s): " << s.seconds << " s\n";
      rows.push_back(row);
    }
  }
  return rows;
}

}  // namespace mvflow::perf
