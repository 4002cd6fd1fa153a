#include "engine/refine/refiner.h"

#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <optional>
#include <span>

#include "engine/model/error.h"
#include "engine/refine/iteration.h"
#include "engine/refine/iteration_graph.h"
#include "engine/model/mesh_stats.h"
#include "engine/model/parallel.h"
#include "stages/topology/adaptive_refinement.h"
#include "stages/flow/curvature.h"
#include "stages/flow/image_denoise.h"
#include "stages/flow/image_noise.h"
#include "stages/flow/image_pyramid.h"
#include "stages/flow/normals.h"
#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_robust.h"
#include "stages/flow/regularization.h"
#include "stages/topology/remeshing.h"
#include "stages/topology/self_intersections.h"
#include "stages/topology/vertex_order.h"
#include "stages/flow/silhouette.h"
#include "stages/flow/silhouette_constraint.h"
#include "stages/flow/silhouette_rims.h"
#include "stages/flow/smoothing.h"
#include "stages/flow/unobserved_displacement.h"
#include "stages/topology/untangling.h"
#include "stages/flow/visibility.h"

namespace mvflow {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The scene indices of the views not excluded, in scene order.
std::vector<std::size_t> kept_view_indices(const Scene& scene, const std::vector<int>& excluded) {
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < scene.size(); ++i)
    if (std::find(excluded.begin(), excluded.end(), static_cast<int>(i)) == excluded.end()) kept.push_back(i);
  return kept;
}

// The views the refinement may use, in scene order without the excluded ones. The exclusions are
// checked before any image is decoded; errors name the scene's folder (when it has one).
std::vector<PhotoView> usable_views(const Scene& scene, const std::vector<int>& excluded) {
  const auto refuse = [&](const std::string& what) {
    if (scene.folder.empty()) throw InputError(what);
    throw InputError(scene.folder, 0, what);
  };
  for (int view : excluded)
    if (view >= static_cast<int>(scene.size()))
      refuse("excluded view " + std::to_string(view) + " does not exist (the scene has " +
             std::to_string(scene.size()) + " views)");
  const std::vector<std::size_t> kept_indices = kept_view_indices(scene, excluded);
  if (kept_indices.size() < 2)
    refuse("fewer than 2 views are left to refine with (" + std::to_string(scene.size()) + " views, " +
           std::to_string(scene.size() - kept_indices.size()) + " excluded)");
  return make_photo_views(scene, kept_indices);  // an excluded view's photograph is never decoded
}

// The silhouettes of the scene's views \p kept from its mask images (Scene::masks), as given: no
// threshold, no hole filling.
std::vector<Mask> given_silhouettes(const Scene& scene, std::span<const std::size_t> kept) {
  decode_images(*scene.masks, kept);
  std::vector<Mask> masks;
  for (std::size_t i : kept) {
    const Image& image = scene.masks->get(i);
    const Camera& camera = scene.views[i].camera;
    if (image.width() != camera.width() || image.height() != camera.height())
      throw InputError("the mask of view " + std::to_string(i) + " is " + std::to_string(image.width()) + "x" +
                       std::to_string(image.height()) + " pixels, but the view is " + std::to_string(camera.width()) +
                       "x" + std::to_string(camera.height()));
    masks.push_back(mask_from_image(image));
  }
  return masks;
}

// g at every vertex of the current mesh (normals, visibility, g; no gradient), and the mean
// colour of the visible views: what the output mesh carries and the summary reports.
struct SurfaceState {
  std::vector<float> g;
  std::vector<Eigen::Vector3f> colours;
  double sum_g_per_vertex = 0.0;
};

