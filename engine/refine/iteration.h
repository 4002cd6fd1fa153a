#pragma once
// One deformation iteration (SPEC §3–§6) cut into per-block kernels. The flow graph
// (engine/refine/iteration_graph.h) and the sequential path call exactly these functions, so both give
// the same bits: every kernel writes only its own block's entries, and sums over blocks are
// combined in block order.

#include <array>
#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "engine/model/mesh.h"
#include "engine/model/mesh_stats.h"
#include "engine/refine/refine_options.h"
#include "engine/model/refine_report.h"
#include "engine/model/surface_query.h"
#include "engine/model/vertex_fields.h"
#include "stages/flow/net_move.h"
#include "stages/flow/photo_gradient.h"
#include "stages/flow/photo_views.h"
#include "stages/flow/silhouette_constraint.h"
#include "stages/flow/silhouette.h"
#include "stages/flow/speed.h"
#include "stages/flow/step_damping.h"
#include "stages/flow/step_momentum.h"

namespace mvflow {

//! What the nodes of one iteration share. The mesh's positions change only in the move and
//! commit kernels, and the Embree scene only in refit(), each ordered by the graph's edges.
struct IterationData {
  IterationData(TriMesh& mesh, const std::vector<PhotoView>& views, const RefineOptions& options,
                const std::atomic<bool>* cancel);

  TriMesh& mesh;
  const std::vector<PhotoView>& views;
  const RefineOptions& options;
  const std::atomic<bool>* cancel;
  //! Called after each per-block kernel did its work (RefineControl::on_block); may be empty.
  std::function<void(std::size_t block)> on_block;
  PhotoGradientStage photo;
  const SilhouetteConstraint* inside = nullptr;  //!< keeps the surface in the visual hull when set
  //! One silhouette per view (full resolution) when the rims are fitted (fits_rims): the
  //! fit_rims phase reads them; otherwise null.
  const std::vector<Mask>* rim_masks = nullptr;
  const std::vector<PhotoView>* rim_views = nullptr;  //!< the full-resolution views of rim_masks
  //! The photographs the surface patches read when they differ from `views` (the photographs as
  //! given while `views` are their blurred copies, DenoiseOptions); null: `views`.
  const std::vector<PhotoView>* surface_views = nullptr;
  //! The photographs at half resolution that the far vertices read (FarVertexOptions), while the
  //! refinement uses them (the first resolution); null: no vertex is far.
  const std::vector<PhotoView>* far_views = nullptr;
  //! One flag per vertex, 1 = far (update_far_vertices, by cfl()); read by the next photo_speed.
  std::vector<std::uint8_t> far;
  //! One flag per vertex: it made a view's outline in the last iteration (only when the rims are
  //! fitted; the silhouettes observe it, so the unobserved spread leaves it where it is).
  std::vector<std::uint8_t> on_rim;

  std::unique_ptr<SurfaceQuery> surface;  //!< rebuilt when the topology changes, refitted otherwise
  VertexFields fields;
  std::vector<IndexRange> blocks;
  std::vector<BlockPartial> partials;            //!< one per block
  std::vector<Eigen::Vector3d> new_positions;    //!< Jacobi buffer of smoothing / regularization
  std::vector<double> moved;                     //!< length of each vertex's move this iteration
  //! When record_moving_speed is set (RefineControl::on_vertex_fields), each vertex's F·N as it
  //! moved: after the damping and momentum, N the normal F was built along (the regularization
  //! recomputes fields.normal later in the iteration); 0 for a vertex without a speed.
  bool record_moving_speed = false;
  std::vector<double> moving_speed;
  //! For the step momentum and the unobserved-speed fill: the positions at the start of the last
  //! iteration (empty until one ran on this topology), then each vertex's whole step in it (refit()).
  std::vector<Eigen::Vector3d> iteration_start, last_step;
  double last_time_step = 0.0;
  std::vector<std::array<double, kStageCount>> block_seconds;  //!< per block, per stage

