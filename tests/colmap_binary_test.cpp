// COLMAP binary models (io/camera_io.h): files built here byte by byte from COLMAP's layout
// (reconstruction_io_binary.cc: little-endian, CameraModelId numbers) must give exactly the
// cameras of the equivalent text model; the writer is checked by decoding its bytes here and by
// round trips; every truncation and malformed value must give "FILE: byte N: expected ...".

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "engine/model/camera.h"
#include "engine/model/error.h"
#include "io/camera_io.h"
#include "io/scene_io.h"
#include "colmap_reference.h"
#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;
using io::CameraFormat;

const fs::path kDefaultScene = fs::path(MVFLOW_TEST_DATA) / "scenes" / "default";

// ---------------------------------------------------------------------------------------------
// An encoder and a decoder of COLMAP's binary layout, written from its definition and independent
// of mvflow's: bytes are assembled least significant first.

struct Encoder {
  std::string bytes;

  void unsigned_bytes(std::uint64_t value, int count) {
    for (int i = 0; i < count; ++i) bytes.push_back(static_cast<char>((value >> (8 * i)) & 0xff));
  }
  Encoder& u32(std::uint32_t v) { return unsigned_bytes(v, 4), *this; }
  Encoder& i32(std::int32_t v) { return unsigned_bytes(static_cast<std::uint32_t>(v), 4), *this; }
  Encoder& u64(std::uint64_t v) { return unsigned_bytes(v, 8), *this; }
  Encoder& i64(std::int64_t v) { return unsigned_bytes(static_cast<std::uint64_t>(v), 8), *this; }
  Encoder& f64(double v) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);  // IEEE 754 double and uint64 share the host's byte order
    return unsigned_bytes(bits, 8), *this;
  }
  Encoder& name(const std::string& text) {
    bytes += text;
    bytes.push_back('\0');
    return *this;
  }
};

struct Decoder {
  std::string bytes;
  std::size_t at = 0;

  std::uint64_t unsigned_bytes(int count) {
    std::uint64_t value = 0;
    for (int i = 0; i < count; ++i)
      value |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes.at(at++))) << (8 * i);
    return value;
  }
  std::uint32_t u32() { return static_cast<std::uint32_t>(unsigned_bytes(4)); }
  std::int32_t i32() { return static_cast<std::int32_t>(static_cast<std::uint32_t>(unsigned_bytes(4))); }
  std::uint64_t u64() { return unsigned_bytes(8); }
  double f64() {
    const std::uint64_t bits = unsigned_bytes(8);
    double v = 0;
    std::memcpy(&v, &bits, 8);
    return v;
  }
  std::string name() {
    const std::size_t end = bytes.find('\0', at);
    std::string text = bytes.substr(at, end - at);
    at = end + 1;
    return text;
  }
};

// ---------------------------------------------------------------------------------------------
// One model, described once and written both as text and as binary.

struct ModelCamera {
  std::uint32_t id;
  std::int32_t model_id;
  std::string model;
  std::uint64_t width, height;
  std::vector<double> params;
};

struct ModelImage {
  std::uint32_t id;
  std::array<double, 4> q;  // w x y z, deliberately not quite unit length
  std::array<double, 3> t;
  std::uint32_t camera_id;
  std::string name;
  std::vector<std::array<double, 3>> points;  // x, y, point3D_id
};

// Every model mvflow reads, with non-contiguous camera ids in no particular order.
std::vector<ModelCamera> all_model_cameras() {
  return {
      {10, 4, "OPENCV", 640, 480, {960.25, 948.75, 322.5, 236.5, -0.21, 0.07, 0.0015, -0.0022}},
      {3, 0, "SIMPLE_PINHOLE", 640, 480, {1100.5, 320.25, 240.75}},
      {7, 1, "PINHOLE", 800, 600, {1100.5, 1093.25, 399.5, 301.125}},
      {42, 2, "SIMPLE_RADIAL", 640, 480, {950.0, 321.0, 239.0, -0.12}},
      {1, 3, "RADIAL", 1024, 768, {955.5, 518.5, 382.5, -0.15, 0.04}},
  };
}

