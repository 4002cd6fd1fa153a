#include "perf/bench_runs.h"

#include <algorithm>
#include <cstring>
#include <numeric>

#include "engine/model/error.h"
#include "engine/refine/refiner.h"
#include "perf/peak_memory.h"

namespace mvflow::perf {

std::string RunConfig::name() const {
  return std::string(engine == EngineKind::Graph ? "graph" : "sequential") + "/" + std::to_string(threads);
}

RefineOptions fixed_topology_options(int iterations) {
  RefineOptions options;
  options.global_remeshing = false;
  options.adaptive_refinement = false;
  options.stopping.min_iterations = iterations;
  options.stopping.max_iterations = iterations;
  return options;
}

std::uint64_t mesh_hash(const TriMesh& mesh) {
  std::uint64_t hash = 1469598103934665603ull;
  const auto add = [&](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) hash = (hash ^ p[i]) * 1099511628211ull;
  };
  for (const auto& p : positions_of(mesh)) add(p.data(), sizeof(double) * 3);
  for (const auto& t : triangles_of(mesh)) add(t.data(), sizeof(std::uint32_t) * 3);
  return hash;
}

namespace {

RefineResult refine_or_throw(const BenchScene& scene, const RefineOptions& options, const RunConfig& config) {
  RefineOptions run = options;
  run.engine = config.engine;
  RefineControl control;
  control.threads = config.threads;
  RefineResult result = refine_mesh(scene.scene, scene.initial, run, control);
  if (result.summary.status == RefineStatus::Failed)
    throw Error(scene.spec.label() + " " + config.name() + ": refinement failed: " + result.summary.message);
  for (const auto& p : positions_of(result.mesh.topology))
    if (!p.allFinite()) throw Error(scene.spec.label() + " " + config.name() + ": a vertex is not finite");
  return result;
}

}  // namespace

Measurement measure(const BenchScene& scene, const RunConfig& config, const RunSettings& settings) {
  MVFLOW_CHECK(settings.timed_iterations >= 6 && settings.refine_iterations >= 6, "at least 6 iterations");
  Measurement m;
  m.scene = scene.spec.label();
  m.config = config;
  release_free_memory();
  m.peak_reset = reset_peak_memory();

  RefineOptions fixed_options = fixed_topology_options(settings.timed_iterations);
  fixed_options.photo.photo.surface_patch = settings.surface_patch;
  const RefineResult fixed = refine_or_throw(scene, fixed_options, config);
  const auto& iterations = fixed.summary.iterations;
  const double timed = static_cast<double>(iterations.size() - 1);
  for (std::size_t i = 1; i < iterations.size(); ++i) {
    m.iteration_seconds += iterations[i].seconds / timed;
    for (std::size_t s = 0; s < kStageCount; ++s) m.stage_seconds[s] += iterations[i].stage_seconds[s] / timed;
  }
  const double all_stages = std::accumulate(m.stage_seconds.begin(), m.stage_seconds.end(), 0.0);
  m.photo_share = all_stages > 0 ? m.stage_seconds[static_cast<int>(Stage::PhotoGradient)] / all_stages : 0.0;
  m.fixed_hash = mesh_hash(fixed.mesh.topology);

  if (settings.whole_refinement) {
    RefineOptions options;
    options.stopping.max_iterations = settings.refine_iterations;
    options.stopping.min_iterations = std::min(options.stopping.min_iterations, settings.refine_iterations);
    options.photo.photo.surface_patch = settings.surface_patch;
    const RefineResult whole = refine_or_throw(scene, options, config);
    m.refine_seconds = whole.summary.seconds;
    m.refine_iterations = static_cast<int>(whole.summary.iterations.size());
    m.refine_vertices = whole.summary.final_vertices;
    m.initial_g_per_vertex = whole.summary.initial_sum_g_per_vertex;
    m.final_g_per_vertex = whole.summary.final_sum_g_per_vertex;
    m.refine_status = to_string(whole.summary.status);
    m.refine_hash = mesh_hash(whole.mesh.topology);
  }
  m.peak_bytes = peak_memory_bytes();
  return m;
}

}  // namespace mvflow::perf
