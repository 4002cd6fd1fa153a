// Object File Format (Geomview OFF): [ST][C][N]OFF header, counts, vertices, polygonal faces.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/number_text.h"
#include "io/mesh_io.h"
#include "io/text_reader.h"

namespace mvflow::io {

namespace {

//! What the header keyword says each vertex line carries after x y z.
struct OffLayout {
  bool texcoords = false;  // ST prefix (read past, not kept: OFF has them per vertex)
  bool colors = false;     // C prefix
  bool normals = false;    // N prefix
};

OffLayout parse_keyword(const TextReader& reader, std::string_view keyword) {
  OffLayout layout;
  std::string_view rest = keyword;
  auto take = [&rest](std::string_view prefix) {
    if (rest.substr(0, prefix.size()) != prefix) return false;
    rest.remove_prefix(prefix.size());
    return true;
  };
  layout.texcoords = take("ST");
  layout.colors = take("C");
  layout.normals = take("N");
  if (rest != "OFF")
    reader.fail("expected the header 'OFF' (or COFF, NOFF, STOFF; 4D and nOFF are not supported), got '" +
                std::string(keyword) + "'");
  return layout;
}

//! Geomview: integer colours are 0-255, real ones already 0-1; a colour with any real component
//! ("1.0 0.5 0") is real as a whole.
Eigen::Vector3f read_color(const TextReader& reader, const std::vector<std::string_view>& tokens, std::size_t first) {
  bool integer = true;
  Eigen::Vector3f color;
  for (int k = 0; k < 3; ++k) {
    const auto token = tokens[first + k];
    color[k] = static_cast<float>(parse_double(reader, token, "a vertex colour"));
    integer = integer && token.find_first_of(".eE") == std::string_view::npos;
  }
  return integer ? Eigen::Vector3f(color / 255.0f) : color;
}

void read_vertex(const TextReader& reader, const OffLayout& layout, IndexedMesh& mesh) {
  const auto t = split_whitespace(reader.line());
  const std::size_t needed = 3 + (layout.normals ? 3 : 0) + (layout.colors ? 3 : 0) + (layout.texcoords ? 2 : 0);
  if (t.size() < needed)
    reader.fail("expected " + std::to_string(needed) + " values on a vertex line, got " + std::to_string(t.size()));
  Eigen::Vector3d p;
  for (int k = 0; k < 3; ++k) p[k] = parse_double(reader, t[k], "a vertex coordinate");
  mesh.positions.push_back(p);
  if (!layout.colors) return;
  mesh.colors.push_back(read_color(reader, t, layout.normals ? 6 : 3));
}

void read_face(const TextReader& reader, std::size_t face, std::size_t n_vertices, IndexedMesh& mesh) {
  const auto t = split_whitespace(reader.line());
  const auto n = static_cast<std::size_t>(parse_integer(reader, t[0], "the number of corners of a face"));
  if (n < 3) reader.fail("face " + std::to_string(face) + ": expected at least 3 corners, got " + std::to_string(n));
  if (t.size() < n + 1)
    reader.fail("face " + std::to_string(face) + ": expected " + std::to_string(n) + " vertex indices, got " +
                std::to_string(t.size() - 1));
  std::vector<std::uint32_t> corners(n);
  for (std::size_t k = 0; k < n; ++k) {
    const long long v = parse_integer(reader, t[1 + k], "a vertex index");
    if (static_cast<std::size_t>(v) >= n_vertices)
      reader.fail("face " + std::to_string(face) + ": vertex index " + std::to_string(v) + " out of range (file has " +
                  std::to_string(n_vertices) + " vertices)");
    corners[k] = static_cast<std::uint32_t>(v);
  }
  // Anything after the indices is a face colour, which mvflow does not keep.
  for (std::size_t k = 1; k + 1 < n; ++k) mesh.triangles.push_back({corners[0], corners[k], corners[k + 1]});
}

[[noreturn]] void truncated(const TextReader& reader, std::size_t expected, const std::string& what, std::size_t got) {
  throw InputError(reader.file(), reader.line_number() + 1,
                   "expected " + std::to_string(expected) + " " + what + ", file ends after " + std::to_string(got));
}

int to_byte(float channel) {
  const float clamped = std::clamp(std::isfinite(channel) ? channel : 0.0f, 0.0f, 1.0f);
  return static_cast<int>(std::lround(clamped * 255.0f));
}

void put_off(std::ostream& out, const IndexedMesh& mesh, bool colors) {
  out << (colors ? "COFF\n" : "OFF\n") << mesh.positions.size() << ' ' << mesh.triangles.size() << " 0\n";
  std::string line;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    line.clear();
    for (int k = 0; k < 3; ++k) append_number(k > 0 ? line.append(" ") : line, mesh.positions[v][k]);
    // Integer 0-255 colours (with opaque alpha), the form every OFF reader understands.
    if (colors)
      for (int k = 0; k < 4; ++k) line.append(" ").append(std::to_string(k < 3 ? to_byte(mesh.colors[v][k]) : 255));
    out << line << '\n';
  }
  for (const auto& t : mesh.triangles) out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
}

}  // namespace

IndexedMesh read_off(const std::filesystem::path& file) {
  TextReader reader(file);
  reader.require_content_line("the header 'OFF'");
  auto tokens = split_whitespace(reader.line());
  const OffLayout layout = parse_keyword(reader, tokens[0]);
  if (tokens.size() == 1) {  // the counts usually follow on their own line
    reader.require_content_line("the counts 'vertices faces edges'");
    tokens = split_whitespace(reader.line());
  } else {
    tokens.erase(tokens.begin());
  }
  if (tokens.size() < 2 || tokens.size() > 3) reader.fail("expected the counts 'vertices faces edges'");
  const auto n_vertices = static_cast<std::size_t>(parse_integer(reader, tokens[0], "the number of vertices"));
  const auto n_faces = static_cast<std::size_t>(parse_integer(reader, tokens[1], "the number of faces"));
  if (n_vertices > std::numeric_limits<std::uint32_t>::max()) reader.fail("too many vertices");

  IndexedMesh mesh;
  // The counts are untrusted: room for no more elements than the file can hold ("0 0 0\n" is 6 bytes,
  // "3 0 0 0\n" 8).
  mesh.positions.reserve(reservable(n_vertices, file, 6));
  for (std::size_t v = 0; v < n_vertices; ++v) {
    if (!reader.next_content_line('#')) truncated(reader, n_vertices, "vertices", v);
    read_vertex(reader, layout, mesh);
  }
  mesh.triangles.reserve(reservable(n_faces, file, 8));
  for (std::size_t f = 0; f < n_faces; ++f) {
    if (!reader.next_content_line('#')) truncated(reader, n_faces, "faces", f);
    read_face(reader, f, n_vertices, mesh);
  }
  if (reader.next_content_line('#')) reader.fail("unexpected content after the last of the " + std::to_string(n_faces) + " faces");
  mesh.validate(file.string());
  return mesh;
}

void write_off(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options) {
  write_atomically(file, false, [&](std::ostream& out) {
    mesh.validate(file.string());
    put_off(out, mesh, options.write_colors && mesh.has_colors());
  });
}

}  // namespace mvflow::io
