// Wavefront OBJ: positions (with optional vertex colours), texture coordinates, polygonal faces
// and the diffuse texture named by the material library.

#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/number_text.h"
#include "io/mesh_io.h"
#include "io/text_reader.h"

namespace mvflow::io {

namespace {

//! Parses a float as a float (not via double) so a shortest-form float round-trips exactly.
float parse_float(const TextReader& reader, std::string_view token, const std::string& what) {
  parse_double(reader, token, what);  // the common errors and their wording
  float value = 0.0f;
  const char* begin = token.data() + (token[0] == '+' ? 1 : 0);
  const auto [ptr, ec] = std::from_chars(begin, token.data() + token.size(), value);
  if (ec != std::errc() || !std::isfinite(value))
    reader.fail("expected a finite float for " + what + ", got '" + std::string(token) + "'");
  return value;
}

//! The largest positive (forward-referencing allowed) index and the first line that used it.
struct LargestReference {
  long long index = -1;
  std::size_t line = 0;
  void note(long long i, std::size_t at) {
    if (i > index) {
      index = i;
      line = at;
    }
  }
};

struct ObjReader {
  explicit ObjReader(const std::filesystem::path& file) : reader(file) {}

  TextReader reader;
  IndexedMesh mesh;
  std::vector<Eigen::Vector3f> colors;  // kept only when every vertex has one
  std::vector<Eigen::Vector2f> uvs;     // the vt list
  std::vector<long long> uv_corners;    // per triangle corner, into uvs
  std::optional<bool> faces_have_uv;    // decided by the first face
  std::size_t first_face_line = 0;
  LargestReference largest_vertex, largest_uv;
  std::vector<std::string> material_libraries;

  void read_vertex(const std::vector<std::string_view>& t) {
    if (t.size() != 4 && t.size() != 5 && t.size() != 7 && t.size() != 8)
      reader.fail("expected 'v x y z' or 'v x y z r g b'");
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) p[k] = parse_double(reader, t[1 + k], "a vertex coordinate");
    mesh.positions.push_back(p);
    if (t.size() >= 7) {
      Eigen::Vector3f c;
      for (int k = 0; k < 3; ++k) c[k] = parse_float(reader, t[4 + k], "a vertex colour");
      colors.push_back(c);
    }
  }

  void read_uv(const std::vector<std::string_view>& t) {
    if (t.size() < 3 || t.size() > 4) reader.fail("expected 'vt u v'");
    uvs.emplace_back(parse_float(reader, t[1], "a texture coordinate"), parse_float(reader, t[2], "a texture coordinate"));
  }

  //! A 1-based or negative (relative to \p count so far) OBJ index, returned 0-based.
  long long resolve(std::string_view token, std::size_t count, const std::string& what, LargestReference& largest) {
    const bool negative = !token.empty() && token[0] == '-';
    const long long value = parse_integer(reader, negative ? token.substr(1) : token, what);
    if (value > std::numeric_limits<std::uint32_t>::max()) reader.fail(what + " '" + std::string(token) + "' is too large");
    if (value == 0) reader.fail("expected a non-zero " + what + " (OBJ indices start at 1), got '" + std::string(token) + "'");
    if (!negative) {
      largest.note(value - 1, reader.line_number());  // checked once the whole file is read
      return value - 1;
    }
    if (static_cast<std::size_t>(value) > count)
      reader.fail(what + " '" + std::string(token) + "' refers before the first of the " + std::to_string(count) +
                  " defined so far");
    return static_cast<long long>(count) - value;
  }

