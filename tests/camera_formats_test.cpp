// Camera file formats (io/camera_io.h): every reader is checked against an independent
// computation from the format's own definition, every writer by a write → read round trip, and
// bad input by the type and the text of its error.

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "engine/model/camera.h"
#include "engine/model/error.h"
#include "io/camera_io.h"
#include "colmap_reference.h"

namespace {

namespace fs = std::filesystem;
using mvflow::Camera;
using mvflow::Distortion;
using mvflow::DistortionModel;
using mvflow::InputError;
using mvflow::IoError;
using mvflow::View;
using mvflow::io::CameraFormat;

// ---------------------------------------------------------------------------------------------
// Helpers

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

// %.17g: the test's numbers are read back bit for bit, so the independent computations below
// use exactly the values the reader sees.
std::string g17(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

class CameraFormats : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("mvflow-camera-formats-" + std::to_string(::getpid()) + "-" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  fs::path dir_;
};

// Expects \p action to throw E whose what() contains every one of \p parts.
template <class E, class F>
void expect_error(F&& action, const std::vector<std::string>& parts) {
  try {
    action();
    ADD_FAILURE() << "no exception thrown; expected one mentioning " << parts.front();
  } catch (const E& error) {
    const std::string what = error.what();
    for (const auto& part : parts)
      EXPECT_NE(what.find(part), std::string::npos) << "'" << what << "' lacks '" << part << "'";
  }
}

// Points within 0.5 of the origin; the synthetic cameras below look at the origin from ~5 away.
std::vector<Eigen::Vector3d> test_points() {
  return {{0, 0, 0},        {0.3, -0.2, 0.1},    {-0.4, 0.25, -0.2},
          {0.1, 0.45, 0.3}, {-0.35, -0.3, 0.35}, {0.2, 0.1, -0.45}};
}

// World-to-camera rotation of a camera at \p centre looking at the origin, twisted about its axis.
Eigen::Matrix3d look_at_origin(const Eigen::Vector3d& centre, double twist) {
  const Eigen::Vector3d forward = (-centre).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d R;
  R.row(0) = right;
  R.row(1) = down;
  R.row(2) = forward;
  return Eigen::AngleAxisd(twist, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R;
}

Camera synthetic_camera(int index, double fx, double fy, double skew, const Distortion& distortion = {},
                        int width = 640, int height = 480) {
  const double angle = 0.7 + 1.3 * index;
  const Eigen::Vector3d centre(5 * std::cos(angle), 5 * std::sin(angle), 0.8 - 0.6 * index);
  const Eigen::Matrix3d R = look_at_origin(centre, 0.3 * index - 0.4);
  Eigen::Matrix3d K;
  K << fx, skew, 317.25 + index, 0, fy, 243.5 - index, 0, 0, 1;
  return Camera(K, R, -R * centre, width, height, distortion);
}

void expect_same_projections(const Camera& expected, const Camera& actual) {
  for (const auto& X : test_points()) {
    const auto a = expected.project(X);
    const auto b = actual.project(X);
    ASSERT_GT(a.depth, 0);
    EXPECT_NEAR(a.u, b.u, 1e-9 * std::max(1.0, std::abs(a.u)));
    EXPECT_NEAR(a.v, b.v, 1e-9 * std::max(1.0, std::abs(a.v)));
    EXPECT_NEAR(a.depth, b.depth, 1e-9 * a.depth);
  }
}

void expect_same_views(const std::vector<View>& expected, const std::vector<View>& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    SCOPED_TRACE("view " + std::to_string(i));
    EXPECT_EQ(expected[i].image_name, actual[i].image_name);
    expect_same_projections(expected[i].camera, actual[i].camera);
  }
}

// ---------------------------------------------------------------------------------------------
// Middlebury

// One `name K R t` line from raw numbers.
std::string middlebury_line(const std::string& name, const Eigen::Matrix3d& K, const Eigen::Matrix3d& R,
                            const Eigen::Vector3d& t) {
  std::string line = name;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) line.append(" ").append(g17(K(r, c)));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) line.append(" ").append(g17(R(r, c)));
  for (int i = 0; i < 3; ++i) line.append(" ").append(g17(t(i)));
  return line + "\n";
}

std::string valid_middlebury_line(const std::string& name = "a.png") {
  const Camera c = synthetic_camera(1, 800, 810, 0);
  return middlebury_line(name, c.K(), c.R(), c.t());
}

