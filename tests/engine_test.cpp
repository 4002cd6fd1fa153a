// The refinement engine: determinism across thread counts, block sizes and engine kinds; that
// the flow moves a synthetic initial mesh toward the ground truth; cancellation (between
// iterations, and from another thread in the middle of one) and bad input.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "cancel_probe.h"
#include "engine/model/error.h"
#include "engine/refine/refiner.h"
#include "stages/eval/evaluation.h"
#include "stages/flow/image_noise.h"
#include "stages/flow/photo_views.h"
#include "stages/synth/synth_scene.h"

namespace mvflow {
namespace {

// A rendered scene with its truth and initial mesh (render_bumpy_scene).
struct SmallScene {
  Scene scene;
  Mesh initial;
  IndexedMesh truth;
};

// The bumpy sphere at \p level, 16 ring views of 320×240, a smoothed offset initial mesh of about
// \p init_vertices vertices.
SmallScene render_bumpy_scene(int level, int init_vertices) {
  SynthOptions options;
  options.rig.views = 16;
  options.rig.width = 320;
  options.rig.height = 240;
  options.init.vertices = init_vertices;
  BuiltinShapeOptions shape;
  shape.level = level;
  SmallScene s;
  s.truth = make_builtin_object("bumpy-sphere", shape);
  SynthScene synth = make_synth_scene(s.truth, nullptr, options);
  s.scene = in_memory_scene(std::move(synth.views), std::move(synth.images), synth.bounding_box);
  s.initial = build_mesh(synth.initial, "initial");
  return s;
}

const SmallScene& small_scene() {
  static const SmallScene cached = render_bumpy_scene(4, 300);
  return cached;
}

// A scene whose iterations take ≥ 100 ms (0.11 s with 2 threads on the development machine) in
// thousands of block kernels: the bumpy sphere at level 6, 16 views of 320×240, 40 000 vertices.
const SmallScene& large_scene() {
  static const SmallScene cached = render_bumpy_scene(6, 40000);
  return cached;
}

// Exactly \p iterations iterations (≥ 6: the stopping rule looks back 5 iterations).
RefineOptions few_iterations(int iterations) {
  RefineOptions options;
  options.stopping.max_iterations = iterations;
  options.stopping.min_iterations = std::min(iterations, 10);
  options.block_size = 64;
  return options;
}

// A budget of \p iterations in which the flow counts as "converged" as soon as the rules may fire
// (after 6 iterations), so that it refines within the run.
RefineOptions converging_early(int iterations) {
  RefineOptions options = few_iterations(iterations);
  options.stopping.min_iterations = 6;
  options.stopping.epsilon_percent = 50.0;
  options.stopping.finest_min_iterations = 0;  // the finest resolution too
  options.stopping.settled_wait = 0.0;
  return options;
}

std::vector<Eigen::Vector3d> positions(const RefineResult& result) { return positions_of(result.mesh.topology); }

// Both time-step rules and both refinement schedules: the default (quantile step, local CFL
// bound, refinement when the flow has converged, which the short minimum lets happen within the
// run) and the thesis's (max|F|, global bound, refinement before every iteration).
std::vector<RefineOptions> determinism_cases() {
  RefineOptions by_default = converging_early(12);  // so it refines within the run
  RefineOptions thesis_rules = few_iterations(6);
  thesis_rules.speed_quantile = 1.0;
  thesis_rules.local_step = false;
  thesis_rules.refinement_schedule = RefinementSchedule::EveryIteration;
  // The optional rules: step control, and the silhouette constraint (with a threshold that cuts
  // the textured background into many pieces, so that the constraint holds vertices back often).
  RefineOptions optional_rules = by_default;
  optional_rules.step_control = true;
  optional_rules.keep_inside_silhouettes = true;
  // ... and far vertices on half-resolution photographs: at 3 × the median g many vertices are
  // far, so runs of far and near vertices alternate within every block.
  optional_rules.far.g_ratio = 3.0;
  // ... and vertices not observed where g is high with its ring (3 × the median: many regions).
  optional_rules.unobserved_displacement.implausible_g_ratio = 3.0;
  optional_rules.silhouettes.threshold = 0.6;
  // The options for real photographs: coarser images first, speeds filled for unobserved and
  // obliquely seen vertices, outlier views dropped, at most 5 views.
  RefineOptions photograph_rules = by_default;
  photograph_rules.stopping.max_iterations = 18;
  photograph_rules.image_levels = 1;
  photograph_rules.unobserved.fill = true;
  photograph_rules.unobserved.weak_angle_degrees = 60.0;
  photograph_rules.photo.photo.drop_views = 1;
  photograph_rules.photo.photo.min_views = 3;
  photograph_rules.visibility.max_views = 5;
  // ... and the blur of noisy photographs: this clean render counts as noisy against a reference
  // of half its estimated noise (σ ≈ 0.55 pixels), so each view's blurred copy is made and read.
  photograph_rules.denoise.noise_reference = 0.5 * estimate_views_noise(make_photo_views(small_scene().scene));
  return {by_default, thesis_rules, optional_rules, photograph_rules};
}

void expect_same_bits(const RefineOptions& options) {
  const SmallScene& s = small_scene();
  RefineControl two, one;
  two.threads = 2;
  one.threads = 1;
  const RefineResult reference = refine_mesh(s.scene, s.initial, options, two);
  ASSERT_NE(reference.summary.status, RefineStatus::Failed) << reference.summary.message;
  std::size_t refined = 0;
  for (const IterationReport& r : reference.summary.iterations) refined += r.refined_faces;
  EXPECT_GT(refined, 0u) << "the case must exercise adaptive refinement";

  const RefineResult single = refine_mesh(s.scene, s.initial, options, one);
  RefineOptions other_blocks = options;
  other_blocks.block_size = 37;
  const RefineResult blocks = refine_mesh(s.scene, s.initial, other_blocks, two);
  RefineOptions sequential = options;
  sequential.engine = EngineKind::Sequential;
  const RefineResult plain = refine_mesh(s.scene, s.initial, sequential, two);

  if (options.denoise.noise_reference < 0.001) {
    EXPECT_GT(reference.summary.denoise_sigma, 0.0);
  }
  if (options.far.g_ratio > 0.0 && options.far.g_ratio < 10.0) {
    // Far vertices at the first resolution only, none after the first refinement.
    std::size_t far = 0;
    bool refined = false;
    for (const IterationReport& r : reference.summary.iterations) {
      if (refined) {
        EXPECT_EQ(r.far_vertices, 0u) << r.iteration;
      }
      far += r.far_vertices;
      refined = refined || r.refined_faces > 0;
    }
    EXPECT_GT(far, 0u) << "the case must exercise far vertices";
  }
  if (options.unobserved_displacement.implausible_g_ratio > 0.0 && options.unobserved_displacement.implausible_g_ratio < 10.0) {
    std::size_t implausible = 0;
    for (const IterationReport& r : reference.summary.iterations) implausible += r.implausible_g;
    EXPECT_GT(implausible, 0u) << "the case must exercise the implausible-g rule";
  }
  for (const RefineResult* other : {&single, &blocks, &plain}) {
    ASSERT_EQ(other->summary.iterations.size(), reference.summary.iterations.size());
    EXPECT_EQ(positions(*other), positions(reference));  // exact, not approximate
    EXPECT_EQ(triangles_of(other->mesh.topology), triangles_of(reference.mesh.topology));
    for (std::size_t i = 0; i < reference.summary.iterations.size(); ++i) {
      EXPECT_EQ(other->summary.iterations[i].sum_g, reference.summary.iterations[i].sum_g);
      EXPECT_EQ(other->summary.iterations[i].time_step, reference.summary.iterations[i].time_step);
      EXPECT_EQ(other->summary.iterations[i].surface_patch_g, reference.summary.iterations[i].surface_patch_g);
      EXPECT_EQ(other->summary.iterations[i].patch_switches, reference.summary.iterations[i].patch_switches);
      EXPECT_EQ(other->summary.iterations[i].far_vertices, reference.summary.iterations[i].far_vertices);
      EXPECT_EQ(other->summary.iterations[i].implausible_g, reference.summary.iterations[i].implausible_g);
      // NaN in the first iterations of each topology: compared as bits.
      EXPECT_EQ(std::bit_cast<std::uint64_t>(other->summary.iterations[i].net_move),
                std::bit_cast<std::uint64_t>(reference.summary.iterations[i].net_move));
      EXPECT_EQ(std::bit_cast<std::uint64_t>(other->summary.iterations[i].net_move_tail),
                std::bit_cast<std::uint64_t>(reference.summary.iterations[i].net_move_tail));
      EXPECT_EQ(std::bit_cast<std::uint64_t>(other->summary.iterations[i].net_move_persistence),
                std::bit_cast<std::uint64_t>(reference.summary.iterations[i].net_move_persistence));
    }
  }
}

// The implausible-g rule reports the vertices it takes for the background showing through and
// averages their speeds; it is off where the rims are fitted to silhouettes (they hold the outline
// there) or at ratio 0.
TEST(Refiner, ImplausibleGVerticesAreReportedAndAveragedOnlyWhereTheRimsAreNotFitted) {
  const SmallScene& s = small_scene();
  const auto run = [&](double ratio, RimFit fit, int rings) {
    RefineOptions options = few_iterations(8);
    options.unobserved_displacement.implausible_g_ratio = ratio;  // 3 × the median: many regions
    options.rims.fit = fit;
    options.implausible_speed.rings = rings;
    RefineResult result = refine_mesh(s.scene, s.initial, options, {});
    EXPECT_NE(result.summary.status, RefineStatus::Failed) << result.summary.message;
    return result;
  };
  const auto reported = [](const RefineResult& result) {
    std::size_t total = 0;
    for (const IterationReport& r : result.summary.iterations) total += r.implausible_g;
    return total;
  };
  const RefineResult averaged = run(3.0, RimFit::Off, 8), not_averaged = run(3.0, RimFit::Off, 0);
  EXPECT_GT(reported(averaged), 0u);
  EXPECT_GT(reported(not_averaged), 0u);  // counted whether or not they are averaged
  EXPECT_NE(positions(averaged), positions(not_averaged));
  const RefineResult rims = run(3.0, RimFit::On, 8);
  EXPECT_EQ(reported(rims), 0u);
  EXPECT_EQ(positions(rims), positions(run(3.0, RimFit::On, 0)));  // nothing averaged either
  EXPECT_EQ(reported(run(0.0, RimFit::Off, 8)), 0u);
}

// The far flags change what the next iteration reads: the runs with and without far vertices agree
// to the bit up to the first iteration that flags one, and Σg differs in the one after.
TEST(Refiner, FarVerticesReadOtherPhotographsFromTheIterationAfterTheyAreFlagged) {
  const SmallScene& s = small_scene();
  RefineOptions with = few_iterations(8);
  with.far.g_ratio = 3.0;
  RefineOptions without = with;
  without.far.g_ratio = 0.0;
  const RefineResult a = refine_mesh(s.scene, s.initial, with, {});
  const RefineResult b = refine_mesh(s.scene, s.initial, without, {});
  ASSERT_NE(a.summary.status, RefineStatus::Failed) << a.summary.message;
  std::size_t first = a.summary.iterations.size();
  for (std::size_t i = 0; i < a.summary.iterations.size(); ++i)
    if (a.summary.iterations[i].far_vertices > 0) {
      first = i;
      break;
    }
  ASSERT_LT(first + 1, a.summary.iterations.size()) << "no far vertex before the last iteration";
  for (std::size_t i = 0; i <= first; ++i) {
    EXPECT_EQ(a.summary.iterations[i].sum_g, b.summary.iterations[i].sum_g) << i;
    EXPECT_EQ(b.summary.iterations[i].far_vertices, 0u) << i;
  }
  EXPECT_NE(a.summary.iterations[first + 1].sum_g, b.summary.iterations[first + 1].sum_g);
}

TEST(Refiner, SameBitsForThreadsBlockSizesAndEngines) {
  for (const RefineOptions& options : determinism_cases()) expect_same_bits(options);
}

// One iteration's per-vertex state as RefineControl::on_vertex_fields hands it over: what the
// test keeps of each call.
struct VertexFieldsCall {
  int iteration = 0;
  double time_step = 0.0;
  std::vector<Eigen::Vector3d> positions;
  std::vector<double> g, moving_speed, moved, damping;
  std::size_t defined_g = 0, moving = 0, moved_without_speed = 0;
};

// A run of the small scene with its calls; it must not fail, and it calls once per iteration.
struct WatchedRun {
  RefineResult result;
  std::vector<VertexFieldsCall> calls;
};

WatchedRun refine_watching_vertex_fields(const RefineOptions& options, int threads) {
  WatchedRun run;
  std::vector<VertexFieldsCall>& calls = run.calls;
  RefineControl control;
  control.threads = threads;
  control.on_vertex_fields = [&](const IterationVertexFields& state) {
    VertexFieldsCall call;
    call.iteration = state.iteration;
    call.time_step = state.time_step;
    const VertexFields& f = *state.fields;
    for (std::size_t v = 0; v < state.mesh->n_vertices(); ++v) {
      call.positions.push_back(to_eigen(state.mesh->point(TriMesh::VertexHandle(static_cast<int>(v)))));
      call.g.push_back(f.photo_consistency[v]);
      call.defined_g += (f.defined[v] & kPhotoDefined) != 0;
      call.moving += (f.defined[v] & kSpeedDefined) != 0;
      call.moved_without_speed += !(f.defined[v] & (kSpeedDefined | kSpeedFilled)) && state.moved[v] != 0.0;
    }
    call.moving_speed.assign(state.moving_speed.begin(), state.moving_speed.end());
    call.moved.assign(state.moved.begin(), state.moved.end());
    call.damping.assign(state.damping_scale.begin(), state.damping_scale.end());
    calls.push_back(std::move(call));
  };
  run.result = refine_mesh(small_scene().scene, small_scene().initial, options, control);
  EXPECT_NE(run.result.summary.status, RefineStatus::Failed) << run.result.summary.message;
  EXPECT_EQ(run.calls.size(), run.result.summary.iterations.size());
  return run;
}

TEST(Refiner, HandsEachIterationsVertexFieldsToTheCaller) {
  // No split/collapse, refinement, untangling or averaging: the result is the last iterate, in the
  // initial mesh's vertex order.
  RefineOptions options = few_iterations(8);
  options.global_remeshing = false;
  options.adaptive_refinement = false;
  options.untangling.max_rounds = 0;
  options.stopping.average_last = 1;
  const WatchedRun run = refine_watching_vertex_fields(options, 2);
  ASSERT_FALSE(HasFailure());
  const auto& [result, calls] = run;
  const auto& reports = result.summary.iterations;
  std::size_t damped_steps = 0;
  for (std::size_t k = 0; k < calls.size(); ++k) {
    // Each call is its iteration's: the report counts the same vertices with g and with a speed.
    EXPECT_EQ(calls[k].iteration, static_cast<int>(k) + 1);
    EXPECT_EQ(calls[k].defined_g, reports[k].defined_g) << k;
    EXPECT_EQ(calls[k].moving, reports[k].moving) << k;
    EXPECT_EQ(calls[k].moved_without_speed, 0u) << k;
    ASSERT_EQ(calls[k].positions.size(), result.mesh.n_vertices());
    ASSERT_EQ(calls[k].moving_speed.size(), calls[k].positions.size());
    EXPECT_EQ(calls[k].moved.size(), calls[k].positions.size());
    EXPECT_EQ(calls[k].damping.size(), calls[k].positions.size());  // damping is on by default
    // The speed recorded is the one the vertices moved by: a step within the CFL bound is Δt·|F·N|
    // to the last bits (F is along N but at the few vertices of implausible g), also at the
    // vertices the damping slowed, whose speeds before it were 2–8 times longer.
    std::size_t moving = 0, matching = 0, damped = 0, damped_matching = 0;
    for (std::size_t v = 0; v < calls[k].moved.size(); ++v) {
      if (calls[k].moved[v] == 0.0) continue;
      const bool match = std::abs(calls[k].moved[v] - calls[k].time_step * std::abs(calls[k].moving_speed[v])) <=
                         1e-12 * calls[k].moved[v];
      ++moving, matching += match;
      if (calls[k].damping[v] < 1.0) ++damped, damped_matching += match;
    }
    EXPECT_GT(moving, 0u) << k;
    EXPECT_GT(matching, moving / 2) << k << ": " << matching << " of " << moving << " steps are Δt·|F·N|";
    EXPECT_TRUE(damped == 0 || 2 * damped_matching > damped)
        << k << ": " << damped_matching << " of " << damped << " damped steps are Δt·|F·N|";
    damped_steps += damped;
  }
  EXPECT_GT(damped_steps, 0u) << "the case must exercise the damping";
  for (std::size_t v = 0; v < result.mesh.n_vertices(); ++v)
    ASSERT_EQ(calls.back().positions[v], result.mesh.position(v)) << "vertex " << v;

  // The same bits with one thread as with two.
  const WatchedRun single = refine_watching_vertex_fields(options, 1);
  const std::vector<VertexFieldsCall>& one = single.calls;
  ASSERT_EQ(one.size(), calls.size());
  for (std::size_t k = 0; k < calls.size(); ++k) {
    EXPECT_EQ(one[k].positions, calls[k].positions) << k;
    EXPECT_EQ(one[k].g, calls[k].g) << k;
    EXPECT_EQ(one[k].moving_speed, calls[k].moving_speed) << k;
    EXPECT_EQ(one[k].moved, calls[k].moved) << k;
    EXPECT_EQ(one[k].damping, calls[k].damping) << k;
  }
}

TEST(Refiner, VertexFieldsFollowTheRefinementsAndTheSequentialEngine) {
  // Coarse to fine: a call comes before its iteration's refinement, so it has the vertices the
  // report counts for that iteration, and the next call those of the refined mesh.
  RefineOptions options = converging_early(24);
  options.engine = EngineKind::Sequential;
  const WatchedRun run = refine_watching_vertex_fields(options, 2);
  ASSERT_FALSE(HasFailure());
  const auto& reports = run.result.summary.iterations;
  const auto& calls = run.calls;
  std::size_t refinements = 0;
  for (std::size_t k = 0; k < calls.size(); ++k) {
    EXPECT_EQ(calls[k].positions.size(), reports[k].vertices) << k;
    EXPECT_EQ(calls[k].moving_speed.size(), reports[k].vertices) << k;
    EXPECT_EQ(calls[k].damping.size(), reports[k].vertices) << k;
    EXPECT_EQ(calls[k].defined_g, reports[k].defined_g) << k;
    if (reports[k].stop.starts_with("refined") && k + 1 < calls.size()) {
      ++refinements;
      EXPECT_GT(calls[k + 1].positions.size(), calls[k].positions.size()) << k;
    }
  }
  EXPECT_GT(refinements, 0u) << "the case must refine within the run";
}

TEST(Refiner, MovesTheInitialMeshTowardTheTruth) {
  const SmallScene& s = small_scene();
  RefineOptions options = few_iterations(40);
  options.block_size = 128;
  const RefineResult result = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_NE(result.summary.status, RefineStatus::Failed) << result.summary.message;
  EvaluationOptions evaluation;
  evaluation.samples = 30000;
  const EvaluationResult before = evaluate_against_truth(to_indexed(s.initial), s.truth, evaluation);
  const EvaluationResult after = evaluate_against_truth(to_indexed(result.mesh), s.truth, evaluation);
  std::printf("[measured] %zu iterations (%s): mean distance %.4g -> %.4g, accuracy(90%%) %.4g -> %.4g, "
              "Σg/vertex %.4g -> %.4g, vertices %zu -> %zu, self-intersections %zu\n",
              result.summary.iterations.size(), to_string(result.summary.status), before.symmetric_mean(),
              after.symmetric_mean(), before.accuracy(), after.accuracy(), result.summary.initial_sum_g_per_vertex,
              result.summary.final_sum_g_per_vertex, result.summary.initial_vertices, result.summary.final_vertices,
              result.summary.self_intersections);
  // Measured (this scene, 40 iterations, 300 → 3827 vertices): mean 0.0294 → 0.0048, accuracy
  // 0.0526 → 0.0091. tests/quality_test.cpp checks the full pipeline on the README's scenes.
  EXPECT_LT(after.symmetric_mean(), 0.5 * before.symmetric_mean());
  EXPECT_LT(after.accuracy(), 0.5 * before.accuracy());
  EXPECT_LT(result.summary.final_sum_g_per_vertex, result.summary.initial_sum_g_per_vertex);
  EXPECT_EQ(result.summary.self_intersections, 0u);
  // The summary's initial counts are the given mesh's, not the split/collapsed one's (which the
  // first iteration reports, and which differs).
  EXPECT_NE(result.summary.iterations.front().vertices, s.initial.n_vertices());
  EXPECT_EQ(result.summary.initial_vertices, s.initial.n_vertices());
  EXPECT_EQ(result.summary.initial_faces, s.initial.n_faces());
  EXPECT_EQ(result.mesh.quality.size(), result.mesh.n_vertices());
  EXPECT_EQ(result.mesh.colors.size(), result.mesh.n_vertices());
}

TEST(Refiner, ReportsTheVerticesWhoseGLaidItsPatchOnTheSurfaceAndTheSwitches) {
  const SmallScene& s = small_scene();
  const auto run = [&](SurfacePatchUse use) {
    RefineOptions options = few_iterations(8);
    options.photo.photo.surface_patch = use;
    const RefineResult result = refine_mesh(s.scene, s.initial, options, {});
    EXPECT_NE(result.summary.status, RefineStatus::Failed) << result.summary.message;
    EXPECT_FALSE(result.summary.iterations.empty());
    return result.summary.iterations;
  };
  for (const IterationReport& r : run(SurfacePatchUse::On)) {
    EXPECT_GT(r.defined_g, 0u);
    EXPECT_EQ(r.surface_patch_g, r.defined_g) << r.iteration;
    EXPECT_EQ(r.patch_switches, 0u) << r.iteration;
  }
  for (const IterationReport& r : run(SurfacePatchUse::Off)) {
    EXPECT_EQ(r.surface_patch_g, 0u) << r.iteration;
    EXPECT_EQ(r.patch_switches, 0u) << r.iteration;
  }
  // The ring of 16 views sees the poles obliquely: some vertices of each kind, and some switch as
  // the normals change (none in the first iteration, which has nothing to switch from).
  const std::vector<IterationReport> oblique = run(SurfacePatchUse::Oblique);
  EXPECT_EQ(oblique.front().patch_switches, 0u);
  std::size_t switches = 0;
  for (const IterationReport& r : oblique) {
    EXPECT_GT(r.surface_patch_g, 0u) << r.iteration;
    EXPECT_LT(r.surface_patch_g, r.defined_g) << r.iteration;
    switches += r.patch_switches;
  }
  EXPECT_GT(switches, 0u);
}

TEST(Refiner, RefinesCoarseToFineWhenTheFlowHasConverged) {
  const SmallScene& s = small_scene();
  RefineOptions options = converging_early(16);
  const RefineResult result = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_NE(result.summary.status, RefineStatus::Failed) << result.summary.message;
  const auto& iterations = result.summary.iterations;
  ASSERT_LE(iterations.size(), 16u);  // the budget counts over the restarts
  std::size_t refinements = 0;
  for (std::size_t i = 0; i < iterations.size(); ++i) {
    if (!iterations[i].stop.starts_with("refined (")) continue;
    ++refinements;
    EXPECT_GT(iterations[i].refined_faces, 0u);
    // The stopping rules start afresh: the next refinement comes min_iterations later at the earliest.
    for (std::size_t j = i + 1; j < std::min(iterations.size(), i + 6); ++j)
      EXPECT_FALSE(iterations[j].stop.starts_with("refined")) << j;
    if (i + 1 < iterations.size()) {
      EXPECT_GT(iterations[i + 1].vertices, iterations[i].vertices);
    }
  }
  EXPECT_GE(refinements, 1u);
  EXPECT_EQ(result.mesh.n_vertices(), iterations.back().vertices);
}

TEST(Refiner, CoarserImagesFirstThenTheFullOnesThenRefinement) {
  const SmallScene& s = small_scene();
  RefineOptions options = converging_early(20);
  options.image_levels = 2;
  const RefineResult result = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_NE(result.summary.status, RefineStatus::Failed) << result.summary.message;
  const auto& iterations = result.summary.iterations;
  std::vector<std::size_t> finer, refined;
  for (std::size_t i = 0; i < iterations.size(); ++i) {
    if (iterations[i].stop.starts_with("finer images (")) finer.push_back(i);
    if (iterations[i].stop.starts_with("refined (")) refined.push_back(i);
  }
  // Quarter, then half, then full resolution, each after the flow settled; the mesh is refined
  // only after that, and switching images does not change it.
  ASSERT_EQ(finer.size(), 2u);
  EXPECT_GE(finer[0], 5u);
  EXPECT_GE(finer[1], finer[0] + 6);
  for (const std::size_t i : finer) {
    EXPECT_EQ(iterations[i].refined_faces, 0u);
    if (i + 1 < iterations.size()) {
      EXPECT_EQ(iterations[i + 1].vertices, iterations[i].vertices);
    }
  }
  ASSERT_FALSE(refined.empty());
  for (const std::size_t i : refined) EXPECT_GT(i, finer[1]);
}

TEST(Refiner, ARefinementBelowTheMinimumGrowthEndsTheRun) {
  // Reference: every refinement done (min_growth 0). The first refinement that adds fewer than
  // 60 % vertices adds `added` to `before`; the ones before it grew the mesh more.
  const SmallScene& s = small_scene();
  RefineOptions options = converging_early(24);
  options.adaptive.min_growth = 0.0;
  const RefineResult every = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_NE(every.summary.status, RefineStatus::Failed) << every.summary.message;
  const auto& iterations = every.summary.iterations;
  std::size_t first = 0, before = 0, added = 0;
  double growth = 0.0, earlier_growth = INFINITY;
  for (; first + 1 < iterations.size(); ++first) {
    if (!iterations[first].stop.starts_with("refined (")) continue;
    before = iterations[first].vertices;
    added = iterations[first + 1].vertices - before;
    growth = static_cast<double>(added) / static_cast<double>(before);
    std::printf("[measured] refinement after iteration %zu: %zu -> %zu vertices (growth %.3f)\n", first + 1, before,
                before + added, growth);
    if (growth < 0.6) break;
    earlier_growth = std::min(earlier_growth, growth);
  }
  ASSERT_LT(first + 1, iterations.size()) << "no refinement below 60 % followed by an iteration";
  ASSERT_GT(earlier_growth, 1.5 * growth);

  // A minimum just above that growth declines it: the run ends there, "converged", with the mesh
  // of the same iterations without refinement (a run whose budget ends at that iteration).
  options.adaptive.min_growth = 1.5 * growth;
  const RefineResult declined = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_EQ(declined.summary.status, RefineStatus::Converged) << declined.summary.message;
  ASSERT_EQ(declined.summary.iterations.size(), first + 1);
  EXPECT_EQ(declined.summary.iterations.back().declined_vertices, added);
  EXPECT_EQ(declined.summary.iterations.back().refined_faces, 0u);
  EXPECT_EQ(declined.summary.iterations.back().stop, "converged");
  RefineOptions budget = options;
  budget.adaptive.min_growth = 0.0;
  budget.stopping.max_iterations = static_cast<int>(first + 1);
  budget.stopping.min_iterations = std::min(budget.stopping.min_iterations, budget.stopping.max_iterations);
  const RefineResult unrefined = refine_mesh(s.scene, s.initial, budget, {});
  EXPECT_EQ(positions(declined), positions(unrefined));

  // A minimum just below it refines exactly as the reference.
  options.adaptive.min_growth = 0.5 * growth;
  const RefineResult accepted = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_GT(accepted.summary.iterations.size(), first + 1);
  EXPECT_EQ(accepted.summary.iterations[first + 1].vertices, before + added);
  EXPECT_EQ(accepted.summary.iterations[first].declined_vertices, 0u);
}

// StoppingOptions::finest_min_iterations: the finest resolution's stops are held until it has run
// that many iterations; the coarser resolutions stop as before, so the run is the same up to the
// finest resolution's first stop.
TEST(Refiner, TheFinestResolutionRunsAtLeastItsMinimum) {
  const SmallScene& s = small_scene();
  RefineOptions options = converging_early(40);
  const RefineResult early = refine_mesh(s.scene, s.initial, options, {});
  options.stopping.finest_min_iterations = 12;
  const RefineResult held = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_NE(early.summary.status, RefineStatus::Failed) << early.summary.message;
  ASSERT_NE(held.summary.status, RefineStatus::Failed) << held.summary.message;
  const auto last_level_start = [](const std::vector<IterationReport>& iterations) {
    std::size_t start = 0;  // index of the first iteration of the last resolution
    for (std::size_t i = 0; i + 1 < iterations.size(); ++i)
      if (iterations[i].stop.starts_with("refined (")) start = i + 1;
    return start;
  };
  const auto& a = early.summary.iterations;
  const auto& b = held.summary.iterations;
  const std::size_t start = last_level_start(a);
  ASSERT_GT(start, 0u) << "no refinement";
  ASSERT_EQ(last_level_start(b), start);
  EXPECT_LT(a.size() - start, 12u);  // without the minimum the finest resolution stops earlier
  ASSERT_EQ(b.size() - start, 12u);  // with it, after exactly 12 (every rule fires as soon as it may)
  for (std::size_t i = 0; i < a.size() - 1; ++i) EXPECT_EQ(a[i].sum_g, b[i].sum_g) << "iteration " << i + 1;
  EXPECT_TRUE(b[a.size() - 1].stop.starts_with("held (")) << b[a.size() - 1].stop;
  EXPECT_EQ(held.summary.status, early.summary.status);
}

// StoppingOptions::run_on: the same run to its stop, then exactly run_on iterations more at that
// resolution with every rule off, ending with the stop's status.
TEST(Refiner, RunningOnGoesOnFromTheStopAtItsResolution) {
  const SmallScene& s = small_scene();
  RefineOptions options = converging_early(24);
  const RefineResult stopped = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_TRUE(stopped.summary.status == RefineStatus::Converged || stopped.summary.status == RefineStatus::Settled)
      << to_string(stopped.summary.status);
  const auto& before = stopped.summary.iterations;
  const std::size_t stop = before.size();
  ASSERT_LT(stop, 24u);

  options.stopping.run_on = 4;
  const RefineResult ran_on = refine_mesh(s.scene, s.initial, options, {});
  EXPECT_EQ(ran_on.summary.status, stopped.summary.status);
  const auto& after = ran_on.summary.iterations;
  ASSERT_EQ(after.size(), stop + 4);
  for (std::size_t i = 0; i + 1 < stop; ++i) {  // the same run up to the stop, bit for bit
    EXPECT_EQ(after[i].sum_g, before[i].sum_g) << "iteration " << i + 1;
    EXPECT_EQ(after[i].stop, before[i].stop) << "iteration " << i + 1;
  }
  EXPECT_EQ(after[stop - 1].sum_g, before[stop - 1].sum_g);
  EXPECT_EQ(after[stop - 1].stop, "run on (" + before[stop - 1].stop + ")");
  for (std::size_t i = stop; i < after.size(); ++i) {
    EXPECT_EQ(after[i].stop, "running on") << "iteration " << i + 1;
    EXPECT_EQ(after[i].vertices, before.back().vertices) << "iteration " << i + 1;  // nothing refined
    EXPECT_EQ(after[i].refined_faces, 0u) << "iteration " << i + 1;
  }
  EXPECT_NE(positions(ran_on), positions(stopped));  // the flow went on

  // A budget that ends at the stop does not bound the running on: every stop gets as many more.
  options.stopping.max_iterations = static_cast<int>(stop);
  const RefineResult at_budget = refine_mesh(s.scene, s.initial, options, {});
  EXPECT_EQ(at_budget.summary.iterations.size(), stop + 4);
  EXPECT_EQ(at_budget.summary.status, stopped.summary.status);
}

// StoppingOptions::average_last: the result is the mean of the last iterates. Runs of K − 1 and
// K iterations give those two iterates (no rule may fire earlier, nothing is refined), so the run
// of K iterations averaging 2 must return their mean, vertex by vertex.
TEST(Refiner, TheResultIsTheMeanOfTheLastIterates) {
  const SmallScene& s = small_scene();
  const auto run = [&](int iterations, int average_last) {
    RefineOptions options = few_iterations(iterations);
    options.stopping.min_iterations = iterations;  // no stop, so no refinement, before the budget
    options.stopping.average_last = average_last;
    const RefineResult result = refine_mesh(s.scene, s.initial, options, {});
    EXPECT_NE(result.summary.status, RefineStatus::Failed) << result.summary.message;
    EXPECT_EQ(result.summary.iterations.size(), static_cast<std::size_t>(iterations));
    return result;
  };
  const RefineResult last = run(8, 1), before_last = run(7, 1), averaged = run(8, 2);
  ASSERT_EQ(last.summary.iterations.back().vertices, before_last.summary.iterations.back().vertices);
  EXPECT_EQ(last.summary.untangled_pairs, 0u);  // the end's untangling moved nothing
  const std::vector<Eigen::Vector3d> a = positions(last), b = positions(before_last), mean = positions(averaged);
  ASSERT_EQ(mean.size(), a.size());
  double largest_step = 0.0;
  for (std::size_t v = 0; v < a.size(); ++v) {
    EXPECT_EQ(mean[v], ((a[v] + b[v]) / 2.0).eval()) << "vertex " << v;
    largest_step = std::max(largest_step, (a[v] - b[v]).norm());
  }
  EXPECT_GT(largest_step, 0.0);  // the two iterates differ: the mean is not either of them
}

// The iterates averaged are of one set of images: a switch to finer images (image_levels) starts
// them afresh, so a run whose budget ends one iteration after the switch ends on its last iterate.
TEST(Refiner, SwitchingToFinerImagesStartsTheAveragingAfresh) {
  const SmallScene& s = small_scene();
  RefineOptions options = converging_early(30);
  options.image_levels = 1;
  options.adaptive_refinement = false;
  const RefineResult probe = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_NE(probe.summary.status, RefineStatus::Failed) << probe.summary.message;
  std::size_t switched = 0;  // iterations up to and including the switch
  for (const IterationReport& r : probe.summary.iterations)
    if (r.stop.starts_with("finer images (")) switched = static_cast<std::size_t>(r.iteration);
  ASSERT_GT(switched, 0u) << "no switch to the full images";
  options.stopping.max_iterations = static_cast<int>(switched) + 1;
  options.stopping.average_last = 2;
  const RefineResult averaged = refine_mesh(s.scene, s.initial, options, {});
  options.stopping.average_last = 1;
  const RefineResult last = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_EQ(averaged.summary.iterations.size(), switched + 1);
  EXPECT_TRUE(averaged.summary.iterations[switched - 1].stop.starts_with("finer images ("));
  EXPECT_EQ(positions(averaged), positions(last));
}

// With the refinement before every iteration, a run whose last iteration refined has one iterate
// of its last topology: the result is that iterate, as without averaging.
TEST(Refiner, ARefinementAtTheLastIterationLeavesTheLastIterate) {
  const SmallScene& s = small_scene();
  RefineOptions options = few_iterations(6);  // its 6th iteration refines
  options.stopping.min_iterations = 6;
  options.refinement_schedule = RefinementSchedule::EveryIteration;
  options.stopping.average_last = 2;
  const RefineResult averaged = refine_mesh(s.scene, s.initial, options, {});
  options.stopping.average_last = 1;
  const RefineResult last = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_EQ(averaged.summary.iterations.size(), 6u) << averaged.summary.message;
  ASSERT_GT(averaged.summary.iterations.back().refined_faces, 0u) << "the last iteration did not refine";
  EXPECT_EQ(positions(averaged), positions(last));
}

// Running on refines nothing with the refinement before every iteration either.
TEST(Refiner, RunningOnRefinesNothingWithTheEveryIterationSchedule) {
  const SmallScene& s = small_scene();
  RefineOptions options = converging_early(24);
  options.refinement_schedule = RefinementSchedule::EveryIteration;
  options.stopping.run_on = 3;
  const RefineResult result = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_NE(result.summary.status, RefineStatus::Failed) << result.summary.message;
  const auto& iterations = result.summary.iterations;
  std::size_t stop = 0;
  for (std::size_t i = 0; i < iterations.size(); ++i)
    if (iterations[i].stop.starts_with("run on (")) stop = i;
  ASSERT_GT(stop, 0u) << "no rule fired within the budget";
  ASSERT_EQ(iterations.size(), stop + 4);
  bool refined_before = false;
  for (std::size_t i = 0; i <= stop; ++i) refined_before |= iterations[i].refined_faces > 0;
  EXPECT_TRUE(refined_before);  // the schedule refines while the flow runs
  for (std::size_t i = stop + 1; i < iterations.size(); ++i) {
    EXPECT_EQ(iterations[i].stop, "running on");
    EXPECT_EQ(iterations[i].refined_faces, 0u) << "iteration " << i + 1;
    EXPECT_EQ(iterations[i].vertices, iterations[stop].vertices) << "iteration " << i + 1;
  }
}

// A cancel while running on ends the run at once, "cancelled", as anywhere else.
TEST(Refiner, CancelWhileRunningOnStopsBeforeTheNextIteration) {
  const SmallScene& s = small_scene();
  RefineOptions options = converging_early(24);
  options.stopping.run_on = 10;
  std::atomic<bool> cancel{false};
  int running_on = 0;
  RefineControl control;
  control.cancel = &cancel;
  control.on_iteration = [&](const IterationReport& report) {
    if (report.stop == "running on" && ++running_on == 2) cancel = true;
  };
  const RefineResult result = refine_mesh(s.scene, s.initial, options, control);
  EXPECT_EQ(result.summary.status, RefineStatus::Cancelled);
  ASSERT_EQ(running_on, 2);
  EXPECT_EQ(result.summary.iterations.back().stop, "running on");
}

// The summary counts each fold the untangling removed once. A run that ends at its first stop
// (no refinement) untangles there, before it knows it ends, and again at its end, on the mean of
// the iterates recorded before the stop's untangling: only the end's removal counts, so the count
// is the folds of the same run without untangling less those left. The CFL number 8 folds the
// small scene within its 6 iterations.
// Either way the stop's positions are dropped: replaced by the mean, or, where the stop spread the
// unobserved vertices, restored to the flowed ones before the spread and the untangling.
TEST(Refiner, FoldsUntangledAtTheLastStopAreCountedOnce) {
  const SmallScene& s = small_scene();
  for (const UnobservedSpread spread : {UnobservedSpread::Off, UnobservedSpread::On}) {
    RefineOptions options = converging_early(30);
    options.adaptive_refinement = false;
    options.cfl = 8.0;
    options.unobserved_displacement.spread = spread;
    options.untangling.max_rounds = 0;
    const RefineResult folded = refine_mesh(s.scene, s.initial, options, {});
    options.untangling.max_rounds = 10;
    const RefineResult untangled = refine_mesh(s.scene, s.initial, options, {});
    ASSERT_EQ(untangled.summary.status, RefineStatus::Converged) << untangled.summary.message;
    ASSERT_EQ(untangled.summary.iterations.size(), folded.summary.iterations.size());
    ASSERT_GT(folded.summary.self_intersections, 0u) << "no fold to untangle";
    EXPECT_EQ(untangled.summary.untangled_pairs,
              folded.summary.self_intersections - untangled.summary.self_intersections)
        << "spread " << static_cast<int>(spread);
    // Keeping the last iterate, the stop's own untangling counts: it did find folds.
    options.stopping.average_last = 1;
    const RefineResult last = refine_mesh(s.scene, s.initial, options, {});
    EXPECT_GT(last.summary.untangled_pairs, 0u) << "spread " << static_cast<int>(spread);
  }
}

// A stop that untangled and was held (finest_min_iterations) lets the flow go on from the
// untangled positions; a mean reaching back across that untangling would undo half of it, so a
// run that ends one iteration later keeps its last iterate, as without averaging.
TEST(Refiner, TheMeanDoesNotReachBackAcrossAStopsUntangling) {
  const SmallScene& s = small_scene();
  RefineOptions options = converging_early(30);
  options.adaptive_refinement = false;
  options.cfl = 8.0;  // folds within the first 6 iterations (above)
  options.unobserved_displacement.spread = UnobservedSpread::Off;
  options.stopping.finest_min_iterations = 7;  // the stop at 6 is held once
  const RefineResult averaged = refine_mesh(s.scene, s.initial, options, {});
  options.stopping.average_last = 1;
  const RefineResult last = refine_mesh(s.scene, s.initial, options, {});
  ASSERT_EQ(averaged.summary.iterations.size(), 7u) << averaged.summary.message;
  EXPECT_TRUE(averaged.summary.iterations[5].stop.starts_with("held (")) << averaged.summary.iterations[5].stop;
  EXPECT_GT(last.summary.untangled_pairs, 0u);  // the stop untangled
  EXPECT_EQ(positions(averaged), positions(last));
  EXPECT_EQ(averaged.summary.untangled_pairs, last.summary.untangled_pairs);
}

TEST(Refiner, CancelFromOnIterationStopsBeforeTheNextIteration) {
  const SmallScene& s = small_scene();
  std::atomic<bool> cancel{false};
  RefineControl control;
  control.cancel = &cancel;
  control.on_iteration = [&](const IterationReport& report) {
    if (report.iteration == 2) cancel = true;
  };
  const RefineResult result = refine_mesh(s.scene, s.initial, few_iterations(50), control);
  EXPECT_EQ(result.summary.status, RefineStatus::Cancelled);
  EXPECT_EQ(result.summary.iterations.size(), 2u);
}

// The block kernels of one whole iteration: iteration 1 of a run that stops after it.
std::size_t blocks_of_one_iteration(const SmallScene& s, const RefineOptions& options, RefineControl control) {
  std::atomic<bool> cancel{false};
  std::atomic<std::size_t> blocks{0};
  std::size_t whole = 0;
  control.cancel = &cancel;
  control.on_block = [&](std::size_t) { ++blocks; };
  control.on_iteration = [&](const IterationReport& report) {
    whole = blocks;
    cancel = true;
    std::printf("[measured] one iteration of %zu vertices: %zu block kernels, %.3f s (%d threads)\n", report.vertices,
                whole, report.seconds, control.threads);
  };
  refine_mesh(s.scene, s.initial, options, control);
  return whole;
}

// The flag is set by another thread while iteration 1 runs, a quarter into its block kernels
// (test::CancelProbe holds one engine thread at that block until the flag is set): the iteration
// must not finish, and only the kernels that had started by then may still complete: with one
// thread (or the sequential engine) none; with two, the other thread's, plus any kernel a
// thread left waiting inside a photo block's nested loop to take another block (measured: 1 in
// 40 runs; the bound allows 2 × threads). Without the kernels' cancel checks the rest of the
// iteration runs: thousands of blocks.
TEST(Refiner, CancelFromAnotherThreadStopsTheRunningIteration) {
  const SmallScene& s = large_scene();
  struct Case {
    EngineKind engine;
    int threads;
    std::size_t most_after;  // blocks that may complete after the flag was set
  };
  std::size_t whole = 0;
  for (const Case c : {Case{EngineKind::Graph, 2, 4}, Case{EngineKind::Graph, 1, 0}, Case{EngineKind::Sequential, 2, 0}}) {
    RefineOptions options = few_iterations(50);
    options.engine = c.engine;
    RefineControl control;
    control.threads = c.threads;
    if (whole == 0) whole = blocks_of_one_iteration(s, options, control);  // the same blocks for every case
    ASSERT_GT(whole, 2000u);

    std::atomic<bool> cancel{false};
    test::CancelProbe probe(whole / 4, [&] { cancel = true; });
    int iterations = 0;
    control.cancel = &cancel;
    control.on_block = probe.hook();
    control.on_iteration = [&](const IterationReport&) { ++iterations; };
    const RefineResult result = refine_mesh(s.scene, s.initial, options, control);
    probe.finish();
    SCOPED_TRACE(std::string(c.engine == EngineKind::Graph ? "graph" : "sequential") + ", " +
                 std::to_string(c.threads) + " threads");
    std::printf("[measured] cancelled at block %zu of %zu: %zu blocks completed after the flag was set\n", whole / 4,
                whole, probe.after_cancel());
    ASSERT_TRUE(probe.fired());
    EXPECT_EQ(result.summary.status, RefineStatus::Cancelled) << result.summary.message;
    EXPECT_TRUE(result.summary.iterations.empty());
    EXPECT_EQ(iterations, 0);
    EXPECT_LT(probe.reported(), whole);  // the iteration did not run all its blocks
    EXPECT_LE(probe.after_cancel(), c.most_after);
  }
}

TEST(Refiner, BadInputIsAFailedStatusNotAnException) {
  const SmallScene& s = small_scene();
  RefineOptions options = few_iterations(6);
  options.excluded_views = {42};
  const RefineResult result = refine_mesh(s.scene, s.initial, options, {});
  EXPECT_EQ(result.summary.status, RefineStatus::Failed);
  EXPECT_NE(result.summary.message.find("excluded view 42"), std::string::npos) << result.summary.message;
  // Every view but one excluded: refused before any image is decoded, naming the counts.
  options.excluded_views.clear();
  for (int v = 1; v < static_cast<int>(s.scene.size()); ++v) options.excluded_views.push_back(v);
  const RefineResult one_left = refine_mesh(s.scene, s.initial, options, {});
  EXPECT_EQ(one_left.summary.status, RefineStatus::Failed);
  EXPECT_NE(one_left.summary.message.find("fewer than 2 views are left to refine with (" +
                                          std::to_string(s.scene.size()) + " views, " +
                                          std::to_string(s.scene.size() - 1) + " excluded)"),
            std::string::npos)
      << one_left.summary.message;
  options.excluded_views = {};
  options.cfl = -1;
  EXPECT_EQ(refine_mesh(s.scene, s.initial, options, {}).summary.status, RefineStatus::Failed);
}

TEST(Refiner, OfSeveralBadImagesTheFirstInViewOrderIsReportedAtAnyThreadCount) {
  const SmallScene& s = small_scene();
  // Views 3, 5 and 9 fail to decode; view 3 fails only once another has (or after a second, when
  // no other thread decodes meanwhile), so a refinement that reported whichever failure came first
  // in time would name 5 or 9 at 2 threads.
  std::atomic<bool> later_view_failed{false};
  Scene scene = s.scene;
  scene.images = std::make_shared<ImageStore>(scene.size(), [&](std::size_t view) -> Image {
    if (view == 3)
      for (int waited = 0; waited < 100 && !later_view_failed; ++waited)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (view == 5 || view == 9) later_view_failed = true;
    if (view == 3 || view == 5 || view == 9) throw InputError("image of view " + std::to_string(view) + " is bad");
    return s.scene.image(view);
  });
  for (int threads : {1, 2}) {
    RefineControl control;
    control.threads = threads;
    const RefineResult result = refine_mesh(scene, s.initial, few_iterations(6), control);
    EXPECT_EQ(result.summary.status, RefineStatus::Failed);
    EXPECT_NE(result.summary.message.find("image of view 3 is bad"), std::string::npos)
        << threads << " threads: " << result.summary.message;
  }
}

TEST(Refiner, AnExcludedViewsPhotographIsNeverDecoded) {
  // View 4's photograph is broken but held out: the refinement runs, and never asks for it.
  const SmallScene& s = small_scene();
  std::atomic<int> asked_for_4{0};
  Scene scene = s.scene;
  scene.images = std::make_shared<ImageStore>(scene.size(), [&](std::size_t view) -> Image {
    if (view == 4) {
      ++asked_for_4;
      throw InputError("image of view 4 is bad");
    }
    return s.scene.image(view);
  });
  RefineOptions options = few_iterations(6);
  options.excluded_views = {4};
  const RefineResult result = refine_mesh(scene, s.initial, options, {});
  EXPECT_NE(result.summary.status, RefineStatus::Failed) << result.summary.message;
  EXPECT_EQ(asked_for_4.load(), 0);
}

TEST(Refiner, ABadImageIsReportedBeforeABadMeshWhileBothArePrepared) {
  // The mesh is prepared while the images are decoded; the errors keep the serial order.
  const SmallScene& s = small_scene();
  Mesh degenerate = s.initial;  // vertex 1 moved onto a neighbour: an edge of length zero
  TriMesh& mesh = degenerate.topology;
  const auto v1 = TriMesh::VertexHandle(1);
  mesh.set_point(v1, mesh.point(*mesh.vv_begin(v1)));
  Scene bad_images = s.scene;
  bad_images.images = std::make_shared<ImageStore>(s.scene.size(), [&s](std::size_t view) -> Image {
    if (view == 2) throw InputError("image of view 2 is bad");
    return s.scene.image(view);
  });
  RefineControl control;
  control.threads = 2;
  const RefineResult both = refine_mesh(bad_images, degenerate, few_iterations(6), control);
  EXPECT_EQ(both.summary.status, RefineStatus::Failed);
  EXPECT_NE(both.summary.message.find("image of view 2 is bad"), std::string::npos) << both.summary.message;
  const RefineResult mesh_only = refine_mesh(s.scene, degenerate, few_iterations(6), control);
  EXPECT_EQ(mesh_only.summary.status, RefineStatus::Failed);
  EXPECT_NE(mesh_only.summary.message.find("edge of length zero"), std::string::npos) << mesh_only.summary.message;
}

}  // namespace
}  // namespace mvflow
