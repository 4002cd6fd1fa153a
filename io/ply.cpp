// PLY (Stanford polygon format): ASCII, binary little- and big-endian.
// The header is read line by line with TextReader; an ASCII body continues that way (one element
// per line), a binary body is read whole and decoded from memory.

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/number_text.h"
#include "io/mesh_io.h"
#include "io/text_reader.h"

namespace mvflow::io {

namespace {

enum class Encoding { Ascii, BinaryLittle, BinaryBig };
enum class Type { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct Property {
  std::string name;
  Type type = Type::Float32;  // the value type (of the entries, for a list)
  bool is_list = false;
  Type count_type = Type::UInt8;
};

struct Element {
  std::string name;
  std::size_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  Encoding encoding = Encoding::Ascii;
  std::vector<Element> elements;
};

std::optional<Type> type_from_name(std::string_view name) {
  if (name == "char" || name == "int8") return Type::Int8;
  if (name == "uchar" || name == "uint8") return Type::UInt8;
  if (name == "short" || name == "int16") return Type::Int16;
  if (name == "ushort" || name == "uint16") return Type::UInt16;
  if (name == "int" || name == "int32") return Type::Int32;
  if (name == "uint" || name == "uint32") return Type::UInt32;
  if (name == "float" || name == "float32") return Type::Float32;
  if (name == "double" || name == "float64") return Type::Float64;
  return std::nullopt;
}

std::size_t type_size(Type type) {
  switch (type) {
    case Type::Int8: case Type::UInt8: return 1;
    case Type::Int16: case Type::UInt16: return 2;
    case Type::Int32: case Type::UInt32: case Type::Float32: return 4;
    case Type::Float64: return 8;
  }
  return 0;
}

bool is_integer_type(Type type) { return type != Type::Float32 && type != Type::Float64; }

//! The scale that maps an integer colour channel to [0,1] (uchar: 255).
float color_scale(Type type) {
  switch (type) {
    case Type::Int8: return 127.0f;
    case Type::UInt8: return 255.0f;
    case Type::Int16: return 32767.0f;
    case Type::UInt16: return 65535.0f;
    case Type::Int32: return 2147483647.0f;
    case Type::UInt32: return 4294967295.0f;
    default: return 1.0f;
  }
}

//! "vertices", "faces", or "elements 'name'" for messages.
std::string plural(const std::string& element) {
  if (element == "vertex") return "vertices";
  if (element == "face") return "faces";
  return "elements '" + element + "'";
}

Property parse_property(const TextReader& reader, const std::vector<std::string_view>& tokens) {
  Property property;
  const bool list = tokens.size() >= 2 && tokens[1] == "list";
  if ((list && tokens.size() != 5) || (!list && tokens.size() != 3))
    reader.fail("expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
  property.is_list = list;
  const auto type = type_from_name(tokens[list ? 3 : 1]);
  if (!type) reader.fail("expected a PLY type (char, uchar, short, ushort, int, uint, float, double), got '" +
                         std::string(tokens[list ? 3 : 1]) + "'");
  property.type = *type;
  if (list) {
    const auto count_type = type_from_name(tokens[2]);
    if (!count_type || !is_integer_type(*count_type))
      reader.fail("expected an integer type for the list count, got '" + std::string(tokens[2]) + "'");
    property.count_type = *count_type;
  }
  property.name = std::string(tokens[list ? 4 : 2]);
  return property;
}

Header read_header(TextReader& reader) {
  if (!reader.next_line() || reader.line() != "ply") reader.fail("expected 'ply' on the first line");
  Header header;
  bool has_format = false;
  while (true) {
    if (!reader.next_line())
      throw InputError(reader.file(), reader.line_number() + 1,
                       "unexpected end of file, expected 'end_header'");
    const auto tokens = split_whitespace(reader.line());
    if (tokens.empty() || tokens[0] == "comment" || tokens[0] == "obj_info") continue;
    if (tokens[0] == "end_header") break;
    if (tokens[0] == "format") {
      if (tokens.size() != 3 || tokens[2] != "1.0")
        reader.fail("unsupported format line '" + reader.line() + "' (expected 'format ascii 1.0')");
      if (tokens[1] == "ascii") header.encoding = Encoding::Ascii;
      else if (tokens[1] == "binary_little_endian") header.encoding = Encoding::BinaryLittle;
      else if (tokens[1] == "binary_big_endian") header.encoding = Encoding::BinaryBig;
      else reader.fail("unsupported format line '" + reader.line() +
                       "' (expected ascii, binary_little_endian or binary_big_endian)");
      has_format = true;
    } else if (tokens[0] == "element") {
      if (tokens.size() != 3) reader.fail("expected 'element NAME COUNT'");
      Element element;
      element.name = std::string(tokens[1]);
      element.count = static_cast<std::size_t>(parse_integer(reader, tokens[2], "the element count"));
      header.elements.push_back(std::move(element));
    } else if (tokens[0] == "property") {
      if (header.elements.empty()) reader.fail("expected 'element' before the first 'property'");
      header.elements.back().properties.push_back(parse_property(reader, tokens));
    } else {
      reader.fail("expected a PLY header line (format, element, property, comment, end_header), got '" +
                  std::string(tokens[0]) + "'");
    }
  }
  if (!has_format) reader.fail("expected a 'format' line in the header");
  return header;
}

// ---- Value sources: one ASCII line or a binary buffer, read property by property. ----

//! Tokens of one ASCII element line.
class AsciiSource {
 public:
  AsciiSource(const TextReader& reader, const std::string& element, std::size_t index)
      : reader_(reader), element_(element), index_(index), tokens_(split_whitespace(reader.line())) {}

  double value(Type type, const std::string& what) {
    const auto token = next(what);
    // Parse a float property as float so that a shortest-form float round-trips exactly.
    if (type == Type::Float32) return parse_float(token, what);
    return parse_double(reader_, token, what);
  }
  void skip(Type, const std::string& what) { next(what); }
  std::size_t count(Type, const std::string& what) {
    return static_cast<std::size_t>(parse_integer(reader_, next(what), what));
  }
  long long index(Type, const std::string& what) {
    return parse_integer(reader_, next(what), what);
  }
  void finish() {
    if (position_ < tokens_.size())
      fail("unexpected extra value '" + std::string(tokens_[position_]) + "' after the last property");
  }
  [[noreturn]] void fail(const std::string& message) const {
    reader_.fail(element_ + " " + std::to_string(index_) + ": " + message);
  }

 private:
  std::string_view next(const std::string& what) {
    if (position_ >= tokens_.size()) fail("expected a value for " + what + ", the line ends");
    return tokens_[position_++];
  }
  double parse_float(std::string_view token, const std::string& what) const {
    parse_double(reader_, token, what);  // errors as for any number
    float value = 0.0f;
    const char* begin = token.data() + (token[0] == '+' ? 1 : 0);
    const auto [ptr, ec] = std::from_chars(begin, token.data() + token.size(), value);
    if (ec != std::errc() || !std::isfinite(value))
      fail("expected a finite float for " + what + ", got '" + std::string(token) + "'");
    return value;
  }

  const TextReader& reader_;
  const std::string& element_;
  std::size_t index_;
  std::vector<std::string_view> tokens_;
  std::size_t position_ = 0;
};

//! The whole binary body, decoded value by value.
class BinarySource {
 public:
  BinarySource(std::filesystem::path file, std::vector<char> data, bool swap)
      : file_(std::move(file)), data_(std::move(data)), swap_(swap) {}

  void start(const Element& element, std::size_t index) {
    element_ = &element;
    index_ = index;
  }
  double value(Type type, const std::string&) { return read(type); }
  void skip(Type type, const std::string&) { advance(type_size(type)); }
  std::size_t count(Type type, const std::string& what) { return static_cast<std::size_t>(index(type, what)); }
  long long index(Type type, const std::string& what) {
    const double value = read(type);
    if (!(value >= 0.0) || value != std::floor(value) || value > 9.0e15)
      fail("expected a non-negative integer for " + what + ", got " + std::to_string(value));
    return static_cast<long long>(value);
  }
  void finish() {}
  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(file_, element_->name, index_, message);
  }
  bool at_end() const { return position_ == data_.size(); }

 private:
  void advance(std::size_t bytes) {
    if (data_.size() - position_ < bytes)
      fail("expected " + std::to_string(element_->count) + " " + plural(element_->name) +
           ", file ends after " + std::to_string(index_));
    position_ += bytes;
  }
  template <typename T>
  T load() {
    const std::size_t start = position_;
    advance(sizeof(T));
    char bytes[sizeof(T)];
    std::memcpy(bytes, data_.data() + start, sizeof(T));
    if (swap_) std::reverse(bytes, bytes + sizeof(T));
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }
  double read(Type type) {
    switch (type) {
      case Type::Int8: return load<std::int8_t>();
      case Type::UInt8: return load<std::uint8_t>();
      case Type::Int16: return load<std::int16_t>();
      case Type::UInt16: return load<std::uint16_t>();
      case Type::Int32: return load<std::int32_t>();
      case Type::UInt32: return load<std::uint32_t>();
      case Type::Float32: return load<float>();
      case Type::Float64: return load<double>();
    }
    return 0.0;
  }

  std::filesystem::path file_;
  std::vector<char> data_;
  bool swap_;
  std::size_t position_ = 0;
  const Element* element_ = nullptr;
  std::size_t index_ = 0;
};

// ---- Element decoding, shared by both sources. ----

//! Where the properties that mvflow uses sit in the vertex element.
struct VertexLayout {
  int x = -1, y = -1, z = -1, red = -1, green = -1, blue = -1, quality = -1;
  bool has_colors() const { return red >= 0 && green >= 0 && blue >= 0; }
};

VertexLayout vertex_layout(const Element& element, const std::filesystem::path& file) {
  VertexLayout layout;
  for (std::size_t i = 0; i < element.properties.size(); ++i) {
    const auto& p = element.properties[i];
    if (p.is_list) continue;
    const int index = static_cast<int>(i);
    if (p.name == "x") layout.x = index;
    else if (p.name == "y") layout.y = index;
    else if (p.name == "z") layout.z = index;
    else if (p.name == "red") layout.red = index;
    else if (p.name == "green") layout.green = index;
    else if (p.name == "blue") layout.blue = index;
    else if (p.name == "quality") layout.quality = index;
  }
  if (layout.x < 0 || layout.y < 0 || layout.z < 0)
    throw InputError(file, 0, "expected scalar properties x, y and z in the vertex element");
  return layout;
}

int face_list_property(const Element& element, const std::filesystem::path& file) {
  for (std::size_t i = 0; i < element.properties.size(); ++i) {
    const auto& p = element.properties[i];
    if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) return static_cast<int>(i);
  }
  throw InputError(file, 0, "expected a list property 'vertex_indices' in the face element");
}

std::string describe(const Property& property) { return "property '" + property.name + "'"; }

template <typename Source>
void skip_property(Source& source, const Property& property) {
  const std::string what = describe(property);
  if (!property.is_list) return source.skip(property.type, what);
  const std::size_t n = source.count(property.count_type, "the list count of " + what);
  for (std::size_t k = 0; k < n; ++k) source.skip(property.type, what);
}

template <typename Source>
void read_vertex(Source& source, const Element& element, const VertexLayout& layout, IndexedMesh& mesh) {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3f color = Eigen::Vector3f::Zero();
  float quality = 0.0f;
  for (std::size_t i = 0; i < element.properties.size(); ++i) {
    const auto& p = element.properties[i];
    const int index = static_cast<int>(i);
    const bool used = index == layout.x || index == layout.y || index == layout.z ||
                      (layout.has_colors() && (index == layout.red || index == layout.green || index == layout.blue)) ||
                      index == layout.quality;
    if (!used) {
      skip_property(source, p);
      continue;
    }
    const double value = source.value(p.type, describe(p));
    if (!std::isfinite(value)) source.fail("expected a finite number for " + describe(p));
    if (index == layout.x) position.x() = value;
    else if (index == layout.y) position.y() = value;
    else if (index == layout.z) position.z() = value;
    else if (index == layout.quality) quality = static_cast<float>(value);
    else {
      const int channel = index == layout.red ? 0 : index == layout.green ? 1 : 2;
      // Integer channels are scaled (uchar /255); float channels are already in [0,1].
      color[channel] = is_integer_type(p.type) ? static_cast<float>(value) / color_scale(p.type)
                                               : static_cast<float>(value);
    }
  }
  source.finish();
  mesh.positions.push_back(position);
  if (layout.has_colors()) mesh.colors.push_back(color);
  if (layout.quality >= 0) mesh.quality.push_back(quality);
}

//! Reads one polygon and appends its fan of triangles. \p n_vertices is 0 when unknown yet.
template <typename Source>
void read_face(Source& source, const Element& element, int list, std::size_t n_vertices,
               std::vector<std::uint32_t>& corners, IndexedMesh& mesh) {
  for (std::size_t i = 0; i < element.properties.size(); ++i) {
    const auto& p = element.properties[i];
    if (static_cast<int>(i) != list) {
      skip_property(source, p);
      continue;
    }
    const std::size_t n = source.count(p.count_type, "the number of corners");
    corners.clear();
    for (std::size_t k = 0; k < n; ++k) {
      const long long v = source.index(p.type, "a vertex index");
      if (n_vertices > 0 && static_cast<std::size_t>(v) >= n_vertices)
        source.fail("vertex index " + std::to_string(v) + " out of range (mesh has " +
                    std::to_string(n_vertices) + " vertices)");
      if (v > std::numeric_limits<std::uint32_t>::max()) source.fail("vertex index too large");
      corners.push_back(static_cast<std::uint32_t>(v));
    }
  }
  source.finish();
  if (corners.size() < 3) source.fail("expected at least 3 corners, got " + std::to_string(corners.size()));
  for (std::size_t k = 1; k + 1 < corners.size(); ++k) mesh.triangles.push_back({corners[0], corners[k], corners[k + 1]});
}

//! The mesh being read and what the elements read so far tell about the next ones.
struct Body {
  explicit Body(const std::filesystem::path& source) : file(source) {}

