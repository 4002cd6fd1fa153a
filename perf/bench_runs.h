#pragma once
// One measured configuration of mvflow_bench: a scene, a thread count and an engine kind.
// Two refinements run: a fixed-topology one (no split/collapse, no adaptive refinement, a fixed
// number of iterations) for the time per iteration and per stage, and a whole one with the
// default options (split/collapse, adaptive refinement, the stopping rules) up to a cap of
// iterations. Rendering the scene is never timed.

#include <array>
#include <cstdint>
#include <string>

#include "engine/refine/refine_options.h"
#include "engine/model/refine_report.h"
#include "perf/bench_scene.h"

namespace mvflow::perf {

struct RunSettings {
  //! Iterations of the fixed-topology refinement (≥ 6, the stopping rule's minimum); the first
  //! (BVH and graph built) is not averaged.
  int timed_iterations = 6;
  //! Cap on the iterations of the whole refinement (≥ 6).
  int refine_iterations = 10;
  bool whole_refinement = true;  //!< false: only the fixed-topology refinement
  //! Where g lays its patches on the surface (the default's Oblique; Off for the thesis's image
  //! patches alone, to compare in one run).
  SurfacePatchUse surface_patch = PhotoConsistencyOptions{}.surface_patch;
};

struct RunConfig {
  int threads = 2;
  EngineKind engine = EngineKind::Graph;
  std::string name() const;  //!< "graph/2"
};

struct Measurement {
  std::string scene;  //!< SceneSpec::label()
  RunConfig config;
  // Fixed topology: means over the timed iterations after the first.
  double iteration_seconds = 0;                    //!< wall time
  std::array<double, kStageCount> stage_seconds{};  //!< per iteration (graph: summed over blocks)
  double photo_share = 0;                          //!< photo_gradient / Σ stages
  std::uint64_t fixed_hash = 0;                    //!< of the final positions (determinism)
  // Whole refinement.
  double refine_seconds = 0;                       //!< RefineSummary::seconds (no image decoding)
  int refine_iterations = 0;
  std::size_t refine_vertices = 0;                 //!< final vertex count
  double initial_g_per_vertex = 0, final_g_per_vertex = 0;
  std::string refine_status;
  std::uint64_t refine_hash = 0;
  std::size_t peak_bytes = 0;                      //!< resident high-water mark of the configuration
  bool peak_reset = false;                         //!< whether the mark was reset before it
};

//! Runs both refinements of \p config on \p scene. \throw Error when a refinement fails.
Measurement measure(const BenchScene& scene, const RunConfig& config, const RunSettings& settings);

//! Options of the fixed-topology refinement: the defaults without split/collapse and adaptive
//! refinement, exactly \p iterations iterations.
RefineOptions fixed_topology_options(int iterations);

//! A hash of the vertex positions' bits and the triangles (FNV-1a): equal meshes, equal hashes.
std::uint64_t mesh_hash(const TriMesh& mesh);

}  // namespace mvflow::perf
