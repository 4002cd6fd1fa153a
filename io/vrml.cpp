// VRML 2.0 (VRML97) IndexedFaceSet geometry, the exchange format of the PhotoModeler workflow.
// Reading walks the node tree: Transform nodes are applied to the points below them, every
// IndexedFaceSet is appended to one mesh, the first ImageTexture url names the texture, and
// every other node or field is skipped with its braces and brackets balanced.

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/number_text.h"
#include "io/mesh_io.h"

namespace mvflow::io {

namespace {

enum class Kind { Word, String, OpenBrace, CloseBrace, OpenBracket, CloseBracket, End };

struct Token {
  Kind kind;
  std::string_view text;  // for a string: the content between the quotes, escapes not resolved
  std::size_t line;
};

bool is_delimiter(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ',' || c == '{' || c == '}' || c == '[' ||
         c == ']' || c == '"' || c == '#';
}

//! Splits the file after its header line. Commas are whitespace; '#' starts a comment. Also checks
//! that braces and brackets are balanced, so the parser can rely on it.
std::vector<Token> tokenize(std::string_view text, std::size_t first_line, const std::filesystem::path& file) {
  std::vector<Token> tokens;
  std::vector<Token> open;  // unclosed braces and brackets
  std::size_t line = first_line;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c == '\n') { ++line; ++i; continue; }
    if (c == ' ' || c == '\t' || c == '\r' || c == ',') { ++i; continue; }
    if (c == '#') {
      while (i < text.size() && text[i] != '\n') ++i;
      continue;
    }
    if (c == '"') {
      const std::size_t start = ++i, start_line = line;
      while (i < text.size() && text[i] != '"') {
        if (text[i] == '\\' && i + 1 < text.size()) ++i;
        if (text[i] == '\n') ++line;
        ++i;
      }
      if (i >= text.size()) throw InputError(file, start_line, "expected the closing '\"' of this string");
      tokens.push_back({Kind::String, text.substr(start, i - start), start_line});
      ++i;
      continue;
    }
    if (c == '{' || c == '[') {
      tokens.push_back({c == '{' ? Kind::OpenBrace : Kind::OpenBracket, text.substr(i, 1), line});
      open.push_back(tokens.back());
      ++i;
      continue;
    }
    if (c == '}' || c == ']') {
      const Kind opener = c == '}' ? Kind::OpenBrace : Kind::OpenBracket;
      if (open.empty() || open.back().kind != opener)
        throw InputError(file, line, std::string("unexpected '") + c + "' (nothing open to close)");
      open.pop_back();
      tokens.push_back({c == '}' ? Kind::CloseBrace : Kind::CloseBracket, text.substr(i, 1), line});
      ++i;
      continue;
    }
    const std::size_t start = i;
    while (i < text.size() && !is_delimiter(text[i])) ++i;
    tokens.push_back({Kind::Word, text.substr(start, i - start), line});
  }
  if (!open.empty())
    throw InputError(file, open.back().line,
                     std::string("expected a '") + (open.back().kind == Kind::OpenBrace ? '}' : ']') +
                         "' to close this '" + std::string(open.back().text) + "' before the end of the file");
  tokens.push_back({Kind::End, {}, line});
  return tokens;
}

std::string unescape(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\\' && i + 1 < text.size()) ++i;
    out += text[i];
  }
  return out;
}

bool is_numeric(const Token& token) {
  if (token.kind != Kind::Word || token.text.empty()) return false;
  const char c = token.text[0];
  return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
}

//! An MFInt32 field: the values and the line of each (for messages).
struct IndexList {
  std::vector<long long> values;
  std::vector<std::size_t> lines;
  std::size_t line = 0;  // of the field name
};

struct FaceSet {
  std::vector<double> points, uvs;  // 3 and 2 per point
  bool has_uvs = false;
  IndexList coord_index, uv_index;
  bool has_uv_index = false;
  bool ccw = true;
  std::size_t line = 0;
};

class VrmlReader {
 public:
  VrmlReader(std::filesystem::path file, std::vector<Token> tokens) : file_(std::move(file)), tokens_(std::move(tokens)) {}

