#include "stages/topology/red_green.h"

namespace mvflow::detail {

namespace {

bool face_is_red(const TriMesh& mesh, TriMesh::HalfedgeHandle h, const std::vector<std::uint8_t>& red) {
  const TriMesh::FaceHandle f = mesh.face_handle(h);
  return f.is_valid() && red[f.idx()];
}

}  // namespace

bool edge_is_split(const TriMesh& mesh, TriMesh::EdgeHandle e, const std::vector<std::uint8_t>& red) {
  return face_is_red(mesh, mesh.halfedge_handle(e, 0), red) || face_is_red(mesh, mesh.halfedge_handle(e, 1), red);
}

std::size_t close_red_faces(const TriMesh& mesh, std::vector<std::uint8_t>& red) {
  // A face's split edges change only when a neighbour turns red, so only those are looked at again.
  std::vector<TriMesh::FaceHandle> work;
  for (auto f : mesh.faces())
    if (red[f.idx()])
      for (auto g : mesh.ff_range(f))
        if (!red[g.idx()]) work.push_back(g);
  std::size_t promoted = 0;
  while (!work.empty()) {
    const TriMesh::FaceHandle f = work.back();
    work.pop_back();
    if (red[f.idx()]) continue;
    int split = 0;
    for (auto e : mesh.fe_range(f)) split += edge_is_split(mesh, e, red) ? 1 : 0;
    if (split < 2) continue;
    red[f.idx()] = 1;
    ++promoted;
    for (auto g : mesh.ff_range(f))
      if (!red[g.idx()]) work.push_back(g);
  }
  return promoted;
}

ChildFaces child_faces(const Corners& c, const Corners& m) {
  ChildFaces out;
  const int split = (m[0] >= 0) + (m[1] >= 0) + (m[2] >= 0);
  if (split == 3) {
    out.faces = {Corners{c[0], m[0], m[2]}, Corners{c[1], m[1], m[0]}, Corners{c[2], m[2], m[1]},
                 Corners{m[0], m[1], m[2]}};
    out.count = 4;
  } else if (split == 1) {
    const int k = m[0] >= 0 ? 0 : m[1] >= 0 ? 1 : 2;
    out.faces[0] = {c[k], m[k], c[(k + 2) % 3]};
    out.faces[1] = {m[k], c[(k + 1) % 3], c[(k + 2) % 3]};
    out.count = 2;
  } else if (split == 0) {
    out.faces[0] = c;
    out.count = 1;
  }
  return out;
}

}  // namespace mvflow::detail