TEST_F(CameraFormats, MiddleburyProjectionIsKTimesRt) {
  std::vector<Eigen::Matrix3d> Ks, Rs;
  std::vector<Eigen::Vector3d> ts;
  std::string text = "3\n";
  for (int i = 0; i < 3; ++i) {
    const Camera c = synthetic_camera(i, 900 + 10 * i, 905 - 7 * i, i == 2 ? 1.5 : 0.0);
    Ks.push_back(c.K());
    Rs.push_back(c.R());
    ts.push_back(c.t());
    text += middlebury_line("view" + std::to_string(i) + ".png", c.K(), c.R(), c.t());
  }
  write_text(dir_ / "scene_par.txt", text);
  const auto views = mvflow::io::read_middlebury(dir_ / "scene_par.txt", 640, 480);
  ASSERT_EQ(views.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(views[i].image_name, "view" + std::to_string(i) + ".png");
    EXPECT_EQ(views[i].camera.width(), 640);
    EXPECT_EQ(views[i].camera.height(), 480);
    Eigen::Matrix<double, 3, 4> Rt;
    Rt << Rs[i], ts[i];
    const Eigen::Matrix<double, 3, 4> P = Ks[i] * Rt;
    for (const auto& X : test_points()) {
      const Eigen::Vector3d x = P * X.homogeneous();
      const auto p = views[i].camera.project(X);
      EXPECT_NEAR(p.u, x(0) / x(2), 1e-9 * std::abs(p.u));
      EXPECT_NEAR(p.v, x(1) / x(2), 1e-9 * std::abs(p.v));
      EXPECT_NEAR(p.depth, x(2), 1e-9 * x(2));  // K's last row is (0, 0, 1)
    }
  }
  // Without a size the views' sizes stay unknown.
  for (const auto& view : mvflow::io::read_middlebury(dir_ / "scene_par.txt")) {
    EXPECT_EQ(view.camera.width(), 0);
    EXPECT_EQ(view.camera.height(), 0);
  }
}

TEST_F(CameraFormats, MiddleburyRealDinoFile) {
  const fs::path file = fs::path(MVFLOW_SHARED_DATA) / "dinoSparseRing" / "dinoSR_par.txt";
  if (!fs::exists(file)) GTEST_SKIP() << file << " not found";
  const auto views = mvflow::io::read_middlebury(file, 640, 480);
  ASSERT_EQ(views.size(), 16u);
  // The centre of the tight bounding box given in the data set's README.
  const Eigen::Vector3d box_min(-0.061897, -0.018874, -0.057845), box_max(0.010897, 0.068227, 0.015495);
  const Eigen::Vector3d centre = 0.5 * (box_min + box_max);
  for (std::size_t i = 0; i < views.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "dinoSR%04zu.png", i + 1);
    EXPECT_EQ(views[i].image_name, name);
    const Camera& camera = views[i].camera;
    EXPECT_TRUE((-camera.R().transpose() * camera.t()).allFinite());
    EXPECT_TRUE(camera.centre().allFinite());
    const auto p = camera.project(centre);
    EXPECT_GT(p.depth, 0) << name;
    EXPECT_TRUE(camera.in_image(p.u, p.v)) << name << " projects the box centre to " << p.u << ", " << p.v;
  }
}

TEST_F(CameraFormats, MiddleburyRealTempleFileReads) {
  const fs::path file = fs::path(MVFLOW_SHARED_DATA) / "templeSparseRing" / "templeSR_par.txt";
  if (!fs::exists(file)) GTEST_SKIP() << file << " not found";
  const auto views = mvflow::io::read_middlebury(file);
  ASSERT_EQ(views.size(), 16u);
  EXPECT_EQ(views.front().image_name, "templeSR0001.png");
}

