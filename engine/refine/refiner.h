#pragma once
// The whole refinement (thesis §5.3.4, SPEC §3–§5): global split/collapse, smoothing and
// regularization once, then iterations of adaptive refinement and the flow until a stopping
// rule fires. Runs inside a task arena of its own with the requested thread count.

#include <atomic>
#include <functional>
#include <memory>

#include <spdlog/logger.h>

#include "engine/model/iteration_vertex_fields.h"
#include "engine/model/mesh.h"
#include "engine/model/refine_report.h"
#include "engine/model/scene.h"
#include "engine/refine/refine_options.h"

namespace mvflow {

//! What a run is doing (RefineProgress::stage; the worker's JobProgress adds Loading).
enum class RefineStage { Preparing, Iterating, Finishing };
const char* to_string(RefineStage stage);  //!< "preparing", "iterating", "finishing"

//! Where the refinement stands, for progress displays.
struct RefineProgress {
  int iteration = 0;          //!< 0 while preparing
  int max_iterations = 0;     //!< the budget, plus StoppingOptions::run_on: no run goes past it
  std::size_t vertices = 0;
  double sum_g_per_vertex = 0.0;
  RefineStage stage = RefineStage::Preparing;
};

//! How the caller steers and watches a run. Everything is optional.
struct RefineControl {
  int threads = 0;                                     //!< 0: every core
  std::shared_ptr<spdlog::logger> logger;              //!< null: no log lines
  const std::atomic<bool>* cancel = nullptr;           //!< set to stop at the next block
  std::function<void(const IterationReport&)> on_iteration;
  //! After each vertex block's kernel (any stage) of an iteration, with the block's index. Runs on
  //! the engine's threads, several at once: keep it short and thread-safe.
  std::function<void(std::size_t block)> on_block;
  std::function<void(const RefineProgress&)> on_progress;
  //! After each iteration, before its IterationReport's callbacks, serially (one call at a time,
  //! between iterations, on one of the run's threads): every vertex's state (IterationVertexFields).
  //! An exception from it fails the run. Costs nothing when empty; `refine --dump-fields`.
  std::function<void(const IterationVertexFields&)> on_vertex_fields;
};

struct RefineResult {
  RefineSummary summary;
  //! The refined surface with per-vertex colour (mean of the visible views) and quality (g).
  //! Its vertices are in the Morton order of their positions whenever the split/collapse or an
  //! adaptive refinement ran (order_vertices_by_locality), else in the initial mesh's order.
  Mesh mesh;
};

//! Refines \p initial against \p scene. Never throws for bad data: the summary says Failed with
//! the message (InputError's text names the file or element); Cancelled when \p control.cancel
//! was set. Bit-identical results for any thread count, block size and engine kind.
RefineResult refine_mesh(const Scene& scene, const Mesh& initial, const RefineOptions& options,
                         const RefineControl& control = {});

}  // namespace mvflow