// \p surface: Embree's scene of \p mesh as it is now. Image patches read \p views, surface patches
// and the colours \p photographs (the same cameras: the photographs as given, whose blurred copies
// \p views may be, DenoiseOptions).
SurfaceState evaluate_surface(const TriMesh& mesh, const std::vector<PhotoView>& views,
                              const std::vector<PhotoView>& photographs, const SurfaceQuery& surface,
                              const RefineOptions& options) {
  VertexFields fields;
  fields.resize(mesh.n_vertices(), views.size());
  const double mean_edge = edge_lengths(mesh).mean;
  SurfaceState state;
  state.g.resize(mesh.n_vertices(), 0.0f);
  state.colours.resize(mesh.n_vertices(), Eigen::Vector3f::Zero());
  // Per vertex block in parallel: every vertex's values depend on that vertex alone.
  const std::vector<IndexRange> blocks = split_into_blocks(mesh.n_vertices(), options.block_size);
  parallel::parallel_for(std::size_t{0}, blocks.size(), [&](std::size_t b) {
    const IndexRange block = blocks[b];
    compute_normals(mesh, block, fields);
    compute_visibility(mesh, block, views, surface, mean_edge, options.visibility, fields);
    drop_outlier_views(mesh, block, views, options.photo.photo, fields);
    compute_photo_consistency(mesh, block, views, options.photo.photo, fields, &photographs);
    for (std::uint32_t v = block.begin; v < block.end; ++v) {
      const Eigen::Vector3d P = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
      Eigen::Vector3d colour = Eigen::Vector3d::Zero();
      for (const std::uint16_t id : fields.visible(v)) {
        const PhotoView& view = photographs[id];
        const Projection p = view.project(P);
        colour += view.image->sample_bilinear(p.u, p.v).cast<double>();
      }
      if (fields.visible_count[v] > 0) state.colours[v] = (colour / fields.visible_count[v]).cast<float>();
    }
  });
  // Σg in id order, whatever the blocks.
  double sum = 0.0;
  std::size_t defined = 0;
  for (std::uint32_t v = 0; v < mesh.n_vertices(); ++v)
    if (fields.defined[v] & kPhotoDefined) {
      state.g[v] = static_cast<float>(fields.photo_consistency[v]);
      sum += fields.photo_consistency[v];
      ++defined;
    }
  state.sum_g_per_vertex = defined ? sum / static_cast<double>(defined) : 0.0;
  return state;
}

RefineStatus status_of(StopReason reason) {
  switch (reason) {
    case StopReason::Converged: return RefineStatus::Converged;
    case StopReason::StepSmall: return RefineStatus::StepSmall;
    case StopReason::Settled: return RefineStatus::Settled;
    default: return RefineStatus::MaxIterations;
  }
}

class Refinement {
 public:
  Refinement(const Scene& scene, const Mesh& initial, const RefineOptions& options, const RefineControl& control)
      : options_(options), control_(control), initial_vertices_(initial.topology.n_vertices()),
        initial_faces_(initial.topology.n_faces()), mesh_(initial.topology),
        data_(mesh_, views_, options_, control.cancel) {
    progress(0, RefineStage::Preparing);
    spreads_ = options.unobserved_displacement.spread != UnobservedSpread::Off;  // prepare() reads it
    const std::exception_ptr preparing_error = decode_while_preparing(scene);
    views_ = flow_views();
    data_.on_block = control.on_block;
    data_.record_moving_speed = static_cast<bool>(control.on_vertex_fields);
    for (int level = 0; level < options.image_levels; ++level)
      levels_.push_back(half_resolution(level == 0 ? flow_views() : levels_.back()->views));
    if (!levels_.empty()) views_ = levels_.back()->views;  // the coarsest first
    data_.surface_views = surface_views();
    // Far vertices need every image halvable (16 × 16 pixels at least); smaller ones run without.
    if (options.far.enabled() && levels_.empty() &&
        std::all_of(full_views_.begin(), full_views_.end(), [](const PhotoView& view) { return halvable(view); })) {
      far_images_ = half_resolution(full_views_);  // not the blurred copies (stages/flow/far_vertices.h)
      data_.far_views = &far_images_->views;
    }
    // Mask images, when the scene has them, stand for the thresholded photographs everywhere.
    rims_from_masks_ = scene.masks != nullptr;
    const std::vector<Mask> given =
        rims_from_masks_ ? given_silhouettes(scene, kept_view_indices(scene, options.excluded_views)) : std::vector<Mask>{};
    if (options.keep_inside_silhouettes) {
      std::vector<Mask> inside = given;
      for (Mask& mask : inside) mask = dilate_mask(mask, options.silhouettes.dilate);
      inside_.emplace(full_views_, rims_from_masks_ ? inside : threshold_silhouettes(full_views_, options.silhouettes));
      data_.inside = &*inside_;
    }
    if (rims_from_masks_ ? options.rims.fit != RimFit::Off
                         : fits_rims(full_views_, options.silhouettes.threshold, options.rims)) {
      rim_masks_ = rims_from_masks_ ? given : rim_silhouettes(full_views_, options.silhouettes, options.rims);
      data_.rim_masks = &rim_masks_;
      data_.rim_views = &full_views_;
    }
    spreads_hardly_observed_ = options.unobserved_displacement.spread == UnobservedSpread::Auto && !data_.rim_masks;
    const UnobservedSpread unmoved = options.unobserved_displacement.spread_unmoved;
    spreads_unmoved_ =
        spreads_ && (unmoved == UnobservedSpread::On || (unmoved == UnobservedSpread::Auto && !data_.rim_masks));
    // Last, as when the mesh was prepared after the constructor: a bad mask or silhouette is
    // reported before a bad mesh.
    if (preparing_error) std::rethrow_exception(preparing_error);
  }