TEST_F(CameraFormats, MiddleburyNearlyOrthonormalRotationIsRepaired) {
  // A rotation perturbed by 2e-6 (like dinoSR_par.txt) is accepted; one off by 1e-2 is not.
  const Camera c = synthetic_camera(0, 800, 800, 0);
  Eigen::Matrix3d R = c.R();
  R(0, 1) += 2e-6;
  write_text(dir_ / "near_par.txt", "1\n" + middlebury_line("a.png", c.K(), R, c.t()));
  const auto views = mvflow::io::read_middlebury(dir_ / "near_par.txt");
  ASSERT_EQ(views.size(), 1u);
  EXPECT_TRUE(
      (views[0].camera.R() * views[0].camera.R().transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_TRUE(views[0].camera.R().isApprox(c.R(), 1e-5));
  R(0, 1) += 1e-2;
  write_text(dir_ / "far_par.txt", "1\n" + middlebury_line("a.png", c.K(), R, c.t()));
  expect_error<InputError>([&] { mvflow::io::read_middlebury(dir_ / "far_par.txt"); },
                           {"far_par.txt:2:", "rotation"});
}

TEST_F(CameraFormats, MiddleburyRoundTripIsExact) {
  std::vector<View> views;
  for (int i = 0; i < 4; ++i)
    views.push_back(
        {synthetic_camera(i, 1234.5678 + i, 1230.1 - i, i * 0.25), "img" + std::to_string(i) + ".png"});
  const fs::path file = dir_ / "out_par.txt";
  mvflow::io::write_middlebury(file, views);
  const auto back = mvflow::io::read_middlebury(file, 640, 480);
  expect_same_views(views, back);
  for (std::size_t i = 0; i < views.size(); ++i) {  // shortest round-trip numbers: bit-exact
    EXPECT_EQ(views[i].camera.K(), back[i].camera.K());
    EXPECT_EQ(views[i].camera.R(), back[i].camera.R());
    EXPECT_EQ(views[i].camera.t(), back[i].camera.t());
  }
}

TEST_F(CameraFormats, MiddleburyBadInput) {
  const fs::path file = dir_ / "bad_par.txt";
  const auto read = [&] { mvflow::io::read_middlebury(file); };
  const std::string name = file.string();
  const std::string good = valid_middlebury_line();

  write_text(file, "3\n" + good + good);
  expect_error<InputError>(read, {name, ":4:", "expected 3 cameras, file ends after 2"});

  std::string short_line = good.substr(0, good.rfind(' ')) + "\n";
  write_text(file, "2\n" + good + short_line);
  expect_error<InputError>(read, {name, ":3:", "expected 22 fields", "got 21"});

  auto fields = [&](int index, const std::string& token) {  // good line with field `index` replaced
    std::istringstream in(good);
    std::string out, word;
    for (int i = 0; in >> word; ++i) out += (i ? " " : "") + (i == index ? token : word);
    return out + "\n";
  };
  write_text(file, "1\n" + fields(11, "abc"));
  expect_error<InputError>(read, {name, ":2:", "expected a number for 'r12', got 'abc'"});
  write_text(file, "1\n" + fields(1, "nan"));
  expect_error<InputError>(read, {name, ":2:", "finite", "'k11'"});
  write_text(file, "1\n" + fields(21, "inf"));
  expect_error<InputError>(read, {name, ":2:", "finite", "'t3'"});
  write_text(file, "1\n" + fields(4, "0.5"));
  expect_error<InputError>(read, {name, ":2:", "upper triangular"});
  write_text(file, "1\n" + fields(10, "2"));
  expect_error<InputError>(read, {name, ":2:", "rotation"});

  write_text(file, "0\n");
  expect_error<InputError>(read, {name, ":1:", "positive number of cameras"});
  write_text(file, "\n-2\n" + good);
  expect_error<InputError>(read, {name, ":2:", "number of cameras"});
  write_text(file, "two\n" + good);
  expect_error<InputError>(read, {name, ":1:", "integer", "number of cameras"});
  write_text(file, "1 2\n" + good);
  expect_error<InputError>(read, {name, ":1:", "number of cameras alone"});
  write_text(file, "");
  expect_error<InputError>(read, {name, ":1:", "number of cameras"});
  write_text(file, "1\n" + good + good);
  expect_error<InputError>(read, {name, ":3:", "expected 1 cameras", "more"});

  expect_error<IoError>([&] { mvflow::io::read_middlebury(dir_ / "missing_par.txt"); }, {"missing_par.txt"});
}

TEST_F(CameraFormats, MiddleburyUnrepresentableWriteLeavesFileUntouched) {
  const fs::path file = dir_ / "keep_par.txt";
  write_text(file, "previous content\n");
  std::vector<View> views{
      {synthetic_camera(0, 800, 800, 0), "a.png"},
      {synthetic_camera(1, 800, 800, 0, {DistortionModel::Radial, {0.1, 0, 0, 0}}), "b.png"}};
  expect_error<InputError>([&] { mvflow::io::write_middlebury(file, views); },
                           {file.string(), "camera 1", "distortion"});
  views[1] = {synthetic_camera(1, 800, 800, 0), "has space.png"};
  expect_error<InputError>([&] { mvflow::io::write_middlebury(file, views); }, {"camera 1", "whitespace"});
  EXPECT_EQ(read_text(file), "previous content\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);  // no temporary left
}

// ---------------------------------------------------------------------------------------------
// COLMAP

// Hamilton quaternion (w, x, y, z) to rotation matrix, written out.
Eigen::Matrix3d quaternion_matrix(double w, double x, double y, double z) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  w /= n, x /= n, y /= n, z /= n;
  Eigen::Matrix3d R;
  R << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  return R;
}

struct ColmapCase {
  std::string model;
  std::vector<double> params;
};

const std::vector<ColmapCase>& colmap_cases() {
  static const std::vector<ColmapCase> cases{
      {"SIMPLE_PINHOLE", {1100.5, 320.25, 240.75}},
      {"PINHOLE", {1100.5, 1093.25, 319.5, 241.125}},
      {"SIMPLE_RADIAL", {950.0, 321.0, 239.0, -0.12}},
      {"RADIAL", {955.5, 318.5, 242.5, -0.15, 0.04}},
      {"OPENCV", {960.25, 948.75, 322.5, 236.5, -0.21, 0.07, 0.0015, -0.0022}},
  };
  return cases;
}

struct ColmapImage {
  std::vector<double> q;  // w x y z (deliberately not quite unit length)
  Eigen::Vector3d t;
};

// Images looking at the origin from ~5 away; quaternions derived from look_at_origin.
std::vector<ColmapImage> colmap_images(std::size_t count) {
  std::vector<ColmapImage> images;
  for (std::size_t i = 0; i < count; ++i) {
    const Camera c = synthetic_camera(static_cast<int>(i), 1, 1, 0);
    const Eigen::Quaterniond q(c.R());
    const double s = 1 + 1e-7 * (static_cast<double>(i) - 2);  // COLMAP normalizes; so must we
    images.push_back({{s * q.w(), s * q.x(), s * q.y(), s * q.z()}, c.t()});
  }
  return images;
}

void write_colmap_model(const fs::path& folder, const std::vector<ColmapCase>& cameras,
                        const std::vector<ColmapImage>& images) {
  fs::create_directories(folder);
  std::string text =
      "# Camera list with one line of data per camera:\n#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n";
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    text += std::to_string(i + 1) + " " + cameras[i].model + " 640 480";
    for (double p : cameras[i].params) text.append(" ").append(g17(p));
    text += "\n";
  }
  write_text(folder / "cameras.txt", text);
  text = "# Image list with two lines of data per image:\n";
  for (std::size_t i = 0; i < images.size(); ++i) {
    const auto& im = images[i];
    text += std::to_string(i + 1);
    for (double q : im.q) text.append(" ").append(g17(q));
    for (int k = 0; k < 3; ++k) text.append(" ").append(g17(im.t(k)));
    text.append(" ")
        .append(std::to_string(i % cameras.size() + 1))
        .append(" image")
        .append(std::to_string(i + 1))
        .append(".jpg\n");
    // Alternate an empty POINTS2D line and one with observations.
    text += i % 2 ? "12.5 30.25 -1 100.0 200.0 7\n" : "\n";
  }
  write_text(folder / "images.txt", text);
}

TEST_F(CameraFormats, ColmapProjectionMatchesColmapModels) {
  const auto& cases = colmap_cases();
  const auto images = colmap_images(cases.size());
  write_colmap_model(dir_, cases, images);
  const auto views = mvflow::io::read_colmap(dir_);
  ASSERT_EQ(views.size(), cases.size());
  for (std::size_t i = 0; i < views.size(); ++i) {
    SCOPED_TRACE(cases[i].model);
    EXPECT_EQ(views[i].image_name, "image" + std::to_string(i + 1) + ".jpg");
    EXPECT_EQ(views[i].camera.width(), 640);
    EXPECT_EQ(views[i].camera.height(), 480);
    const auto& q = images[i].q;
    const Eigen::Matrix3d R = quaternion_matrix(q[0], q[1], q[2], q[3]);
    for (const auto& X : test_points()) {
      const Eigen::Vector3d x = R * X + images[i].t;
      const Eigen::Vector2d colmap_pixel =
          mvflow::test::colmap_image_from_camera(cases[i].model, cases[i].params, x(0) / x(2), x(1) / x(2));
      const auto p = views[i].camera.project(X);
      // COLMAP's top-left pixel centre is (0.5, 0.5), mvflow's (0, 0).
      EXPECT_NEAR(p.u, colmap_pixel.x() - 0.5, 1e-9 * std::abs(p.u));
      EXPECT_NEAR(p.v, colmap_pixel.y() - 0.5, 1e-9 * std::abs(p.v));
      EXPECT_NEAR(p.depth, x(2), 1e-9 * x(2));
    }
  }
}

TEST_F(CameraFormats, ColmapFindsSparseFoldersAndSortsByImageId) {
  const auto images = colmap_images(3);
  write_colmap_model(dir_ / "sparse" / "0", {colmap_cases()[1]}, images);
  // Reorder images.txt: ids 3, 1, 2 with comments and blank lines between the records.
  std::string text = "# header\n\n";
  for (int id : {3, 1, 2}) {
    const auto& im = images[id - 1];
    text += std::to_string(id);
    for (double q : im.q) text.append(" ").append(g17(q));
    for (int k = 0; k < 3; ++k) text.append(" ").append(g17(im.t(k)));
    text += " 1 name" + std::to_string(id) + ".png\n\n";
    text += "# between records\n\n";
  }
  write_text(dir_ / "sparse" / "0" / "images.txt", text);
  const auto views = mvflow::io::read_colmap(dir_);
  ASSERT_EQ(views.size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(views[i].image_name, "name" + std::to_string(i + 1) + ".png");
  EXPECT_EQ(mvflow::io::read_cameras(dir_ / "sparse" / "0", CameraFormat::Colmap).size(), 3u);

  // sparse/ beats sparse/0/.
  write_colmap_model(dir_ / "sparse", {colmap_cases()[0]}, colmap_images(2));
  EXPECT_EQ(mvflow::io::read_colmap(dir_).size(), 2u);
}

TEST_F(CameraFormats, ColmapPointsLineIsAlwaysConsumed) {
  // Two images, each with an empty POINTS2D line: the empty line is the record's second line,
  // not a blank line to skip, so the next image line must not be taken for a POINTS2D line.
  write_colmap_model(dir_, {colmap_cases()[0]}, {});
  const auto images = colmap_images(2);
  std::string text;
  for (int id : {1, 2}) {
    text += std::to_string(id);
    for (double q : images[id - 1].q) text.append(" ").append(g17(q));
    for (int k = 0; k < 3; ++k) text.append(" ").append(g17(images[id - 1].t(k)));
    text += " 1 v" + std::to_string(id) + ".png\n\n";
  }
  write_text(dir_ / "images.txt", text);
  EXPECT_EQ(mvflow::io::read_colmap(dir_).size(), 2u);
  // The last record's POINTS2D line may be missing at the end of the file (COLMAP accepts it).
  write_text(dir_ / "images.txt", text.substr(0, text.size() - 1));
  EXPECT_EQ(mvflow::io::read_colmap(dir_).size(), 2u);
  // Without the POINTS2D line the second image line is read as points and rejected.
  const std::string first = text.substr(0, text.find("\n\n") + 1);
  write_text(dir_ / "images.txt", first + text.substr(first.size() + 1));
  expect_error<InputError>([&] { mvflow::io::read_colmap(dir_); }, {"images.txt:2:", "POINTS2D"});
}

TEST_F(CameraFormats, ColmapRoundTripEveryModel) {
  std::vector<View> views{
      {synthetic_camera(0, 1000, 1010, 0), "pinhole.png"},
      {synthetic_camera(1, 990, 990, 0, {DistortionModel::Radial, {-0.1, 0, 0, 0}}), "simple_radial.png"},
      {synthetic_camera(2, 980, 980, 0, {DistortionModel::Radial, {-0.1, 0.03, 0, 0}}), "radial.png"},
      {synthetic_camera(3, 970, 975, 0, {DistortionModel::Radial, {-0.12, 0.02, 0, 0}}), "radial_fx_fy.png"},
      {synthetic_camera(4, 960, 955, 0, {DistortionModel::OpenCV, {-0.2, 0.05, 0.001, -0.002}}),
       "opencv.png"},
      {synthetic_camera(5, 950, 950, 0, {DistortionModel::Radial, {0, 0, 0, 0}}), "identity.png"},
  };
  const fs::path folder = dir_ / "model";
  mvflow::io::write_colmap(folder, views);
  const auto back = mvflow::io::read_colmap(folder);
  expect_same_views(views, back);
  for (std::size_t i = 0; i < views.size(); ++i) {
    EXPECT_EQ(back[i].camera.width(), 640);
    EXPECT_EQ(back[i].camera.height(), 480);
  }
  // The chosen models, in order.
  std::istringstream cameras(read_text(folder / "cameras.txt"));
  std::vector<std::string> chosen;
  for (std::string line; std::getline(cameras, line);) {
    std::istringstream fields(line);
    std::string id, model;
    if (fields >> id >> model && id[0] != '#') chosen.push_back(model);
  }
  EXPECT_EQ(chosen,
            (std::vector<std::string>{"PINHOLE", "SIMPLE_RADIAL", "RADIAL", "OPENCV", "OPENCV", "PINHOLE"}));
  const std::string images = read_text(folder / "images.txt");
  EXPECT_NE(images.find("# Image list with two lines of data per image:"), std::string::npos);
  EXPECT_NE(images.find(" 1 pinhole.png\n\n2 "), std::string::npos);  // empty POINTS2D lines
}

TEST_F(CameraFormats, ColmapReadModelsRoundTrip) {
  // Files in each COLMAP model, read, written and read again: same projections.
  write_colmap_model(dir_ / "in", colmap_cases(), colmap_images(colmap_cases().size()));
  const auto views = mvflow::io::read_colmap(dir_ / "in");
  mvflow::io::write_colmap(dir_ / "out", views);
  expect_same_views(views, mvflow::io::read_colmap(dir_ / "out"));
}

TEST_F(CameraFormats, CrossFormatMiddleburyColmapMiddlebury) {
  std::vector<View> views;
  for (int i = 0; i < 3; ++i)
    views.push_back({synthetic_camera(i, 1500 + i, 1490 - i, 0), "v" + std::to_string(i) + ".png"});
  mvflow::io::write_middlebury(dir_ / "a_par.txt", views);
  const auto from_middlebury = mvflow::io::read_middlebury(dir_ / "a_par.txt", 640, 480);
  mvflow::io::write_colmap(dir_ / "colmap", from_middlebury);
  const auto from_colmap = mvflow::io::read_colmap(dir_ / "colmap");
  mvflow::io::write_middlebury(dir_ / "b_par.txt", from_colmap);
  const auto again = mvflow::io::read_middlebury(dir_ / "b_par.txt");
  expect_same_views(views, from_colmap);
  expect_same_views(views, again);
}

TEST_F(CameraFormats, ColmapBadInput) {
  write_colmap_model(dir_, colmap_cases(), colmap_images(2));
  const auto read = [&] { mvflow::io::read_colmap(dir_); };
  const std::string cameras = (dir_ / "cameras.txt").string();
  const std::string images = (dir_ / "images.txt").string();
  const std::string good_cameras = read_text(dir_ / "cameras.txt");
  const std::string good_images = read_text(dir_ / "images.txt");

  write_text(dir_ / "cameras.txt", good_cameras + "9 FULL_OPENCV 640 480 1 1 1 1 0 0 0 0 0 0 0 0\n");
  expect_error<InputError>(read,
                           {cameras + ":8:", "unsupported camera model 'FULL_OPENCV'", "SIMPLE_RADIAL"});
  write_text(dir_ / "cameras.txt", good_cameras + "9 PINHOLE 640 480 1 1 1\n");
  expect_error<InputError>(read, {cameras + ":8:", "expected 8 fields for PINHOLE"});
  write_text(dir_ / "cameras.txt", good_cameras + "9 PINHOLE 640 480 1 x 1 1\n");
  expect_error<InputError>(read, {cameras + ":8:", "expected a number for 'fy', got 'x'"});
  write_text(dir_ / "cameras.txt", good_cameras + "9 PINHOLE 640 480 0 1 1 1\n");
  expect_error<InputError>(read, {cameras + ":8:", "focal"});
  write_text(dir_ / "cameras.txt", good_cameras + "2 PINHOLE 640 480 1 1 1 1\n");
  expect_error<InputError>(read, {cameras + ":8:", "CAMERA_ID 2", "twice"});
  write_text(dir_ / "cameras.txt", good_cameras);

  // images.txt lines: 1 comment, then image 1 (line 2), POINTS2D (3), image 2 (4), POINTS2D (5).
  // \p text with field `field` of line `line_number` replaced by `token`.
  auto replace_in_line = [](const std::string& text, int line_number, int field, const std::string& token) {
    std::istringstream in(text);
    std::string out, line;
    for (int n = 1; std::getline(in, line); ++n) {
      if (n == line_number) {
        std::istringstream words(line);
        std::string word, joined;
        for (int i = 0; words >> word; ++i) joined += (i ? " " : "") + (i == field ? token : word);
        line = joined;
      }
      out += line + "\n";
    }
    return out;
  };
  auto replace = [&](int line_number, int field, const std::string& token) {
    return replace_in_line(good_images, line_number, field, token);
  };
  write_text(dir_ / "images.txt", replace(4, 8, "42"));
  expect_error<InputError>(read, {images + ":4:", "unknown CAMERA_ID 42"});
  std::string zero = good_images;
  for (int field = 1; field <= 4; ++field) zero = replace_in_line(zero, 2, field, "0");
  write_text(dir_ / "images.txt", zero);
  expect_error<InputError>(read, {images + ":2:", "unit quaternion"});
  write_text(dir_ / "images.txt", replace(2, 1, "2"));
  expect_error<InputError>(read, {images + ":2:", "unit quaternion"});
  write_text(dir_ / "images.txt", replace(4, 6, "nan"));
  expect_error<InputError>(read, {images + ":4:", "finite", "'TY'"});
  write_text(dir_ / "images.txt", replace(4, 7, "-inf"));
  expect_error<InputError>(read, {images + ":4:", "finite", "'TZ'"});
  write_text(dir_ / "images.txt", replace(2, 3, "abc"));
  expect_error<InputError>(read, {images + ":2:", "expected a number for 'QY', got 'abc'"});
  write_text(dir_ / "images.txt", replace(2, 9, "two words.png"));
  expect_error<InputError>(read, {images + ":2:", "expected 10 fields"});
  write_text(dir_ / "images.txt", replace(4, 0, "1"));
  expect_error<InputError>(read, {images + ":4:", "IMAGE_ID 1", "twice"});

  expect_error<IoError>([&] { mvflow::io::read_colmap(dir_ / "nowhere"); }, {"nowhere", "cameras.txt"});
}

TEST_F(CameraFormats, ColmapUnrepresentableWriteLeavesFilesUntouched) {
  const fs::path folder = dir_ / "model";
  fs::create_directories(folder);
  write_text(folder / "cameras.txt", "old cameras\n");
  write_text(folder / "images.txt", "old images\n");
  std::vector<View> views{{synthetic_camera(0, 1000, 1000, 0), "a.png"},
                          {synthetic_camera(1, 1000, 1000, 2.5), "b.png"}};
  expect_error<InputError>([&] { mvflow::io::write_colmap(folder, views); },
                           {"camera 1", "COLMAP cannot represent", "skew"});
  views[1] = {synthetic_camera(1, 1000, 1000, 0, {DistortionModel::InverseRadial, {0.1, 0, 0, 0}}), "b.png"};
  expect_error<InputError>([&] { mvflow::io::write_colmap(folder, views); },
                           {"camera 1", "COLMAP cannot represent", "inverse radial"});
  views[1] = {synthetic_camera(1, 1000, 1000, 0), "b c.png"};
  expect_error<InputError>([&] { mvflow::io::write_colmap(folder, views); }, {"camera 1", "whitespace"});
  EXPECT_EQ(read_text(folder / "cameras.txt"), "old cameras\n");
  EXPECT_EQ(read_text(folder / "images.txt"), "old images\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(folder), fs::directory_iterator()), 2);
}

// ---------------------------------------------------------------------------------------------
// PhotoModeler-style

struct PhotoRecord {
  double center[3];
  double omega, phi, kappa;  // degrees
  double sx, sy, f, ppx, ppy, k1, k2;
  int width, height;
  std::string name;
};

std::string photo_line(const PhotoRecord& p) {
  std::string line;
  for (double v : {p.center[0], p.center[1], p.center[2], p.omega, p.phi, p.kappa, p.sx, p.sy, p.f, p.ppx,
                   p.ppy, p.k1, p.k2})
    line += g17(v) + " ";
  return line + std::to_string(p.width) + " " + std::to_string(p.height) + " " + p.name + "\n";
}

// Thesis eq. 2.3's R = Rκ·Rφ·Rω from the three elementary rotations as written in §2.1's sources.
Eigen::Matrix3d thesis_rotation(double omega_deg, double phi_deg, double kappa_deg) {
  const double o = omega_deg * std::numbers::pi / 180, p = phi_deg * std::numbers::pi / 180,
               k = kappa_deg * std::numbers::pi / 180;
  Eigen::Matrix3d Ro, Rp, Rk;
  Ro << 1, 0, 0, 0, std::cos(o), std::sin(o), 0, -std::sin(o), std::cos(o);
  Rp << std::cos(p), 0, -std::sin(p), 0, 1, 0, std::sin(p), 0, std::cos(p);
  Rk << std::cos(k), std::sin(k), 0, -std::sin(k), std::cos(k), 0, 0, 0, 1;
  return Rk * Rp * Ro;
}

std::vector<PhotoRecord> photo_records() {
  return {
      {{2.5, -3.25, 10.0},
       12.5,
       -33.1,
       101.7,
       0.0064,
       0.0065,
       35.2,
       12.1,
       8.3,
       2e-4,
       -3e-7,
       3872,
       2592,
       "IMG_0001.JPG"},
      {{-4.0, 1.5, -2.0},
       -170.25,
       47.5,
       -20.0,
       0.0071,
       0.0071,
       24.0,
       10.9,
       7.2,
       -4e-4,
       6e-7,
       3008,
       2000,
       "photo two.jpg"},
      {{0.1, 0.2, 0.3}, 0.0, 0.0, 0.0, 0.005, 0.005, 50.0, 8.0, 6.0, 0.0, 0.0, 0, 0, "plain.png"},
  };
}

// World points in front of \p p's camera: camera-frame points mapped back by Pw = T + Rᵀ·Pc.
std::vector<Eigen::Vector3d> points_before(const PhotoRecord& p) {
  const Eigen::Matrix3d R = thesis_rotation(p.omega, p.phi, p.kappa);
  const Eigen::Vector3d T(p.center[0], p.center[1], p.center[2]);
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3d& Pc :
       {Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(1.2, -0.8, 6), Eigen::Vector3d(-1.5, 1.1, 7.5),
        Eigen::Vector3d(0.4, 1.3, 4.5), Eigen::Vector3d(-0.9, -1.0, 3.9)})
    points.push_back(T + R.transpose() * Pc);
  return points;
}

TEST_F(CameraFormats, PhotoModelerProjectionFollowsThesisEquations) {
  const auto records = photo_records();
  std::string text = "# centerX centerY centerZ omega phi kappa ...\n\n";
  for (const auto& r : records) text += photo_line(r);
  write_text(dir_ / "scene_pm.txt", text);
  const auto views = mvflow::io::read_photomodeler(dir_ / "scene_pm.txt");
  ASSERT_EQ(views.size(), records.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    const PhotoRecord& p = records[i];
    SCOPED_TRACE(p.name);
    EXPECT_EQ(views[i].image_name, p.name);
    EXPECT_EQ(views[i].camera.width(), p.width);
    EXPECT_EQ(views[i].camera.height(), p.height);
    const Eigen::Matrix3d R = thesis_rotation(p.omega, p.phi, p.kappa);
    const Eigen::Vector3d T(p.center[0], p.center[1], p.center[2]);
    // Principal point in pixels: mm from the image's top-left corner, which is pixel −0.5.
    const double ox = p.ppx / p.sx - 0.5, oy = p.ppy / p.sy - 0.5;
    for (const auto& Pw : points_before(p)) {
      const Eigen::Vector3d Pc = R * (Pw - T);                            // (2.3)
      const double x = p.f * Pc.x() / Pc.z(), y = p.f * Pc.y() / Pc.z();  // (2.1), (2.2)
      // (2.6), (2.7) give the true (x, y) from the observed (xd, yd): invert by fixed point.
      double xd = x, yd = y;
      for (int k = 0; k < 200; ++k) {
        const double r2 = xd * xd + yd * yd;
        const double factor = 1 + p.k1 * r2 + p.k2 * r2 * r2;
        xd = x / factor, yd = y / factor;
      }
      const double xim = ox - xd / p.sx, yim = oy - yd / p.sy;  // (2.4), (2.5) solved for the pixel
      const auto projection = views[i].camera.project(Pw);
      EXPECT_NEAR(projection.u, xim, 1e-9 * std::max(1.0, std::abs(xim)));
      EXPECT_NEAR(projection.v, yim, 1e-9 * std::max(1.0, std::abs(yim)));
      EXPECT_NEAR(projection.depth, Pc.z(), 1e-9 * Pc.z());

      // Reverse: from mvflow's pixel, apply (2.4)–(2.7) directly.
      const double xd2 = -(projection.u - ox) * p.sx, yd2 = -(projection.v - oy) * p.sy;
      const double r2 = xd2 * xd2 + yd2 * yd2;
      const double factor = 1 + p.k1 * r2 + p.k2 * r2 * r2;
      EXPECT_NEAR(xd2 * factor, x, 1e-9 * std::max(1.0, std::abs(x)));
      EXPECT_NEAR(yd2 * factor, y, 1e-9 * std::max(1.0, std::abs(y)));
    }
  }
}

TEST_F(CameraFormats, PhotoModelerRoundTrip) {
  std::vector<View> views = mvflow::io::read_photomodeler([&] {
    std::string text;
    for (const auto& r : photo_records()) text += photo_line(r);
    write_text(dir_ / "in_pm.txt", text);
    return dir_ / "in_pm.txt";
  }());
  // Plus synthetic cameras, one with inverse radial distortion, one at gimbal lock (phi = ±90°).
  views.push_back(
      {synthetic_camera(2, 1200, 1180, 0, {DistortionModel::InverseRadial, {0.08, -0.01, 0, 0}}), "syn.png"});
  {
    const Eigen::Vector3d T(0.3, -0.2, 6.0);
    const Eigen::Matrix3d R = Eigen::Vector3d(-1, -1, 1).asDiagonal() * thesis_rotation(25.0, 90.0, -40.0);
    Eigen::Matrix3d K;
    K << 1000, 0, 300, 0, 1000, 200, 0, 0, 1;
    views.push_back({Camera(K, R, -R * T, 640, 480), "lock.png"});
  }
  const fs::path file = dir_ / "out_pm.txt";
  mvflow::io::write_photomodeler(file, views);
  const auto back = mvflow::io::read_photomodeler(file);
  ASSERT_EQ(back.size(), views.size());
  for (std::size_t i = 0; i < views.size(); ++i) {
    SCOPED_TRACE(views[i].image_name);
    EXPECT_EQ(back[i].image_name, views[i].image_name);
    EXPECT_EQ(back[i].camera.width(), views[i].camera.width());
    // Points in front of this camera: its centre plus a few metres along its viewing direction.
    const Camera& c = views[i].camera;
    const Eigen::Matrix3d Rt = c.R().transpose();
    for (const Eigen::Vector3d& Pc :
         {Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(1, -0.7, 6), Eigen::Vector3d(-1.2, 0.9, 4)}) {
      const Eigen::Vector3d X = c.centre() + Rt * Pc;
      const auto a = c.project(X), b = back[i].camera.project(X);
      EXPECT_NEAR(a.u, b.u, 1e-9 * std::max(1.0, std::abs(a.u)));
      EXPECT_NEAR(a.v, b.v, 1e-9 * std::max(1.0, std::abs(a.v)));
      EXPECT_NEAR(a.depth, b.depth, 1e-9 * a.depth);
    }
  }
}

TEST_F(CameraFormats, PhotoModelerBadInput) {
  const fs::path file = dir_ / "bad_pm.txt";
  const std::string name = file.string();
  const auto read = [&] { mvflow::io::read_photomodeler(file); };
  const std::string good = photo_line(photo_records()[0]);
  auto with_field = [&](int index, const std::string& token) {
    std::istringstream in(good);
    std::string out, word;
    for (int i = 0; in >> word; ++i) out += (i ? " " : "") + (i == index ? token : word);
    return out + "\n";
  };
  write_text(file, "# comment\n" + good + "1 2 3 4 5 6 7 8 9 10 11 12 13 14 15\n");
  expect_error<InputError>(read, {name + ":3:", "expected 16 fields", "got 15"});
  write_text(file, with_field(4, "abc"));
  expect_error<InputError>(read, {name + ":1:", "expected a number for 'phi', got 'abc'"});
  write_text(file, "\n" + with_field(11, "nan"));
  expect_error<InputError>(read, {name + ":2:", "finite", "'K1'"});
  write_text(file, with_field(0, "inf"));
  expect_error<InputError>(read, {name + ":1:", "finite", "'centerX'"});
  write_text(file, with_field(6, "-0.005"));
  expect_error<InputError>(read, {name + ":1:", "positive pixelSizeX"});
  write_text(file, with_field(8, "0"));
  expect_error<InputError>(read, {name + ":1:", "positive focalLength"});
  write_text(file, with_field(13, "12.5"));
  expect_error<InputError>(read, {name + ":1:", "integer", "'imageWidth'"});
  expect_error<IoError>([&] { mvflow::io::read_photomodeler(dir_ / "missing_pm.txt"); }, {"missing_pm.txt"});
}

TEST_F(CameraFormats, PhotoModelerUnrepresentableWriteLeavesFileUntouched) {
  const fs::path file = dir_ / "keep_pm.txt";
  write_text(file, "old\n");
  const auto attempt = [&](const View& bad, const std::string& expected) {
    const std::vector<View> views{{synthetic_camera(0, 1000, 1000, 0), "ok.png"}, bad};
    expect_error<InputError>([&] { mvflow::io::write_photomodeler(file, views); },
                             {file.string(), "camera 1", expected});
  };
  attempt({synthetic_camera(1, 1000, 1000, 3.0), "b.png"}, "skew");
  attempt({synthetic_camera(1, 1000, 1000, 0, {DistortionModel::OpenCV, {0.1, 0, 0.01, 0}}), "b.png"},
          "distortion");
  attempt({synthetic_camera(1, 1000, 1000, 0, {DistortionModel::Radial, {0.1, 0, 0, 0}}), "b.png"},
          "distortion");
  attempt({synthetic_camera(1, 1000, 1000, 0), " padded.png"}, "whitespace");
  EXPECT_EQ(read_text(file), "old\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

// ---------------------------------------------------------------------------------------------
// Dispatch

TEST_F(CameraFormats, FormatNamesAndDispatch) {
  for (CameraFormat format : {CameraFormat::Middlebury, CameraFormat::Colmap, CameraFormat::PhotoModeler})
    EXPECT_EQ(mvflow::io::camera_format_from_name(mvflow::io::camera_format_name(format)), format);
  expect_error<InputError>([] { mvflow::io::camera_format_from_name("bundler"); }, {"bundler", "middlebury"});

  const std::vector<View> views{{synthetic_camera(0, 900, 900, 0), "a.png"},
                                {synthetic_camera(1, 910, 905, 0), "b.png"}};
  const std::vector<std::pair<CameraFormat, fs::path>> targets{
      {CameraFormat::Middlebury, dir_ / "x_par.txt"},
      {CameraFormat::Colmap, dir_ / "colmap"},
      {CameraFormat::PhotoModeler, dir_ / "x_pm.txt"}};
  for (const auto& [format, path] : targets) {
    SCOPED_TRACE(mvflow::io::camera_format_name(format));
    mvflow::io::write_cameras(path, views, format);
    expect_same_views(views, mvflow::io::read_cameras(path, format));
  }
}

}  // namespace
