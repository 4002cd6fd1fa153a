#include "stages/topology/untangling.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "engine/model/error.h"
#include "engine/model/one_ring.h"
#include "engine/model/option_check.h"
#include "stages/topology/self_intersections.h"

namespace mvflow {

void UntanglingOptions::check() const {
  require_option(max_rounds >= 0, "max_rounds", max_rounds, ">= 0");
  require_option(ring >= 0, "ring", ring, ">= 0");
  require_option(steps >= 1, "steps", steps, ">= 1");
  require_option(fraction > 0.0 && fraction <= 1.0, "fraction", fraction, "(0, 1]");
}

namespace {

// The vertices of the crossing faces, grown by `rings` vertex rings; sorted ids.
std::vector<std::uint32_t> region_around(const TriMesh& mesh,
                                         const std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs,
                                         int rings) {
  std::vector<std::uint8_t> in(mesh.n_vertices(), 0);
  for (const auto& [f, g] : pairs)
    for (const std::uint32_t face : {f, g})
      for (auto v : mesh.fv_range(TriMesh::FaceHandle(static_cast<int>(face)))) in[v.idx()] = 1;
  for (int r = 0; r < rings; ++r) {
    std::vector<std::uint8_t> grown = in;
    for (auto v : mesh.vertices())
      if (in[v.idx()])
        for (auto w : mesh.vv_range(v)) grown[w.idx()] = 1;
    in.swap(grown);
  }
  std::vector<std::uint32_t> region;
  for (std::uint32_t v = 0; v < in.size(); ++v)
    if (in[v] && !mesh.is_boundary(TriMesh::VertexHandle(static_cast<int>(v)))) region.push_back(v);
  return region;
}

// One Jacobi umbrella step over `region`: every vertex reads the positions before the step.
void umbrella_step(TriMesh& mesh, const std::vector<std::uint32_t>& region, double fraction,
                   std::vector<Eigen::Vector3d>& moved) {
  moved.resize(region.size());
  for (std::size_t i = 0; i < region.size(); ++i) {
    const TriMesh::VertexHandle v(static_cast<int>(region[i]));
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (auto w : mesh.vv_range(v)) {
      sum += detail::point(mesh, w);
      ++count;
    }
    const Eigen::Vector3d p = detail::point(mesh, v);
    moved[i] = count > 0 ? Eigen::Vector3d(p + fraction * (sum / count - p)) : p;
  }
  for (std::size_t i = 0; i < region.size(); ++i)
    mesh.set_point(TriMesh::VertexHandle(static_cast<int>(region[i])), to_openmesh(moved[i]));
}

}  // namespace

UntanglingResult untangle(TriMesh& mesh, const UntanglingOptions& options) {
  options.check();
  UntanglingResult result;
  auto pairs = self_intersecting_pairs(mesh);
  result.crossing_pairs_before = pairs.size();
  std::vector<Eigen::Vector3d> buffer;
  for (int round = 0; round < options.max_rounds && !pairs.empty(); ++round) {
    const std::vector<std::uint32_t> region = region_around(mesh, pairs, options.ring + round);
    for (int step = 0; step < options.steps; ++step) umbrella_step(mesh, region, options.fraction, buffer);
    result.smoothed_vertices += region.size();
    ++result.rounds;
    pairs = self_intersecting_pairs(mesh);
  }
  result.crossing_pairs_after = pairs.size();
  return result;
}

}  // namespace mvflow