// Images around the origin, ~5 away, looking roughly at it; ids out of order, cameras shared.
std::vector<ModelImage> model_images(const std::vector<ModelCamera>& cameras, std::size_t count) {
  std::vector<ModelImage> images;
  for (std::size_t i = 0; i < count; ++i) {
    const double angle = 0.7 + 1.3 * static_cast<double>(i);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()));
    const double s = 1 + 1e-7 * (static_cast<double>(i) - 2);    // COLMAP normalizes; so must we
    ModelImage image{static_cast<std::uint32_t>(count - i) * 3,  // 3·count, …, 6, 3
                     {s * q.w(), s * q.x(), s * q.y(), s * q.z()},
                     {0.1 * static_cast<double>(i), -0.2, 5.0 + 0.01 * static_cast<double>(i)},
                     cameras[i % cameras.size()].id,
                     "image" + std::to_string(i) + ".jpg",
                     {}};
    if (i % 2) image.points = {{12.5, 30.25, -1}, {100.0, 200.0, 7}};
    images.push_back(image);
  }
  return images;
}

std::string cameras_bin(const std::vector<ModelCamera>& cameras) {
  Encoder e;
  e.u64(cameras.size());
  for (const auto& c : cameras) {
    e.u32(c.id).i32(c.model_id).u64(c.width).u64(c.height);
    for (double p : c.params) e.f64(p);
  }
  return e.bytes;
}

std::string images_bin(const std::vector<ModelImage>& images) {
  Encoder e;
  e.u64(images.size());
  for (const auto& im : images) {
    e.u32(im.id);
    for (double q : im.q) e.f64(q);
    for (double t : im.t) e.f64(t);
    e.u32(im.camera_id).name(im.name).u64(im.points.size());
    for (const auto& p : im.points) e.f64(p[0]).f64(p[1]).i64(static_cast<std::int64_t>(p[2]));
  }
  return e.bytes;
}

// %.17g: read back bit for bit, so the text model holds exactly the binary model's numbers.
std::string g17(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

void write_text_model(const fs::path& folder, const std::vector<ModelCamera>& cameras,
                      const std::vector<ModelImage>& images) {
  fs::create_directories(folder);
  std::string text = "# Camera list with one line of data per camera:\n";
  for (const auto& c : cameras) {
    text +=
        std::to_string(c.id) + " " + c.model + " " + std::to_string(c.width) + " " + std::to_string(c.height);
    for (double p : c.params) text += " " + g17(p);
    text += "\n";
  }
  test::write_text(folder / "cameras.txt", text);
  text = "# Image list with two lines of data per image:\n";
  for (const auto& im : images) {
    text += std::to_string(im.id);
    for (double q : im.q) text += " " + g17(q);
    for (double t : im.t) text += " " + g17(t);
    text += " " + std::to_string(im.camera_id) + " " + im.name + "\n";
    for (const auto& p : im.points) text += g17(p[0]) + " " + g17(p[1]) + " " + g17(p[2]) + " ";
    text += "\n";
  }
  test::write_text(folder / "images.txt", text);
}

void write_binary_model(const fs::path& folder, const std::vector<ModelCamera>& cameras,
                        const std::vector<ModelImage>& images) {
  fs::create_directories(folder);
  test::write_text(folder / "cameras.bin", cameras_bin(cameras));
  test::write_text(folder / "images.bin", images_bin(images));
  test::write_text(folder / "points3D.bin", Encoder().u64(0).bytes);
}

// Bit-for-bit equality of everything a view holds.
void expect_identical(const View& expected, const View& actual) {
  EXPECT_EQ(expected.image_name, actual.image_name);
  const Camera& a = expected.camera;
  const Camera& b = actual.camera;
  EXPECT_EQ(a.width(), b.width());
  EXPECT_EQ(a.height(), b.height());
  EXPECT_EQ(a.K(), b.K());
  EXPECT_EQ(a.R(), b.R());
  EXPECT_EQ(a.t(), b.t());
  EXPECT_EQ(a.distortion().model, b.distortion().model);
  EXPECT_EQ(a.distortion().coefficients, b.distortion().coefficients);
}

// Expects \p action to throw E whose what() contains every one of \p parts; returns what().
template <class E, class F>
std::string expect_error(F&& action, const std::vector<std::string>& parts) {
  try {
    action();
    ADD_FAILURE() << "no exception thrown; expected one mentioning " << parts.front();
  } catch (const E& error) {
    const std::string what = error.what();
    for (const auto& part : parts)
      EXPECT_NE(what.find(part), std::string::npos) << "'" << what << "' lacks '" << part << "'";
    return what;
  }
  return "";
}

// ---------------------------------------------------------------------------------------------
// Reading

TEST(ColmapBinary, ColmapLayoutDecodesToTheCamerasOfTheTextModel) {
  test::ScratchFolder folder;
  const auto cameras = all_model_cameras();
  const auto images = model_images(cameras, 7);
  write_binary_model(folder / "bin", cameras, images);
  write_text_model(folder / "txt", cameras, images);

  const auto from_binary = io::read_colmap_binary(folder / "bin");
  const auto from_text = io::read_colmap(folder / "txt");
  ASSERT_EQ(from_binary.size(), images.size());
  ASSERT_EQ(from_text.size(), images.size());
  for (std::size_t i = 0; i < from_binary.size(); ++i) {
    SCOPED_TRACE("view " + std::to_string(i));
    expect_identical(from_text[i], from_binary[i]);
  }

  // Sorted by IMAGE_ID (the file has them in descending order), and projecting as COLMAP does,
  // with COLMAP's top-left pixel centre (0.5, 0.5) at mvflow's (0, 0).
  for (std::size_t i = 0; i < images.size(); ++i) {
    const ModelImage& image = images[images.size() - 1 - i];
    const View& view = from_binary[i];
    SCOPED_TRACE(image.name);
    EXPECT_EQ(view.image_name, image.name);
    const ModelCamera& camera = *std::find_if(cameras.begin(), cameras.end(),
                                              [&](const ModelCamera& c) { return c.id == image.camera_id; });
    EXPECT_EQ(view.camera.width(), static_cast<int>(camera.width));
    EXPECT_EQ(view.camera.height(), static_cast<int>(camera.height));
    const auto& q = image.q;
    const Eigen::Matrix3d R = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
    const Eigen::Vector3d t(image.t[0], image.t[1], image.t[2]);
    for (const Eigen::Vector3d& X : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.3, -0.2, 0.1),
                                     Eigen::Vector3d(-0.4, 0.25, -0.2), Eigen::Vector3d(0.1, 0.45, 0.3)}) {
      const Eigen::Vector3d x = R * X + t;
      const Eigen::Vector2d colmap_pixel =
          test::colmap_image_from_camera(camera.model, camera.params, x(0) / x(2), x(1) / x(2));
      const Projection p = view.camera.project(X);
      EXPECT_NEAR(p.u, colmap_pixel.x() - 0.5, 1e-9 * std::abs(colmap_pixel.x()));
      EXPECT_NEAR(p.v, colmap_pixel.y() - 0.5, 1e-9 * std::abs(colmap_pixel.y()));
      EXPECT_NEAR(p.depth, x(2), 1e-12 * x(2));
    }
  }
  // The dispatcher reads the same.
  const auto dispatched = io::read_cameras(folder / "bin", CameraFormat::ColmapBinary);
  ASSERT_EQ(dispatched.size(), from_binary.size());
  for (std::size_t i = 0; i < dispatched.size(); ++i) expect_identical(from_binary[i], dispatched[i]);
}

