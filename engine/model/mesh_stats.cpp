#include "engine/model/mesh_stats.h"

#include <algorithm>
#include <limits>
#include <vector>

namespace mvflow {

EdgeLengths edge_lengths(const TriMesh& mesh) {
  EdgeLengths lengths;
  if (mesh.n_edges() == 0) return lengths;
  lengths.shortest = std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (auto e : mesh.edges()) {
    const double length = mesh.calc_edge_length(e);
    lengths.shortest = std::min(lengths.shortest, length);
    lengths.longest = std::max(lengths.longest, length);
    sum += length;
  }
  lengths.mean = sum / static_cast<double>(mesh.n_edges());
  return lengths;
}

MeshStats compute_mesh_stats(const Mesh& mesh) {
  const TriMesh& m = mesh.topology;
  MeshStats s;
  s.vertices = m.n_vertices();
  s.faces = m.n_faces();
  s.edges = m.n_edges();

  const EdgeLengths lengths = edge_lengths(m);
  s.shortest_edge = lengths.shortest;
  s.longest_edge = lengths.longest;
  s.mean_edge = lengths.mean;
  for (auto e : m.edges()) s.boundary_edges += m.is_boundary(e);

  std::size_t used_vertices = 0;
  s.bounding_box = bounding_box_of(m);
  for (auto v : m.vertices()) {
    if (m.is_isolated(v)) {
      ++s.isolated_vertices;
      continue;
    }
    ++used_vertices;
    if (!m.is_manifold(v)) ++s.non_manifold_vertices;
  }

  // Boundary loops: follow boundary halfedges once each.
  std::vector<char> seen(m.n_halfedges(), 0);
  for (auto h : m.halfedges()) {
    if (!m.is_boundary(h) || seen[h.idx()]) continue;
    ++s.boundary_loops;
    auto current = h;
    do {
      seen[current.idx()] = 1;
      current = m.next_halfedge_handle(current);
    } while (current != h && !seen[current.idx()]);
  }

  // Components over faces (flood fill through shared edges).
  std::vector<int> component(m.n_faces(), -1);
  std::vector<TriMesh::FaceHandle> stack;
  for (auto f : m.faces()) {
    if (component[f.idx()] >= 0) continue;
    const int id = static_cast<int>(s.components++);
    component[f.idx()] = id;
    stack.push_back(f);
    while (!stack.empty()) {
      const auto current = stack.back();
      stack.pop_back();
      for (auto neighbour : m.ff_range(current))
        if (component[neighbour.idx()] < 0) {
          component[neighbour.idx()] = id;
          stack.push_back(neighbour);
        }
    }
  }

  s.euler_characteristic = static_cast<long>(used_vertices) - static_cast<long>(s.edges) +
                           static_cast<long>(s.faces);
  s.genus = (2 * static_cast<long>(s.components) - s.euler_characteristic -
             static_cast<long>(s.boundary_loops)) / 2;
  return s;
}

BoundingBox bounding_box_of(const TriMesh& mesh) {
  BoundingBox box;
  for (auto v : mesh.vertices()) box.extend(to_eigen(mesh.point(v)));
  return box;
}

}  // namespace mvflow
