#include "stages/topology/self_intersections.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "engine/model/parallel.h"

namespace mvflow {

namespace {

using Triangle = std::array<Eigen::Vector3d, 3>;

// Segment [a, b] against triangle t (Möller–Trumbore), endpoints excluded by a hair.
bool segment_crosses(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Triangle& t) {
  const Eigen::Vector3d d = b - a, e1 = t[1] - t[0], e2 = t[2] - t[0];
  const Eigen::Vector3d p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-300) return false;  // parallel (coplanar overlaps are not counted)
  const Eigen::Vector3d s = a - t[0];
  const double u = s.dot(p) / det;
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (v < 0 || u + v > 1) return false;
  const double at = e2.dot(q) / det;
  return at > 1e-12 && at < 1 - 1e-12;
}

bool triangles_cross(const Triangle& x, const Triangle& y) {
  for (int i = 0; i < 3; ++i)
    if (segment_crosses(x[i], x[(i + 1) % 3], y) || segment_crosses(y[i], y[(i + 1) % 3], x)) return true;
  return false;
}

}  // namespace

std::size_t count_self_intersections(const TriMesh& mesh) { return self_intersecting_pairs(mesh).size(); }

std::vector<std::pair<std::uint32_t, std::uint32_t>> self_intersecting_pairs(const TriMesh& mesh) {
  const std::size_t n = mesh.n_faces();
  if (n < 2) return {};
  std::vector<Triangle> triangles(n);
  std::vector<std::array<int, 3>> corners(n);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  double edge_sum = 0;
  for (auto f : mesh.faces()) {
    int c = 0;
    for (auto v : mesh.fv_range(f)) {
      triangles[f.idx()][c] = to_eigen(mesh.point(v));
      corners[f.idx()][c++] = v.idx();
      lo = lo.cwiseMin(to_eigen(mesh.point(v)));
      hi = hi.cwiseMax(to_eigen(mesh.point(v)));
    }
    edge_sum += (triangles[f.idx()][1] - triangles[f.idx()][0]).norm();
  }
  const double cell = std::max(edge_sum / static_cast<double>(n), 1e-12 * (hi - lo).norm());
  const Eigen::Vector3i dims = (((hi - lo) / cell).array().floor().cast<int>().cwiseMax(0) + 1).matrix();
  auto cell_of = [&](const Eigen::Vector3d& p) {
    return ((p - lo) / cell).array().floor().cast<int>().cwiseMax(0).cwiseMin(dims.array() - 1).matrix().eval();
  };
  // (cell id, face) for every cell a face's box touches, sorted: faces sharing a cell are adjacent.
  std::vector<std::pair<std::int64_t, std::uint32_t>> entries;
  for (std::uint32_t f = 0; f < n; ++f) {
    Eigen::Vector3d a = triangles[f][0].cwiseMin(triangles[f][1]).cwiseMin(triangles[f][2]);
    Eigen::Vector3d b = triangles[f][0].cwiseMax(triangles[f][1]).cwiseMax(triangles[f][2]);
    const Eigen::Vector3i c0 = cell_of(a), c1 = cell_of(b);
    for (int z = c0.z(); z <= c1.z(); ++z)
      for (int y = c0.y(); y <= c1.y(); ++y)
        for (int x = c0.x(); x <= c1.x(); ++x)
          entries.emplace_back((static_cast<std::int64_t>(z) * dims.y() + y) * dims.x() + x, f);
  }
  std::sort(entries.begin(), entries.end());
  std::vector<std::size_t> cell_begin;  // where each cell's run of entries starts, then the end
  for (std::size_t i = 0; i < entries.size(); ++i)
    if (i == 0 || entries[i].first != entries[i - 1].first) cell_begin.push_back(i);
  cell_begin.push_back(entries.size());
  // The cells in chunks, each chunk's pairs in its own list: after the sort below the result does
  // not depend on the chunks or the threads. Serial, this test was 7 % of a whole 2-thread refine.
  constexpr std::size_t kChunks = 64;
  const std::size_t cells = cell_begin.size() - 1;
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> found(kChunks);
  parallel::parallel_for(std::size_t{0}, kChunks, [&](std::size_t chunk) {
    for (std::size_t cell = cells * chunk / kChunks; cell < cells * (chunk + 1) / kChunks; ++cell)
      for (std::size_t a = cell_begin[cell]; a < cell_begin[cell + 1]; ++a)
        for (std::size_t b = a + 1; b < cell_begin[cell + 1]; ++b) {
          const std::uint32_t f = entries[a].second, g = entries[b].second;
          bool shares_vertex = false;
          for (int p : corners[f])
            for (int q : corners[g]) shares_vertex |= p == q;
          if (!shares_vertex && triangles_cross(triangles[f], triangles[g]))
            found[chunk].emplace_back(std::min(f, g), std::max(f, g));
        }
  });
  std::vector<std::pair<std::uint32_t, std::uint32_t>> crossing;
  for (const auto& pairs : found) crossing.insert(crossing.end(), pairs.begin(), pairs.end());
  std::sort(crossing.begin(), crossing.end());
  crossing.erase(std::unique(crossing.begin(), crossing.end()), crossing.end());
  return crossing;
}

}  // namespace mvflow