TEST(ColmapBinary, TextToBinaryRoundTripIsExact) {
  test::ScratchFolder folder;
  const auto cameras = all_model_cameras();
  write_text_model(folder / "txt", cameras, model_images(cameras, 5));
  const auto from_text = io::read_colmap(folder / "txt");
  io::write_colmap_binary(folder / "bin", from_text);
  io::write_colmap(folder / "txt2", from_text);
  const auto from_binary = io::read_colmap_binary(folder / "bin");
  const auto from_text2 = io::read_colmap(folder / "txt2");
  ASSERT_EQ(from_binary.size(), from_text.size());
  for (std::size_t i = 0; i < from_text.size(); ++i) {
    SCOPED_TRACE("view " + std::to_string(i));
    // The binary model keeps every number the text model keeps, bit for bit.
    expect_identical(from_text2[i], from_binary[i]);
    // Intrinsics, translation, size and name survive exactly. R is stored as a quaternion, and
    // R → q → R is exact in neither format, so R agrees to rounding.
    const Camera& a = from_text[i].camera;
    const Camera& b = from_binary[i].camera;
    EXPECT_EQ(a.K(), b.K());
    EXPECT_EQ(a.t(), b.t());
    EXPECT_EQ(a.distortion().model, b.distortion().model);
    EXPECT_EQ(a.distortion().coefficients, b.distortion().coefficients);
    EXPECT_EQ(a.width(), b.width());
    EXPECT_EQ(a.height(), b.height());
    EXPECT_EQ(from_text[i].image_name, from_binary[i].image_name);
    EXPECT_LT((a.R() - b.R()).cwiseAbs().maxCoeff(), 1e-15);
  }
  // A second round trip changes nothing the first did not.
  io::write_colmap_binary(folder / "bin2", from_binary);
  const auto again = io::read_colmap_binary(folder / "bin2");
  for (std::size_t i = 0; i < again.size(); ++i) {
    EXPECT_EQ(again[i].camera.K(), from_binary[i].camera.K());
    EXPECT_EQ(again[i].camera.t(), from_binary[i].camera.t());
    EXPECT_LT((again[i].camera.R() - from_binary[i].camera.R()).cwiseAbs().maxCoeff(), 1e-15);
  }
}