  const std::filesystem::path& file;
  IndexedMesh mesh;
  std::vector<std::uint32_t> corners;
  bool vertices_read = false;
  VertexLayout layout;
  int face_list = -1;

  template <typename Source>
  void read_item(Source& source, const Element& element) {
    if (element.name == "vertex") {
      read_vertex(source, element, layout, mesh);
    } else if (element.name == "face") {
      read_face(source, element, face_list, vertices_read ? mesh.positions.size() : 0, corners, mesh);
    } else {
      for (const auto& p : element.properties) skip_property(source, p);
      source.finish();
    }
  }
  void prepare(const Element& element) {
    if (element.name == "vertex") {
      layout = vertex_layout(element, file);
      // The count is untrusted: room for no more vertices than the file can hold (at least one byte
      // per property), and for faces (a count and three indices) likewise.
      mesh.positions.reserve(reservable(element.count, file, element.properties.size()));
    } else if (element.name == "face") {
      face_list = face_list_property(element, file);
      mesh.triangles.reserve(reservable(element.count, file, 4));
    }
  }
  void done(const Element& element) {
    if (element.name == "vertex") vertices_read = true;
  }
};

IndexedMesh read_ascii_body(TextReader& reader, const Header& header) {
  Body body(reader.file());
  for (const auto& element : header.elements) {
    body.prepare(element);
    for (std::size_t i = 0; i < element.count; ++i) {
      if (!reader.next_content_line(0))
        throw InputError(reader.file(), reader.line_number() + 1,
                         "expected " + std::to_string(element.count) + " " + plural(element.name) +
                             ", file ends after " + std::to_string(i));
      AsciiSource source(reader, element.name, i);
      body.read_item(source, element);
    }
    body.done(element);
  }
  if (reader.next_content_line(0)) reader.fail("unexpected content after the last element declared in the header");
  return std::move(body.mesh);
}

std::vector<char> read_rest(std::istream& in, const std::filesystem::path& file) {
  const auto start = in.tellg();
  in.seekg(0, std::ios::end);
  const auto end = in.tellg();
  in.seekg(start);
  if (start < 0 || end < start) throw IoError(file, "cannot read the binary body");
  std::vector<char> data(static_cast<std::size_t>(end - start));
  if (!data.empty() && !in.read(data.data(), static_cast<std::streamsize>(data.size())))
    throw IoError(file, "cannot read the binary body");
  return data;
}

IndexedMesh read_binary_body(TextReader& reader, const Header& header) {
  const bool little = header.encoding == Encoding::BinaryLittle;
  const bool swap = little != (std::endian::native == std::endian::little);
  BinarySource source(reader.file(), read_rest(reader.stream(), reader.file()), swap);
  Body body(reader.file());
  for (const auto& element : header.elements) {
    body.prepare(element);
    for (std::size_t i = 0; i < element.count; ++i) {
      source.start(element, i);
      body.read_item(source, element);
    }
    body.done(element);
  }
  // Trailing bytes are tolerated: some writers pad the file.
  return std::move(body.mesh);
}

// ---- Writing ----

void put_header(std::ostream& out, const IndexedMesh& mesh, const MeshWriteOptions& options) {
  out << "ply\nformat " << (options.binary ? "binary_little_endian" : "ascii") << " 1.0\n"
      << "comment written by mvflow\n";
  out << "element vertex " << mesh.positions.size() << "\n"
      << "property double x\nproperty double y\nproperty double z\n";
  if (options.write_colors && mesh.has_colors())
    out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (options.write_quality && mesh.has_quality()) out << "property float quality\n";
  out << "element face " << mesh.triangles.size() << "\n"
      << "property list uchar int vertex_indices\nend_header\n";
}

std::uint8_t to_byte(float channel) {
  const float clamped = std::clamp(std::isfinite(channel) ? channel : 0.0f, 0.0f, 1.0f);
  return static_cast<std::uint8_t>(std::lround(clamped * 255.0f));
}

template <typename T>
void put_binary(std::string& data, T value) {
  static_assert(std::is_arithmetic_v<T>);
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
  data.append(bytes, sizeof(T));
}

void put_ascii_body(std::ostream& out, const IndexedMesh& mesh, bool colors, bool quality) {
  std::string line;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    line.clear();
    const auto& p = mesh.positions[v];
    for (int k = 0; k < 3; ++k) {
      if (k > 0) line += ' ';
      append_number(line, p[k]);
    }
    if (colors)
      for (int k = 0; k < 3; ++k) line.append(" ").append(std::to_string(to_byte(mesh.colors[v][k])));
    if (quality) {
      line += ' ';
      append_number(line, mesh.quality[v]);
    }
    line += '\n';
    out << line;
  }
  for (const auto& t : mesh.triangles)
    out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
}

void put_binary_body(std::ostream& out, const IndexedMesh& mesh, bool colors, bool quality) {
  std::string data;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    for (int k = 0; k < 3; ++k) put_binary(data, mesh.positions[v][k]);
    if (colors)
      for (int k = 0; k < 3; ++k) put_binary(data, to_byte(mesh.colors[v][k]));
    if (quality) put_binary(data, mesh.quality[v]);
    if (data.size() > (1u << 20)) {
      out.write(data.data(), static_cast<std::streamsize>(data.size()));
      data.clear();
    }
  }
  for (const auto& t : mesh.triangles) {
    put_binary(data, std::uint8_t{3});
    for (auto v : t) put_binary(data, static_cast<std::int32_t>(v));
  }
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
}

}  // namespace

IndexedMesh read_ply(const std::filesystem::path& file) {
  TextReader reader(file);
  const Header header = read_header(reader);
  IndexedMesh mesh = header.encoding == Encoding::Ascii ? read_ascii_body(reader, header)
                                                        : read_binary_body(reader, header);
  mesh.validate(file.string());
  return mesh;
}

void write_ply(const std::filesystem::path& file, const IndexedMesh& mesh, const MeshWriteOptions& options) {
  write_atomically(file, options.binary, [&](std::ostream& out) {
    mesh.validate(file.string());
    const bool colors = options.write_colors && mesh.has_colors();
    const bool quality = options.write_quality && mesh.has_quality();
    put_header(out, mesh, options);
    if (options.binary) put_binary_body(out, mesh, colors, quality);
    else put_ascii_body(out, mesh, colors, quality);
  });
}

}  // namespace mvflow::io
