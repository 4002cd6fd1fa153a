// Choosing the mesh format from the file name and dispatching to the format's reader or writer.

#include "io/mesh_io.h"

#include <algorithm>
#include <cctype>

#include "engine/model/error.h"

namespace mvflow::io {

MeshFormat mesh_format_from_path(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".ply") return MeshFormat::Ply;
  if (extension == ".obj") return MeshFormat::Obj;
  if (extension == ".off") return MeshFormat::Off;
  if (extension == ".stl") return MeshFormat::Stl;
  if (extension == ".wrl" || extension == ".vrml") return MeshFormat::Vrml;
  throw InputError(file, 0,
                   "unsupported mesh format '" + extension +
                       "' (expected the extension .ply, .obj, .off, .stl, .wrl or .vrml)");
}

IndexedMesh read_mesh(const std::filesystem::path& file) {
  switch (mesh_format_from_path(file)) {
    case MeshFormat::Ply: return read_ply(file);
    case MeshFormat::Obj: return read_obj(file);
    case MeshFormat::Off: return read_off(file);
    case MeshFormat::Stl: return read_stl(file);
    case MeshFormat::Vrml: return read_vrml(file);
  }
  throw InputError(file, 0, "unsupported mesh format");
}

void write_mesh(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options) {
  switch (mesh_format_from_path(file)) {
    case MeshFormat::Ply: return write_ply(file, mesh, options);
    case MeshFormat::Obj: return write_obj(file, mesh, options);
    case MeshFormat::Off: return write_off(file, mesh, options);
    case MeshFormat::Stl: return write_stl(file, mesh, options);
    case MeshFormat::Vrml: return write_vrml(file, mesh, options);
  }
}

Mesh load_mesh(const std::filesystem::path& file, MeshBuildReport* report) {
  const IndexedMesh indexed = read_mesh(file);
  if (indexed.triangles.empty()) throw InputError(file, 0, "mesh has no triangles");
  Mesh mesh = build_mesh(indexed, file.string(), report);
  // Every face may have been rejected (degenerate or non-manifold): still no surface to work on.
  if (mesh.n_faces() == 0) throw InputError(file, 0, "mesh has no triangles that form a manifold surface");
  return mesh;
}

}  // namespace mvflow::io