TEST(ColmapBinary, WriterFollowsColmapsLayout) {
  // The writer's bytes, decoded here: the models write_colmap chooses, its numbers, one camera
  // per view, no points, and an empty points3D.bin.
  test::ScratchFolder folder;
  const auto cameras = all_model_cameras();
  write_text_model(folder / "txt", cameras, model_images(cameras, 5));
  const auto views = io::read_colmap(folder / "txt");
  io::write_colmap_binary(folder / "bin", views);
  io::write_colmap(folder / "txt2", views);

  // cameras.txt as written by write_colmap: "ID MODEL W H PARAMS..." per line.
  std::vector<std::vector<std::string>> text_cameras;
  {
    std::istringstream lines(test::read_text(folder / "txt2" / "cameras.txt"));
    for (std::string line; std::getline(lines, line);) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream words(line);
      text_cameras.emplace_back(std::istream_iterator<std::string>(words),
                                std::istream_iterator<std::string>());
    }
  }
  const std::vector<std::string> model_names{"SIMPLE_PINHOLE", "PINHOLE", "SIMPLE_RADIAL", "RADIAL",
                                             "OPENCV"};
  Decoder c{test::read_text(folder / "bin" / "cameras.bin")};
  ASSERT_EQ(c.u64(), views.size());
  ASSERT_EQ(text_cameras.size(), views.size());
  for (std::size_t i = 0; i < views.size(); ++i) {
    SCOPED_TRACE("camera " + std::to_string(i));
    const auto& words = text_cameras[i];
    EXPECT_EQ(c.u32(), i + 1);
    const std::int32_t model = c.i32();
    ASSERT_GE(model, 0);
    ASSERT_LT(model, 5);
    EXPECT_EQ(model_names[static_cast<std::size_t>(model)], words[1]);
    EXPECT_EQ(c.u64(), std::stoull(words[2]));
    EXPECT_EQ(c.u64(), std::stoull(words[3]));
    for (std::size_t k = 4; k < words.size(); ++k) EXPECT_EQ(c.f64(), std::stod(words[k]));
  }
  EXPECT_EQ(c.at, c.bytes.size());

  Decoder im{test::read_text(folder / "bin" / "images.bin")};
  ASSERT_EQ(im.u64(), views.size());
  for (std::size_t i = 0; i < views.size(); ++i) {
    SCOPED_TRACE("image " + std::to_string(i));
    EXPECT_EQ(im.u32(), i + 1);
    Eigen::Quaterniond q;
    q.w() = im.f64();
    q.x() = im.f64();
    q.y() = im.f64();
    q.z() = im.f64();
    EXPECT_GE(q.w(), 0);
    EXPECT_NEAR(q.norm(), 1, 1e-15);
    EXPECT_LT((q.toRotationMatrix() - views[i].camera.R()).cwiseAbs().maxCoeff(), 1e-15);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(im.f64(), views[i].camera.t()(k));
    EXPECT_EQ(im.u32(), i + 1);
    EXPECT_EQ(im.name(), views[i].image_name);
    EXPECT_EQ(im.u64(), 0u);
  }
  EXPECT_EQ(im.at, im.bytes.size());
  EXPECT_EQ(test::read_text(folder / "bin" / "points3D.bin"), std::string(8, '\0'));
}

