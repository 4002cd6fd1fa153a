// Throughput of each stage of an iteration on a rendered scene (the bumpy sphere, a 10k-vertex
// initial mesh, 16 views of 640×480), of a whole iteration with the flow graph and the
// sequential path, of the graph alone (empty node bodies), and the read bound of the photo
// kernel (the same patch reads with nothing else to do). Items are vertices unless a label or
// counter says otherwise. Build Release; perf/README.md has the latest numbers.

#include <benchmark/benchmark.h>

#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "engine/refine/iteration.h"
#include "engine/refine/iteration_graph.h"
#include "engine/model/error.h"
#include "engine/model/mesh_stats.h"
#include "engine/model/surface_query.h"
#include "perf/bench_scene.h"
#include "perf/patch_gather.h"
#include "stages/topology/adaptive_refinement.h"
#include "stages/flow/commit.h"
#include "stages/flow/curvature.h"
#include "stages/flow/image_denoise.h"
#include "stages/flow/image_noise.h"
#include "stages/flow/normals.h"
#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_gradient.h"
#include "stages/flow/photo_kernel.h"
#include "stages/flow/regularization.h"
#include "stages/flow/smoothing.h"
#include "stages/flow/speed.h"
#include "stages/flow/surface_patch.h"
#include "stages/flow/visibility.h"

