#include "io/report_io.h"

#include <cmath>

#include "io/atomic_write.h"

namespace mvflow::io {

namespace {

nlohmann::json iteration_json(const IterationReport& r) {
  nlohmann::json stages;
  for (std::size_t s = 0; s < kStageCount; ++s) stages[kStageNames[s]] = r.stage_seconds[s];
  return {{"iteration", r.iteration},
          {"vertices", r.vertices},
          {"faces", r.faces},
          {"refined_faces", r.refined_faces},
          {"declined_vertices", r.declined_vertices},
          {"sum_g", r.sum_g},
          {"sum_g_per_vertex", r.sum_g_per_vertex()},
          {"defined_g", r.defined_g},
          {"surface_patch_g", r.surface_patch_g},
          {"patch_switches", r.patch_switches},
          {"far_vertices", r.far_vertices},
          {"implausible_g", r.implausible_g},
          {"moving_vertices", r.moving},
          {"shortest_edge", r.shortest_edge},
          {"max_speed", r.max_speed},
          {"time_step", r.time_step},
          {"median_move_over_cfl_edge", r.median_move},
          {"net_normal_move_over_edge", std::isfinite(r.net_move) ? nlohmann::json(r.net_move) : nlohmann::json(nullptr)},
          {"net_normal_move_p90_over_edge",
           std::isfinite(r.net_move_tail) ? nlohmann::json(r.net_move_tail) : nlohmann::json(nullptr)},
          {"net_normal_move_persistence",
           std::isfinite(r.net_move_persistence) ? nlohmann::json(r.net_move_persistence) : nlohmann::json(nullptr)},
          {"stop", r.stop},
          {"seconds", r.seconds},
          {"stage_seconds", stages}};
}

}  // namespace

nlohmann::json report_to_json(const RefineSummary& summary, const nlohmann::json& inputs, const nlohmann::json& options) {
  nlohmann::json iterations = nlohmann::json::array();
  for (const auto& r : summary.iterations) iterations.push_back(iteration_json(r));
  return {{"inputs", inputs},
          {"options", options},
          {"status", to_string(summary.status)},
          {"message", summary.message},
          {"initial", {{"vertices", summary.initial_vertices}, {"faces", summary.initial_faces},
                       {"sum_g_per_vertex", summary.initial_sum_g_per_vertex},
                       {"image_noise", summary.image_noise},
                       {"denoise_sigma", summary.denoise_sigma},
                       {"settled_tolerance", summary.settled_tolerance}}},
          {"final", {{"vertices", summary.final_vertices}, {"faces", summary.final_faces},
                     {"sum_g_per_vertex", summary.final_sum_g_per_vertex},
                     {"self_intersecting_face_pairs", summary.self_intersections},
                     {"untangled_face_pairs", summary.untangled_pairs}}},
          {"seconds", summary.seconds},
          {"iterations", iterations}};
}

void write_report(const std::filesystem::path& file, const RefineSummary& summary, const nlohmann::json& inputs,
                  const nlohmann::json& options) {
  const nlohmann::json report = report_to_json(summary, inputs, options);
  write_atomically(file, false, [&](std::ostream& out) { out << report.dump(2) << '\n'; });
}

}  // namespace mvflow::io