TEST(ColmapBinary, UnrepresentableWriteLeavesFilesUntouched) {
  test::ScratchFolder folder;
  const auto views = io::read_middlebury(kDefaultScene / "default_par.txt", 80, 60);
  const fs::path model = folder / "model";
  fs::create_directories(model);
  test::write_text(model / "cameras.bin", "old");
  auto bad = views;
  bad[1].image_name = std::string("a\0b.png", 7);
  expect_error<InputError>([&] { io::write_colmap_binary(model, bad); }, {"images.bin", "camera 1", "NUL"});
  bad = views;
  bad[2].image_name.clear();
  expect_error<InputError>([&] { io::write_colmap_binary(model, bad); }, {"camera 2", "empty"});
  bad = views;
  Eigen::Matrix3d K = bad[3].camera.K();
  K(0, 1) = 0.5;
  bad[3].camera = Camera(K, bad[3].camera.R(), bad[3].camera.t(), 80, 60);
  expect_error<InputError>([&] { io::write_colmap_binary(model, bad); }, {"cameras.bin", "camera 3", "skew"});
  EXPECT_EQ(test::read_text(model / "cameras.bin"), "old");
  EXPECT_EQ(std::distance(fs::directory_iterator(model), fs::directory_iterator()), 1);  // no temporary left
  // Names with spaces are fine in binary (not in text).
  bad = views;
  bad[0].image_name = "with space.png";
  io::write_colmap_binary(model, bad);
  EXPECT_EQ(io::read_colmap_binary(model)[0].image_name, "with space.png");
}

// ---------------------------------------------------------------------------------------------
// Finding the model

TEST(ColmapBinary, BinaryBeatsTextInOneFolderAndFoldersKeepTheirOrder) {
  test::ScratchFolder folder;
  const auto cameras = all_model_cameras();
  const auto count_views = [](const fs::path& path) {
    const io::SceneLocation location = io::locate_scene(path);
    return io::read_cameras(location.camera_path, location.format).size();
  };

  // Both models in one folder: binary (3 images) before text (2 images), as COLMAP reads.
  const fs::path both = folder / "both";
  write_text_model(both, cameras, model_images(cameras, 2));
  write_binary_model(both, cameras, model_images(cameras, 3));
  auto found = io::find_colmap_model(both);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->folder, both);
  EXPECT_EQ(found->format, CameraFormat::ColmapBinary);
  EXPECT_EQ(io::locate_scene(both).format, CameraFormat::ColmapBinary);
  EXPECT_EQ(count_views(both), 3u);
  // Naming a file picks its model; the format-specific readers read theirs.
  EXPECT_EQ(count_views(both / "cameras.txt"), 2u);
  EXPECT_EQ(count_views(both / "images.txt"), 2u);
  EXPECT_EQ(count_views(both / "cameras.bin"), 3u);
  EXPECT_EQ(io::locate_scene(both / "images.bin").format, CameraFormat::ColmapBinary);
  EXPECT_EQ(io::read_colmap(both).size(), 2u);
  EXPECT_EQ(io::read_colmap_binary(both).size(), 3u);

  // The folder order stays: sparse/ (text) before sparse/0/ (binary).
  const fs::path nested = folder / "nested";
  write_text_model(nested / "sparse", cameras, model_images(cameras, 2));
  write_binary_model(nested / "sparse" / "0", cameras, model_images(cameras, 4));
  found = io::find_colmap_model(nested);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->folder, nested / "sparse");
  EXPECT_EQ(found->format, CameraFormat::Colmap);
  EXPECT_EQ(count_views(nested), 2u);
  EXPECT_EQ(io::read_colmap_binary(nested).size(), 4u);  // the binary reader looks further

  // A binary model needs both files; a lone cameras.bin leaves the text model.
  const fs::path half = folder / "half";
  write_text_model(half, cameras, model_images(cameras, 2));
  test::write_text(half / "cameras.bin", cameras_bin(cameras));
  EXPECT_EQ(io::find_colmap_model(half)->format, CameraFormat::Colmap);
  EXPECT_FALSE(io::find_colmap_model(folder / "nowhere"));
  expect_error<IoError>([&] { io::read_colmap_binary(folder / "nowhere"); }, {"nowhere", "cameras.bin"});
}

TEST(ColmapBinary, SceneWithSparseZeroBinaryLoadsLikeAnyScene) {
  test::ScratchFolder folder;
  const fs::path scene = folder / "scene";
  fs::copy(kDefaultScene, scene, fs::copy_options::recursive);
  fs::remove(scene / "default_par.txt");
  const auto middlebury = io::read_middlebury(kDefaultScene / "default_par.txt", 80, 60);
  io::write_colmap_binary(scene / "sparse" / "0", middlebury);

  const Scene loaded = io::load_scene(scene);
  EXPECT_EQ(loaded.camera_format, "colmap-bin");
  EXPECT_EQ(loaded.camera_file, scene / "sparse" / "0");
  ASSERT_EQ(loaded.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(loaded.views[i].camera.width(), 80);
    EXPECT_EQ(loaded.views[i].camera.K(), middlebury[i].camera.K());
    EXPECT_EQ(loaded.views[i].camera.t(), middlebury[i].camera.t());
    EXPECT_LT((loaded.views[i].camera.R() - middlebury[i].camera.R()).cwiseAbs().maxCoeff(), 1e-15);
  }
  EXPECT_EQ(loaded.image(1).width(), 80);  // images found beside the scene folder

  const test::CommandResult r = test::run_mvflow("info " + scene.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("cameras    4 (colmap-bin, " + (scene / "sparse" / "0").string()),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("4 × 80x60"), std::string::npos) << r.output;
}