  void read_face(const std::vector<std::string_view>& t) {
    if (t.size() < 4) reader.fail("expected a face with at least 3 corners");
    std::vector<long long> vertices, corner_uvs;
    for (std::size_t k = 1; k < t.size(); ++k) {
      const auto corner = t[k];
      const auto slash = corner.find('/');
      vertices.push_back(resolve(corner.substr(0, slash), mesh.positions.size(), "vertex index", largest_vertex));
      if (slash == std::string_view::npos) continue;
      const auto rest = corner.substr(slash + 1);
      const auto uv = rest.substr(0, rest.find('/'));
      if (!uv.empty()) corner_uvs.push_back(resolve(uv, uvs.size(), "texture coordinate index", largest_uv));
    }
    check_uv_consistency(corner_uvs.size(), vertices.size());
    for (std::size_t k = 1; k + 1 < vertices.size(); ++k) {
      mesh.triangles.push_back({static_cast<std::uint32_t>(vertices[0]), static_cast<std::uint32_t>(vertices[k]),
                                static_cast<std::uint32_t>(vertices[k + 1])});
      if (!corner_uvs.empty()) uv_corners.insert(uv_corners.end(), {corner_uvs[0], corner_uvs[k], corner_uvs[k + 1]});
    }
  }

  // Texture coordinates are per triangle corner for the whole mesh or not at all.
  void check_uv_consistency(std::size_t n_uv, std::size_t n_corners) {
    if (n_uv != 0 && n_uv != n_corners) reader.fail("expected a texture coordinate index on every corner of the face");
    const bool has_uv = n_uv != 0;
    if (!faces_have_uv) {
      faces_have_uv = has_uv;
      first_face_line = reader.line_number();
      return;
    }
    if (*faces_have_uv != has_uv)
      reader.fail(std::string("expected ") + (*faces_have_uv ? "texture coordinate indices (v/vt)" : "no texture coordinate indices") +
                  " like the first face on line " + std::to_string(first_face_line) + ": either every face has them or none");
  }

  void read_line() {
    const auto t = split_whitespace(reader.line());
    if (t.empty()) return;
    const auto keyword = t[0];
    if (keyword == "v") read_vertex(t);
    else if (keyword == "vt") read_uv(t);
    else if (keyword == "f") read_face(t);
    else if (keyword == "mtllib" && t.size() >= 2) add_libraries(t);
    // vn, o, g, s, usemtl, l, p and anything else carry nothing mvflow uses.
  }

  //! "mtllib a.mtl b.mtl" lists libraries; a name with spaces is tried as a whole first.
  void add_libraries(const std::vector<std::string_view>& t) {
    const auto& line = reader.line();
    const auto start = static_cast<std::size_t>(t[1].data() - line.data());
    const auto end = static_cast<std::size_t>(t.back().data() + t.back().size() - line.data());
    material_libraries.push_back(line.substr(start, end - start));
    for (std::size_t k = 1; t.size() > 2 && k < t.size(); ++k) material_libraries.emplace_back(t[k]);
  }