  IndexedMesh read() {
    while (peek().kind != Kind::End) statement();
    if (face_sets_with_uvs_ > 0 && face_sets_with_uvs_ == face_sets_)
      mesh_.texcoords = std::move(uvs_);  // texture coordinates only when every face set has them
    mesh_.texture_file = texture_;
    return std::move(mesh_);
  }

 private:
  const Token& peek(std::size_t ahead = 0) const { return tokens_[std::min(pos_ + ahead, tokens_.size() - 1)]; }
  const Token& next() {
    const Token& token = peek();
    if (token.kind != Kind::End) ++pos_;
    return token;
  }
  [[noreturn]] void fail(const Token& at, const std::string& message) const { throw InputError(file_, at.line, message); }
  std::string describe(const Token& token) const {
    return token.kind == Kind::End ? std::string("the end of the file") : "'" + std::string(token.text) + "'";
  }
  const Token& expect(Kind kind, const std::string& what) {
    const Token& token = next();
    if (token.kind != kind) fail(token, "expected " + what + ", got " + describe(token));
    return token;
  }
  bool node_starts() const {
    const Token& t = peek();
    if (t.kind != Kind::Word) return false;
    return t.text == "DEF" || t.text == "USE" || peek(1).kind == Kind::OpenBrace;
  }

  // ---- Skipping ----

  //! Skips from an opening brace or bracket to its partner (the tokenizer checked the balance).
  void skip_balanced() {
    int depth = 0;
    do {
      const Kind kind = next().kind;
      if (kind == Kind::OpenBrace || kind == Kind::OpenBracket) ++depth;
      if (kind == Kind::CloseBrace || kind == Kind::CloseBracket) --depth;
    } while (depth > 0 && peek().kind != Kind::End);
  }
  //! Skips one field value: a list, a node, or a run of scalars (numbers, TRUE, a string).
  void skip_value() {
    const Token& t = peek();
    if (t.kind == Kind::OpenBracket) return skip_balanced();
    if (t.kind == Kind::Word && t.text == "USE") {
      next();
      expect(Kind::Word, "a name after USE");
      return;
    }
    if (t.kind == Kind::Word && t.text == "DEF") {
      next();
      expect(Kind::Word, "a name after DEF");
    }
    if (peek().kind == Kind::Word && peek(1).kind == Kind::OpenBrace) {
      next();
      return skip_balanced();
    }
    if (peek().kind == Kind::CloseBrace || peek().kind == Kind::End) fail(peek(), "expected a field value, got " + describe(peek()));
    next();
    while (is_numeric(peek())) next();
  }

  // ---- The node tree ----

  void statement() {
    const Token& t = peek();
    if (t.kind == Kind::Word && (t.text == "PROTO" || t.text == "EXTERNPROTO")) {
      next();
      expect(Kind::Word, "a name after " + describe(t));
      if (peek().kind == Kind::OpenBracket) skip_balanced();
      if (peek().kind == Kind::OpenBrace) skip_balanced();  // PROTO body
      else skip_value();                                   // EXTERNPROTO url
    } else if (t.kind == Kind::Word && t.text == "ROUTE") {
      next();  // ROUTE a.field TO b.field
      for (const char* part : {"a node.field after ROUTE", "TO", "a node.field after TO"}) expect(Kind::Word, part);
    } else if (node_starts()) {
      node(Eigen::Affine3d::Identity());
    } else {
      fail(t, "expected a node, got " + describe(t));
    }
  }

  void node(const Eigen::Affine3d& transform) {
    std::string def_name;
    if (peek().text == "USE") {  // re-used geometry is not duplicated
      next();
      expect(Kind::Word, "a name after USE");
      return;
    }
    if (peek().text == "DEF") {
      next();
      def_name = std::string(expect(Kind::Word, "a name after DEF").text);
    }
    const Token& type = expect(Kind::Word, "a node type");
    expect(Kind::OpenBrace, "'{' after " + describe(type));
    if (type.text == "IndexedFaceSet") return face_set(transform, type.line);
    if (type.text == "ImageTexture") return image_texture();
    if (type.text == "Transform") return transform_node(transform);
    if (type.text == "Coordinate" || type.text == "TextureCoordinate") {
      const auto values = point_fields(type.text == "Coordinate" ? 3 : 2, type);
      if (!def_name.empty()) definitions_[def_name] = values;
      return;
    }
    fields(transform);
  }

