#include "stages/flow/unobserved_speed.h"

#include <cmath>
#include <numbers>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/option_check.h"

namespace mvflow {

void UnobservedSpeedOptions::check() const {
  require_option(max_rings >= 1, "max_rings", max_rings, ">= 1");
  require_option(weak_angle_degrees > 0 && weak_angle_degrees <= 90, "weak_angle_degrees", weak_angle_degrees,
                 "(0, 90]");
}

std::size_t demote_weakly_seen(const TriMesh& mesh, const std::vector<PhotoView>& views,
                               const UnobservedSpeedOptions& options, VertexFields& fields) {
  options.check();
  if (!options.fill || options.weak_angle_degrees >= 90.0) return 0;
  const double cos_weak = std::cos(options.weak_angle_degrees * std::numbers::pi / 180.0);
  std::size_t demoted = 0;
  for (std::uint32_t v = 0; v < fields.size(); ++v) {
    if (!(fields.defined[v] & kSpeedDefined)) continue;
    const Eigen::Vector3d P = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
    bool direct = false;
    for (const std::uint16_t id : fields.visible(v)) {
      const Eigen::Vector3d to_camera = views[id].camera->centre() - P;
      if (fields.normal[v].dot(to_camera) > cos_weak * to_camera.norm()) {
        direct = true;
        break;
      }
    }
    if (direct) continue;
    fields.defined[v] &= static_cast<std::uint8_t>(~kSpeedDefined);
    fields.speed[v].setZero();
    ++demoted;
  }
  return demoted;
}

std::size_t fill_unobserved_speeds(const TriMesh& mesh, const UnobservedSpeedOptions& options,
                                   std::span<const double> rate, VertexFields& fields) {
  options.check();
  MVFLOW_CHECK(fields.size() == mesh.n_vertices() && rate.size() == mesh.n_vertices(),
               "fill_unobserved_speeds: fields or rates are not sized for the mesh");
  if (!options.fill) return 0;
  std::vector<double> filled_rate(fields.size(), 0.0);
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
        if (fields.defined[j] & kSpeedDefined)
          sum += rate[j];
        else if (fields.defined[j] & kSpeedFilled)
          sum += filled_rate[j];
        else
          continue;
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
      filled_rate[id] = speeds[k];
      fields.defined[id] |= kSpeedFilled;
      ++filled;
    }
    pending.swap(next);
  }
  return filled;
}

}  // namespace mvflow