  RefineResult run() {
    const auto start = Clock::now();
    RefineResult result;
    RefineSummary& summary = result.summary;
    summary.initial_vertices = initial_vertices_;  // before the split/collapse
    summary.initial_faces = initial_faces_;
    if (control_.logger && data_.rim_masks && rims_from_masks_)
      control_.logger->info("fitting the rims to the silhouettes of the mask images");
    else if (control_.logger && data_.rim_masks)
      control_.logger->info("fitting the rims to the silhouettes (threshold {}){}", options_.silhouettes.threshold,
                            options_.rims.fit == RimFit::Auto ? ": every view's border is dark" : "");
    if (control_.logger && spreads_)
      control_.logger->info("{} follow the observed surface{}",
                            spreads_hardly_observed_ ? "hardly observed vertices" : "unobserved vertices",
                            data_.rim_masks ? " and the silhouette rims" : "");
    if (control_.logger && data_.rim_masks && options_.unobserved_displacement.implausible_g_ratio > 0.0)
      control_.logger->info("the rims are fitted: implausible g ratio {} not applied, neither to the spread nor to the "
                            "speeds (the silhouettes hold the outline)",
                            options_.unobserved_displacement.implausible_g_ratio);
    data_.reset_topology();  // the first iteration's Embree scene serves the initial evaluation too
    summary.initial_sum_g_per_vertex = evaluate_surface(mesh_, flow_views(), full_views_, *data_.surface, options_).sum_g_per_vertex;

    StoppingOptions stopping_options = options_.stopping;
    stopping_options.settled_tolerance = settled_tolerance_for_noise(options_.stopping, flow_noise_);
    summary.image_noise = image_noise_;
    summary.denoise_sigma = denoise_sigma_;
    summary.settled_tolerance = stopping_options.settled_tolerance;
    if (control_.logger && denoised_)
      control_.logger->info("image noise {:.4f} (median over the views): blurred with σ {:.2f} pixels to {:.4f}",
                            image_noise_, denoise_sigma_, flow_noise_);
    if (control_.logger && stopping_options.settled_tolerance != options_.stopping.settled_tolerance)
      control_.logger->info("image noise {:.4f}: settled tolerance {:.4f} instead of {:.4f}", flow_noise_,
                            stopping_options.settled_tolerance, options_.stopping.settled_tolerance);
    StoppingCriterion stopping(stopping_options);
    RefineStatus status = RefineStatus::MaxIterations;
    for (int iteration = 1;; ++iteration) {
      if (cancelled()) {
        status = RefineStatus::Cancelled;
        break;
      }
      const auto iteration_start = Clock::now();
      stop_untangling_.pairs = 0;  // the flow goes on from the last stop's untangled positions: they count
      IterationReport report;
      report.iteration = iteration;
      double refinement_seconds = 0.0;
      // Refinement waits for the full-resolution images with either schedule.
      const bool refine_now = options_.refinement_schedule == RefinementSchedule::EveryIteration && iteration > 1 &&
                              levels_.empty() && run_on_left_ == 0;
      if ((refine_now && adapt(report, refinement_seconds)) || !data_.surface) {
        data_.reset_topology();
        graph_.reset();
      }
      const EdgeLengths edges = edge_lengths(mesh_);
      data_.set_edge_lengths(edges);
      std::fill(std::begin(data_.serial_seconds), std::end(data_.serial_seconds), 0.0);
      for (auto& slots : data_.block_seconds) slots.fill(0.0);

      if (options_.engine == EngineKind::Graph) {
        if (!graph_) graph_ = std::make_unique<IterationGraph>(data_);  // inside the arena: attaches to it
        graph_->run();
      } else {
        run_iteration_sequential(data_);
      }
      if (cancelled() || data_.stopped) {  // its kernels skipped blocks: the iteration did not happen
        status = RefineStatus::Cancelled;
        break;
      }
      fill_report(report, edges, refinement_seconds, iteration_start);
      if (control_.on_vertex_fields) report_vertex_fields(iteration);
      count_observed();
      StopReason reason = stopping.add_iteration(data_.total.sum_g, data_.median_move, data_.total.defined_g,
                                                   data_.net_move_over_edge);
      report.stop = to_string(reason);
      const bool budget_left = stopping.iterations() < static_cast<std::size_t>(options_.stopping.max_iterations);
      const bool rule_fired = is_rule_stop(reason);
      if (run_on_left_ > 0) {  // StoppingOptions::run_on: every rule off, nothing refined
        report.stop = "running on";
        reason = --run_on_left_ > 0 ? StopReason::Continue : run_on_from_;
      } else if (budget_left && !finest_wait_.reached() && refine_at_convergence(reason, report)) {
        stopping.restart();
        reason = StopReason::Continue;
      } else if (rule_fired && finest_wait_.wait(options_.stopping, reason, data_.net_move.last_persistence(),
                                                 stopping.level_iterations(), budget_left)) {
        report.stop = std::string("held (") + to_string(reason) + ")";
        reason = StopReason::Continue;
      } else if (rule_fired && options_.stopping.run_on > 0) {
        report.stop = std::string("run on (") + to_string(reason) + ")";
        run_on_left_ = options_.stopping.run_on;
        run_on_from_ = reason;
        reason = StopReason::Continue;
      }
      summary.iterations.push_back(report);
      announce(report);
      if (reason != StopReason::Continue) {
        status = status_of(reason);
        break;
      }
    }

    progress(static_cast<int>(summary.iterations.size()), RefineStage::Finishing);
    // Before the end's spread and untangling, which act on the mean as on the last iterate.
    if (status != RefineStatus::Cancelled) average_last_iterates();
    // At convergence the spread runs before each refinement (refine_at_convergence); refined every
    // iteration, once here.
    if (status != RefineStatus::Cancelled && options_.refinement_schedule == RefinementSchedule::EveryIteration)
      spread_unobserved(spread_fraction());
    else if (status != RefineStatus::Cancelled && spreads_unmoved_)
      spread_unobserved(0.0);
    const std::optional<UntanglingResult> untangled =
        status == RefineStatus::Cancelled ? std::nullopt : untangle_folds();
    summary.untangled_pairs = untangled_pairs_;
    const SurfaceState final_state = evaluate_surface(mesh_, flow_views(), full_views_, SurfaceQuery(mesh_), options_);
    summary.status = status;
    summary.final_vertices = mesh_.n_vertices();
    summary.final_faces = mesh_.n_faces();
    summary.final_sum_g_per_vertex = final_state.sum_g_per_vertex;
    // The untangling's last count holds unless the silhouette constraint cut its moves short.
    const bool counted = untangled && !(inside_ && untangled->rounds > 0);
    summary.self_intersections = counted ? untangled->crossing_pairs_after : count_self_intersections(mesh_);
    result.mesh.topology = mesh_;
    result.mesh.quality = final_state.g;
    result.mesh.colors = final_state.colours;
    summary.seconds = seconds_since(start);
    return result;
  }

