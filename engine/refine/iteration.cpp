#include "engine/refine/iteration.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <limits>

#include "engine/model/error.h"
#include "engine/model/parallel.h"
#include "stages/flow/commit.h"
#include "stages/flow/curvature.h"
#include "stages/flow/far_vertices.h"
#include "stages/flow/implausible_speed.h"
#include "stages/flow/normals.h"
#include "stages/flow/photo_robust.h"
#include "stages/flow/regularization.h"
#include "stages/flow/silhouette_rims.h"
#include "stages/flow/smoothing.h"
#include "stages/flow/unobserved_displacement.h"
#include "stages/flow/unobserved_speed.h"
#include "stages/flow/visibility.h"

namespace mvflow {

namespace {

// Vertices per nested task of a photo node (each vertex costs 61 evaluations of g).
constexpr std::uint32_t kPhotoGrain = 16;

// Adds the wall time of its scope to one stage's slot.
class StageTimer {
 public:
  explicit StageTimer(double& slot) : slot_(slot), start_(std::chrono::steady_clock::now()) {}
  ~StageTimer() { slot_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  double& slot_;
  std::chrono::steady_clock::time_point start_;
};

double largest_speed(const VertexFields& fields) {
  double largest = 0.0;
  for (std::size_t v = 0; v < fields.size(); ++v)
    if (fields.defined[v] & kSpeedDefined) largest = std::max(largest, fields.speed[v].norm());
  return largest;
}

// Every per-block kernel: nothing once the run is cancelled (the rest of a cancelled graph
// drains at once), \p body timed into \p seconds (null: untimed), then on_block.
template <class Body>
void run_block(IterationData& data, std::size_t block, double* seconds, Body&& body) {
  if (data.cancelled()) return;
  if (seconds) {
    StageTimer timer(*seconds);
    body();
  } else {
    body();
  }
  if (data.on_block) data.on_block(block);
}

}  // namespace

IterationData::IterationData(TriMesh& mesh_, const std::vector<PhotoView>& views_, const RefineOptions& options_,
                             const std::atomic<bool>* cancel_)
    : mesh(mesh_),
      views(views_),
      options(options_),
      cancel(cancel_),
      photo(options_.photo),
      net_move(options_.stopping.lookback) {}

void IterationData::reset_topology() {
  surface = std::make_unique<SurfaceQuery>(mesh);
  fields.resize(mesh.n_vertices(), views.size());
  blocks = split_into_blocks(mesh.n_vertices(), options.block_size);
  partials.assign(blocks.size(), BlockPartial{});
  new_positions.assign(mesh.n_vertices(), Eigen::Vector3d::Zero());
  moved.assign(mesh.n_vertices(), 0.0);
  moving_speed.assign(record_moving_speed ? mesh.n_vertices() : 0, 0.0);
  far.assign(mesh.n_vertices(), 0);
  far_count = 0;
  block_seconds.assign(blocks.size(), {});
  refit_needed = false;
  iteration_start.clear();
  last_step.clear();
  last_time_step = 0.0;
  step_scale = 1.0;  // Σg/vertex of another mesh says nothing about the steps on this one
  previous_g_per_vertex = 0.0;
  damping.reset(mesh.n_vertices());
  on_rim.assign(mesh.n_vertices(), 0);
  net_move.reset();
  net_move_over_edge = std::numeric_limits<double>::quiet_NaN();
}

void IterationData::set_edge_lengths(const EdgeLengths& edges) {
  shortest_edge = edges.shortest;
  mean_edge = edges.mean;
  sample_spacing = photo.sample_spacing(edges.shortest);
}

void IterationData::refit() {
  if (cancelled()) return;
  StageTimer timer(serial_seconds[static_cast<int>(Stage::Refit)]);
  if (refit_needed) surface->update_positions(mesh);
  refit_needed = true;  // every later iteration moves the vertices first
  if (options.unobserved.fill || options.momentum.carry > 0.0) {
    const std::size_t n = mesh.n_vertices();
    if (iteration_start.size() == n) {
      last_step.resize(n);
      for (std::size_t v = 0; v < n; ++v)
        last_step[v] = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v)))) - iteration_start[v];
    }
    iteration_start.resize(n);
    for (std::size_t v = 0; v < n; ++v) iteration_start[v] = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
  }
}

void IterationData::geometry(std::size_t block) {
  run_block(*this, block, &block_seconds[block][static_cast<int>(Stage::Geometry)], [&] {
    compute_normals(mesh, blocks[block], fields);
    compute_mean_curvature(mesh, blocks[block], fields, options.curvature);
    compute_local_edges(mesh, blocks[block], fields);
  });
}

void IterationData::visibility(std::size_t block) {
  run_block(*this, block, &block_seconds[block][static_cast<int>(Stage::Visibility)], [&] {
    compute_visibility(mesh, blocks[block], views, *surface, mean_edge, options.visibility, fields);
    drop_outlier_views(mesh, blocks[block], views, options.photo.photo, fields);
  });
}

