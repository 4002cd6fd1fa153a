// Mesh files: write→read round trips for every format, hand-written files with the variants the
// readers must accept, and bad input that must fail with the file, the position and what was expected.

#include "io/mesh_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

#include "engine/model/error.h"
#include "io/vertex_fields_io.h"
#include "stages_meshes.h"
#include "vertex_fields_reader.h"

namespace mvflow::io {
namespace {

namespace fs = std::filesystem;

//! A folder of its own for each test, removed afterwards.
class MeshIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("mvflow_mesh_io_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path path(const std::string& name) const { return dir_ / name; }
  fs::path write_text(const std::string& name, const std::string& content) const {
    std::ofstream(path(name), std::ios::binary) << content;
    return path(name);
  }
  fs::path write_bytes(const std::string& name, const std::string& bytes) const { return write_text(name, bytes); }

  fs::path dir_;
};

//! An octahedron with values that are not short decimals, so that a lossy writer shows up.
IndexedMesh octahedron() {
  IndexedMesh mesh;
  const double a = 1.0 / 3.0, b = -2.718281828459045, c = 1e-7 + 0.1;
  mesh.positions = {{a, 0, 0}, {-a, 0, 0}, {0, b, 0}, {0, -b, 0}, {0, 0, c}, {0, 0, -c}};
  mesh.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const auto k = static_cast<float>(v);
    mesh.colors.emplace_back((40.0f * k) / 255.0f, (255.0f - 30.0f * k) / 255.0f, 7.0f / 255.0f);
    mesh.quality.push_back(0.1f * k + 1.0f / 3.0f);
  }
  for (std::size_t i = 0; i < 3 * mesh.triangles.size(); ++i)
    mesh.texcoords.emplace_back(static_cast<float>(i) / 24.0f + 1e-3f, 1.0f - static_cast<float>(i) / 7.0f);
  mesh.texture_file = "texture image.png";
  return mesh;
}

//! The same mesh with only what the format carries.
IndexedMesh only(IndexedMesh mesh, bool colors, bool quality, bool texcoords) {
  if (!colors) mesh.colors.clear();
  if (!quality) mesh.quality.clear();
  if (!texcoords) {
    mesh.texcoords.clear();
    mesh.texture_file.clear();
  }
  return mesh;
}

void expect_equal(const IndexedMesh& expected, const IndexedMesh& actual) {
  ASSERT_EQ(expected.positions.size(), actual.positions.size());
  for (std::size_t i = 0; i < expected.positions.size(); ++i)
    EXPECT_EQ(expected.positions[i], actual.positions[i]) << "vertex " << i;
  ASSERT_EQ(expected.triangles.size(), actual.triangles.size());
  for (std::size_t i = 0; i < expected.triangles.size(); ++i) EXPECT_EQ(expected.triangles[i], actual.triangles[i]) << "face " << i;
  ASSERT_EQ(expected.colors.size(), actual.colors.size());
  for (std::size_t i = 0; i < expected.colors.size(); ++i) EXPECT_EQ(expected.colors[i], actual.colors[i]) << "colour " << i;
  ASSERT_EQ(expected.quality.size(), actual.quality.size());
  for (std::size_t i = 0; i < expected.quality.size(); ++i) EXPECT_EQ(expected.quality[i], actual.quality[i]) << "quality " << i;
  ASSERT_EQ(expected.texcoords.size(), actual.texcoords.size());
  for (std::size_t i = 0; i < expected.texcoords.size(); ++i)
    EXPECT_EQ(expected.texcoords[i], actual.texcoords[i]) << "texcoord " << i;
  EXPECT_EQ(expected.texture_file, actual.texture_file);
}

//! Runs \p f, which must throw E with a message containing every one of \p parts.
template <typename E>
void expect_error(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no exception; expected one mentioning '" << parts.front() << "'";
  } catch (const E& e) {
    const std::string message = e.what();
    for (const auto& part : parts) EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
  }
}

