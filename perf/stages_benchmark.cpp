// Throughput of each stage on a rendered scene (the default synth scene's bumpy sphere, 16
// views of 640×480), and of a whole iteration with the flow graph and the sequential path.
// Items are vertices unless a label says otherwise.

#include <benchmark/benchmark.h>

#include <oneapi/tbb/task_arena.h>

#include <random>

#include "engine/iteration.h"
#include "engine/iteration_graph.h"
#include "engine/surface_query.h"
#include "stages/curvature.h"
#include "stages/normals.h"
#include "stages/photo_consistency.h"
#include "stages/photo_gradient.h"
#include "stages/smoothing.h"
#include "stages/synth_scene.h"
#include "stages/visibility.h"

namespace mvflow {
namespace {

struct BenchScene {
  SynthScene synth;
  std::vector<Camera> cameras;
  std::vector<PhotoView> views;
  Mesh mesh;  // the initial mesh
  double mean_edge = 0, shortest_edge = 0;
};

const BenchScene& scene() {
  static const BenchScene cached = [] {
    BenchScene s;
    SynthOptions options;
    options.init.vertices = 10000;
    BuiltinShapeOptions shape;
    shape.level = 6;
    s.synth = make_synth_scene(make_builtin_object("bumpy-sphere", shape), nullptr, options);
    for (const auto& v : s.synth.views) s.cameras.push_back(v.camera);
    std::vector<const Image*> images;
    for (const auto& image : s.synth.images) images.push_back(&image);
    s.views = make_photo_views(s.cameras, images);
    s.mesh = build_mesh(s.synth.initial, "initial");
    s.shortest_edge = 1e300;
    for (auto e : s.mesh.topology.edges()) {
      s.mean_edge += s.mesh.topology.calc_edge_length(e);
      s.shortest_edge = std::min(s.shortest_edge, s.mesh.topology.calc_edge_length(e));
    }
    s.mean_edge /= static_cast<double>(s.mesh.topology.n_edges());
    return s;
  }();
  return cached;
}

IndexRange everything(const Mesh& mesh) { return {0, static_cast<std::uint32_t>(mesh.n_vertices())}; }

VertexFields visible_fields() {
  const BenchScene& s = scene();
  VertexFields fields;
  fields.resize(s.mesh.n_vertices(), s.views.size());
  compute_normals(s.mesh.topology, everything(s.mesh), fields);
  const SurfaceQuery surface(s.mesh.topology);
  compute_visibility(s.mesh.topology, everything(s.mesh), s.views, surface, s.mean_edge, {}, fields);
  return fields;
}

void BM_NormalsAndCurvature(benchmark::State& state) {
  const BenchScene& s = scene();
  VertexFields fields;
  fields.resize(s.mesh.n_vertices(), 0);
  for (auto _ : state) {
    compute_normals(s.mesh.topology, everything(s.mesh), fields);
    compute_mean_curvature(s.mesh.topology, everything(s.mesh), fields);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.mesh.n_vertices()));
}
BENCHMARK(BM_NormalsAndCurvature)->Unit(benchmark::kMillisecond);

void BM_Visibility(benchmark::State& state) {
  const BenchScene& s = scene();
  VertexFields fields;
  fields.resize(s.mesh.n_vertices(), s.views.size());
  compute_normals(s.mesh.topology, everything(s.mesh), fields);
  const SurfaceQuery surface(s.mesh.topology);
  for (auto _ : state)
    compute_visibility(s.mesh.topology, everything(s.mesh), s.views, surface, s.mean_edge, {}, fields);
  // Items: candidate vertex–view pairs (at most one occlusion ray each).
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.mesh.n_vertices() * s.views.size()));
  state.SetLabel("items = vertex-view pairs");
}
BENCHMARK(BM_Visibility)->Unit(benchmark::kMillisecond);

void BM_PhotoConsistency(benchmark::State& state) {
  const BenchScene& s = scene();
  VertexFields fields = visible_fields();
  std::size_t view_samples = 0;
  for (auto count : fields.visible_count) view_samples += count;
  for (auto _ : state) compute_photo_consistency(s.mesh.topology, everything(s.mesh), s.views, {}, fields);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.mesh.n_vertices()));
  // Patch-pixel reads: 36 pixels (6×6 bilinear support) × 3 channels per view sample.
  state.counters["patch_pixel_reads/s"] =
      benchmark::Counter(static_cast<double>(view_samples) * 36 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PhotoConsistency)->Unit(benchmark::kMillisecond);

void BM_PhotoGradient(benchmark::State& state) {
  const BenchScene& s = scene();
  VertexFields fields = visible_fields();
  const PhotoGradientStage stage;
  for (auto _ : state) stage.run(s.mesh.topology, everything(s.mesh), s.views, stage.sample_spacing(s.shortest_edge), fields);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.mesh.n_vertices()));
  state.SetLabel("61 evaluations of g per vertex");
}
BENCHMARK(BM_PhotoGradient)->Unit(benchmark::kMillisecond);

void BM_Smoothing(benchmark::State& state) {
  const BenchScene& s = scene();
  std::vector<Eigen::Vector3d> buffer(s.mesh.n_vertices());
  for (auto _ : state) smooth_curvature_normal(s.mesh.topology, everything(s.mesh), SmoothingOptions{}, buffer);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.mesh.n_vertices()));
}
BENCHMARK(BM_Smoothing)->Unit(benchmark::kMillisecond);

// One whole iteration: arg 0 = engine (0 graph, 1 sequential), arg 1 = threads.
void BM_Iteration(benchmark::State& state) {
  const BenchScene& s = scene();
  RefineOptions options;
  options.engine = state.range(0) == 0 ? EngineKind::Graph : EngineKind::Sequential;
  oneapi::tbb::task_arena arena(static_cast<int>(state.range(1)));
  TriMesh mesh = s.mesh.topology;
  arena.execute([&] {
    IterationData data(mesh, s.views, options, nullptr);
    data.reset_topology();
    data.shortest_edge = s.shortest_edge;
    data.mean_edge = s.mean_edge;
    data.sample_spacing = data.photo.sample_spacing(s.shortest_edge);
    IterationGraph graph(data);
    for (auto _ : state) {
      if (options.engine == EngineKind::Graph)
        graph.run();
      else
        run_iteration_sequential(data);
    }
  });
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.mesh.n_vertices()));
  state.SetLabel(std::string(state.range(0) == 0 ? "graph" : "sequential") + ", " + std::to_string(state.range(1)) +
                 " thread(s)");
}
BENCHMARK(BM_Iteration)->Args({0, 1})->Args({0, 2})->Args({1, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace mvflow

BENCHMARK_MAIN();