void IterationData::photo_speed(std::size_t block) {
  // Each run of consecutive vertices that are all far or all near, on its own photographs.
  const auto photo_of = [&](std::uint32_t begin, std::uint32_t end) {
    if (far_views == nullptr || far_count == 0) {
      photo.run(mesh, {begin, end}, views, sample_spacing, fields, surface_views);
      return;
    }
    for (std::uint32_t first = begin; first < end;) {
      std::uint32_t last = first + 1;
      while (last < end && far[last] == far[first]) ++last;
      if (far[first])
        photo.run(mesh, {first, last}, *far_views, sample_spacing, fields);  // surface patches on them too
      else
        photo.run(mesh, {first, last}, views, sample_spacing, fields, surface_views);
      first = last;
    }
  };
  run_block(*this, block, &block_seconds[block][static_cast<int>(Stage::PhotoGradient)], [&] {
    if (options.engine == EngineKind::Graph) {
      // Idle threads take parts of a long photo node (nested parallelism: the graph is the coarse
      // level). Every vertex is independent, so the parts do not change any result.
      const IndexRange range = blocks[block];
      parallel::parallel_for(oneapi::tbb::blocked_range<std::uint32_t>(range.begin, range.end, kPhotoGrain),
                             [&](const oneapi::tbb::blocked_range<std::uint32_t>& part) {
                               photo_of(part.begin(), part.end());
                             });
    } else {
      photo_of(blocks[block].begin, blocks[block].end);
    }
    compute_speed(blocks[block], options.speed, fields);
    partials[block] = reduce_block(blocks[block], fields);
  });
}

void IterationData::cfl() {
  if (cancelled()) return;
  StageTimer timer(serial_seconds[static_cast<int>(Stage::Cfl)]);
  total = combine(partials);
  // Σg again over all vertices in id order: the per-block partial sums would associate the
  // additions differently for another block size, and Σg steers the stopping rule, so it must
  // not depend on the blocking (a max and a count do not).
  double sum_g = 0.0;
  surface_patch_g = patch_switches = 0;
  for (std::size_t v = 0; v < fields.size(); ++v) {
    patch_switches += (fields.defined[v] & kPatchSwitched) != 0;
    if (fields.defined[v] & kPhotoDefined) {
      sum_g += fields.photo_consistency[v];
      surface_patch_g += fields.patch_kind[v] == PatchKind::Surface;
    }
  }
  total.sum_g = sum_g;
  far_count = far_views != nullptr ? update_far_vertices(mesh, views, fields, options.far, far) : 0;
  // Before the step: weakly seen vertices only follow it, so they leave the maximum too; then the
  // speeds of implausibly high g are averaged among the vertices that keep a speed.
  const bool demoted = demote_weakly_seen(mesh, views, options.unobserved, fields) > 0;
  const bool averaged = average_implausible() > 0;
  if (demoted || averaged) total.max_speed = largest_speed(fields);
  const double reference_speed =
      options.speed_quantile < 1.0 ? speed_quantile(mesh, fields, options.speed_quantile) : total.max_speed;
  const double step_edge = options.local_step ? mean_edge : shortest_edge;
  adapt_step_scale();
  time_step = step_scale * cfl_time_step(step_edge, reference_speed, options.cfl);
  const double cfl_fraction = step_scale * cfl_time_step(1.0, 1.0, options.cfl);  // Δt·|F| / edge at the bound
  move_limit = options.local_step ? MoveLimit{.local_edge_fraction = cfl_fraction}
                                  : MoveLimit{.distance = cfl_fraction * shortest_edge};
  moving = 0;
  for (std::uint8_t bits : fields.defined) moving += (bits & kSpeedDefined) != 0;
  if (options.unobserved.fill) fill_speeds();
}

std::size_t IterationData::average_implausible() {
  // Where the background shows through, the speed's sign is noise; the region moves by its mean.
  implausible_count = 0;
  if (!(applied_implausible_g_ratio() > 0.0)) return 0;
  const std::vector<std::uint8_t> implausible = implausible_g_vertices(mesh, fields, applied_implausible_g_ratio());
  for (const std::uint8_t flag : implausible) implausible_count += flag;
  return average_implausible_speeds(mesh, implausible, options.implausible_speed, fields);
}

void IterationData::fill_speeds() {
  // After Δt: the step is set by what the photographs say, the filled speeds only follow it. The
  // observed rate is the vertex's whole last step per unit time once there is one (see
  // stages/flow/unobserved_speed.h), its flow speed before.
  const bool history = last_step.size() == fields.size() && last_time_step > 0.0;
  std::vector<double> rate(fields.size(), 0.0);
  for (std::size_t v = 0; v < fields.size(); ++v)
    if (fields.defined[v] & kSpeedDefined)
      rate[v] = history ? last_step[v].dot(fields.normal[v]) / last_time_step : fields.speed[v].dot(fields.normal[v]);
  fill_unobserved_speeds(mesh, options.unobserved, rate, fields);
  last_time_step = time_step;
}

