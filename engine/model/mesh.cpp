#include "engine/model/mesh.h"

#include <mutex>

#include <OpenMesh/Core/System/omstream.hh>
#include <cmath>

#include "engine/model/error.h"

namespace mvflow {

void IndexedMesh::validate(const std::string& source) const {
  const std::size_t n = positions.size();
  for (std::size_t i = 0; i < n; ++i)
    if (!positions[i].allFinite()) throw InputError(source, "vertex", i, "coordinate is not a finite number");
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const auto& t = triangles[f];
    for (std::uint32_t v : t)
      if (v >= n)
        throw InputError(source, "face", f,
                         "vertex index " + std::to_string(v) + " out of range (mesh has " +
                             std::to_string(n) + " vertices)");
  }
  if (!colors.empty() && colors.size() != n)
    throw InputError(source, 0, "has " + std::to_string(colors.size()) + " vertex colours for " +
                                 std::to_string(n) + " vertices");
  if (!quality.empty() && quality.size() != n)
    throw InputError(source, 0, "has " + std::to_string(quality.size()) + " quality values for " +
                                 std::to_string(n) + " vertices");
  if (!texcoords.empty() && texcoords.size() != 3 * triangles.size())
    throw InputError(source, 0, "has " + std::to_string(texcoords.size()) +
                                 " texture coordinates for " + std::to_string(triangles.size()) +
                                 " triangles (expected 3 per triangle)");
}

Mesh build_mesh(const IndexedMesh& indexed, const std::string& source, MeshBuildReport* report) {
  indexed.validate(source);
  Mesh mesh;
  TriMesh& m = mesh.topology;
  m.reserve(indexed.positions.size(), indexed.positions.size() + indexed.triangles.size(),
            indexed.triangles.size());
  for (const auto& p : indexed.positions) m.add_vertex(to_openmesh(p));

  // OpenMesh reports a complex edge or vertex on omerr; we report it ourselves instead.
  const QuietOpenMesh quiet;
  MeshBuildReport local;
  for (std::size_t f = 0; f < indexed.triangles.size(); ++f) {
    const auto& t = indexed.triangles[f];
    const bool degenerate = t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    const auto handle =
        degenerate ? TriMesh::FaceHandle()
                   : m.add_face(TriMesh::VertexHandle(static_cast<int>(t[0])),
                                TriMesh::VertexHandle(static_cast<int>(t[1])),
                                TriMesh::VertexHandle(static_cast<int>(t[2])));
    if (!handle.is_valid()) {
      ++local.rejected_faces;
      if (local.first_rejected.size() < 8) local.first_rejected.push_back(f);
      continue;
    }
    if (indexed.has_texcoords()) {
      // OpenMesh may start a face's vertex cycle at any corner: keep each corner's coordinate.
      for (auto v : m.fv_range(handle)) {
        const int corner = static_cast<std::uint32_t>(v.idx()) == t[0] ? 0
                           : static_cast<std::uint32_t>(v.idx()) == t[1] ? 1 : 2;
        mesh.texcoords.push_back(indexed.texcoords[3 * f + corner]);
      }
    }
  }

  mesh.colors = indexed.colors;
  mesh.quality = indexed.quality;
  mesh.texture_file = indexed.texture_file;
  if (report) *report = std::move(local);
  return mesh;
}

IndexedMesh to_indexed(const Mesh& mesh) {
  IndexedMesh out;
  out.positions = positions_of(mesh.topology);
  out.triangles = triangles_of(mesh.topology);
  out.colors = mesh.colors;
  out.quality = mesh.quality;
  out.texcoords = mesh.texcoords;
  out.texture_file = mesh.texture_file;
  return out;
}

std::vector<Eigen::Vector3d> positions_of(const TriMesh& mesh) {
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(mesh.n_vertices());
  for (auto v : mesh.vertices()) positions.push_back(to_eigen(mesh.point(v)));
  return positions;
}

void set_positions(TriMesh& mesh, const std::vector<Eigen::Vector3d>& positions) {
  MVFLOW_CHECK(positions.size() == mesh.n_vertices(), "set_positions: " + std::to_string(positions.size()) +
                                                          " positions for " + std::to_string(mesh.n_vertices()) +
                                                          " vertices");
  for (auto v : mesh.vertices()) mesh.set_point(v, to_openmesh(positions[static_cast<std::size_t>(v.idx())]));
}

std::vector<std::array<std::uint32_t, 3>> triangles_of(const TriMesh& mesh) {
  std::vector<std::array<std::uint32_t, 3>> triangles;
  triangles.reserve(mesh.n_faces());
  for (auto f : mesh.faces()) {
    std::array<std::uint32_t, 3> t{};
    int corner = 0;
    for (auto v : mesh.fv_range(f)) t[corner++] = static_cast<std::uint32_t>(v.idx());
    triangles.push_back(t);
  }
  return triangles;
}

namespace {

// The streams' state before the first live QuietOpenMesh, and how many live now.
struct QuietState {
  std::mutex mutex;
  int live = 0;
  bool err = false, log = false, out = false;
};

QuietState& quiet_state() {
  static QuietState state;
  return state;
}

}  // namespace

QuietOpenMesh::QuietOpenMesh() {
  QuietState& s = quiet_state();
  const std::lock_guard lock(s.mutex);
  if (s.live++ > 0) return;
  s.err = omerr().is_enabled(), s.log = omlog().is_enabled(), s.out = omout().is_enabled();
  omerr().disable();
  omlog().disable();
  omout().disable();
}

QuietOpenMesh::~QuietOpenMesh() {
  QuietState& s = quiet_state();
  const std::lock_guard lock(s.mutex);
  if (--s.live > 0) return;
  if (s.err) omerr().enable();
  if (s.log) omlog().enable();
  if (s.out) omout().enable();
}

}  // namespace mvflow
