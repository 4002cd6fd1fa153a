#include "perf/openmvs_case.h"

#include <cmath>
#include <iostream>
#include <optional>

#include "engine/model/bounding_box.h"
#include "engine/model/error.h"
#include "engine/refine/refiner.h"
#include "perf/bench_runs.h"
#include "perf/bench_scene.h"
#include "perf/peak_memory.h"

namespace mvflow::perf {

double mean_radial_error(const std::vector<Eigen::Vector3d>& positions) {
  double sum = 0;
  for (const auto& p : positions) sum += std::abs(p.norm() - 1.0);
  return positions.empty() ? 0.0 : sum / static_cast<double>(positions.size());
}

std::vector<Row> run_openmvs_case(const OpenMvsCaseSettings& settings, bool validate) {
  SceneSpec spec = SceneSpec::parse("2562/24/640x480");
  spec.amplitude = 0;    // a unit sphere
  spec.supersample = 2;  // the accuracy is measured: render as `mvflow synth` does
  // The initial mesh is pushed out by init_offset × the truth's diagonal (2√3 for a unit sphere).
  spec.init_offset = settings.initial_error / (2 * std::sqrt(3.0));
  std::cerr << "openmvs case: rendering " << spec.label() << " ...\n";
  const BenchScene scene = make_bench_scene(spec);
  const double initial_error = mean_radial_error(positions_of(scene.initial.topology));
  std::vector<Row> rows;
  std::optional<std::uint64_t> first_hash;
  for (const int threads : settings.threads) {
    RefineControl control;
    control.threads = threads;
    release_free_memory();
    const bool reset = reset_peak_memory();
    const RefineResult result = refine_mesh(scene.scene, scene.initial, RefineOptions{}, control);
    const RefineSummary& s = result.summary;
    if (s.status == RefineStatus::Failed) throw Error("openmvs case: " + s.message);
    const double final_error = mean_radial_error(positions_of(result.mesh.topology));
    const std::uint64_t hash = mesh_hash(result.mesh.topology);
    if (validate) {
      if (!(final_error < initial_error)) throw Error("openmvs case: the radial error did not fall");
      if (!first_hash) first_hash = hash;
      if (hash != *first_hash) throw Error("openmvs case: thread counts gave different meshes");
    }
    Row row;
    row["case"] = "sphere " + spec.label();
    row["threads"] = threads;
    row["vertices"] = std::to_string(s.initial_vertices) + "->" + std::to_string(s.final_vertices);
    row["iterations"] = s.iterations.size();
    row["status"] = to_string(s.status);
    row["seconds"] = s.seconds;
    row["peer_seconds"] = 37.0;
    row["initial_error"] = initial_error;
    row["final_error"] = final_error;
    row["peer_final_error"] = 0.0027;
    row["self_intersections"] = s.self_intersections;
    row["peak_MB"] = static_cast<double>(peak_memory_bytes()) / (1 << 20);
    row["peak_reset"] = reset;
    std::cerr << "  " << threads << " thread(s): " << s.seconds << " s, radial error " << initial_error << " -> "
              << final_error << "\n";
    rows.push_back(row);
  }
  return rows;
}

}  // namespace mvflow::perf
