#pragma once
// What a refinement reports: one record per iteration (the thesis's table 5.1 columns and more)
// and a summary. Plain data, so that io/ can write it and hosts can read it without linking the
// engine.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace mvflow {

//! The timed stages of an iteration (SPEC §7). For the flow graph each entry is the summed
//! time of that stage's nodes over all blocks (CPU seconds); for the sequential path it is wall time.
enum class Stage : int { Refinement, Refit, Geometry, Visibility, PhotoGradient, Cfl, Move, Smoothing, Regularization, Rims };
inline constexpr std::size_t kStageCount = 10;
inline constexpr std::array<const char*, kStageCount> kStageNames{
    "refinement", "refit", "geometry", "visibility", "photo_gradient", "cfl", "move", "smoothing", "regularization", "silhouette_rims"};

struct IterationReport {
  int iteration = 0;                  //!< 1-based
  std::size_t vertices = 0;
  std::size_t faces = 0;
  //! faces added by adaptive refinement: before this iteration (schedule EveryIteration), or
  //! after it when its stop says "refined (…)" (AtConvergence)
  std::size_t refined_faces = 0;
  //! vertices a refinement would have added when it was declined as too small
  //! (AdaptiveRefinementOptions::min_growth); coarse to fine, the run then ended after this
  //! iteration
  std::size_t declined_vertices = 0;
  double sum_g = 0.0;                 //!< Σ g over vertices with defined g (the stopping criterion's G_i)
  std::size_t defined_g = 0;          //!< vertices with defined g
  //! of those, the vertices whose g laid its patch on the surface (PhotoConsistencyOptions::surface_patch)
  std::size_t surface_patch_g = 0;
  //! The far vertices after this iteration's g (stages/flow/far_vertices.h): they read the
  //! half-resolution photographs in the next iteration unless this one ends the first resolution.
  std::size_t far_vertices = 0;
  //! The vertices with a speed whose g is implausibly high with their ring
  //! (UnobservedDisplacementOptions::implausible_g_ratio): their speeds are averaged
  //! (ImplausibleSpeedOptions) and the unobserved spread counts them as not observed. 0 where the
  //! rims are fitted to silhouettes (the rule is off there) or the ratio is 0.
  std::size_t implausible_g = 0;
  //! vertices whose g took the other kind of patch than in the previous iteration of this mesh
  std::size_t patch_switches = 0;
  std::size_t moving = 0;             //!< vertices with a defined speed
  double shortest_edge = 0.0;         //!< e_min of the mesh the iteration started from
  double max_speed = 0.0;             //!< max |F|
  double time_step = 0.0;             //!< Δt (CFL)
  //! median over the moving vertices of their move divided by the edge the CFL bound used for them
  //! (their own shortest edge with the local bound, e_min with the global one)
  double median_move = 0.0;
  //! median over the moving vertices of their net move along the normal over the stopping rule's
  //! lookback, divided by their shortest edge (NetNormalMove); NaN in the first iterations of a topology
  double net_move = 0.0;
  //! the 90th percentile of the same (NetNormalMove::last_tail): the vertices still on their way
  //! when the median has settled; NaN where net_move is
  double net_move_tail = 0.0;
  //! how much of the previous window's net move the last one carried on
  //! (NetNormalMove::last_persistence, the finest resolution's hold); NaN in the first 2·lookback
  //! iterations of a topology
  double net_move_persistence = 0.0;
  std::string stop;                   //!< "continue", or why the refinement stops after it
  double seconds = 0.0;               //!< wall time of the whole iteration
  std::array<double, kStageCount> stage_seconds{};

  double sum_g_per_vertex() const { return defined_g ? sum_g / static_cast<double>(defined_g) : 0.0; }
};

enum class RefineStatus { Converged, StepSmall, Settled, MaxIterations, Cancelled, Failed };
const char* to_string(RefineStatus status);

struct RefineSummary {
  RefineStatus status = RefineStatus::Failed;
  std::string message;                 //!< the error for Failed
  std::size_t initial_vertices = 0;
  std::size_t initial_faces = 0;
  std::size_t final_vertices = 0;
  std::size_t final_faces = 0;
  double initial_sum_g_per_vertex = 0.0;  //!< after the global remeshing, before the flow
  double final_sum_g_per_vertex = 0.0;    //!< at the final positions
  std::size_t self_intersections = 0;     //!< pairs of non-adjacent faces that intersect (final mesh)
  std::size_t untangled_pairs = 0;        //!< crossing face pairs the untangling removed, over the calls whose positions the result keeps
  double image_noise = 0.0;               //!< the photographs' noise σ (estimate_views_noise; 0 when not estimated)
  //! σ in pixels of the Gaussian the image patches' photographs were blurred with (DenoiseOptions); 0: as given
  double denoise_sigma = 0.0;
  double settled_tolerance = 0.0;         //!< the settled rule's tolerance the run used (settled_tolerance_for_noise)
  double seconds = 0.0;
  std::vector<IterationReport> iterations;
};

inline const char* to_string(RefineStatus status) {
  switch (status) {
    case RefineStatus::Converged: return "converged";
    case RefineStatus::StepSmall: return "step-small";
    case RefineStatus::Settled: return "settled";
    case RefineStatus::MaxIterations: return "max-iterations";
    case RefineStatus::Cancelled: return "cancelled";
    case RefineStatus::Failed: return "failed";
  }
  return "?";
}

}  // namespace mvflow