  //! Fields of any other node: child nodes are visited, everything else skipped.
  void fields(const Eigen::Affine3d& transform) {
    while (peek().kind != Kind::CloseBrace) {
      expect(Kind::Word, "a field name or '}'");
      value(transform);
    }
    next();
  }

  void value(const Eigen::Affine3d& transform) {
    if (peek().kind == Kind::OpenBracket) {
      next();
      while (peek().kind != Kind::CloseBracket) {
        if (peek().kind == Kind::End) fail(peek(), "expected ']' to close the list, got the end of the file");
        if (node_starts()) node(transform);
        else next();
      }
      next();
    } else if (node_starts()) {
      node(transform);
    } else {
      skip_value();
    }
  }

  // Transform: P' = T·C·R·SR·S·SR⁻¹·C⁻¹·P (VRML97 6.52). The children may come before the other
  // fields, so they are visited after the closing brace.
  void transform_node(const Eigen::Affine3d& parent) {
    Eigen::Vector3d translation = Eigen::Vector3d::Zero(), center = Eigen::Vector3d::Zero(), scale = Eigen::Vector3d::Ones();
    Eigen::AngleAxisd rotation(0.0, Eigen::Vector3d::UnitZ()), scale_orientation(0.0, Eigen::Vector3d::UnitZ());
    std::vector<std::size_t> children;
    while (peek().kind != Kind::CloseBrace) {
      const Token& field = expect(Kind::Word, "a field name or '}'");
      if (field.text == "translation") translation = vector3(field);
      else if (field.text == "center") center = vector3(field);
      else if (field.text == "scale") scale = vector3(field);
      else if (field.text == "rotation") rotation = axis_angle(field);
      else if (field.text == "scaleOrientation") scale_orientation = axis_angle(field);
      else if (field.text == "children" || field.text == "addChildren") {
        children.push_back(pos_);
        skip_value();
      } else skip_value();
    }
    next();
    Eigen::Affine3d local = Eigen::Translation3d(translation + center) * rotation * scale_orientation *
                            Eigen::Scaling(scale) * scale_orientation.inverse() * Eigen::Translation3d(-center);
    const Eigen::Affine3d composed = parent * local;
    const std::size_t after = pos_;
    for (std::size_t start : children) {
      pos_ = start;
      value(composed);
    }
    pos_ = after;
  }

  void image_texture() {
    while (peek().kind != Kind::CloseBrace) {
      const Token& field = expect(Kind::Word, "a field name or '}'");
      if (field.text != "url") {
        skip_value();
        continue;
      }
      std::string url;
      if (peek().kind == Kind::String) {
        url = unescape(next().text);
      } else {
        expect(Kind::OpenBracket, "a string or '[' after url");
        while (peek().kind == Kind::String) {
          const auto text = unescape(next().text);
          if (url.empty()) url = text;  // the first of the alternatives
        }
        expect(Kind::CloseBracket, "']' to close the url list");
      }
      if (texture_.empty()) texture_ = url;
    }
    next();
  }

  // ---- Values ----

  double number(const Token& token, const std::string& what, bool as_float) const {
    if (token.kind != Kind::Word) fail(token, "expected a number for " + what + ", got " + describe(token));
    const char* begin = token.text.data() + (token.text[0] == '+' ? 1 : 0);
    const char* end = token.text.data() + token.text.size();
    double value = 0.0;
    std::from_chars_result result;
    if (as_float) {  // parsed as float so that a shortest-form float round-trips exactly
      float f = 0.0f;
      result = std::from_chars(begin, end, f);
      value = f;
    } else {
      result = std::from_chars(begin, end, value);
    }
    if (result.ec == std::errc::result_out_of_range || (result.ec == std::errc() && !std::isfinite(value)))
      fail(token, "expected a finite number for " + what + ", got " + describe(token));
    if (result.ec != std::errc() || result.ptr != end) fail(token, "expected a number for " + what + ", got " + describe(token));
    return value;
  }