namespace mvflow {
namespace {

struct StageScene {
  perf::BenchScene bench;
  std::vector<PhotoView> views;
  double mean_edge = 0, shortest_edge = 0;
  const TriMesh& mesh() const { return bench.initial.topology; }
  IndexRange everything() const { return {0, static_cast<std::uint32_t>(bench.initial.n_vertices())}; }
  std::size_t n_vertices() const { return bench.initial.n_vertices(); }
};

const StageScene& scene() {
  static const StageScene cached = [] {
    StageScene s;
    s.bench = perf::make_bench_scene(perf::SceneSpec::parse("10k/16/640x480"));
    s.views = make_photo_views(s.bench.scene);
    const EdgeLengths edges = edge_lengths(s.mesh());
    s.mean_edge = edges.mean;
    s.shortest_edge = edges.shortest;
    return s;
  }();
  return cached;
}

// Normals, curvature and visibility of the initial mesh: the inputs of the photo stages.
const VertexFields& visible_fields() {
  static const VertexFields cached = [] {
    const StageScene& s = scene();
    VertexFields fields;
    fields.resize(s.n_vertices(), s.views.size());
    compute_normals(s.mesh(), s.everything(), fields);
    compute_mean_curvature(s.mesh(), s.everything(), fields);
    const SurfaceQuery surface(s.mesh());
    compute_visibility(s.mesh(), s.everything(), s.views, surface, s.mean_edge, {}, fields);
    return fields;
  }();
  return cached;
}

double sample_spacing() { return PhotoGradientStage().sample_spacing(scene().shortest_edge); }

// The patch reads of the gradient stage (centre + 60 axis samples, usable views only).
const std::vector<perf::PatchBlock>& gradient_blocks() {
  static const std::vector<perf::PatchBlock> cached = [] {
    const StageScene& s = scene();
    const VertexFields& fields = visible_fields();
    std::vector<Eigen::Vector3d> points(s.n_vertices());
    std::vector<std::vector<std::uint16_t>> visible(s.n_vertices());
    for (std::size_t v = 0; v < s.n_vertices(); ++v) {
      points[v] = s.bench.initial.position(v);
      const auto ids = fields.visible(v);
      visible[v].assign(ids.begin(), ids.end());
      // The stage samples the axes only where g is defined at the vertex itself.
      if (!photo_consistency(points[v], ids, s.views).defined()) visible[v].clear();
    }
    return perf::gradient_patch_blocks(points, visible, s.views, sample_spacing(), PhotoGradientStage().options().savitzky_golay.half_window());
  }();
  return cached;
}

constexpr double kPixelsPerPatch = 36;  // the 6×6-pixel bilinear support of a 5×5 patch

void BM_NormalsAndCurvature(benchmark::State& state) {
  const StageScene& s = scene();
  VertexFields fields;
  fields.resize(s.n_vertices(), 0);
  for (auto _ : state) {
    compute_normals(s.mesh(), s.everything(), fields);
    compute_mean_curvature(s.mesh(), s.everything(), fields);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
}
BENCHMARK(BM_NormalsAndCurvature)->Unit(benchmark::kMillisecond);

void BM_Visibility(benchmark::State& state) {
  const StageScene& s = scene();
  VertexFields fields;
  fields.resize(s.n_vertices(), s.views.size());
  compute_normals(s.mesh(), s.everything(), fields);
  const SurfaceQuery surface(s.mesh());
  // Occlusion rays: the vertex–view pairs that pass the cheap tests (in front, patch inside the
  // image, not grazing) and so reach Embree.
  const double cos_max = std::cos(VisibilityOptions{}.max_angle_degrees * std::numbers::pi / 180.0);
  int64_t rays = 0;
  for (std::size_t v = 0; v < s.n_vertices(); ++v) {
    if (!(fields.defined[v] & kNormalDefined)) continue;
    const Eigen::Vector3d P = s.bench.initial.position(v);
    for (const PhotoView& view : s.views) {
      const Projection p = view.project(P);
      const Eigen::Vector3d to_camera = view.camera->centre() - P;
      rays += p.depth > 0 && view.patch_inside(p.u, p.v, 2) &&
              fields.normal[v].dot(to_camera) > cos_max * to_camera.norm();
    }
  }
  for (auto _ : state)
    compute_visibility(s.mesh(), s.everything(), s.views, surface, s.mean_edge, {}, fields);
  state.SetItemsProcessed(state.iterations() * rays);
  state.SetLabel("items = occlusion rays");
}
BENCHMARK(BM_Visibility)->Unit(benchmark::kMillisecond);

void BM_PhotoConsistency(benchmark::State& state) {
  const StageScene& s = scene();
  VertexFields fields = visible_fields();
  double view_samples = 0;
  for (std::size_t v = 0; v < s.n_vertices(); ++v)
    view_samples += photo_consistency(s.bench.initial.position(v), fields.visible(v), s.views).views;
  PhotoConsistencyOptions whole_pixel;
  whole_pixel.surface_patch = SurfacePatchUse::Off;  // the image-patch kernel alone, as counted
  for (auto _ : state) compute_photo_consistency(s.mesh(), s.everything(), s.views, whole_pixel, fields);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
  state.counters["patch_pixel_reads/s"] =
      benchmark::Counter(view_samples * kPixelsPerPatch * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel("items = evaluations of g");
}
BENCHMARK(BM_PhotoConsistency)->Unit(benchmark::kMillisecond);

// The stage's options with 5×5 image patches at every vertex (--surface-patch off): the kernel
// whose reads are counted against the gather bound.
PhotoGradientOptions image_patches_only() {
  PhotoGradientOptions options;
  options.photo.surface_patch = SurfacePatchUse::Off;
  return options;
}

// The 5×5 image-patch kernel alone (--surface-patch off), whose reads are counted against the
// gather bound.
void BM_PhotoGradient(benchmark::State& state) {
  const StageScene& s = scene();
  VertexFields fields = visible_fields();
  const PhotoGradientStage stage(image_patches_only());
  const double evaluations = 3.0 * stage.options().savitzky_golay.k + 1;
  const double view_samples = static_cast<double>(gradient_blocks().size());
  const double spacing = sample_spacing();
  for (auto _ : state) stage.run(s.mesh(), s.everything(), s.views, spacing, fields);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
  const double runs = static_cast<double>(state.iterations());
  state.counters["g_evaluations/s"] =
      benchmark::Counter(evaluations * static_cast<double>(s.n_vertices()) * runs, benchmark::Counter::kIsRate);
  state.counters["patch_pixel_reads/s"] =
      benchmark::Counter(view_samples * kPixelsPerPatch * runs, benchmark::Counter::kIsRate);
  state.SetLabel("61 evaluations of g per vertex");
}
BENCHMARK(BM_PhotoGradient)->Unit(benchmark::kMillisecond);

// The stage as the flow runs it by default (SurfacePatchUse::Oblique): surface patches at the
// vertices with a view beyond 60°, image patches elsewhere; the label gives their share.
void BM_PhotoGradientDefault(benchmark::State& state) {
  const StageScene& s = scene();
  VertexFields fields = visible_fields();
  const PhotoGradientStage stage;
  std::size_t oblique = 0;
  for (std::uint32_t v = 0; v < s.n_vertices(); ++v)
    oblique += uses_surface_patch(s.bench.initial.position(v), fields.normal[v], fields.visible(v), s.views,
                                  stage.options().photo);
  const double spacing = sample_spacing();
  for (auto _ : state) stage.run(s.mesh(), s.everything(), s.views, spacing, fields);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
  state.SetLabel("61 evaluations of g per vertex, surface patches at " +
                 std::to_string(100 * oblique / std::max<std::size_t>(1, s.n_vertices())) + " % of the vertices");
}
BENCHMARK(BM_PhotoGradientDefault)->Unit(benchmark::kMillisecond);

// The same stage with surface patches (PhotoConsistencyOptions::surface_patch): every view reads
// the (2h+1)² tangent-plane points bilinearly, one 2×2-pixel support per point.
void BM_PhotoGradientSurfacePatch(benchmark::State& state) {
  const StageScene& s = scene();
  VertexFields fields = visible_fields();
  PhotoGradientOptions options;
  options.photo.surface_patch = SurfacePatchUse::On;
  const PhotoGradientStage stage(options);
  const double evaluations = 3.0 * stage.options().savitzky_golay.k + 1;
  const double spacing = sample_spacing();
  for (auto _ : state) stage.run(s.mesh(), s.everything(), s.views, spacing, fields);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
  state.counters["g_evaluations/s"] = benchmark::Counter(
      evaluations * static_cast<double>(s.n_vertices()) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel("61 evaluations of g per vertex, surface patches");
}
BENCHMARK(BM_PhotoGradientSurfacePatch)->Unit(benchmark::kMillisecond);

// What BM_PhotoGradientSurfacePatch computes (each layout and g the same bits), one
// surface_patch_consistency per sample: the plain path the samples kernel replaces
// (stages/flow/surface_patch_samples_body.inc), for the ratio in one run. Without the stage's
// prefetch of the next vertex and its Savitzky–Golay sums (a few per cent of it).
void BM_PhotoGradientSurfacePatchPerSample(benchmark::State& state) {
  const StageScene& s = scene();
  const VertexFields fields = visible_fields();
  PhotoConsistencyOptions photo;
  photo.surface_patch = SurfacePatchUse::On;
  const double spacing = sample_spacing();
  const int half = PhotoGradientOptions{}.savitzky_golay.half_window();
  SurfacePatchLayout layout;
  for (auto _ : state) {
    double total = 0;
    for (std::uint32_t v = 0; v < s.n_vertices(); ++v) {
      const Eigen::Vector3d X = to_eigen(s.mesh().point(TriMesh::VertexHandle(static_cast<int>(v))));
      layout_surface_patch(X, fields.normal[v], fields.visible(v), s.views, photo.half_patch, photo.surface_patch_spacing,
                           layout);
      PhotoValue centre;  // as the stage, no samples where g(X) is undefined
      for_each_gradient_sample(X, spacing, half, [&](std::size_t slot, const Eigen::Vector3d& point) {
        const PhotoValue value = surface_patch_consistency(point, layout, s.views);
        if (slot == 0) centre = value;
        total += value.g;
        return centre.defined();
      });
    }
    benchmark::DoNotOptimize(total);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
  state.SetLabel("BM_PhotoGradientSurfacePatch's g values, one sample at a time");
}
BENCHMARK(BM_PhotoGradientSurfacePatchPerSample)->Unit(benchmark::kMillisecond);

// The bound for BM_PhotoGradient's patch_pixel_reads/s: its reads without its arithmetic.
void BM_PatchGatherBound(benchmark::State& state) {
  const auto& blocks = gradient_blocks();
  for (auto _ : state) benchmark::DoNotOptimize(perf::gather_patch_blocks(blocks));
  state.counters["patch_pixel_reads/s"] = benchmark::Counter(
      static_cast<double>(blocks.size()) * kPixelsPerPatch * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(blocks.size()));
  state.SetLabel(std::string("items = 6x6-pixel blocks of the gradient's samples; loads of the ") +
                 detail::active_photo_kernel().name + " build");
}
BENCHMARK(BM_PatchGatherBound)->Unit(benchmark::kMillisecond);

// BM_PhotoGradient's share of BM_PatchGatherBound's read rate, the two passes alternated within
// each benchmark iteration (each timed alone, either first in turn): a machine whose speed drifts by
// tens of percent within minutes moves both passes of a pair alike, where the two benchmarks run
// seconds apart each saw their own phase. Both read the same blocks, the same count, so the share
// of a pair is bound time / kernel time; the counters give the median over the pairs (percent) and
// the pairs' kernel and bound medians (ms). The benchmark's own time is that of both passes.
void BM_PhotoGradientShareOfBound(benchmark::State& state) {
  const StageScene& s = scene();
  VertexFields fields = visible_fields();
  const PhotoGradientStage stage(image_patches_only());
  const double spacing = sample_spacing();
  const auto& blocks = gradient_blocks();
  using Clock = std::chrono::steady_clock;
  std::vector<double> kernel_ms, bound_ms, shares;
  const auto milliseconds = [](const auto& run) {
    const Clock::time_point start = Clock::now();
    run();
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  };
  const auto kernel_pass = [&] { stage.run(s.mesh(), s.everything(), s.views, spacing, fields); };
  const auto bound_pass = [&] { benchmark::DoNotOptimize(perf::gather_patch_blocks(blocks)); };
  for (auto _ : state) {
    // Either pass first in turn: each starts half the time from the other's cache contents.
    if (shares.size() % 2 == 0) {
      kernel_ms.push_back(milliseconds(kernel_pass));
      bound_ms.push_back(milliseconds(bound_pass));
    } else {
      bound_ms.push_back(milliseconds(bound_pass));
      kernel_ms.push_back(milliseconds(kernel_pass));
    }
    shares.push_back(100 * bound_ms.back() / kernel_ms.back());
  }
  state.counters["share_percent"] = median_of(shares);
  state.counters["kernel_ms"] = median_of(kernel_ms);
  state.counters["bound_ms"] = median_of(bound_ms);
  state.counters["pairs"] = static_cast<double>(shares.size());
  state.SetLabel(std::string(detail::active_photo_kernel().name) + " build; g with its gradient against the bare reads, pairs alternated");
}
BENCHMARK(BM_PhotoGradientShareOfBound)->Unit(benchmark::kMillisecond);

// What the refiner sets before an iteration runs: blocks and fields sized, the edge lengths and Δx.
void prepare(IterationData& data, const StageScene& s) {
  data.reset_topology();
  data.set_edge_lengths({.shortest = s.shortest_edge, .mean = s.mean_edge});
}

// The serial reduction node: partials, Σg in id order, the quantile and median of |F|, Δt.
void BM_CflReduction(benchmark::State& state) {
  const StageScene& s = scene();
  TriMesh mesh = s.mesh();
  const RefineOptions options;
  IterationData data(mesh, s.views, options, nullptr);
  prepare(data, s);
  data.fields = visible_fields();
  for (std::size_t b = 0; b < data.blocks.size(); ++b) data.photo_speed(b);
  for (auto _ : state) data.cfl();
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
}
BENCHMARK(BM_CflReduction)->Unit(benchmark::kMillisecond);

// Move, smoothing and regularization (each with its commit) as one iteration runs them.
void BM_MoveSmoothRegularize(benchmark::State& state) {
  const StageScene& s = scene();
  TriMesh mesh = s.mesh();
  const RefineOptions options;
  IterationData data(mesh, s.views, options, nullptr);
  prepare(data, s);
  data.fields = visible_fields();
  for (std::size_t b = 0; b < data.blocks.size(); ++b) {
    data.geometry(b);
    data.photo_speed(b);
  }
  data.cfl();
  const std::size_t n = data.blocks.size();
  for (auto _ : state) {
    state.PauseTiming();
    mesh = s.mesh();
    state.ResumeTiming();
    for (std::size_t b = 0; b < n; ++b) data.move(b);
    for (std::size_t b = 0; b < n; ++b) data.smooth(b);
    for (std::size_t b = 0; b < n; ++b) data.commit(b);
    for (std::size_t b = 0; b < n; ++b) data.regularize(b);
    for (std::size_t b = 0; b < n; ++b) data.commit(b);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
}
BENCHMARK(BM_MoveSmoothRegularize)->Unit(benchmark::kMillisecond);

void BM_Smoothing(benchmark::State& state) {
  const StageScene& s = scene();
  std::vector<Eigen::Vector3d> buffer(s.n_vertices());
  for (auto _ : state) smooth_curvature_normal(s.mesh(), s.everything(), SmoothingOptions{}, buffer);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
}
BENCHMARK(BM_Smoothing)->Unit(benchmark::kMillisecond);

void BM_Regularization(benchmark::State& state) {
  const StageScene& s = scene();
  const VertexFields& fields = visible_fields();
  std::vector<Eigen::Vector3d> buffer(s.n_vertices());
  for (auto _ : state) regularize_tangential(s.mesh(), s.everything(), fields, RegularizationOptions{}, buffer);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
}
BENCHMARK(BM_Regularization)->Unit(benchmark::kMillisecond);

// Once per run, before the flow: the photographs' noise estimate (arg 0 = 0) and, for noisy
// photographs, their blur (arg 0 = 1; σ 0.82 pixels, what a noise of 0.0058 gets), over the 16
// views with arg 1 threads; items are pixels.
void BM_NoiseEstimateAndBlur(benchmark::State& state) {
  const StageScene& s = scene();
  oneapi::tbb::task_arena arena(static_cast<int>(state.range(1)));
  const double sigma = denoise_sigma_for(0.0058, 0.002);
  for (auto _ : state)
    arena.execute([&] {
      if (state.range(0) == 0) benchmark::DoNotOptimize(estimate_views_noise(s.views));
      else benchmark::DoNotOptimize(blurred_views(s.views, sigma));
    });
  std::int64_t pixels = 0;
  for (const PhotoView& view : s.views) pixels += static_cast<std::int64_t>(view.width) * view.height;
  state.SetItemsProcessed(state.iterations() * pixels);
}
BENCHMARK(BM_NoiseEstimateAndBlur)->Args({0, 1})->Args({0, 2})->Args({1, 1})->Args({1, 2})->Unit(benchmark::kMillisecond);

// Adaptive refinement (red–green) of the initial mesh with a threshold that marks about a
// tenth of the vertices; items are input vertices.
void BM_AdaptiveRefinement(benchmark::State& state) {
  const StageScene& s = scene();
  const VertexFields& fields = visible_fields();
  std::vector<double> lengths;
  for (std::size_t v = 0; v < s.n_vertices(); ++v)
    if (fields.defined[v] & kCurvatureDefined) lengths.push_back(fields.curvature_normal_length[v]);
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() * 9 / 10, lengths.end());
  AdaptiveRefinementOptions options;
  options.min_edge_pixels = 0;
  options.min_growth = 0;  // every refinement is done: this measures its throughput
  const double reference_edge = lengths[lengths.size() * 9 / 10] / options.curvature_factor;
  std::size_t added = 0;
  for (auto _ : state) {
    state.PauseTiming();
    TriMesh mesh = s.mesh();
    state.ResumeTiming();
    added = refine_adaptively(mesh, fields, reference_edge, options).new_vertices;
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
  state.SetLabel("adds " + std::to_string(added) + " vertices");
}
BENCHMARK(BM_AdaptiveRefinement)->Unit(benchmark::kMillisecond);

// One whole iteration: arg 0 = engine (0 graph, 1 sequential), arg 1 = threads.
// Arg 2 = 1 runs the graph with every node body empty (the kernels return at once when the
// cancel flag is set): the graph's own cost over the same blocks.
void BM_Iteration(benchmark::State& state) {
  const StageScene& s = scene();
  RefineOptions options;
  options.engine = state.range(0) == 0 ? EngineKind::Graph : EngineKind::Sequential;
  const bool empty_bodies = state.range(2) == 1;
  std::atomic<bool> skip_bodies{false};
  oneapi::tbb::task_arena arena(static_cast<int>(state.range(1)));
  TriMesh mesh = s.mesh();
  arena.execute([&] {
    IterationData data(mesh, s.views, options, &skip_bodies);
    prepare(data, s);
    IterationGraph graph(data);
    skip_bodies = empty_bodies;
    for (auto _ : state) {
      if (options.engine == EngineKind::Graph)
        graph.run();
      else
        run_iteration_sequential(data);
    }
  });
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(s.n_vertices()));
  state.SetLabel(std::string(empty_bodies ? "graph, empty bodies" : state.range(0) == 0 ? "graph" : "sequential") +
                 ", " + std::to_string(state.range(1)) + " thread(s)");
}
BENCHMARK(BM_Iteration)
    ->Args({0, 1, 0})
    ->Args({0, 2, 0})
    ->Args({1, 1, 0})
    ->Args({0, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace mvflow

// BENCHMARK_MAIN with the photo kernel's build chosen first: MVFLOW_KERNEL naming a build this
// CPU cannot run (or an unknown one) is said in one line and exits 1, before the scene is rendered.
int main(int argc, char** argv) {
  try {
    (void)mvflow::detail::active_photo_kernel();
  } catch (const mvflow::Error& error) {
    std::fprintf(stderr, "mvflow_stages_benchmark: %s\n", error.what());
    return 1;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
