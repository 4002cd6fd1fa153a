#include "stages/synth/synth_initial_mesh.h"

#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

#include "engine/model/bounding_box.h"
#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "stages/hull/mesh_cleanup.h"
#include "stages/synth/synth_render.h"
#include "stages/synth/synth_texture.h"

namespace mvflow {

namespace {

// One-ring neighbours of every vertex with normalized weights, compressed: the neighbours of v
// are ids[start[v] .. start[v+1]), their weights sum to 1.
struct Adjacency {
  std::vector<std::size_t> start;
  std::vector<std::uint32_t> ids;
  std::vector<double> weights;
};

// Cotangent weights clamped at zero (obtuse corners would make them negative), normalized per
// vertex: a geometric Laplacian, so irregular sampling does not distort the smoothed shape the
// way uniform weights do. A vertex whose weights all vanish falls back to uniform weights.
Adjacency cotangent_adjacency(const IndexedMesh& mesh) {
  std::vector<std::map<std::uint32_t, double>> rings(mesh.positions.size());
  for (const auto& t : mesh.triangles)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t i = t[c], j = t[(c + 1) % 3], k = t[(c + 2) % 3];
      const Eigen::Vector3d a = mesh.positions[i] - mesh.positions[k], b = mesh.positions[j] - mesh.positions[k];
      const double sine = a.cross(b).norm();
      const double cotangent = sine > 0 ? a.dot(b) / sine : 0.0;  // of the corner at k, facing edge ij
      rings[i][j] += 0.5 * cotangent;
      rings[j][i] += 0.5 * cotangent;
    }
  Adjacency a;
  a.start.push_back(0);
  for (const auto& ring : rings) {
    double sum = 0.0;
    for (const auto& [id, w] : ring) sum += std::max(0.0, w);
    for (const auto& [id, w] : ring) {
      a.ids.push_back(id);
      a.weights.push_back(sum > 0 ? std::max(0.0, w) / sum : 1.0 / static_cast<double>(ring.size()));
    }
    a.start.push_back(a.ids.size());
  }
  return a;
}

void laplacian_step(const Adjacency& a, double factor, std::vector<Eigen::Vector3d>& p,
                    std::vector<Eigen::Vector3d>& scratch) {
  for (std::size_t v = 0; v < p.size(); ++v) {
    if (a.start[v + 1] == a.start[v]) {
      scratch[v] = p[v];
      continue;
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t k = a.start[v]; k < a.start[v + 1]; ++k) mean += a.weights[k] * p[a.ids[k]];
    scratch[v] = p[v] + factor * (mean - p[v]);
  }
  std::swap(p, scratch);
}

double mean_edge_length(const IndexedMesh& mesh) {
  double sum = 0.0;
  for (const auto& t : mesh.triangles)
    for (int c = 0; c < 3; ++c) sum += (mesh.positions[t[c]] - mesh.positions[t[(c + 1) % 3]]).norm();
  return sum / (3.0 * static_cast<double>(mesh.triangles.size()));
}

void require_closed_manifold(const IndexedMesh& mesh) {
  QuietOpenMesh quiet;
  MeshBuildReport report;
  const Mesh built = build_mesh(mesh, "ground truth", &report);
  if (report.rejected_faces > 0) throw InputError("initial mesh: the ground truth is not manifold");
  for (const auto h : built.topology.halfedges())
    if (built.topology.is_boundary(h)) throw InputError("initial mesh: the ground truth is not closed (it has a boundary)");
}

double box_diagonal(const IndexedMesh& mesh) {
  BoundingBox box;
  for (const auto& p : mesh.positions) box.extend(p);
  return box.diagonal();
}

void push_along_normals(IndexedMesh& mesh, const std::vector<double>& distances) {
  const auto normals = vertex_normals(mesh);
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) mesh.positions[v] += distances[v] * normals[v];
}

}  // namespace

void InitialMeshOptions::check() const {
  require_option(amount >= 0 && amount <= 0.5, "amount", amount, "[0, 0.5]");
  require_option(vertices >= 20, "vertices", vertices, ">= 20");
  require_option(smoothing >= 0 && smoothing <= 0.5, "smoothing", smoothing, "[0, 0.5]");
}

int smooth_keeping_volume(IndexedMesh& mesh, double length) {
  // n steps of λ·L spread like a heat kernel of variance n·λ·h²/4 on a regular mesh of edge h.
  const double h = mean_edge_length(mesh);
  const int steps = std::clamp(static_cast<int>(std::ceil(4.0 * length * length / (0.5 * h * h))), 0, 5000);
  const double volume = enclosed_volume(mesh);
  const Adjacency a = cotangent_adjacency(mesh);
  std::vector<Eigen::Vector3d> scratch(mesh.positions.size());
  for (int i = 0; i < steps; ++i) laplacian_step(a, 0.5, mesh.positions, scratch);
  const double smoothed = enclosed_volume(mesh);
  if (steps > 0 && smoothed > 0 && volume > 0) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const auto& p : mesh.positions) centroid += p;
    centroid /= static_cast<double>(mesh.positions.size());
    const double scale = std::cbrt(volume / smoothed);
    for (auto& p : mesh.positions) p = centroid + scale * (p - centroid);
  }
  return steps;
}

IndexedMesh decimate(const IndexedMesh& mesh, int vertices) {
  QuietOpenMesh quiet;
  IndexedMesh plain;
  plain.positions = mesh.positions;
  plain.triangles = mesh.triangles;
  Mesh built = build_mesh(plain, "decimation input");
  TriMesh& m = built.topology;
  if (static_cast<std::size_t>(vertices) < m.n_vertices()) {
    m.request_vertex_status();
    m.request_edge_status();
    m.request_face_status();
    m.request_face_normals();
    m.update_face_normals();
    OpenMesh::Decimater::DecimaterT<TriMesh> decimater(m);
    OpenMesh::Decimater::ModQuadricT<TriMesh>::Handle quadric;
    OpenMesh::Decimater::ModNormalFlippingT<TriMesh>::Handle no_flips;
    decimater.add(quadric);
    decimater.add(no_flips);
    decimater.module(quadric).unset_max_err();
    decimater.initialize();
    decimater.decimate_to(static_cast<std::size_t>(vertices));
    m.garbage_collection();
  }
  IndexedMesh out;
  out.positions = positions_of(m);
  out.triangles = triangles_of(m);
  return out;
}

IndexedMesh make_initial_mesh(const IndexedMesh& truth, const InitialMeshOptions& options) {
  options.check();
  if (options.kind == InitialMeshKind::Hull)
    throw InputError("initial mesh: the visual hull needs the views; make_synth_scene builds it");
  require_closed_manifold(truth);
  IndexedMesh mesh;
  mesh.positions = truth.positions;
  mesh.triangles = truth.triangles;
  const double diagonal = box_diagonal(truth);
  if (options.kind == InitialMeshKind::Offset) {
    smooth_keeping_volume(mesh, options.smoothing * diagonal);
    push_along_normals(mesh, std::vector<double>(mesh.positions.size(), options.amount * diagonal));
    return decimate(mesh, options.vertices);
  }
  mesh = decimate(mesh, options.vertices);
  std::vector<double> distances(mesh.positions.size());
  for (std::size_t v = 0; v < distances.size(); ++v) {
    const std::uint64_t bits = mix_seed(options.seed, v);
    distances[v] = options.amount * diagonal * (2.0 * static_cast<double>(bits >> 11) * 0x1.0p-53 - 1.0);
  }
  push_along_normals(mesh, distances);
  return mesh;
}

}  // namespace mvflow
