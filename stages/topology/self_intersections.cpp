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
  // Every step over all faces runs in chunks: serial, the grid's sort and the gathering took 0.24 s
  // of a 2.5 s two-thread refine of the sphere case (perf/README), run before every refinement.
  constexpr std::size_t kChunks = 64;
  auto chunk_begin = [](std::size_t chunk, std::size_t count) { return count * chunk / kChunks; };
  std::vector<Triangle> triangles(n);
  std::vector<std::array<int, 3>> corners(n);
  std::vector<Eigen::Vector3d> box_lo(n), box_hi(n);  // each face's bounding box
  parallel::parallel_for(std::size_t{0}, kChunks, [&](std::size_t chunk) {
    for (std::size_t f = chunk_begin(chunk, n); f < chunk_begin(chunk + 1, n); ++f) {
      int c = 0;
      for (auto v : mesh.fv_range(TriMesh::FaceHandle(static_cast<int>(f)))) {
        triangles[f][c] = to_eigen(mesh.point(v));
        corners[f][c++] = v.idx();
      }
      const Triangle& t = triangles[f];
      box_lo[f] = t[0].cwiseMin(t[1]).cwiseMin(t[2]);
      box_hi[f] = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
    }
  });
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (auto v : mesh.vertices()) {
    lo = lo.cwiseMin(to_eigen(mesh.point(v)));
    hi = hi.cwiseMax(to_eigen(mesh.point(v)));
  }
  double edge_sum = 0;  // in face order: the same cell size whatever the threads
  for (const Triangle& t : triangles) edge_sum += (t[1] - t[0]).norm();
  const double cell = std::max(edge_sum / static_cast<double>(n), 1e-12 * (hi - lo).norm());
  const Eigen::Vector3i dims = (((hi - lo) / cell).array().floor().cast<int>().cwiseMax(0) + 1).matrix();
  auto cell_of = [&](const Eigen::Vector3d& p) {
    return ((p - lo) / cell).array().floor().cast<int>().cwiseMax(0).cwiseMin(dims.array() - 1).matrix().eval();
  };
  auto cell_id = [&](const Eigen::Vector3i& c) {
    return (static_cast<std::int64_t>(c.z()) * dims.y() + c.y()) * dims.x() + c.x();
  };
  // (cell id, face) for every cell a face's box touches, per chunk of faces, sorted.
  using Entry = std::pair<std::int64_t, std::uint32_t>;
  std::vector<std::vector<Entry>> entries(kChunks);
  parallel::parallel_for(std::size_t{0}, kChunks, [&](std::size_t chunk) {
    for (std::size_t f = chunk_begin(chunk, n); f < chunk_begin(chunk + 1, n); ++f) {
      const Eigen::Vector3i c0 = cell_of(box_lo[f]), c1 = cell_of(box_hi[f]);
      for (int z = c0.z(); z <= c1.z(); ++z)
        for (int y = c0.y(); y <= c1.y(); ++y)
          for (int x = c0.x(); x <= c1.x(); ++x)
            entries[chunk].emplace_back(cell_id(Eigen::Vector3i(x, y, z)), static_cast<std::uint32_t>(f));
    }
    std::sort(entries[chunk].begin(), entries[chunk].end());
  });
  // The cell ids in ranges; each range gathers its entries from every chunk, so the faces sharing
  // a cell lie side by side, and tests them in pairs into its own list. After the sort below the
  // result depends neither on the chunks nor on the threads.
  const std::int64_t cells = static_cast<std::int64_t>(dims.x()) * dims.y() * dims.z();
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> found(kChunks);
  parallel::parallel_for(std::size_t{0}, kChunks, [&](std::size_t range) {
    const std::int64_t first = cells * static_cast<std::int64_t>(range) / kChunks;
    const std::int64_t last = cells * static_cast<std::int64_t>(range + 1) / kChunks;
    std::vector<Entry> mine;
    for (const std::vector<Entry>& list : entries) {
      const auto from = std::lower_bound(list.begin(), list.end(), Entry{first, 0});
      const auto to = std::lower_bound(from, list.end(), Entry{last, 0});
      mine.insert(mine.end(), from, to);
    }
    std::sort(mine.begin(), mine.end());
    for (std::size_t begin = 0, end = 0; begin < mine.size(); begin = end) {
      end = begin + 1;
      while (end < mine.size() && mine[end].first == mine[begin].first) ++end;
      for (std::size_t a = begin; a < end; ++a)
        for (std::size_t b = a + 1; b < end; ++b) {
          const std::uint32_t f = mine[a].second, g = mine[b].second;
          // Only boxes that overlap, and each pair only in the cell of their overlap's low
          // corner (which both faces' cell ranges contain): no pair is tested twice.
          const Eigen::Vector3d overlap_lo = box_lo[f].cwiseMax(box_lo[g]);
          if ((overlap_lo.array() > box_hi[f].cwiseMin(box_hi[g]).array()).any()) continue;
          if (cell_id(cell_of(overlap_lo)) != mine[begin].first) continue;
          bool shares_vertex = false;
          for (int p : corners[f])
            for (int q : corners[g]) shares_vertex |= p == q;
          if (!shares_vertex && triangles_cross(triangles[f], triangles[g]))
            found[range].emplace_back(std::min(f, g), std::max(f, g));
        }
    }
  });
  std::vector<std::pair<std::uint32_t, std::uint32_t>> crossing;
  for (const auto& pairs : found) crossing.insert(crossing.end(), pairs.begin(), pairs.end());
  std::sort(crossing.begin(), crossing.end());
  return crossing;
}

}  // namespace mvflow
