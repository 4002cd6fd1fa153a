// STL (ASCII and binary) through OpenMesh, whose reader welds equal corner positions into shared
// vertices. OpenMesh only says "failed", so the checks around it name the file and the problem.

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <fstream>
#include <sstream>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/mesh_io.h"

namespace mvflow::io {

namespace {

//! Every triangle with its own three vertices: STL has no shared vertices anyway, and this way
//! OpenMesh cannot drop a non-manifold or degenerate triangle while building its mesh.
TriMesh to_triangle_soup(const IndexedMesh& mesh) {
  TriMesh m;
  m.reserve(3 * mesh.triangles.size(), 3 * mesh.triangles.size(), mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const auto a = m.add_vertex(to_openmesh(mesh.positions[t[0]]));
    const auto b = m.add_vertex(to_openmesh(mesh.positions[t[1]]));
    const auto c = m.add_vertex(to_openmesh(mesh.positions[t[2]]));
    m.add_face(a, b, c);
  }
  return m;
}

}  // namespace

IndexedMesh read_stl(const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error) || !std::ifstream(file, std::ios::binary))
    throw IoError(file, "cannot open for reading");
  if (std::filesystem::file_size(file, error) == 0) throw InputError(file, 0, "expected an STL file, the file is empty");
  TriMesh m;
  OpenMesh::IO::Options options;
  bool ok = false;
  {
    QuietOpenMesh quiet;
    ok = OpenMesh::IO::read_mesh(m, file.string(), options);
  }
  if (!ok) throw InputError(file, 0, "expected an ASCII or binary STL file (OpenMesh could not read it)");
  if (m.n_faces() == 0) throw InputError(file, 0, "expected at least one triangle, the STL file has none");
  IndexedMesh mesh;
  mesh.positions = positions_of(m);
  mesh.triangles = triangles_of(m);
  mesh.validate(file.string());  // finite coordinates
  return mesh;
}

void write_stl(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options) {
  mesh.validate(file.string());
  const TriMesh soup = to_triangle_soup(mesh);
  OpenMesh::IO::Options om_options;
  if (options.binary) om_options += OpenMesh::IO::Options::Binary;
  // Into memory, then through a checked stream: OpenMesh's file writer reports success on a full
  // disk and leaves an empty file.
  std::ostringstream encoded(std::ios::binary);
  bool ok = false;
  {
    QuietOpenMesh quiet;
    // STL stores floats: 9 significant digits make the ASCII form exact for them.
    ok = OpenMesh::IO::write_mesh(soup, encoded, ".stl", om_options, 9);
  }
  if (!ok) throw IoError(file, "cannot encode the STL file (OpenMesh failed)");
  const std::string bytes = encoded.str();
  write_atomically(file, options.binary, [&](std::ostream& out) { out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); });
}

}  // namespace mvflow::io