 private:
  bool cancelled() const { return control_.cancel && control_.cancel->load(); }

  // No run goes past the budget plus the running on (an int, saturated).
  int iteration_bound() const {
    return static_cast<int>(std::min<long long>(std::numeric_limits<int>::max(),
                                                static_cast<long long>(options_.stopping.max_iterations) +
                                                    options_.stopping.run_on));
  }

  void progress(int iteration, RefineStage stage) {
    if (!control_.on_progress) return;
    RefineProgress p;
    p.iteration = iteration;
    p.max_iterations = iteration_bound();
    p.vertices = mesh_.n_vertices();
    p.stage = stage;
    control_.on_progress(p);
  }

  // The photographs are decoded (full_views_) while the mesh is prepared: preparing needs no
  // image and is serial (about 25 ms of the sphere case's 1.8 s at 2 threads), decoding keeps both
  // threads busy for longer. A decoding error is thrown here; the preparing one is returned, for
  // the constructor to throw after its other checks, in the order of the serial code.
  std::exception_ptr decode_while_preparing(const Scene& scene) {
    // The pixel size that limits refinement is taken at the centre of the mesh as given, not as
    // prepared: the cow scene's refinement changed (125 → 142 iterations) when it was not.
    const Eigen::Vector3d centre = bounding_box_of(mesh_).centre();
    std::exception_ptr decoding_error, preparing_error;
    parallel::parallel_for(0, 2, [&](int task) {
      try {
        if (task == 0)
          full_views_ = usable_views(scene, options_.excluded_views);
        else
          prepare();
      } catch (...) {
        (task == 0 ? decoding_error : preparing_error) = std::current_exception();
      }
    });
    if (decoding_error) std::rethrow_exception(decoding_error);
    pixel_size_ = finest_pixel_size(full_views_, centre);
    // The photographs' noise decides their blur (DenoiseOptions) and sets the settled rule's
    // tolerance (StoppingOptions::settled_noise_reference) from what the blur leaves of it.
    const bool settles_by_noise = options_.stopping.settled_tolerance > 0 && options_.stopping.settled_noise_reference > 0;
    if (settles_by_noise || options_.denoise.use == DenoiseUse::Auto) image_noise_ = estimate_views_noise(full_views_);
    flow_noise_ = image_noise_;
    // With surface patches everywhere no vertex would read the blurred copies (surface_views()).
    const bool image_patches = options_.photo.photo.surface_patch != SurfacePatchUse::On;
    if (options_.denoise.use == DenoiseUse::Auto && image_patches && image_noise_ > options_.denoise.noise_reference) {
      denoise_sigma_ = denoise_sigma_for(image_noise_, options_.denoise.noise_reference);
      denoised_ = blurred_views(full_views_, denoise_sigma_);
      // At most the reference: the bisection's σ leaves no more, and rounding must not lift it above.
      flow_noise_ = std::min(image_noise_ * gaussian_noise_gain(denoise_sigma_), options_.denoise.noise_reference);
    }
    return preparing_error;
  }

