#include "stages/hull/mesh_cleanup.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace mvflow {

namespace {

//! Union–find with path halving; the root of a set is its smallest element, so the labels do
//! not depend on the order of the unions.
struct DisjointSets {
  std::vector<std::uint32_t> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

IndexedMesh largest_component(const IndexedMesh& mesh, std::size_t* components) {
  DisjointSets sets(mesh.positions.size());
  for (const auto& t : mesh.triangles) {
    sets.unite(t[0], t[1]);
    sets.unite(t[0], t[2]);
  }
  std::vector<std::size_t> triangles_of_root(mesh.positions.size(), 0);
  for (const auto& t : mesh.triangles) ++triangles_of_root[sets.find(t[0])];
  if (components)
    *components = static_cast<std::size_t>(
        std::count_if(triangles_of_root.begin(), triangles_of_root.end(), [](std::size_t n) { return n > 0; }));

  // The largest count; among equals, the component met first in triangle order.
  std::uint32_t best = 0;
  std::size_t best_count = 0;
  for (const auto& t : mesh.triangles) {
    const std::uint32_t root = sets.find(t[0]);
    if (triangles_of_root[root] > best_count) {
      best = root;
      best_count = triangles_of_root[root];
    }
  }

  IndexedMesh kept;
  if (best_count == 0) return kept;
  constexpr std::uint32_t kUnused = ~0u;
  std::vector<std::uint32_t> new_id(mesh.positions.size(), kUnused);
  for (std::uint32_t v = 0; v < mesh.positions.size(); ++v)
    if (sets.find(v) == best) {
      new_id[v] = static_cast<std::uint32_t>(kept.positions.size());
      kept.positions.push_back(mesh.positions[v]);
    }
  for (const auto& t : mesh.triangles)
    if (sets.find(t[0]) == best) kept.triangles.push_back({new_id[t[0]], new_id[t[1]], new_id[t[2]]});
  return kept;
}

double enclosed_volume(const IndexedMesh& mesh) {
  double six_volume = 0.0;
  for (const auto& t : mesh.triangles)
    six_volume += mesh.positions[t[0]].dot(mesh.positions[t[1]].cross(mesh.positions[t[2]]));
  return six_volume / 6.0;
}

}  // namespace mvflow