std::string read_all(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// ---------------------------------------------------------------------------------------------
// Format selection and dispatch

TEST(MeshFormat, FollowsTheExtensionCaseInsensitively) {
  EXPECT_EQ(mesh_format_from_path("a/b.ply"), MeshFormat::Ply);
  EXPECT_EQ(mesh_format_from_path("B.PLY"), MeshFormat::Ply);
  EXPECT_EQ(mesh_format_from_path("x.Obj"), MeshFormat::Obj);
  EXPECT_EQ(mesh_format_from_path("x.off"), MeshFormat::Off);
  EXPECT_EQ(mesh_format_from_path("x.stl"), MeshFormat::Stl);
  EXPECT_EQ(mesh_format_from_path("x.wrl"), MeshFormat::Vrml);
  EXPECT_EQ(mesh_format_from_path("x.vrml"), MeshFormat::Vrml);
  expect_error<InputError>([] { mesh_format_from_path("mesh.xyz"); }, {"mesh.xyz", ".xyz", "expected"});
  expect_error<InputError>([] { mesh_format_from_path("mesh"); }, {"mesh", "expected"});
}

TEST_F(MeshIoTest, ReadMeshOfAMissingFileIsAnIoError) {
  for (const char* name : {"missing.ply", "missing.obj", "missing.off", "missing.stl", "missing.wrl"})
    expect_error<IoError>([&] { read_mesh(path(name)); }, {name});
}

// ---------------------------------------------------------------------------------------------
// PLY

TEST_F(MeshIoTest, PlyAsciiRoundTripIsExact) {
  const auto mesh = octahedron();
  MeshWriteOptions options;
  options.binary = false;
  write_mesh(path("m.ply"), mesh, options);
  EXPECT_NE(read_all(path("m.ply")).find("format ascii 1.0"), std::string::npos);
  expect_equal(only(mesh, true, true, false), read_mesh(path("m.ply")));
}

TEST_F(MeshIoTest, PlyBinaryRoundTripIsExact) {
  const auto mesh = octahedron();
  write_mesh(path("m.ply"), mesh);
  EXPECT_NE(read_all(path("m.ply")).find("format binary_little_endian 1.0"), std::string::npos);
  expect_equal(only(mesh, true, true, false), read_mesh(path("m.ply")));
}

TEST_F(MeshIoTest, PlyOptionsLeaveOutColorsAndQuality) {
  MeshWriteOptions options;
  options.write_colors = false;
  options.write_quality = false;
  write_ply(path("m.ply"), octahedron(), options);
  expect_equal(only(octahedron(), false, false, false), read_ply(path("m.ply")));
}

TEST_F(MeshIoTest, PlyAsciiSkipsPropertiesAndElementsOfAnyType) {
  const auto file = write_text("odd.ply",
                               "ply\r\n"
                               "format ascii 1.0\n"
                               "comment made by hand\n"
                               "obj_info nothing\n"
                               "element vertex 4\n"
                               "property float nx\n"
                               "property int x\n"
                               "property list uchar int something\n"
                               "property double y\n"
                               "property short z\n"
                               "property uchar red\n"
                               "property uchar green\n"
                               "property uchar blue\n"
                               "property uchar alpha\n"
                               "property double quality\n"
                               "element material 2\n"
                               "property list int float weights\n"
                               "property char kind\n"
                               "element face 2\n"
                               "property uchar flags\n"
                               "property list ushort uint vertex_index\n"
                               "property list uchar float texcoord\n"
                               "end_header\n"
                               "0.5 0 2 7 8 0.25 0 0 255 0 9 1.5\n"
                               "0.5 1 0 0 1 255 255 255 0 2.25\n"
                               "\n"
                               "0.5 1 3 1 2 3 1.5 1 0 0 0 255 -3\n"
                               "0.5 0 1 9 1 1 1 1 1 1 1e2\n"
                               "3 1 2 3 -1\n"
                               "0 1\n"
                               "5 4 0 1 2 3 0\n"
                               "5 4 3 2 1 0 6 0.1 0.2 0.3 0.4 0.5 0.6\n");
  const auto mesh = read_ply(file);
  ASSERT_EQ(mesh.positions.size(), 4u);
  EXPECT_EQ(mesh.positions[0], Eigen::Vector3d(0, 0.25, 0));
  EXPECT_EQ(mesh.positions[1], Eigen::Vector3d(1, 0, 1));
  EXPECT_EQ(mesh.positions[2], Eigen::Vector3d(1, 1.5, 1));
  EXPECT_EQ(mesh.positions[3], Eigen::Vector3d(0, 1, 1));
  ASSERT_EQ(mesh.colors.size(), 4u);
  EXPECT_EQ(mesh.colors[0], Eigen::Vector3f(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(mesh.colors[1], Eigen::Vector3f(1.0f, 1.0f, 1.0f));
  EXPECT_EQ(mesh.colors[3], Eigen::Vector3f(1 / 255.0f, 1 / 255.0f, 1 / 255.0f));
  EXPECT_EQ(mesh.quality, (std::vector<float>{1.5f, 2.25f, -3.0f, 100.0f}));
  ASSERT_EQ(mesh.triangles.size(), 4u);  // two quads, fan-triangulated
  EXPECT_EQ(mesh.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(mesh.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(mesh.triangles[2], (std::array<std::uint32_t, 3>{3, 2, 1}));
  EXPECT_EQ(mesh.triangles[3], (std::array<std::uint32_t, 3>{3, 1, 0}));
}

//! Big-endian bytes of a value.
template <typename T>
std::string big_endian(T value) {
  std::string bytes(sizeof(T), '\0');
  std::memcpy(bytes.data(), &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::little) std::reverse(bytes.begin(), bytes.end());
  return bytes;
}

std::string binary_header(const std::string& format, std::size_t vertices, std::size_t faces) {
  return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nproperty list uchar short extra\n"
         "property ushort red\nproperty ushort green\nproperty ushort blue\nproperty double quality\n"
         "element edge 1\nproperty int a\nproperty int b\n"
         "element face " + std::to_string(faces) + "\nproperty list int uint vertex_indices\nproperty float area\nend_header\n";
}

TEST_F(MeshIoTest, PlyBinaryBigEndianWithOddTypes) {
  std::string data = binary_header("binary_big_endian", 3, 1);
  const float xyz[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1.5f, -2}};
  for (int v = 0; v < 3; ++v) {
    for (float c : xyz[v]) data += big_endian(c);
    data += big_endian(std::uint8_t{2}) + big_endian(std::int16_t{-1}) + big_endian(std::int16_t{5});
    data += big_endian(std::uint16_t{65535}) + big_endian(std::uint16_t{0}) + big_endian(std::uint16_t{65535});
    data += big_endian(0.5 * v);
  }
  data += big_endian(std::int32_t{0}) + big_endian(std::int32_t{1});
  data += big_endian(std::int32_t{3}) + big_endian(std::uint32_t{0}) + big_endian(std::uint32_t{1}) +
          big_endian(std::uint32_t{2}) + big_endian(1.0f);
  const auto mesh = read_ply(write_bytes("big.ply", data));
  ASSERT_EQ(mesh.positions.size(), 3u);
  EXPECT_EQ(mesh.positions[2], Eigen::Vector3d(0, 1.5, -2));
  EXPECT_EQ(mesh.colors[1], Eigen::Vector3f(1, 0, 1));
  EXPECT_EQ(mesh.quality, (std::vector<float>{0.0f, 0.5f, 1.0f}));
  ASSERT_EQ(mesh.triangles.size(), 1u);
  EXPECT_EQ(mesh.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
}

TEST_F(MeshIoTest, PlyBinaryTruncatedNamesTheElement) {
  std::string data = binary_header("binary_big_endian", 3, 1);
  data += big_endian(1.0f) + big_endian(2.0f);  // vertex 0 stops after y
  const auto file = write_bytes("truncated.ply", data);
  expect_error<InputError>([&] { read_ply(file); }, {"truncated.ply", "vertex 0", "expected 3 vertices, file ends after 0"});
}

TEST_F(MeshIoTest, PlyBinaryFaceIndexOutOfRangeNamesTheFace) {
  IndexedMesh mesh = octahedron();
  write_ply(path("m.ply"), mesh, {});
  // Patch the last face's last index (little endian int32 at the very end) to 6.
  std::string data = read_all(path("m.ply"));
  data[data.size() - 4] = 6;
  const auto file = write_bytes("bad_face.ply", data);
  expect_error<InputError>([&] { read_ply(file); }, {"bad_face.ply", "face 7", "vertex index 6 out of range"});
}

TEST_F(MeshIoTest, PlyBinaryNanCoordinateIsRejected) {
  std::string data = binary_header("binary_big_endian", 1, 0);
  data += big_endian(1.0f) + big_endian(std::nanf("")) + big_endian(0.0f) + big_endian(std::uint8_t{0});
  data += std::string(6, '\0') + big_endian(0.0) + big_endian(std::int32_t{0}) + big_endian(std::int32_t{1});
  const auto file = write_bytes("nan.ply", data);
  expect_error<InputError>([&] { read_ply(file); }, {"nan.ply", "vertex 0", "finite", "'y'"});
}

std::string ascii_ply(const std::string& vertices, const std::string& faces, std::size_t nv = 3, std::size_t nf = 1) {
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(nv) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(nf) +
         "\nproperty list uchar int vertex_indices\nend_header\n" + vertices + faces;
}

TEST_F(MeshIoTest, PlyAsciiErrorsNameFileLineAndWhatWasExpected) {
  const std::string good_vertices = "0 0 0\n1 0 0\n0 1 0\n";  // lines 10-12
  struct Case {
    std::string name, content;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {"truncated.ply", ascii_ply("0 0 0\n1 0 0\n", ""), {"truncated.ply:12:", "expected 3 vertices, file ends after 2"}},
      {"no_faces.ply", ascii_ply(good_vertices, "3 0 1 2\n", 3, 2), {"no_faces.ply:14:", "expected 2 faces, file ends after 1"}},
      {"too_many.ply", ascii_ply(good_vertices + "1.5 1 1\n", "3 0 1 2\n"), {"too_many.ply:13:", "integer", "'1.5'"}},
      {"short_line.ply", ascii_ply("0 0 0\n1 0\n0 1 0\n", "3 0 1 2\n"), {"short_line.ply:11:", "vertex 1", "expected a value", "'z'"}},
      {"extra.ply", ascii_ply(good_vertices, "3 0 1 2 7\n"), {"extra.ply:13:", "face 0", "extra value '7'"}},
      {"word.ply", ascii_ply("0 0 0\n1 zero 0\n0 1 0\n", "3 0 1 2\n"), {"word.ply:11:", "expected a number", "'zero'"}},
      {"nan.ply", ascii_ply("0 0 0\n1 nan 0\n0 1 0\n", "3 0 1 2\n"), {"nan.ply:11:", "finite", "'nan'"}},
      {"inf.ply", ascii_ply("0 0 0\n1 0 -inf\n0 1 0\n", "3 0 1 2\n"), {"inf.ply:11:", "finite", "'-inf'"}},
      {"range.ply", ascii_ply(good_vertices, "3 0 1 3\n"), {"range.ply:13:", "face 0", "vertex index 3 out of range"}},
      {"negative.ply", ascii_ply(good_vertices, "3 0 -1 2\n"), {"negative.ply:13:", "non-negative", "'-1'"}},
      {"two.ply", ascii_ply(good_vertices, "2 0 1\n"), {"two.ply:13:", "face 0", "at least 3"}},
      {"format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n", {"format.ply:2:", "unsupported format line"}},
      {"noend.ply", "ply\nformat ascii 1.0\nelement vertex 0\n", {"noend.ply:4:", "expected 'end_header'"}},
      {"notply.ply", "solid cube\n", {"notply.ply:1:", "expected 'ply'"}},
      {"type.ply", "ply\nformat ascii 1.0\nelement vertex 0\nproperty real x\nend_header\n", {"type.ply:4:", "'real'"}},
      {"noxyz.ply", "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nend_header\n", {"noxyz.ply", "x, y and z"}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const auto file = write_text(c.name, c.content);
    expect_error<InputError>([&] { read_mesh(file); }, c.parts);
  }
}

// ---------------------------------------------------------------------------------------------
// OBJ

TEST_F(MeshIoTest, ObjRoundTripWithColorsTexcoordsAndMaterial) {
  const auto mesh = octahedron();
  write_mesh(path("m.obj"), mesh);
  ASSERT_TRUE(fs::exists(path("m.mtl")));
  EXPECT_NE(read_all(path("m.mtl")).find("map_Kd texture image.png"), std::string::npos);
  expect_equal(only(mesh, true, false, true), read_mesh(path("m.obj")));
}

TEST_F(MeshIoTest, ObjRoundTripWithoutOptionalData) {
  const auto mesh = only(octahedron(), false, false, false);
  write_obj(path("plain.obj"), mesh, {});
  EXPECT_FALSE(fs::exists(path("plain.mtl")));
  expect_equal(mesh, read_obj(path("plain.obj")));
  MeshWriteOptions options;
  options.write_colors = false;
  options.write_texcoords = false;
  write_obj(path("opt.obj"), octahedron(), options);
  auto expected = only(octahedron(), false, false, false);
  expected.texture_file = octahedron().texture_file;  // the material is still written
  expect_equal(expected, read_obj(path("opt.obj")));
}

TEST_F(MeshIoTest, ObjQuadsNegativeIndicesAndSlashForms) {
  write_text("quad.mtl", "newmtl a\nKd 1 1 1\nmap_Kd -s 1 1 -o 0.5 -clamp on wood grain.jpg\n");
  const auto file = write_text("quad.obj",
                               "# a cube side and a triangle\n"
                               "mtllib quad.mtl\n"
                               "o thing\ng group\ns 1\nusemtl a\n"
                               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                               "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                               "vn 0 0 1\n"
                               "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
                               "v 2 2 2\n"
                               "f -1/-4 -4/-3 -3/-2\n");
  const auto mesh = read_obj(file);
  ASSERT_EQ(mesh.positions.size(), 5u);
  ASSERT_EQ(mesh.triangles.size(), 3u);
  EXPECT_EQ(mesh.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(mesh.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(mesh.triangles[2], (std::array<std::uint32_t, 3>{4, 1, 2}));
  ASSERT_EQ(mesh.texcoords.size(), 9u);
  EXPECT_EQ(mesh.texcoords[4], Eigen::Vector2f(1, 1));
  EXPECT_EQ(mesh.texcoords[5], Eigen::Vector2f(0, 1));
  EXPECT_EQ(mesh.texcoords[6], Eigen::Vector2f(0, 0));
  EXPECT_EQ(mesh.texcoords[8], Eigen::Vector2f(1, 1));
  EXPECT_EQ(mesh.texture_file, "wood grain.jpg");
  EXPECT_FALSE(mesh.has_colors());
}

TEST_F(MeshIoTest, ObjNormalOnlyCornersHaveNoTexcoords) {
  const auto file = write_text("n.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 3 2 1\n");
  const auto mesh = read_obj(file);
  EXPECT_EQ(mesh.triangles.size(), 2u);
  EXPECT_FALSE(mesh.has_texcoords());
  EXPECT_TRUE(mesh.texture_file.empty());  // no mtllib
}

TEST_F(MeshIoTest, ObjErrorsNameFileLineAndWhatWasExpected) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\n";  // lines 1-4
  struct Case {
    std::string name, content;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {"mixed.obj", v + "f 1/1 2/1 3/1\nf 1 2 3\n", {"mixed.obj:6:", "texture coordinate", "first face on line 5"}},
      {"corner.obj", v + "f 1/1 2 3/1\n", {"corner.obj:5:", "every corner"}},
      {"range.obj", v + "f 1 2 4\n", {"range.obj:5:", "vertex index 4 out of range"}},
      {"negative.obj", v + "f 1 2 -4\n", {"negative.obj:5:", "vertex index '-4'"}},
      {"uvrange.obj", v + "f 1/1 2/2 3/1\n", {"uvrange.obj:5:", "texture coordinate index 2 out of range"}},
      {"zero.obj", v + "f 0 1 2\n", {"zero.obj:5:", "non-zero"}},
      {"word.obj", "v 0 0 0\nv 1 x 0\n", {"word.obj:2:", "expected a number", "'x'"}},
      {"nan.obj", "v 0 0 0\nv 1 NaN 0\n", {"nan.obj:2:", "finite"}},
      {"short.obj", "v 0 0\n", {"short.obj:1:", "expected 'v x y z'"}},
      {"face.obj", v + "f 1 2\n", {"face.obj:5:", "at least 3"}},
      {"index.obj", v + "f 1 b 3\n", {"index.obj:5:", "integer", "'b'"}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const auto file = write_text(c.name, c.content);
    expect_error<InputError>([&] { read_mesh(file); }, c.parts);
  }
}

TEST(MeshIoShared, BunnyIsAClosedMeshOf1839Vertices) {
  const fs::path file = fs::path(MVFLOW_SHARED_DATA) / "models" / "bunny-lowres-npm.obj";
  if (!fs::exists(file)) GTEST_SKIP() << file << " is not available";
  MeshBuildReport report;
  const Mesh mesh = load_mesh(file, &report);
  EXPECT_EQ(mesh.n_vertices(), 1839u);
  EXPECT_EQ(report.rejected_faces, 0u);
  std::size_t boundary = 0;
  for (auto e : mesh.topology.edges()) boundary += mesh.topology.is_boundary(e) ? 1 : 0;
  EXPECT_EQ(boundary, 0u);
}

TEST(MeshIoShared, SpotQuadsAndTrianglesGiveTheSameTexturedSurface) {
  const fs::path folder = fs::path(MVFLOW_SHARED_DATA) / "models" / "spot";
  if (!fs::exists(folder / "spot_quadrangulated.obj")) GTEST_SKIP() << folder << " is not available";
  const auto quads = read_obj(folder / "spot_quadrangulated.obj");
  const auto triangles = read_obj(folder / "spot_triangulated.obj");
  EXPECT_EQ(quads.positions.size(), 2930u);
  EXPECT_EQ(quads.triangles.size(), 2u * 2928u);  // every quad split in two
  EXPECT_EQ(triangles.triangles.size(), 5856u);
  EXPECT_EQ(quads.texcoords.size(), 3 * quads.triangles.size());
  MeshBuildReport report;
  const Mesh mesh = load_mesh(folder / "spot_triangulated.obj", &report);
  EXPECT_EQ(report.rejected_faces, 0u);
  EXPECT_EQ(mesh.texcoords.size(), 3 * mesh.n_faces());
}

TEST_F(MeshIoTest, BunnyRoundTripsThroughEveryFormat) {
  const fs::path file = fs::path(MVFLOW_SHARED_DATA) / "models" / "bunny-lowres-npm.obj";
  if (!fs::exists(file)) GTEST_SKIP() << file << " is not available";
  const auto bunny = read_obj(file);
  for (const char* name : {"b.ply", "b.obj", "b.off", "b.wrl"}) {
    SCOPED_TRACE(name);
    write_mesh(path(name), bunny);
    expect_equal(bunny, read_mesh(path(name)));
  }
}

// ---------------------------------------------------------------------------------------------
// OFF

TEST_F(MeshIoTest, OffRoundTripWithAndWithoutColors) {
  const auto mesh = octahedron();
  write_mesh(path("c.off"), mesh);
  EXPECT_EQ(read_all(path("c.off")).substr(0, 5), "COFF\n");
  expect_equal(only(mesh, true, false, false), read_mesh(path("c.off")));
  MeshWriteOptions options;
  options.write_colors = false;
  write_off(path("p.off"), mesh, options);
  EXPECT_EQ(read_all(path("p.off")).substr(0, 4), "OFF\n");
  expect_equal(only(mesh, false, false, false), read_off(path("p.off")));
}

TEST_F(MeshIoTest, OffVariants) {
  // Counts on the header line, comments, a quad, a face colour.
  auto mesh = read_off(write_text("a.off", "OFF 4 1 0\n# square\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n"));
  EXPECT_EQ(mesh.triangles.size(), 2u);
  EXPECT_FALSE(mesh.has_colors());
  // COFF with float colours (0-1) and integer ones (0-255), with and without alpha.
  mesh = read_off(write_text("b.off", "COFF\n3 1 3\n0 0 0 1.0 0.5 0 1\n1 0 0 255 0 51\n0 1 0 0 0 0 0\n3 0 1 2\n"));
  ASSERT_EQ(mesh.colors.size(), 3u);
  EXPECT_EQ(mesh.colors[0], Eigen::Vector3f(1.0f, 0.5f, 0.0f));
  EXPECT_EQ(mesh.colors[1], Eigen::Vector3f(1.0f, 0.0f, 51 / 255.0f));
  // NOFF: normals before nothing else.
  mesh = read_off(write_text("c.off", "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n"));
  EXPECT_EQ(mesh.positions[1], Eigen::Vector3d(1, 0, 0));
}

TEST_F(MeshIoTest, OffErrorsNameFileLineAndWhatWasExpected) {
  struct Case {
    std::string name, content;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {"truncated.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n", {"truncated.off:5:", "expected 3 vertices, file ends after 2"}},
      {"faces.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", {"faces.off:7:", "expected 2 faces, file ends after 1"}},
      {"range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", {"range.off:6:", "face 0", "vertex index 3 out of range"}},
      {"word.off", "OFF\n3 1 0\n0 0 0\n1 0 y\n0 1 0\n3 0 1 2\n", {"word.off:4:", "expected a number", "'y'"}},
      {"inf.off", "OFF\n3 1 0\n0 0 0\n1 0 inf\n0 1 0\n3 0 1 2\n", {"inf.off:4:", "finite"}},
      {"header.off", "PLY\n", {"header.off:1:", "expected the header 'OFF'"}},
      {"counts.off", "OFF\n3\n", {"counts.off:2:", "counts"}},
      {"extra.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n", {"extra.off:7:", "unexpected content"}},
      {"short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", {"short.off:6:", "face 0", "expected 4 vertex indices"}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const auto file = write_text(c.name, c.content);
    expect_error<InputError>([&] { read_mesh(file); }, c.parts);
  }
}

// ---------------------------------------------------------------------------------------------
// STL

//! Triangles as their corner positions: STL welds vertices in its own order.
std::multiset<std::array<double, 9>> corner_positions(const IndexedMesh& mesh) {
  std::multiset<std::array<double, 9>> result;
  for (const auto& t : mesh.triangles) {
    std::array<double, 9> p{};
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) p[3 * c + k] = mesh.positions[t[c]][k];
    // Any rotation of the corners is the same triangle: start at the smallest corner.
    std::array<double, 9> best = p;
    for (int r = 1; r < 3; ++r) {
      std::array<double, 9> q{};
      for (int i = 0; i < 9; ++i) q[i] = p[(i + 3 * r) % 9];
      best = std::min(best, q);
    }
    result.insert(best);
  }
  return result;
}

IndexedMesh float_octahedron() {
  IndexedMesh mesh = only(octahedron(), false, false, false);
  for (auto& p : mesh.positions) p = p.cast<float>().cast<double>();  // STL stores floats
  return mesh;
}

TEST_F(MeshIoTest, StlBinaryAndAsciiRoundTrips) {
  const auto mesh = float_octahedron();
  for (bool binary : {true, false}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    MeshWriteOptions options;
    options.binary = binary;
    const auto file = path(binary ? "b.stl" : "A.STL");
    write_mesh(file, mesh, options);
    EXPECT_EQ(read_all(file).substr(0, 5) == "solid", !binary);
    const auto back = read_mesh(file);
    EXPECT_EQ(back.positions.size(), 6u);  // welded again
    EXPECT_EQ(corner_positions(mesh), corner_positions(back));
    EXPECT_NO_THROW(load_mesh(file));
  }
}

TEST_F(MeshIoTest, StlBadInput) {
  expect_error<InputError>([&] { read_stl(write_text("empty.stl", "")); }, {"empty.stl", "expected"});
  expect_error<InputError>([&] { read_stl(write_text("none.stl", "solid x\nendsolid x\n")); }, {"none.stl", "expected"});
  expect_error<IoError>([&] { read_stl(path("missing.stl")); }, {"missing.stl"});
}

// ---------------------------------------------------------------------------------------------
// VRML

TEST_F(MeshIoTest, VrmlRoundTripWithTexcoordsIsExact) {
  const auto mesh = octahedron();
  write_mesh(path("m.wrl"), mesh);
  expect_equal(only(mesh, false, false, true), read_mesh(path("m.wrl")));
  MeshWriteOptions options;
  options.write_texcoords = false;
  write_vrml(path("n.vrml"), mesh, options);
  auto expected = only(mesh, false, false, false);
  expected.texture_file = mesh.texture_file;
  expect_equal(expected, read_mesh(path("n.vrml")));
}

TEST_F(MeshIoTest, VrmlNestedTransformsAndTwoFaceSets) {
  const auto file = write_text("scene.wrl", R"(#VRML V2.0 utf8
# exported by hand, like PhotoModeler would
WorldInfo { title "two faces" info [ "a" "b" ] }
PROTO Ignored [ field SFFloat x 1 ] { Group { children [ Shape { geometry IndexedFaceSet { coordIndex [ 0 1 2 ] } } ] } }
DEF Root Transform {
  children [
    Shape {
      appearance Appearance {
        material Material { diffuseColor 0.8 0.8 0.8 shininess 0.2 }
        texture ImageTexture { url [ "photo 1.jpg", "fallback.jpg" ] repeatS FALSE }
      }
      geometry IndexedFaceSet {
        solid FALSE creaseAngle 0.5
        coord DEF Pts Coordinate { point [ 0 0 0, 1 0 0, 1 1 0, 0 1 0 ] }
        coordIndex [ 0, 1, 2, 3, -1 ]
        texCoord TextureCoordinate { point [ 0 0, 1 0, 1 1, 0 1 ] }
        normal Normal { vector [ 0 0 1 ] }
      }
    }
    Transform {
      translation 10 0 0  # moves the second face set
      children Shape {
        geometry IndexedFaceSet {
          coordIndex [ 0 1 2 -1 2 1 0 ]
          texCoordIndex [ 1 0 2 -1 2 1 0 -1 ]
          texCoord TextureCoordinate { point [ 0.25 0.5 0.75 1 0 0.125 ] }
          coord USE Pts
        }
      }
    }
  ]
  scale 2 2 2
}
ROUTE A.b TO C.d
)");
  const auto mesh = read_vrml(file);
  ASSERT_EQ(mesh.positions.size(), 8u);
  EXPECT_EQ(mesh.positions[2], Eigen::Vector3d(2, 2, 0));   // scaled by the outer Transform
  EXPECT_EQ(mesh.positions[5], Eigen::Vector3d(22, 0, 0));  // inner translation, then outer scale
  ASSERT_EQ(mesh.triangles.size(), 4u);
  EXPECT_EQ(mesh.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(mesh.triangles[2], (std::array<std::uint32_t, 3>{4, 5, 6}));
  EXPECT_EQ(mesh.triangles[3], (std::array<std::uint32_t, 3>{6, 5, 4}));
  ASSERT_EQ(mesh.texcoords.size(), 12u);
  EXPECT_EQ(mesh.texcoords[4], Eigen::Vector2f(1, 1));       // coordIndex used for texCoord
  EXPECT_EQ(mesh.texcoords[6], Eigen::Vector2f(0.75f, 1));   // texCoordIndex 1
  EXPECT_EQ(mesh.texcoords[8], Eigen::Vector2f(0, 0.125f));  // texCoordIndex 2
  EXPECT_EQ(mesh.texture_file, "photo 1.jpg");
}

TEST_F(MeshIoTest, VrmlCounterClockwiseFalseIsReversed) {
  const auto file = write_text("cw.wrl",
                               "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { ccw FALSE "
                               "coord Coordinate { point [ 0 0 0 1 0 0 0 1 0 ] } coordIndex [ 0 1 2 -1 ] } }\n");
  const auto mesh = read_vrml(file);
  ASSERT_EQ(mesh.triangles.size(), 1u);
  EXPECT_EQ(mesh.triangles[0], (std::array<std::uint32_t, 3>{0, 2, 1}));
}

TEST_F(MeshIoTest, VrmlErrorsNameFileLineAndWhatWasExpected) {
  const std::string head = "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet {\n";  // lines 1-2
  struct Case {
    std::string name, content;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {"version.wrl", "#VRML V1.0 ascii\nSeparator { }\n", {"version.wrl:1:", "expected the header"}},
      {"word.wrl", head + "coord Coordinate { point [ 0 0 0,\n 1 zero 0 ] }\n} }\n", {"word.wrl:4:", "expected a number", "'zero'"}},
      {"nan.wrl", head + "coord Coordinate { point [ 0 0 nan ] }\n} }\n", {"nan.wrl:3:", "finite"}},
      {"range.wrl", head + "coord Coordinate { point [ 0 0 0 1 0 0 0 1 0 ] }\ncoordIndex [ 0 1 2 -1\n 0 2 3 -1 ]\n} }\n",
       {"range.wrl:5:", "coordIndex", "index 3 out of range"}},
      {"count.wrl", head + "coord Coordinate { point [ 0 0 0 1 0 ] }\n} }\n", {"count.wrl:3:", "3 numbers per point"}},
      {"open.wrl", head + "coord Coordinate { point [ 0 0 0 ] }\n}\n", {"open.wrl:2:", "expected a '}'"}},
      {"close.wrl", head + "coord Coordinate { point [ 0 0 0 } ]\n} }\n", {"close.wrl:3:", "unexpected '}'"}},
      {"uvshape.wrl",
       head + "coord Coordinate { point [ 0 0 0 1 0 0 0 1 0 ] } coordIndex [ 0 1 2 ]\n"
              "texCoord TextureCoordinate { point [ 0 0 ] }\ntexCoordIndex [ 0 0 0 0 ] } }\n",
       {"uvshape.wrl:5:", "same polygons"}},
      {"use.wrl", head + "coord USE Nothing\n} }\n", {"use.wrl:3:", "DEF"}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const auto file = write_text(c.name, c.content);
    expect_error<InputError>([&] { read_mesh(file); }, c.parts);
  }
}

// ---------------------------------------------------------------------------------------------
// load_mesh and building

TEST_F(MeshIoTest, LoadMeshOfAnEmptyMeshIsAnInputError) {
  const auto file = write_text("empty.ply", ascii_ply("0 0 0\n1 0 0\n0 1 0\n", "", 3, 0));
  EXPECT_EQ(read_mesh(file).positions.size(), 3u);  // reading alone is fine
  expect_error<InputError>([&] { load_mesh(file); }, {"empty.ply", "no triangles"});
  const auto obj = write_text("empty.obj", "# nothing\n");
  expect_error<InputError>([&] { load_mesh(obj); }, {"empty.obj", "no triangles"});
}

TEST_F(MeshIoTest, NonManifoldEdgeIsReportedNotFatal) {
  // Three triangles on the edge 0-1.
  const auto file = write_text("fin.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
  MeshBuildReport report;
  const Mesh mesh = load_mesh(file, &report);
  EXPECT_GE(report.rejected_faces, 1u);
  EXPECT_EQ(mesh.n_faces() + report.rejected_faces, 3u);
}

// ---------------------------------------------------------------------------------------------
// Atomic writes

TEST_F(MeshIoTest, WritingIntoAMissingFolderIsAnIoError) {
  const auto mesh = octahedron();
  for (const char* name : {"m.ply", "m.obj", "m.off", "m.stl", "m.wrl"}) {
    SCOPED_TRACE(name);
    const auto file = path("no such folder") / name;
    expect_error<IoError>([&] { write_mesh(file, mesh); }, {"no such folder"});
    EXPECT_FALSE(fs::exists(file.parent_path()));
  }
}

TEST_F(MeshIoTest, FailedWriteLeavesTheDestinationUntouched) {
  IndexedMesh bad = octahedron();
  bad.triangles[3][1] = 99;  // out of range: the writer must refuse before replacing anything
  for (const char* name : {"m.ply", "m.obj", "m.off", "m.stl", "m.wrl"}) {
    SCOPED_TRACE(name);
    const auto file = write_text(name, std::string("precious content of ") + name);
    const std::string before = read_all(file);
    expect_error<InputError>([&] { write_mesh(file, bad); }, {name, "face 3", "out of range"});
    EXPECT_EQ(read_all(file), before);
  }
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(dir_)) left.push_back(entry.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"m.obj", "m.off", "m.ply", "m.stl", "m.wrl"}));
}

TEST_F(MeshIoTest, VertexFieldsDumpHoldsEveryVertexsStateAndTheFaces) {
  // A level-1 icosphere (42 vertices) with values that tell the columns apart: vertex v's g is
  // 0.5·v + 1 where defined, its H −v, ∇g = (v, 2v, 3v), F·N as it moved 7·v, scale 1/(v + 1),
  // move 0.01·v.
  const TriMesh mesh = test::icosphere(1.0, 1);
  const std::size_t n = mesh.n_vertices();
  VertexFields fields;
  fields.resize(n, 4);
  std::vector<double> scale(n), moved(n), moving_speed(n);
  for (std::size_t v = 0; v < n; ++v) {
    const double x = static_cast<double>(v);
    fields.normal[v] = Eigen::Vector3d(x, 1.0, -2.0).normalized();
    fields.mean_curvature[v] = -x;
    fields.photo_consistency[v] = 0.5 * x + 1.0;
    fields.photo_gradient[v] = Eigen::Vector3d(x, 2 * x, 3 * x);
    // Every third vertex has no g (nor gradient, nor speed); every fifth g but no gradient; every
    // other one a curvature.
    fields.defined[v] = v % 3 == 0 ? kNormalDefined
                                   : (v % 5 == 0 ? kNormalDefined | kPhotoDefined | kSpeedDefined
                                                 : kNormalDefined | kPhotoDefined | kGradientDefined | kSpeedDefined);
    if (v % 2 == 0) fields.defined[v] |= kCurvatureDefined;
    moving_speed[v] = v % 3 == 0 ? 0.0 : 7.0 * x;  // what the refinement records as the vertex moves
    fields.visible_count[v] = static_cast<std::uint16_t>(v % 4);
    fields.patch_kind[v] = static_cast<PatchKind>(v % 3);
    scale[v] = 1.0 / (x + 1.0);
    moved[v] = 0.01 * x;
  }
  IterationVertexFields state{.iteration = 7, .time_step = 0.0625, .mesh = &mesh, .fields = &fields,
                              .moving_speed = moving_speed, .damping_scale = scale, .moved = moved};
  const fs::path file = path(vertex_fields_file_name(7));
  EXPECT_EQ(file.filename(), "iteration_0007.ply");
  write_vertex_fields(file, state);

  const test::VertexFieldsDump dump = test::read_vertex_fields_dump(file);
  EXPECT_EQ(dump.comments.at("iteration"), "7");
  EXPECT_EQ(std::stod(dump.comments.at("time_step")), 0.0625);
  ASSERT_EQ(dump.rows.size(), n);
  for (std::size_t v = 0; v < n; ++v) {
    const double x = static_cast<double>(v);
    const auto p = mesh.point(TriMesh::VertexHandle(static_cast<int>(v)));
    const Eigen::Vector3d normal = Eigen::Vector3d(x, 1.0, -2.0).normalized();
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_EQ(dump.value(v, std::string(1, "xyz"[axis])), p[axis]);
      EXPECT_EQ(dump.value(v, std::string("n") + "xyz"[axis]), normal[axis]);
    }
    if (v % 2 == 0)
      EXPECT_EQ(dump.value(v, "mean_curvature"), -x);
    else
      EXPECT_TRUE(std::isnan(dump.value(v, "mean_curvature"))) << v;
    EXPECT_EQ(dump.value(v, "speed_normal"), moving_speed[v]);
    EXPECT_EQ(dump.value(v, "damping"), 1.0 / (x + 1.0));
    EXPECT_EQ(dump.value(v, "moved"), 0.01 * x);
    const bool has_g = v % 3 != 0, has_gradient = has_g && v % 5 != 0;
    if (has_g)
      EXPECT_EQ(dump.value(v, "g"), 0.5 * x + 1.0) << v;
    else
      EXPECT_TRUE(std::isnan(dump.value(v, "g"))) << v;
    if (has_gradient)
      EXPECT_NEAR(dump.value(v, "grad_g_normal"), Eigen::Vector3d(x, 2 * x, 3 * x).dot(normal), 1e-12 * (1 + x)) << v;
    else
      EXPECT_TRUE(std::isnan(dump.value(v, "grad_g_normal"))) << v;
    EXPECT_EQ(dump.byte(v, "defined"), fields.defined[v]);
    EXPECT_EQ(dump.byte(v, "views"), v % 4);
    EXPECT_EQ(dump.byte(v, "patch"), v % 3);
  }
  const auto triangles = triangles_of(mesh);
  ASSERT_EQ(dump.faces.size(), triangles.size());
  for (std::size_t f = 0; f < triangles.size(); ++f)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(static_cast<std::uint32_t>(dump.faces[f][c]), triangles[f][c]);

  // Without damping the scale reads 1; arrays sized for another mesh are refused, nothing written.
  state.damping_scale = {};
  write_vertex_fields(file, state);
  EXPECT_EQ(test::read_vertex_fields_dump(file).value(5, "damping"), 1.0);
  const std::vector<double> short_moves(n - 1, 0.0);
  state.moved = short_moves;
  EXPECT_THROW(write_vertex_fields(path("other.ply"), state), Error);
  EXPECT_FALSE(fs::exists(path("other.ply")));
}

}  // namespace
}  // namespace mvflow::io