  // Set before the iteration runs (set_edge_lengths).
  double shortest_edge = 0.0;
  double mean_edge = 0.0;
  double sample_spacing = 0.0;  //!< Δx of the gradient's samples, from the shortest edge
  bool refit_needed = false;
  // Set by the CFL kernel.
  BlockPartial total;
  double time_step = 0.0;
  MoveLimit move_limit;      //!< the CFL bound on one vertex's move
  double step_scale = 1.0;   //!< the fraction of the CFL step taken (step control), reset with the topology
  double previous_g_per_vertex = 0.0;  //!< Σg/vertex of the previous iteration on this topology
  StepDampingState damping;  //!< per-vertex step scales (options.damping), reset with the topology
  NetNormalMove net_move;    //!< positions of the last iterations of this topology and images: settled rule, wait, mean
  //! Set by measure_moves(): the median over the moving vertices of their move divided by the
  //! edge the CFL bound used for them (their own shortest edge, or e_min with the global bound).
  double median_move = 0.0;
  //! Set by measure_moves(): NetNormalMove::record over options.stopping.lookback iterations (NaN
  //! until that many ran on this topology).
  double net_move_over_edge = 0.0;
  //! Set by cfl(): the vertices with defined g from a surface patch, and those whose kind of patch
  //! changed since the previous iteration (VertexFields::patch_kind).
  std::size_t surface_patch_g = 0;
  std::size_t patch_switches = 0;
  std::size_t moving = 0;
  std::size_t far_count = 0;  //!< set by cfl(): the far vertices for the next iteration (0 without far_views)
  //! set by cfl(): the vertices of implausibly high g with their ring (implausible_g_vertices; 0
  //! where the ratio is 0 or the rims are fitted), whose speeds it averaged (ImplausibleSpeedOptions)
  std::size_t implausible_count = 0;
  double serial_seconds[kStageCount] = {};

  //! Sizes everything for the mesh's current topology (new blocks, fields, Embree scene).
  void reset_topology();
  //! True once the cancel flag has been seen, even if the host clears it again: an iteration
  //! whose kernels skipped blocks never counts as done (see stopped).
  bool cancelled() {
    if (stopped.load(std::memory_order_relaxed)) return true;
    if (!cancel || !cancel->load(std::memory_order_relaxed)) return false;
    stopped.store(true, std::memory_order_relaxed);
    return true;
  }
  std::atomic<bool> stopped{false};  //!< a kernel saw the cancel flag (set by cancelled())

  // The kernels. `block` indexes `blocks`.
  void set_edge_lengths(const EdgeLengths& edges);  //!< e_min, the mean edge and Δx, before an iteration
  void refit();                        //!< serial: Embree refit to the current positions
  void geometry(std::size_t block);    //!< N and H
  void visibility(std::size_t block);  //!< visible views
  //! g, ∇g (3k+1 samples), F, and the block's partial; with the graph engine the block's
  //! vertices are shared among idle threads (nested parallel_for), never with the sequential one.
  void photo_speed(std::size_t block);
  void cfl();                          //!< serial: combine partials in block order, Δt, median move
  void adapt_step_scale();             //!< part of cfl(): the step control
  void fill_speeds();                  //!< part of cfl(): speeds of unobserved vertices
  //! part of cfl(): averages the speeds of implausibly high g (ImplausibleSpeedOptions) where the
  //! rule applies, sets implausible_count; returns the vertices averaged
  std::size_t average_implausible();
  //! UnobservedDisplacementOptions::implausible_g_ratio as applied, to the speeds and to the
  //! unobserved spread: 0 where the rims are fitted (the silhouettes hold the outline there).
  double applied_implausible_g_ratio() const {
    return rim_masks != nullptr ? 0.0 : options.unobserved_displacement.implausible_g_ratio;
  }
  //! the steps damped (options.damping), the last steps carried (options.momentum), then P ← P + Δt·F
  void move(std::size_t block);
  void measure_moves();                //!< serial, after the iteration: median_move and net_move_over_edge
  void smooth(std::size_t block);      //!< new position of curvature-normal smoothing
  void inflate(std::size_t block);     //!< new position of Taubin's second step (taubin_pass_band > 0)
  void regularize(std::size_t block);  //!< normals at the current positions, then regularization
  void commit(std::size_t block);      //!< new positions into the mesh
  void fit_rims(std::size_t block);    //!< new position of the silhouette rims (with rim_masks)
};

//! A per-block kernel of IterationData.
using BlockKernel = void (IterationData::*)(std::size_t block);

//! The phases of one iteration, the one schedule both engines walk (IterationGraph and
//! run_iteration_sequential):
//!   1. refit (serial);
//!   2. `pipeline` per block: each block's kernels in order, independent of the other blocks, so
//!      the graph pipelines them (a block's photo node starts when its own visibility is done);
//!   3. cfl (serial): joins every block's partial;
//!   4. each of `phases` on every block, all blocks of one phase before any block of the next
//!      (a phase reads the neighbours' output of the one before, across blocks);
//!   5. measure_moves (serial).
struct IterationPhases {
  std::array<BlockKernel, 3> pipeline;
  std::vector<BlockKernel> phases;
};

//! The phases of an iteration under \p options: move; per smoothing step smooth, commit (and
//! inflate, commit with a Taubin pass band); per regularization step regularize, commit; with
//! \p rims (silhouette rims fitted), fit_rims, commit.
IterationPhases iteration_phases(const RefineOptions& options, bool rims);

//! Runs one iteration's kernels in a plain loop on the calling thread, phase by phase and block by
//! block (iteration_phases): the reference path for determinism tests and benchmarks.
void run_iteration_sequential(IterationData& data);

}  // namespace mvflow