void IterationData::measure_moves() {
  if (cancelled()) return;
  std::vector<double> relative;
  relative.reserve(moved.size());
  for (std::uint32_t id = 0; id < moved.size(); ++id) {
    if (!(fields.defined[id] & kSpeedDefined) || mesh.is_boundary(TriMesh::VertexHandle(static_cast<int>(id)))) continue;
    const double edge = options.local_step ? fields.local_edge[id] : shortest_edge;
    relative.push_back(edge > 0 ? moved[id] / edge : 0.0);
  }
  median_move = median_of(relative);
  net_move_over_edge = net_move.record(mesh, fields);
}

void IterationData::adapt_step_scale() {
  const double g_per_vertex = total.defined_g ? total.sum_g / static_cast<double>(total.defined_g) : 0.0;
  if (options.step_control && previous_g_per_vertex > 0.0) {
    // The last step raised Σg/vertex: it overshot the minimum of g, so halve the steps; after
    // a step that lowered it, let them grow back toward the CFL bound.
    step_scale = g_per_vertex > previous_g_per_vertex ? 0.5 * step_scale : std::min(1.0, 1.25 * step_scale);
  }
  previous_g_per_vertex = g_per_vertex;
}

void IterationData::move(std::size_t block) {
  run_block(*this, block, &block_seconds[block][static_cast<int>(Stage::Move)],
            [&] {
              if (options.damping.enabled) damp_speeds(blocks[block], options.damping, fields, damping);
              if (time_step > 0.0) carry_momentum(blocks[block], options.momentum, time_step, last_step, fields);
              if (record_moving_speed)
                for (std::uint32_t v = blocks[block].begin; v < blocks[block].end; ++v) {
                  const bool has_speed = fields.defined[v] & (kSpeedDefined | kSpeedFilled);
                  moving_speed[v] = has_speed ? fields.speed[v].dot(fields.normal[v]) : 0.0;
                }
              move_vertices(mesh, blocks[block], fields, time_step, move_limit, inside, &moved);
            });
}

void IterationData::smooth(std::size_t block) {
  run_block(*this, block, &block_seconds[block][static_cast<int>(Stage::Smoothing)],
            [&] { smooth_curvature_normal(mesh, blocks[block], options.smoothing, new_positions); });
}

void IterationData::inflate(std::size_t block) {
  run_block(*this, block, &block_seconds[block][static_cast<int>(Stage::Smoothing)],
            [&] { inflate_curvature_normal(mesh, blocks[block], options.smoothing, new_positions); });
}

void IterationData::regularize(std::size_t block) {
  run_block(*this, block, &block_seconds[block][static_cast<int>(Stage::Regularization)], [&] {
    compute_normals(mesh, blocks[block], fields);  // at the smoothed positions
    regularize_tangential(mesh, blocks[block], fields, options.regularization, new_positions);
  });
}

void IterationData::commit(std::size_t block) {
  run_block(*this, block, nullptr, [&] { commit_positions(mesh, blocks[block], new_positions, inside); });
}

void IterationData::fit_rims(std::size_t block) {
  run_block(*this, block, &block_seconds[block][static_cast<int>(Stage::Rims)], [&] {
    fit_silhouette_rims(mesh, blocks[block], *rim_views, *rim_masks, surface.get(), mean_edge, options.rims, fields,
                        new_positions, &on_rim);
  });
}

IterationPhases iteration_phases(const RefineOptions& options, bool rims) {
  IterationPhases schedule{
      .pipeline = {&IterationData::geometry, &IterationData::visibility, &IterationData::photo_speed}, .phases = {}};
  schedule.phases.push_back(&IterationData::move);
  for (int step = 0; step < options.smoothing.steps; ++step) {
    schedule.phases.push_back(&IterationData::smooth);
    schedule.phases.push_back(&IterationData::commit);
    if (options.smoothing.taubin_pass_band > 0.0) {
      schedule.phases.push_back(&IterationData::inflate);
      schedule.phases.push_back(&IterationData::commit);
    }
  }
  for (int step = 0; step < options.regularization.steps; ++step) {
    schedule.phases.push_back(&IterationData::regularize);
    schedule.phases.push_back(&IterationData::commit);
  }
  // Last, with the normals the regularization computed: the rims correct what the flow and the
  // smoothing did to the outline.
  if (rims) {
    schedule.phases.push_back(&IterationData::fit_rims);
    schedule.phases.push_back(&IterationData::commit);
  }
  return schedule;
}

void run_iteration_sequential(IterationData& data) {
  const IterationPhases schedule = iteration_phases(data.options, data.rim_masks != nullptr);
  const std::size_t n = data.blocks.size();
  data.refit();
  for (BlockKernel kernel : schedule.pipeline)
    for (std::size_t b = 0; b < n; ++b) (data.*kernel)(b);
  data.cfl();
  for (BlockKernel kernel : schedule.phases)
    for (std::size_t b = 0; b < n; ++b) (data.*kernel)(b);
  data.measure_moves();
}

}  // namespace mvflow
