#include "stages/topology/vertex_order.h"

#include <algorithm>
#include <array>
#include <string>
#include <utility>

#include "engine/model/bounding_box.h"

namespace mvflow {

namespace {

// The 21 low bits of v spread to every third bit of the result.
std::uint64_t spread_bits(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

std::uint64_t morton_key(const Eigen::Vector3d& p, const Eigen::Vector3d& low, const Eigen::Vector3d& scale) {
  std::uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double steps = std::clamp((p[axis] - low[axis]) * scale[axis], 0.0, double((1 << 21) - 1));
    key |= spread_bits(static_cast<std::uint64_t>(steps)) << axis;
  }
  return key;
}

// True when \p mesh stores nothing per element but its points (the rebuild carries only those):
// the element-data slots OpenMesh adds (empty with mvflow's traits) and released properties hold
// nothing.
bool carries_only_points(const TriMesh& mesh) {
  const auto only = [](auto begin, auto end, const std::string& placeholder, const std::string& allowed) {
    for (auto it = begin; it != end; ++it)
      if (*it && (*it)->name() != placeholder && (*it)->name() != allowed) return false;
    return true;
  };
  return only(mesh.vprops_begin(), mesh.vprops_end(), "<vprop>", "v:points") &&
         only(mesh.hprops_begin(), mesh.hprops_end(), "<hprop>", "") &&
         only(mesh.eprops_begin(), mesh.eprops_end(), "<eprop>", "") &&
         only(mesh.fprops_begin(), mesh.fprops_end(), "<fprop>", "");
}

}  // namespace

std::vector<std::uint32_t> order_vertices_by_locality(TriMesh& mesh) {
  const std::size_t n = mesh.n_vertices();
  if (n == 0 || !carries_only_points(mesh)) return {};
  const std::vector<Eigen::Vector3d> positions = positions_of(mesh);
  BoundingBox box;
  for (const Eigen::Vector3d& p : positions) {
    if (!p.allFinite()) return {};  // no key to give it (and the rebuild would refuse it)
    box.extend(p);
  }
  const Eigen::Vector3d extent = box.size();
  Eigen::Vector3d scale;
  for (int axis = 0; axis < 3; ++axis) scale[axis] = extent[axis] > 0 ? ((1 << 21) - 1) / extent[axis] : 0.0;

  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(n);
  for (std::uint32_t v = 0; v < n; ++v) keyed[v] = {morton_key(positions[v], box.min, scale), v};
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> new_of_old(n);
  IndexedMesh ordered;
  ordered.positions.resize(n);
  for (std::uint32_t k = 0; k < n; ++k) {
    new_of_old[keyed[k].second] = k;
    ordered.positions[k] = positions[keyed[k].second];
  }

  ordered.triangles = triangles_of(mesh);
  for (auto& t : ordered.triangles) {
    for (auto& corner : t) corner = new_of_old[corner];
    // The lowest id first; a rotation keeps the orientation.
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  }
  std::sort(ordered.triangles.begin(), ordered.triangles.end());

  MeshBuildReport report;
  Mesh rebuilt = build_mesh(ordered, "order_vertices_by_locality", &report);
  if (report.rejected_faces > 0) return {};
  mesh = std::move(rebuilt.topology);
  return new_of_old;
}

}  // namespace mvflow
