#include "engine/model/primitives.h"

#include <cmath>
#include <map>
#include <utility>

#include "engine/model/error.h"

namespace mvflow {

IndexedMesh make_icosphere(double radius, int level, const Eigen::Vector3d& centre) {
  MVFLOW_CHECK(radius > 0 && level >= 0 && level <= 10, "icosphere: radius > 0 and 0 <= level <= 10");
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> unit = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                       {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : unit) p.normalize();
  std::vector<std::array<std::uint32_t, 3>> faces = {
      {0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
      {3, 9, 4},  {3, 4, 2}, {3, 2, 6}, {3, 6, 8},  {3, 8, 9},   {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto found = midpoints.find(key);
      if (found != midpoints.end()) return found->second;
      unit.push_back((unit[a] + unit[b]).normalized());
      const auto id = static_cast<std::uint32_t>(unit.size() - 1);
      midpoints.emplace(key, id);
      return id;
    };
    std::vector<std::array<std::uint32_t, 3>> finer;
    finer.reserve(4 * faces.size());
    for (const auto& f : faces) {
      const std::uint32_t ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
      finer.push_back({f[0], ab, ca});
      finer.push_back({f[1], bc, ab});
      finer.push_back({f[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    faces = std::move(finer);
  }
  IndexedMesh mesh;
  mesh.positions.reserve(unit.size());
  for (const auto& p : unit) mesh.positions.push_back(centre + radius * p);
  mesh.triangles = std::move(faces);
  return mesh;
}

IndexedMesh make_grid(double size, int cells) {
  MVFLOW_CHECK(size > 0 && cells >= 1, "grid: size > 0 and cells >= 1");
  IndexedMesh mesh;
  const int n = cells + 1;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) mesh.positions.emplace_back(size * i / cells, size * j / cells, 0.0);
  auto id = [n](int i, int j) { return static_cast<std::uint32_t>(j * n + i); };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return mesh;
}

}  // namespace mvflow