// ---------------------------------------------------------------------------------------------
// Malformed files

// A small valid model: two cameras, two images (one with points).
std::vector<ModelCamera> small_cameras() {
  return {{1, 1, "PINHOLE", 640, 480, {500, 501, 320, 240}},
          {2, 4, "OPENCV", 640, 480, {500, 501, 320, 240, -0.1, 0.01, 0.001, 0.002}}};
}
std::vector<ModelImage> small_images() {
  auto images = model_images(small_cameras(), 2);
  images[0].points = {{1.5, 2.5, 3}};
  return images;
}

// The byte offset N of "FILE: byte N: ...", or -1 when the message does not start that way.
long long byte_offset(const std::string& message, const fs::path& file) {
  const std::string prefix = file.string() + ": byte ";
  if (message.rfind(prefix, 0) != 0) return -1;
  const std::size_t end = message.find(": ", prefix.size());
  if (end == std::string::npos) return -1;
  return std::stoll(message.substr(prefix.size(), end - prefix.size()));
}

// Every prefix of \p bytes as \p file: an InputError "FILE: byte N: expected ..." with N within
// the prefix that says where the file ends; nothing else (no crash, no other exception).
void expect_every_truncation_fails(const fs::path& model, const std::string& name, const std::string& bytes) {
  const fs::path file = model / name;
  for (std::size_t length = 0; length < bytes.size(); ++length) {
    SCOPED_TRACE(name + " cut to " + std::to_string(length) + " of " + std::to_string(bytes.size()) +
                 " bytes");
    test::write_text(file, bytes.substr(0, length));
    try {
      io::read_colmap_binary(model);
      ADD_FAILURE() << "read without error";
    } catch (const InputError& error) {
      const std::string what = error.what();
      const long long offset = byte_offset(what, file);
      EXPECT_GE(offset, 0) << what;
      EXPECT_LE(offset, static_cast<long long>(length)) << what;
      EXPECT_NE(what.find(": expected "), std::string::npos) << what;
      EXPECT_NE(what.find("the file ends at byte " + std::to_string(length)), std::string::npos) << what;
    } catch (const std::exception& error) {
      ADD_FAILURE() << "unexpected exception: " << error.what();
    }
  }
  test::write_text(file, bytes);
  EXPECT_EQ(io::read_colmap_binary(model).size(), small_images().size());
}

TEST(ColmapBinary, EveryTruncationNamesTheFileAndTheByte) {
  test::ScratchFolder folder;
  write_binary_model(folder.path(), small_cameras(), small_images());
  expect_every_truncation_fails(folder.path(), "cameras.bin", cameras_bin(small_cameras()));
  expect_every_truncation_fails(folder.path(), "images.bin", images_bin(small_images()));
}

class ColmapBinaryBadInput : public ::testing::Test {
 protected:
  void SetUp() override { write_binary_model(folder_.path(), small_cameras(), small_images()); }
  //! Writes \p bytes as \p name and expects read_colmap_binary's InputError to start with
  //! "FILE: byte OFFSET: " and to contain \p parts.
  void expect_bad(const std::string& name, const std::string& bytes, std::uint64_t offset,
                  const std::vector<std::string>& parts) {
    test::write_text(folder_ / name, bytes);
    const std::string what = expect_error<InputError>([&] { io::read_colmap_binary(folder_.path()); }, parts);
    EXPECT_EQ(byte_offset(what, folder_ / name), static_cast<long long>(offset)) << what;
    write_binary_model(folder_.path(), small_cameras(), small_images());
  }
  test::ScratchFolder folder_;
};