  //! An MF field of numbers: "[ a b c, ... ]" or a single value of \p single numbers.
  std::vector<double> numbers(const Token& field, std::size_t single, bool as_float) {
    const std::string what = "'" + std::string(field.text) + "'";
    std::vector<double> values;
    if (peek().kind != Kind::OpenBracket) {
      for (std::size_t k = 0; k < single; ++k) values.push_back(number(next(), what, as_float));
      return values;
    }
    next();
    while (peek().kind != Kind::CloseBracket) values.push_back(number(next(), what, as_float));
    next();
    return values;
  }

  Eigen::Vector3d vector3(const Token& field) {
    const auto v = numbers(field, 3, false);
    if (v.size() != 3) fail(field, "expected 3 numbers for '" + std::string(field.text) + "'");
    return {v[0], v[1], v[2]};
  }
  Eigen::AngleAxisd axis_angle(const Token& field) {
    const auto v = numbers(field, 4, false);
    if (v.size() != 4) fail(field, "expected 4 numbers (axis and angle) for '" + std::string(field.text) + "'");
    const Eigen::Vector3d axis(v[0], v[1], v[2]);
    if (axis.norm() == 0.0) return Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitZ());
    return Eigen::AngleAxisd(v[3], axis.normalized());
  }

  IndexList indices(const Token& field) {
    IndexList list;
    list.line = field.line;
    auto add = [&](const Token& token) {
      long long value = 0;
      const auto [ptr, ec] = std::from_chars(token.text.data(), token.text.data() + token.text.size(), value);
      if (token.kind != Kind::Word || ec != std::errc() || ptr != token.text.data() + token.text.size())
        fail(token, "expected an integer for '" + std::string(field.text) + "', got " + describe(token));
      if (value < -1) fail(token, "expected an index or -1 in '" + std::string(field.text) + "', got " + describe(token));
      list.values.push_back(value);
      list.lines.push_back(token.line);
    };
    if (peek().kind != Kind::OpenBracket) {
      add(next());
      return list;
    }
    next();
    while (peek().kind != Kind::CloseBracket) add(next());
    next();
    return list;
  }

  //! The fields of a Coordinate (3) or TextureCoordinate (2) node after its '{'.
  std::vector<double> point_fields(std::size_t dimension, const Token& type) {
    std::vector<double> values;
    while (peek().kind != Kind::CloseBrace) {
      const Token& field = expect(Kind::Word, "a field name or '}'");
      if (field.text == "point") values = numbers(field, dimension, dimension == 2);
      else skip_value();
    }
    next();
    if (values.size() % dimension != 0)
      fail(type, "expected " + std::to_string(dimension) + " numbers per point, got " + std::to_string(values.size()) +
                     " numbers");
    return values;
  }

  //! A coord or texCoord field value: DEF / USE / NULL or the node itself.
  std::vector<double> point_node(std::size_t dimension, const char* expected_type) {
    if (peek().text == "NULL") {
      next();
      return {};
    }
    if (peek().text == "USE") {
      next();
      const Token& name = expect(Kind::Word, "a name after USE");
      const auto found = definitions_.find(std::string(name.text));
      if (found == definitions_.end()) fail(name, "expected a name defined with DEF before, got " + describe(name));
      return found->second;
    }
    std::string def_name;
    if (peek().text == "DEF") {
      next();
      def_name = std::string(expect(Kind::Word, "a name after DEF").text);
    }
    const Token& type = expect(Kind::Word, std::string("a ") + expected_type + " node");
    if (type.text != expected_type) fail(type, std::string("expected a ") + expected_type + " node, got " + describe(type));
    expect(Kind::OpenBrace, "'{'");
    auto values = point_fields(dimension, type);
    if (!def_name.empty()) definitions_[def_name] = values;
    return values;
  }

  void face_set(const Eigen::Affine3d& transform, std::size_t line) {
    FaceSet set;
    set.line = line;
    while (peek().kind != Kind::CloseBrace) {
      const Token& field = expect(Kind::Word, "a field name or '}'");
      if (field.text == "coord") set.points = point_node(3, "Coordinate");
      else if (field.text == "texCoord") {
        set.has_uvs = peek().text != "NULL";
        set.uvs = point_node(2, "TextureCoordinate");
      } else if (field.text == "coordIndex") set.coord_index = indices(field);
      else if (field.text == "texCoordIndex") {
        set.uv_index = indices(field);
        set.has_uv_index = true;
      } else if (field.text == "ccw") {
        const Token& value = expect(Kind::Word, "TRUE or FALSE");
        if (value.text != "TRUE" && value.text != "FALSE") fail(value, "expected TRUE or FALSE, got " + describe(value));
        set.ccw = value.text == "TRUE";
      } else skip_value();
    }
    next();
    append(set, transform);
  }

  // ---- Building the mesh ----

  //! Polygons of an index list as [begin, end) ranges; the final -1 may be missing.
  std::vector<std::pair<std::size_t, std::size_t>> polygons(const IndexList& list, const char* field) const {
    std::vector<std::pair<std::size_t, std::size_t>> result;
    std::size_t begin = 0;
    for (std::size_t i = 0; i <= list.values.size(); ++i) {
      if (i < list.values.size() && list.values[i] != -1) continue;
      if (i > begin && i - begin < 3)
        throw InputError(file_, list.lines[begin],
                         "polygon " + std::to_string(result.size()) + " of " + field + ": expected at least 3 corners, got " +
                             std::to_string(i - begin));
      if (i > begin) result.emplace_back(begin, i);
      begin = i + 1;
    }
    return result;
  }

  void check_range(const IndexList& list, std::size_t count, const char* field, const char* what) const {
    for (std::size_t i = 0; i < list.values.size(); ++i)
      if (list.values[i] >= static_cast<long long>(count))
        throw InputError(file_, list.lines[i],
                         std::string(field) + ": index " + std::to_string(list.values[i]) + " out of range (" +
                             std::to_string(count) + " " + what + ")");
  }

  void append(const FaceSet& set, const Eigen::Affine3d& transform) {
    const std::size_t n_points = set.points.size() / 3;
    const std::size_t offset = mesh_.positions.size();
    if (offset + n_points > std::numeric_limits<std::uint32_t>::max()) throw InputError(file_, set.line, "too many points");
    const bool identity = transform.matrix().isIdentity(0.0);
    for (std::size_t p = 0; p < n_points; ++p) {
      const Eigen::Vector3d point(set.points[3 * p], set.points[3 * p + 1], set.points[3 * p + 2]);
      mesh_.positions.push_back(identity ? point : Eigen::Vector3d(transform * point));
    }
    check_range(set.coord_index, n_points, "coordIndex", "points");
    const auto faces = polygons(set.coord_index, "coordIndex");

    // Per the VRML spec, without texCoordIndex the coordIndex also indexes the texture coordinates.
    const IndexList& uv_list = set.has_uv_index ? set.uv_index : set.coord_index;
    const bool uvs = set.has_uvs;
    std::vector<std::pair<std::size_t, std::size_t>> uv_faces;
    if (uvs) {
      check_range(uv_list, set.uvs.size() / 2, set.has_uv_index ? "texCoordIndex" : "coordIndex", "texture coordinates");
      uv_faces = polygons(uv_list, "texCoordIndex");
      if (!same_shape(faces, uv_faces))
        throw InputError(file_, uv_list.line, "expected texCoordIndex to have the same polygons as coordIndex");
    }
    // A mirroring transform or ccw FALSE reverses the corner order to keep faces counter-clockwise.
    const bool flip = !set.ccw != (transform.linear().determinant() < 0.0);
    for (std::size_t f = 0; f < faces.size(); ++f) {
      const auto [begin, end] = faces[f];
      for (std::size_t k = begin + 1; k + 1 < end; ++k) {
        std::array<std::size_t, 3> c{begin, k, k + 1};
        if (flip) std::swap(c[1], c[2]);
        std::array<std::uint32_t, 3> triangle{};
        for (int i = 0; i < 3; ++i) triangle[i] = static_cast<std::uint32_t>(offset + set.coord_index.values[c[i]]);
        mesh_.triangles.push_back(triangle);
        if (!uvs) continue;
        for (int i = 0; i < 3; ++i) {
          const auto u = static_cast<std::size_t>(uv_list.values[uv_faces[f].first + (c[i] - begin)]);
          uvs_.emplace_back(static_cast<float>(set.uvs[2 * u]), static_cast<float>(set.uvs[2 * u + 1]));
        }
      }
    }
    ++face_sets_;
    if (uvs) ++face_sets_with_uvs_;
  }

  static bool same_shape(const std::vector<std::pair<std::size_t, std::size_t>>& a,
                         const std::vector<std::pair<std::size_t, std::size_t>>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a[i].second - a[i].first != b[i].second - b[i].first) return false;
    return true;
  }

  std::filesystem::path file_;
  std::vector<Token> tokens_;
  std::size_t pos_ = 0;
  IndexedMesh mesh_;
  std::vector<Eigen::Vector2f> uvs_;
  std::size_t face_sets_ = 0, face_sets_with_uvs_ = 0;
  std::string texture_;
  std::map<std::string, std::vector<double>> definitions_;
};