  // Thesis §5.3.4, before the flow: split/collapse against e_S, one smoothing and one
  // regularization pass over the whole mesh.
  void prepare() {
    reference_edge_ = edge_lengths(mesh_).shortest;
    if (!(reference_edge_ > 0)) throw InputError("the initial mesh has an edge of length zero");
    if (options_.global_remeshing) {
      remesh_edges(mesh_, reference_edge_, options_.remeshing);
      // Neighbours close in memory: at 2 threads a block's one rings stay in its block.
      order_vertices_by_locality(mesh_);
    }
    apply_smoothing(mesh_, options_.smoothing);
    apply_regularization(mesh_, options_.regularization);
    if (spreads_) reference_ = positions_of(mesh_);
    if (spreads_) speed_iterations_.assign(mesh_.n_vertices(), 0);
  }

  // The share of a resolution's iterations with a speed up to which a poorly observed vertex
  // is spread (1: every unobserved vertex; UnobservedDisplacementOptions::hardly_observed_fraction).
  double spread_fraction() const {
    return spreads_hardly_observed_ ? options_.unobserved_displacement.hardly_observed_fraction : 1.0;
  }

  // spread_fraction() at this resolution's convergence: the first resolution's own
  // (--hardly-observed-first) before the first refinement where the spread is auto without rims.
  double hardly_observed_fraction() const {
    const bool first = mesh_refinements_ == 0 && spreads_hardly_observed_;
    return first ? options_.unobserved_displacement.first_hardly_observed_fraction : spread_fraction();
  }

  // The unobserved spread's options as applied (IterationData::applied_implausible_g_ratio).
  UnobservedDisplacementOptions observed_options() const {
    UnobservedDisplacementOptions options = options_.unobserved_displacement;
    options.implausible_g_ratio = data_.applied_implausible_g_ratio();
    return options;
  }

  // One more iteration at this resolution, and which vertices had a speed in it.
  void count_observed() {
    if (!spreads_) return;
    ++level_iterations_;
    observed_vertices(mesh_, views_, data_.fields, observed_options(), observed_);
    for (std::size_t v = 0; v < speed_iterations_.size(); ++v) speed_iterations_[v] += observed_[v];
  }

  // Removes the folds of the current surface (UntanglingOptions), counted for the summary;
  // nothing (nullopt) when the untangling is disabled.
  std::optional<UntanglingResult> untangle_folds() {
    if (options_.untangling.max_rounds == 0) return std::nullopt;
    const std::vector<Eigen::Vector3d> before = inside_ ? positions_of(mesh_) : std::vector<Eigen::Vector3d>{};
    const UntanglingResult result = untangle(mesh_, options_.untangling);
    // The last round's count: a smoothing that crossed more faces than it freed removed none.
    if (result.crossing_pairs_before > result.crossing_pairs_after)
      untangled_pairs_ += result.crossing_pairs_before - result.crossing_pairs_after;
    if (result.rounds > 0) limit_to_silhouettes(before);
    if (control_.logger && result.crossing_pairs_before > 0)
      control_.logger->info("untangled {} crossing face pairs ({} left) by smoothing {} vertices in {} rounds",
                            result.crossing_pairs_before, result.crossing_pairs_after, result.smoothed_vertices,
                            result.rounds);
    return result;
  }

  // The result is the mean of the last iterates of this topology (StoppingOptions::average_last);
  // the last iterate where fewer were recorded (a refinement just before the end).
  void average_last_iterates() {
    if (options_.stopping.average_last < 2) return;
    const auto count = static_cast<std::size_t>(options_.stopping.average_last);
    // An untangling at a stop the flow went on from lies between the iterates: a mean across it
    // would undo part of it, so the last iterate stands.
    const std::size_t recorded = data_.net_move.recorded();
    const std::size_t after = stop_untangling_.after_iterate;
    if (after > 0 && after < recorded && recorded - after < count)
      return;
    std::vector<Eigen::Vector3d> mean;
    if (!data_.net_move.mean_of_last(count, mean)) return;
    const std::vector<Eigen::Vector3d> last = inside_ ? positions_of(mesh_) : std::vector<Eigen::Vector3d>{};
    set_positions(mesh_, mean);
    untangled_pairs_ -= stop_untangling_.pairs;  // the iterates were recorded before the stop's untangling
    limit_to_silhouettes(last);  // a mean of two inside positions may leave a concave silhouette
  }