// Byte offsets in the small model's cameras.bin: count 0, then camera 1 at 8: id 8, model 12,
// width 16, height 24, params 32...; camera 2 at 64 (PINHOLE has 4 params).
// In images.bin: count 0, image 1 at 8: id 8, QW..QZ 12..36, TX..TZ 44..60, CAMERA_ID 68, NAME 72.
TEST_F(ColmapBinaryBadInput, HugeCountsAreRefusedBeforeAllocating) {
  std::string bytes = cameras_bin(small_cameras());
  const auto with_u64 = [](std::string b, std::size_t at, std::uint64_t v) {
    return b.replace(at, 8, Encoder().u64(v).bytes);
  };
  const std::uint64_t huge = std::numeric_limits<std::uint64_t>::max();
  expect_bad("cameras.bin", with_u64(bytes, 0, huge), 0,
             {"expected the number of cameras", "18446744073709551615", "the file ends at byte"});
  // 144 bytes after the count hold at most 3 cameras of 48 bytes.
  expect_bad("cameras.bin", with_u64(bytes, 0, 4), 0, {"number of cameras", "got 4", "hold at most 3"});
  // count × 24 overflows to a small number: still refused.
  const std::string images = images_bin(small_images());
  const std::size_t points_at = 8 + 4 + 56 + 4 + small_images()[0].name.size() + 1;
  expect_bad("images.bin", with_u64(images, points_at, 0x0AAAAAAAAAAAAAABull), points_at,
             {"expected the number of POINTS2D of image 1 of 2", "768614336404564651"});
  expect_bad("images.bin", with_u64(images, 0, huge), 0,
             {"expected the number of images", "18446744073709551615"});
  // A count too small leaves bytes over, which say so.
  const std::size_t second_image_at = images_bin({small_images()[0]}).size();  // count + image 1
  expect_bad("images.bin", with_u64(images, 0, 1), second_image_at,
             {"expected the end of the file after the 1 images", "more bytes"});
}

TEST_F(ColmapBinaryBadInput, UnknownAndUnsupportedModelIds) {
  const std::string cameras = cameras_bin(small_cameras());
  const auto with_model = [&](std::int32_t id) {
    return std::string(cameras).replace(12, 4, Encoder().i32(id).bytes);
  };
  expect_bad("cameras.bin", with_model(42), 12,
             {"unknown camera model id 42 for camera 1 of 2", "0 SIMPLE_PINHOLE, 1 PINHOLE", "4 OPENCV"});
  expect_bad("cameras.bin", with_model(-1), 12, {"unknown camera model id -1"});
  expect_bad("cameras.bin", with_model(5), 12,
             {"unsupported camera model 5 (OPENCV_FISHEYE)", "supported: 0 "});
  expect_bad("cameras.bin", with_model(6), 12, {"unsupported camera model 6 (FULL_OPENCV)"});
  expect_bad("cameras.bin", with_model(17), 12, {"unsupported camera model 17 (EQUIRECTANGULAR)"});
}