std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(file, "cannot open for reading");
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw IoError(file, "read failed");
  return content.str();
}

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

void put_vrml(std::ostream& out, const IndexedMesh& mesh, const MeshWriteOptions& options) {
  const bool uvs = options.write_texcoords && mesh.has_texcoords();
  out << "#VRML V2.0 utf8\n# written by mvflow\nShape {\n  appearance Appearance {\n"
      << "    material Material { diffuseColor 1 1 1 }\n";
  if (!mesh.texture_file.empty()) out << "    texture ImageTexture { url " << quoted(mesh.texture_file) << " }\n";
  out << "  }\n  geometry IndexedFaceSet {\n    solid FALSE\n    coord Coordinate {\n      point [\n";
  std::string line;
  for (const auto& p : mesh.positions) {
    line.assign(8, ' ');
    for (int k = 0; k < 3; ++k) append_number(k > 0 ? line.append(" ") : line, p[k]);
    out << line << ",\n";
  }
  out << "      ]\n    }\n    coordIndex [\n";
  for (const auto& t : mesh.triangles) out << "      " << t[0] << ", " << t[1] << ", " << t[2] << ", -1,\n";
  out << "    ]\n";
  if (uvs) {
    out << "    texCoord TextureCoordinate {\n      point [\n";
    for (const auto& uv : mesh.texcoords) {
      line.assign(8, ' ');
      append_number(line, uv[0]);
      append_number(line.append(" "), uv[1]);
      out << line << ",\n";
    }
    out << "      ]\n    }\n    texCoordIndex [\n";
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
      out << "      " << 3 * f << ", " << 3 * f + 1 << ", " << 3 * f + 2 << ", -1,\n";
    out << "    ]\n";
  }
  out << "  }\n}\n";
}

}  // namespace

IndexedMesh read_vrml(const std::filesystem::path& file) {
  const std::string content = read_file(file);
  const std::string_view text(content);
  const auto header_end = std::min(text.find('\n'), text.size());
  if (text.substr(0, 10) != "#VRML V2.0")
    throw InputError(file, 1, "expected the header '#VRML V2.0 utf8' (VRML 1.0 is not supported), got '" +
                                  std::string(text.substr(0, std::min<std::size_t>(header_end, 40))) + "'");
  const std::size_t body_start = std::min(header_end + 1, text.size());
  VrmlReader reader(file, tokenize(text.substr(body_start), 2, file));
  IndexedMesh mesh = reader.read();
  mesh.validate(file.string());
  return mesh;
}

void write_vrml(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options) {
  write_atomically(file, false, [&](std::ostream& out) {
    mesh.validate(file.string());
    put_vrml(out, mesh, options);
  });
}

}  // namespace mvflow::io