  // The silhouette constraint holds for the moves outside the flow too: each vertex moved since
  // \p before (its positions then; empty without the constraint) is pulled back inside.
  void limit_to_silhouettes(const std::vector<Eigen::Vector3d>& before) {
    if (!inside_) return;
    for (auto v : mesh_.vertices()) {
      const Eigen::Vector3d& from = before[static_cast<std::size_t>(v.idx())];
      const Eigen::Vector3d to = to_eigen(mesh_.point(v));
      if (to != from) mesh_.set_point(v, to_openmesh(inside_->limit_move(from, to)));
    }
  }

  // Moves the vertices the last iteration did not observe well with the observed surface
  // (UnobservedDisplacementOptions), of those only the ones that had a speed in at most
  // \p fraction of this resolution's iterations when it is below 1; the fields still describe
  // the current topology. True when vertices moved.
  bool spread_unobserved(double fraction) {
    if (!spreads_) return false;
    std::vector<std::uint8_t> poor =
        poorly_observed_vertices(mesh_, views_, data_.fields, observed_options(), data_.on_rim);
    // Kept among those after their erosion: growing the hardly observed set by the ring instead
    // spread more of a bumpy object's underside (bumpy sphere 0.00173 → 0.00241).
    if (fraction < 1) keep_hardly_observed(poor, speed_iterations_, level_iterations_, fraction);
    const std::vector<Eigen::Vector3d> before = inside_ ? positions_of(mesh_) : std::vector<Eigen::Vector3d>{};
    const DisplacementResult result = spread_displacement(mesh_, reference_, poor);
    if (result.moved_vertices > 0) limit_to_silhouettes(before);
    if (control_.logger && result.moved_vertices > 0)
      control_.logger->info("moved {} unobserved vertices with the observed surface", result.moved_vertices);
    return result.moved_vertices > 0;
  }

  // Normals and curvature at the current positions for every vertex (after the untangling moved
  // some), for the adaptive refinement's marks.
  void update_curvature() {
    // Per block in parallel: a vertex's curvature reads its own normal only.
    const std::vector<IndexRange> blocks = split_into_blocks(mesh_.n_vertices(), options_.block_size);
    parallel::parallel_for(std::size_t{0}, blocks.size(), [&](std::size_t b) {
      compute_normals(mesh_, blocks[b], data_.fields);
      compute_mean_curvature(mesh_, blocks[b], data_.fields, options_.curvature);
    });
  }

  // Adaptive refinement from the curvature of the last iteration (SPEC §5). True when the
  // topology changed, so the blocks, fields, Embree scene and graph are rebuilt.
  bool adapt(IterationReport& report, double& seconds) {
    if (!options_.adaptive_refinement) return false;
    const auto start = Clock::now();
    const std::size_t faces = mesh_.n_faces();
    const RefinementResult result = refine_adaptively(mesh_, data_.fields, reference_edge_, options_.adaptive, pixel_size_);
    if (spreads_) extend_reference(reference_, result.parents);
    if (mesh_.n_faces() != faces) {  // a new resolution
      data_.far_views = nullptr;  // far vertices at the first resolution only (stages/flow/far_vertices.h)
      far_images_.reset();
      // The added vertices were appended far from their neighbours.
      const std::vector<std::uint32_t> new_of_old = order_vertices_by_locality(mesh_);
      if (spreads_) {
        if (!new_of_old.empty()) renumber_vertices(reference_, new_of_old);
        speed_iterations_.assign(mesh_.n_vertices(), 0);  // its own counts
        level_iterations_ = 0;
      }
    }
    report.refined_faces += mesh_.n_faces() - faces;
    report.declined_vertices += result.declined;
    seconds += seconds_since(start);
    return mesh_.n_faces() != faces;
  }