TEST_F(ColmapBinaryBadInput, NonFiniteNumbersAreNamed) {
  const std::string cameras = cameras_bin(small_cameras());
  const auto with_f64 = [](const std::string& b, std::size_t at, double v) {
    return std::string(b).replace(at, 8, Encoder().f64(v).bytes);
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  expect_bad("cameras.bin", with_f64(cameras, 32, nan), 32,
             {"expected a finite number for 'fx' of camera 1 of 2, got nan"});
  // Camera 2 (OPENCV) at 64: parameters from 64 + 24 = 88; p2 is the eighth.
  expect_bad("cameras.bin", with_f64(cameras, 88 + 7 * 8, -inf), 88 + 7 * 8,
             {"'p2' of camera 2 of 2", "got -inf"});
  const std::string images = images_bin(small_images());
  expect_bad("images.bin", with_f64(images, 12, inf), 12,
             {"finite number for QW of image 1 of 2", "got inf"});
  expect_bad("images.bin", with_f64(images, 60, nan), 60, {"finite number for TZ of image 1 of 2"});
}

TEST_F(ColmapBinaryBadInput, NamesMustEndAndNotBeEmpty) {
  // The last image's NAME runs to the end of the file without its NUL byte.
  auto images = small_images();
  images[1].points.clear();
  std::string bytes = images_bin(images);
  bytes.resize(bytes.size() - 9);  // drop the point count and the NUL
  const std::size_t name_at = bytes.size() - images[1].name.size();
  expect_bad("images.bin", bytes, name_at,
             {"expected NAME of image 2 of 2 ending in a NUL byte",
              "the file ends at byte " + std::to_string(bytes.size())});
  images[1].name.clear();
  bytes = images_bin(images);
  expect_bad("images.bin", bytes, name_at, {"expected the NAME of image 2 of 2", "empty"});
}

TEST_F(ColmapBinaryBadInput, ContentErrorsNameTheRecord) {
  auto cameras = small_cameras();
  cameras[1].id = 1;
  expect_bad("cameras.bin", cameras_bin(cameras), 64,
             {"camera 2 of 2 (CAMERA_ID 1) is defined twice", "byte 8"});
  cameras = small_cameras();
  cameras[0].params[0] = 0;
  expect_bad("cameras.bin", cameras_bin(cameras), 8, {"camera 1 of 2 (CAMERA_ID 1)", "focal"});
  cameras = small_cameras();
  cameras[1].width = 1ull << 40;
  expect_bad("cameras.bin", cameras_bin(cameras), 64 + 8,
             {"fits in an int for WIDTH of camera 2 of 2", "1099511627776"});

  auto images = small_images();
  images[1].camera_id = 9;
  const std::size_t second = images_bin({images[0]}).size();  // count + image 1
  expect_bad("images.bin", images_bin(images), second + 60,
             {"unknown CAMERA_ID 9 for image 2 of 2", "not defined in cameras.bin"});
  images = small_images();
  images[1].id = images[0].id;
  expect_bad("images.bin", images_bin(images), second,
             {"image 2 of 2 (IMAGE_ID", "used twice (first at byte 8)"});
  images = small_images();
  images[0].q = {0.5, 0.5, 0.5, 0.6};
  expect_bad("images.bin", images_bin(images), 12, {"image 1 of 2", "expected a unit quaternion", "norm"});
  images[0].q = {0, 0, 0, 0};
  expect_bad("images.bin", images_bin(images), 12, {"unit quaternion", "norm 0"});
  // Missing files are I/O errors naming what was looked for.
  fs::remove(folder_ / "images.bin");
  expect_error<IoError>([&] { io::read_colmap_binary(folder_.path()); }, {"cameras.bin and images.bin"});
}

// ---------------------------------------------------------------------------------------------
// The program

TEST(ColmapBinary, ConvertWritesBinaryThatInfoAndConvertRead) {
  test::ScratchFolder folder;
  const fs::path scene = folder / "scene";
  fs::create_directories(scene);
  for (const char* image : {"view00.png", "view01.png", "view02.png", "view03.png"})
    fs::copy_file(kDefaultScene / image, scene / image);
  const fs::path model = scene / "sparse" / "0";
  test::CommandResult r =
      test::run_mvflow("convert " + kDefaultScene.string() + " " + model.string() + " --to colmap-bin");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* file : {"cameras.bin", "images.bin", "points3D.bin"})
    EXPECT_TRUE(fs::exists(model / file)) << file;
  EXPECT_FALSE(fs::exists(model / "cameras.txt"));
  EXPECT_EQ(test::read_text(model / "points3D.bin"), std::string(8, '\0'));

  r = test::run_mvflow("info " + scene.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("cameras    4 (colmap-bin"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("4 × 80x60"), std::string::npos) << r.output;

  // Back to Middlebury: the same cameras as the original.
  r = test::run_mvflow("convert " + scene.string() + " " + (folder / "back_par.txt").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto original = io::read_middlebury(kDefaultScene / "default_par.txt");
  const auto back = io::read_middlebury(folder / "back_par.txt");
  ASSERT_EQ(back.size(), original.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].camera.K(), original[i].camera.K());
    EXPECT_LT((back[i].camera.R() - original[i].camera.R()).cwiseAbs().maxCoeff(), 1e-15);
  }

  // OUT named cameras.bin chooses the binary model without --to.
  r = test::run_mvflow("convert " + kDefaultScene.string() + " " +
                       (folder / "named" / "cameras.bin").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(io::read_colmap_binary(folder / "named").size(), 4u);

  // A text model written where a binary one is warns that the binary one is what gets read.
  r = test::run_mvflow("convert " + kDefaultScene.string() + " " + model.string() + " --to colmap");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("also holds a COLMAP colmap-bin model"), std::string::npos) << r.output;

  // A damaged binary model: exit 1 naming the file and the byte.
  const std::string images = test::read_text(model / "images.bin");
  test::write_text(model / "images.bin", images.substr(0, images.size() - 3));
  r = test::run_mvflow("info " + scene.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((model / "images.bin").string() + ": byte "), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("terminate"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mvflow
