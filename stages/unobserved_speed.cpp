#include "stages/unobserved_speed.h"

#include <vector>

#include "engine/error.h"

namespace mvflow {

std::size_t fill_unobserved_speeds(const TriMesh& mesh, const UnobservedSpeedOptions& options, VertexFields& fields) {
  MVFLOW_CHECK(options.check(), "unobserved speed options out of range");
  MVFLOW_CHECK(fields.size() == mesh.n_vertices(), "fill_unobserved_speeds: fields are not sized for the mesh");
  if (!options.fill) return 0;
  std::vector<std::uint32_t> pending;
  for (std::uint32_t id = 0; id < fields.size(); ++id) {
    const std::uint8_t bits = fields.defined[id];
    if (!(bits & kSpeedDefined) && (bits & kNormalDefined) && !mesh.is_boundary(TriMesh::VertexHandle(static_cast<int>(id))))
      pending.push_back(id);
  }
  std::size_t filled = 0;
  std::vector<std::uint32_t> ring, next;
  std::vector<double> speeds;
  for (int r = 0; r < options.max_rings && !pending.empty(); ++r) {
    // This ring: the pending vertices with a neighbour that has a speed now.
    ring.clear();
    speeds.clear();
    next.clear();
    for (const std::uint32_t id : pending) {
      double sum = 0.0;
      int count = 0;
      for (auto w = mesh.cvv_iter(TriMesh::VertexHandle(static_cast<int>(id))); w.is_valid(); ++w) {
        const auto j = static_cast<std::size_t>(w->idx());
        if (!(fields.defined[j] & (kSpeedDefined | kSpeedFilled))) continue;
        sum += fields.speed[j].dot(fields.normal[j]);
        ++count;
      }
      if (count == 0) {
        next.push_back(id);
        continue;
      }
      ring.push_back(id);
      speeds.push_back(sum / count);
    }
    if (ring.empty()) break;  // the rest is cut off from every observed vertex
    for (std::size_t k = 0; k < ring.size(); ++k) {
      const std::uint32_t id = ring[k];
      const Eigen::Vector3d f = speeds[k] * fields.normal[id];
      if (!f.allFinite()) continue;
      fields.speed[id] = f;
      fields.defined[id] |= kSpeedFilled;
      ++filled;
    }
    pending.swap(next);
  }
  return filled;
}

}  // namespace mvflow