  // The coarse-to-fine schedule: when the flow has settled on coarser images, the next finer ones
  // (with either refinement schedule); at full resolution, refine; true when that changed the
  // images or the mesh (the run goes on), recorded in \p report.
  bool refine_at_convergence(StopReason reason, IterationReport& report) {
    if (!is_rule_stop(reason)) return false;
    if (!levels_.empty()) {  // settled on these images: the next finer ones before any refinement
      levels_.pop_back();
      views_ = levels_.empty() ? flow_views() : levels_.back()->views;
      data_.surface_views = surface_views();
      data_.step_scale = 1.0;  // Σg/vertex on other images says nothing about the steps on these
      data_.previous_g_per_vertex = 0.0;
      data_.damping.reset(mesh_.n_vertices());  // reversals on other images say nothing about these
      data_.net_move.reset();  // nor do positions on them: no net move or average across images
      data_.net_move_over_edge = std::numeric_limits<double>::quiet_NaN();
      report.stop = std::string("finer images (") + to_string(reason) + ")";
      if (control_.logger) control_.logger->info("images at 1/{} of their resolution from here", 1 << levels_.size());
      return true;
    }
    if (options_.refinement_schedule != RefinementSchedule::AtConvergence) return false;
    const auto start = Clock::now();
    const std::vector<Eigen::Vector3d> flowed = spreads_ ? positions_of(mesh_) : std::vector<Eigen::Vector3d>{};
    const bool spread = spread_unobserved(hardly_observed_fraction());
    const std::size_t untangled_before = untangled_pairs_;
    const std::optional<UntanglingResult> untangled = untangle_folds();
    if (spread || (untangled && untangled->rounds > 0)) update_curvature();  // the marks follow the moves
    double seconds = seconds_since(start);
    const bool refined = adapt(report, seconds);
    report.stage_seconds[static_cast<int>(Stage::Refinement)] += seconds;
    if (!refined) {
      // The finest resolution: the flow has the last word (the run's end untangles again). A
      // spread is kept only where a refinement and more flow follow it; after the finest level it
      // undid what the flow had recovered of weakly seen regions (README, "Weakly seen regions").
      // Restoring the flowed positions undoes the untangling too, so its folds are not counted;
      // otherwise they count unless the run ends here and the averaging replaces these positions.
      if (spread) {
        set_positions(mesh_, flowed);
        untangled_pairs_ = untangled_before;
      } else {
        stop_untangling_.pairs = untangled_pairs_ - untangled_before;
        if (untangled && untangled->rounds > 0) stop_untangling_.after_iterate = data_.net_move.recorded();
      }
      return false;
    }
    ++mesh_refinements_;
    report.stop = std::string("refined (") + to_string(reason) + ")";
    data_.reset_topology();
    graph_.reset();
    return true;
  }

  void fill_report(IterationReport& report, const EdgeLengths& edges, double refinement_seconds,
                   Clock::time_point iteration_start) {
    report.vertices = mesh_.n_vertices();
    report.faces = mesh_.n_faces();
    report.sum_g = data_.total.sum_g;
    report.defined_g = data_.total.defined_g;
    report.surface_patch_g = data_.surface_patch_g;
    report.far_vertices = data_.far_count;
    report.implausible_g = data_.implausible_count;
    report.patch_switches = data_.patch_switches;
    report.moving = data_.moving;
    report.shortest_edge = edges.shortest;
    report.max_speed = data_.total.max_speed;
    report.time_step = data_.time_step;
    report.median_move = data_.median_move;
    report.net_move = data_.net_move_over_edge;
    report.net_move_tail = data_.net_move.last_tail();  // NaN after a reset, as net_move
    report.net_move_persistence = data_.net_move.last_persistence();
    for (std::size_t s = 0; s < kStageCount; ++s) report.stage_seconds[s] = data_.serial_seconds[s];
    for (const auto& slots : data_.block_seconds)  // block order: the same sum every run
      for (std::size_t s = 0; s < kStageCount; ++s) report.stage_seconds[s] += slots[s];
    report.stage_seconds[static_cast<int>(Stage::Refinement)] = refinement_seconds;
    report.seconds = seconds_since(iteration_start);
  }

  void report_vertex_fields(int iteration) const {
    IterationVertexFields state;
    state.iteration = iteration;
    state.time_step = data_.time_step;
    state.mesh = &mesh_;
    state.fields = &data_.fields;
    if (options_.damping.enabled) state.damping_scale = data_.damping.scale;
    state.moved = data_.moved;
    state.moving_speed = data_.moving_speed;
    control_.on_vertex_fields(state);
  }

  void announce(const IterationReport& report) {
    if (control_.logger)
      control_.logger->info("iteration {:3d}  vertices {:7d}  Σg/vertex {:.6g}  Δt {:.4g}  max|F| {:.4g}  {:.3f} s",
                            report.iteration, report.vertices, report.sum_g_per_vertex(), report.time_step,
                            report.max_speed, report.seconds);
    RefineProgress p;
    p.iteration = report.iteration;
    p.max_iterations = iteration_bound();
    p.vertices = report.vertices;
    p.sum_g_per_vertex = report.sum_g_per_vertex();
    p.stage = RefineStage::Iterating;
    if (control_.on_progress) control_.on_progress(p);  // first: on_iteration sees the same state
    if (control_.on_iteration) control_.on_iteration(report);
  }

