#include "stages/flow/implausible_speed.h"

#include <vector>

#include "engine/model/error.h"
#include "engine/model/option_check.h"

namespace mvflow {

void ImplausibleSpeedOptions::check() const {
  require_option(rings >= 0 && rings <= 16, "rings", rings, "in [0, 16]");
}

std::size_t average_implausible_speeds(const TriMesh& mesh, std::span<const std::uint8_t> implausible,
                                       const ImplausibleSpeedOptions& options, VertexFields& fields) {
  options.check();
  MVFLOW_CHECK(fields.size() == mesh.n_vertices(), "average_implausible_speeds: fields not sized for the mesh");
  MVFLOW_CHECK(implausible.size() == fields.size(), "average_implausible_speeds: flags not sized for the fields");
  std::vector<std::uint32_t> flagged;
  for (std::uint32_t v = 0; v < implausible.size(); ++v)
    if (implausible[v] && (fields.defined[v] & kSpeedDefined)) flagged.push_back(v);
  if (options.rings == 0 || flagged.empty()) return 0;
  // Each round reads the previous round's speeds only (Jacobi: all means first, then all written),
  // so the order does not matter; only the flagged vertices' new speeds need room.
  std::vector<Eigen::Vector3d> mean(flagged.size());
  for (int round = 0; round < options.rings; ++round) {
    for (std::size_t k = 0; k < flagged.size(); ++k) {
      const std::uint32_t v = flagged[k];
      Eigen::Vector3d sum = fields.speed[v];
      int count = 1;
      for (auto w : mesh.vv_range(TriMesh::VertexHandle(static_cast<int>(v))))
        if (fields.defined[w.idx()] & kSpeedDefined) {
          sum += fields.speed[w.idx()];
          ++count;
        }
      mean[k] = sum / count;
    }
    for (std::size_t k = 0; k < flagged.size(); ++k) fields.speed[flagged[k]] = mean[k];
  }
  return flagged.size();
}

}  // namespace mvflow