  void check_references() const {
    if (largest_vertex.index >= static_cast<long long>(mesh.positions.size()))
      throw InputError(reader.file(), largest_vertex.line,
                       "vertex index " + std::to_string(largest_vertex.index + 1) + " out of range (file has " +
                           std::to_string(mesh.positions.size()) + " vertices)");
    if (largest_uv.index >= static_cast<long long>(uvs.size()))
      throw InputError(reader.file(), largest_uv.line,
                       "texture coordinate index " + std::to_string(largest_uv.index + 1) + " out of range (file has " +
                           std::to_string(uvs.size()) + " texture coordinates)");
  }
};

//! The file name of a `map_Kd` line: what follows its options ("-s 1 1 1", "-clamp on", ...),
//! spaces included.
std::string texture_name(std::string_view line) {
  auto tokens = split_whitespace(line);
  std::size_t i = 1;  // after map_Kd
  while (i + 1 < tokens.size() && tokens[i].size() > 1 && tokens[i][0] == '-') {
    const auto option = tokens[i++];
    // -o, -s and -t take one to three numbers, -mm two, every other option one value.
    const std::size_t most = (option == "-o" || option == "-s" || option == "-t") ? 3 : option == "-mm" ? 2 : 1;
    for (std::size_t k = 0; k < most && i + 1 < tokens.size(); ++k) {
      const bool number = std::isdigit(static_cast<unsigned char>(tokens[i][0])) || tokens[i][0] == '.' ||
                          (tokens[i][0] == '-' && tokens[i].size() > 1 && !std::isalpha(static_cast<unsigned char>(tokens[i][1])));
      if (k > 0 && !number) break;
      ++i;
    }
  }
  if (i >= tokens.size()) return {};
  const auto start = static_cast<std::size_t>(tokens[i].data() - line.data());
  const auto end = static_cast<std::size_t>(tokens.back().data() + tokens.back().size() - line.data());
  return std::string(line.substr(start, end - start));
}

//! The first `map_Kd` of the material library beside the OBJ file, if the library exists.
std::string diffuse_texture(const std::filesystem::path& obj, const std::string& library) {
  const auto path = obj.parent_path() / library;
  // A missing .mtl only loses the texture name; so does a name the file system refuses (too long,
  // a folder, ...): the error_code overload, since the throwing one escapes as filesystem_error.
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return {};
  TextReader reader(path);
  while (reader.next_content_line('#')) {
    const auto t = split_whitespace(reader.line());
    if (t.size() >= 2 && t[0] == "map_Kd") return texture_name(reader.line());
  }
  return {};
}

void put_obj(std::ostream& out, const IndexedMesh& mesh, const MeshWriteOptions& options, const std::string& library) {
  const bool colors = options.write_colors && mesh.has_colors();
  const bool uvs = options.write_texcoords && mesh.has_texcoords();
  out << "# written by mvflow\n";
  if (!library.empty()) out << "mtllib " << library << "\nusemtl material0\n";
  std::string line;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    line.clear();
    line.push_back('v');
    for (int k = 0; k < 3; ++k) append_number(line.append(" "), mesh.positions[v][k]);
    if (colors)
      for (int k = 0; k < 3; ++k) append_number(line.append(" "), mesh.colors[v][k]);
    out << line << '\n';
  }
  if (uvs)
    for (const auto& uv : mesh.texcoords) {
      line.clear();
      line.push_back('v');
      line.push_back('t');
      for (int k = 0; k < 2; ++k) append_number(line.append(" "), uv[k]);
      out << line << '\n';
    }
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    out << 'f';
    for (int c = 0; c < 3; ++c) {
      out << ' ' << mesh.triangles[f][c] + 1;
      if (uvs) out << '/' << 3 * f + c + 1;
    }
    out << '\n';
  }
}

}  // namespace

IndexedMesh read_obj(const std::filesystem::path& file) {
  ObjReader obj(file);
  while (obj.reader.next_content_line('#')) obj.read_line();
  obj.check_references();
  IndexedMesh mesh = std::move(obj.mesh);
  if (obj.colors.size() == mesh.positions.size()) mesh.colors = std::move(obj.colors);
  if (obj.faces_have_uv.value_or(false)) {
    mesh.texcoords.reserve(obj.uv_corners.size());
    for (long long i : obj.uv_corners) mesh.texcoords.push_back(obj.uvs[static_cast<std::size_t>(i)]);
  }
  for (const auto& library : obj.material_libraries) {
    mesh.texture_file = diffuse_texture(file, library);
    if (!mesh.texture_file.empty()) break;
  }
  mesh.validate(file.string());
  return mesh;
}

void write_obj(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options) {
  mesh.validate(file.string());
  std::string library;
  if (!mesh.texture_file.empty()) {
    auto mtl = file;
    mtl.replace_extension(".mtl");
    library = mtl.filename().string();
    write_atomically(mtl, false, [&](std::ostream& out) {
      out << "# written by mvflow\nnewmtl material0\nKa 1 1 1\nKd 1 1 1\nmap_Kd " << mesh.texture_file << '\n';
    });
  }
  write_atomically(file, false, [&](std::ostream& out) { put_obj(out, mesh, options, library); });
}

}  // namespace mvflow::io