  const RefineOptions& options_;
  const RefineControl& control_;
  std::size_t initial_vertices_ = 0, initial_faces_ = 0;  //!< of the mesh given
  std::vector<PhotoView> full_views_;  //!< the photographs the refinement may use, as given
  //! Their blurred copies when they are noisy (DenoiseOptions), else null.
  std::unique_ptr<ImageLevel> denoised_;
  //! The full-resolution views the whole-pixel image patches read: the blurred ones when there
  //! are, else the photographs as given (the silhouettes always threshold those).
  const std::vector<PhotoView>& flow_views() const { return denoised_ ? denoised_->views : full_views_; }
  //! What the surface patches read instead of views_: the photographs as given while views_ are
  //! their blurred copies (a blur in the image smears an oblique view's patch along the surface:
  //! the grazing caps of the noisiest spheres lost up to 79 % with it, README "Convergence");
  //! null otherwise (on a coarser level the halving has averaged the noise for both kinds).
  const std::vector<PhotoView>* surface_views() const { return denoised_ && levels_.empty() ? &full_views_ : nullptr; }
  std::vector<std::unique_ptr<ImageLevel>> levels_;  //!< halved once, twice, ...; dropped as the flow gets there
  //! The photographs at half resolution that far vertices read (FarVertexOptions), until the first refinement.
  std::unique_ptr<ImageLevel> far_images_;
  std::vector<PhotoView> views_;       //!< the views the iterations read now (a level's or the full ones)
  TriMesh mesh_;
  IterationData data_;
  double reference_edge_ = 0.0;
  double pixel_size_ = 0.0;  //!< world length of one pixel at the object, finest view
  std::size_t untangled_pairs_ = 0;
  //! The untangling at a stop that refined nothing (refine_at_convergence), which the run's end
  //! may replace by the mean of the iterates before it (average_last_iterates).
  struct StopUntangling {
    //! Of untangled_pairs_, those it removed; 0 once the flow goes on from its positions (then
    //! they stay counted).
    std::size_t pairs = 0;
    //! The iterates net_move had recorded when it untangled positions the flow then went on from
    //! (0: none): the final mean does not reach back across it.
    std::size_t after_iterate = 0;
  } stop_untangling_;
  bool rims_from_masks_ = false;  //!< the silhouettes are the scene's mask images (Scene::masks)
  //! At the run's end the vertices the finest resolution never gave a speed follow too
  //! (UnobservedDisplacementOptions::spread_unmoved).
  bool spreads_unmoved_ = false;
  double image_noise_ = 0.0;  //!< estimate_views_noise of the photographs (0 when not needed)
  double denoise_sigma_ = 0.0;  //!< the blur of denoised_ in pixels (0: none)
  double flow_noise_ = 0.0;     //!< the noise the image patches' photographs keep (after the blur)
  int mesh_refinements_ = 0;  //!< refinements at convergence so far (the first resolution until one)
  //! Whether a stop found nothing left to refine, and the wait there (StoppingOptions::
  //! finest_min_iterations, persistence_wait).
  FinestResolutionWait finest_wait_;
  //! StoppingOptions::run_on: the iterations left past the stop (0: not running on), that stop.
  int run_on_left_ = 0;
  StopReason run_on_from_ = StopReason::Continue;
  bool spreads_ = false;  //!< the unobserved vertices follow the observed surface (UnobservedSpread)
  //! Of those, only the hardly observed (the spread is auto without rims: spread_fraction()).
  bool spreads_hardly_observed_ = false;
  std::vector<std::uint32_t> speed_iterations_;  //!< per vertex, iterations at this resolution with a speed
  std::vector<std::uint8_t> observed_;            //!< count_observed()'s flags of the last iteration, reused
  int level_iterations_ = 0;                      //!< iterations at this resolution
  // Where each vertex was when the flow started (UnobservedDisplacementOptions), midpoints for the
  // vertices refinement added; empty when the option is off.
  std::vector<Eigen::Vector3d> reference_;
  std::unique_ptr<IterationGraph> graph_;  //!< rebuilt when the topology changes
  std::optional<SilhouetteConstraint> inside_;
  std::vector<Mask> rim_masks_;  //!< one per view of full_views_ when the rims are fitted (fits_rims)
};

}  // namespace

const char* to_string(RefineStage stage) {
  switch (stage) {
    case RefineStage::Preparing: return "preparing";
    case RefineStage::Iterating: return "iterating";
    case RefineStage::Finishing: return "finishing";
  }
  return "?";
}

RefineResult refine_mesh(const Scene& scene, const Mesh& initial, const RefineOptions& options,
                         const RefineControl& control) {
  const auto start = Clock::now();
  RefineResult result;
  try {
    options.check();
    if (initial.n_faces() == 0) throw InputError("the initial mesh has no faces");
    const int threads = control.threads > 0 ? control.threads : oneapi::tbb::info::default_concurrency();
    // The engine's own arena: the host's default arena and thread count stay untouched.
    oneapi::tbb::task_arena arena(threads);
    parallel::execute(arena, [&] {
      Refinement refinement(scene, initial, options, control);
      result = refinement.run();
    });
  } catch (const std::exception& e) {
    result.summary.status = RefineStatus::Failed;
    result.summary.message = e.what();
    result.summary.seconds = seconds_since(start);
    if (control.logger) control.logger->error("{}", e.what());
  }
  return result;
}

}  // namespace mvflow
