// COLMAP text model: cameras.txt (`CAMERA_ID MODEL WIDTH HEIGHT PARAMS...`) and images.txt (two
// lines per image: `IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME`, then the POINTS2D line).
//
// Conventions converted here:
// - the quaternion (QW, QX, QY, QZ) is Hamilton and maps world to camera, like mvflow's R;
// - COLMAP puts the centre of the top-left pixel at (0.5, 0.5), mvflow at (0, 0): cx = cx_colmap − 0.5;
// - COLMAP's distortion models act on normalized coordinates exactly like mvflow's Radial
//   (SIMPLE_RADIAL, RADIAL) and OpenCV (OPENCV) models.
// The reader returns views sorted by IMAGE_ID (COLMAP writes images in no guaranteed order).

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <charconv>
#include <climits>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>

#include "engine/error.h"
#include "io/atomic_write.h"
#include "io/number_text.h"
#include "io/camera_io.h"
#include "io/text_reader.h"

namespace mvflow::io {

namespace {

namespace fs = std::filesystem;

// The camera models mvflow reads, with COLMAP's parameter order.
enum class Model { SimplePinhole, Pinhole, SimpleRadial, Radial, OpenCV };

struct ModelInfo {
  Model model;
  const char* name;
  const char* parameters;  // for error messages
  std::size_t parameter_count;
};

constexpr std::array<ModelInfo, 5> models{{
    {Model::SimplePinhole, "SIMPLE_PINHOLE", "f cx cy", 3},
    {Model::Pinhole, "PINHOLE", "fx fy cx cy", 4},
    {Model::SimpleRadial, "SIMPLE_RADIAL", "f cx cy k", 4},
    {Model::Radial, "RADIAL", "f cx cy k1 k2", 5},
    {Model::OpenCV, "OPENCV", "fx fy cx cy k1 k2 p1 p2", 8},
}};

const ModelInfo& model_info(Model model) {
  return *std::find_if(models.begin(), models.end(), [&](const ModelInfo& m) { return m.model == model; });
}

// Intrinsics of one COLMAP camera, already in mvflow's pixel convention.
struct Intrinsics {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Distortion distortion;
  int width = 0;
  int height = 0;
};

int parse_size(const TextReader& reader, std::string_view token, const std::string& what) {
  const long long value = parse_integer(reader, token, what);
  if (value > INT_MAX) reader.fail("expected an image size that fits in an int for " + what);
  return static_cast<int>(value);
}

const ModelInfo& find_model(const TextReader& reader, std::string_view name) {
  for (const ModelInfo& info : models)
    if (name == info.name) return info;
  reader.fail("unsupported camera model '" + std::string(name) +
              "' (supported: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV)");
}

Intrinsics intrinsics_from(const ModelInfo& info, const std::vector<double>& p) {
  Intrinsics result;
  const bool one_focal =
      info.model == Model::SimplePinhole || info.model == Model::SimpleRadial || info.model == Model::Radial;
  const std::size_t c = one_focal ? 1 : 2;  // index of cx
  result.K(0, 0) = p[0];
  result.K(1, 1) = one_focal ? p[0] : p[1];
  result.K(0, 2) = p[c] - 0.5;
  result.K(1, 2) = p[c + 1] - 0.5;
  switch (info.model) {
    case Model::SimplePinhole:
    case Model::Pinhole:
      break;
    case Model::SimpleRadial:
      result.distortion = {DistortionModel::Radial, {p[3], 0.0, 0.0, 0.0}};
      break;
    case Model::Radial:
      result.distortion = {DistortionModel::Radial, {p[3], p[4], 0.0, 0.0}};
      break;
    case Model::OpenCV:
      result.distortion = {DistortionModel::OpenCV, {p[4], p[5], p[6], p[7]}};
      break;
  }
  return result;
}

// One line of cameras.txt; the intrinsics are validated here so errors name this line.
std::pair<long long, Intrinsics> read_camera_line(const TextReader& reader) {
  const auto tokens = split_whitespace(reader.line());
  if (tokens.size() < 4)
    reader.fail("expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS..., got " + std::to_string(tokens.size()) +
                " fields");
  const long long id = parse_integer(reader, tokens[0], "CAMERA_ID");
  const ModelInfo& info = find_model(reader, tokens[1]);
  if (tokens.size() != 4 + info.parameter_count)
    reader.fail("expected " + std::to_string(4 + info.parameter_count) + " fields for " + info.name +
                ": CAMERA_ID MODEL WIDTH HEIGHT " + info.parameters + ", got " +
                std::to_string(tokens.size()));
  std::vector<double> parameters;
  std::istringstream names(info.parameters);
  for (std::size_t i = 4; i < tokens.size(); ++i) {
    std::string name;
    names >> name;
    parameters.push_back(parse_double(reader, tokens[i], "'" + name + "'"));
  }
  Intrinsics intrinsics = intrinsics_from(info, parameters);
  intrinsics.width = parse_size(reader, tokens[2], "WIDTH");
  intrinsics.height = parse_size(reader, tokens[3], "HEIGHT");
  try {
    Camera(intrinsics.K, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), intrinsics.width,
           intrinsics.height, intrinsics.distortion);
  } catch (const InputError& error) {
    reader.fail(error.what());
  }
  return {id, intrinsics};
}

std::map<long long, Intrinsics> read_cameras_txt(const fs::path& file) {
  TextReader reader(file);
  std::map<long long, Intrinsics> cameras;
  std::map<long long, std::size_t> defined_on;
  while (reader.next_content_line()) {
    auto [id, intrinsics] = read_camera_line(reader);
    if (!defined_on.emplace(id, reader.line_number()).second)
      reader.fail("CAMERA_ID " + std::to_string(id) + " is defined twice (first on line " +
                  std::to_string(defined_on[id]) + ")");
    cameras.emplace(id, intrinsics);
  }
  return cameras;
}

Eigen::Matrix3d rotation_from_quaternion(const TextReader& reader, const Eigen::Vector4d& wxyz) {
  const double norm = wxyz.norm();
  if (norm == 0 || std::abs(norm - 1) > 1e-3)
    reader.fail("expected a unit quaternion QW QX QY QZ, got one of norm " + format_number(norm));
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized().toRotationMatrix();
}

// The image line at the reader's current line; the POINTS2D line is consumed by the caller.
std::pair<long long, View> read_image_line(const TextReader& reader,
                                           const std::map<long long, Intrinsics>& cameras) {
  const auto tokens = split_whitespace(reader.line());
  if (tokens.size() != 10)
    reader.fail("expected 10 fields: IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME (no spaces in NAME), got " +
                std::to_string(tokens.size()));
  const long long image_id = parse_integer(reader, tokens[0], "IMAGE_ID");
  Eigen::Vector4d q;
  Eigen::Vector3d t;
  constexpr std::array<const char*, 7> names{"QW", "QX", "QY", "QZ", "TX", "TY", "TZ"};
  for (int i = 0; i < 4; ++i) q[i] = parse_double(reader, tokens[1 + i], std::string("'") + names[i] + "'");
  for (int i = 0; i < 3; ++i)
    t[i] = parse_double(reader, tokens[5 + i], std::string("'") + names[4 + i] + "'");
  const long long camera_id = parse_integer(reader, tokens[8], "CAMERA_ID");
  const auto camera = cameras.find(camera_id);
  if (camera == cameras.end())
    reader.fail("unknown CAMERA_ID " + std::to_string(camera_id) + " (not defined in cameras.txt)");
  const Intrinsics& in = camera->second;
  const Eigen::Matrix3d R = rotation_from_quaternion(reader, q);
  try {
    return {image_id, View{Camera(in.K, R, t, in.width, in.height, in.distortion), std::string(tokens[9])}};
  } catch (const InputError& error) {
    reader.fail(error.what());
  }
}

// COLMAP's images.txt has exactly two lines per image; the second (POINTS2D) may be empty and is
// read raw, never skipped as a blank line. Comments and blank lines only come before an image line.
std::vector<View> read_images_txt(const fs::path& file, const std::map<long long, Intrinsics>& cameras) {
  TextReader reader(file);
  std::vector<std::pair<long long, View>> images;
  std::map<long long, std::size_t> defined_on;
  while (reader.next_content_line()) {
    auto image = read_image_line(reader, cameras);
    if (!defined_on.emplace(image.first, reader.line_number()).second)
      reader.fail("IMAGE_ID " + std::to_string(image.first) + " is used twice (first on line " +
                  std::to_string(defined_on[image.first]) + ")");
    images.push_back(std::move(image));
    // The POINTS2D line; COLMAP tolerates its absence after the last image, and so does this.
    if (reader.next_line() && split_whitespace(reader.line()).size() % 3 != 0)
      reader.fail(
          "expected the POINTS2D line (X Y POINT3D_ID triples, possibly empty) after the image line, got " +
          std::to_string(split_whitespace(reader.line()).size()) + " fields");
  }
  std::sort(images.begin(), images.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<View> views;
  views.reserve(images.size());
  for (auto& image : images) views.push_back(std::move(image.second));
  return views;
}

std::optional<fs::path> model_folder(const fs::path& folder) {
  for (const fs::path& candidate : {folder, folder / "sparse", folder / "sparse" / "0"})
    if (fs::is_regular_file(candidate / "cameras.txt") && fs::is_regular_file(candidate / "images.txt"))
      return candidate;
  return std::nullopt;
}

// The COLMAP model for one view; throws when COLMAP cannot represent the camera.
Model choose_model(const fs::path& file, std::size_t index, const Camera& camera) {
  const auto cannot = [&](const std::string& what) {
    return InputError(file, "camera", index, "COLMAP cannot represent " + what);
  };
  if (camera.K()(0, 1) != 0) throw cannot("a skewed camera (K12 = " + format_number(camera.K()(0, 1)) + ")");
  const Distortion& d = camera.distortion();
  if (d.is_identity()) return Model::Pinhole;
  const bool square = camera.K()(0, 0) == camera.K()(1, 1);
  switch (d.model) {
    case DistortionModel::None:
      return Model::Pinhole;
    case DistortionModel::Radial:
      if (!square) return Model::OpenCV;  // OPENCV with p1 = p2 = 0 is the same radial model
      return d.coefficients[1] == 0 ? Model::SimpleRadial : Model::Radial;
    case DistortionModel::OpenCV:
      return Model::OpenCV;
    case DistortionModel::InverseRadial:
      break;
  }
  throw cannot("the inverse radial distortion model (thesis eq. 2.6/2.7)");
}

std::vector<double> colmap_parameters(Model model, const Camera& camera) {
  const Eigen::Matrix3d& K = camera.K();
  const double cx = K(0, 2) + 0.5, cy = K(1, 2) + 0.5;
  const auto& k = camera.distortion().coefficients;
  switch (model) {
    case Model::SimplePinhole:
      return {K(0, 0), cx, cy};
    case Model::Pinhole:
      return {K(0, 0), K(1, 1), cx, cy};
    case Model::SimpleRadial:
      return {K(0, 0), cx, cy, k[0]};
    case Model::Radial:
      return {K(0, 0), cx, cy, k[0], k[1]};
    case Model::OpenCV:
      if (camera.distortion().model == DistortionModel::Radial)
        return {K(0, 0), K(1, 1), cx, cy, k[0], k[1], 0, 0};
      return {K(0, 0), K(1, 1), cx, cy, k[0], k[1], k[2], k[3]};
  }
  return {};
}

void check_name(const fs::path& file, std::size_t index, const std::string& name) {
  if (name.empty() || name.find_first_of(" \t\r\n\f\v") != std::string::npos)
    throw InputError(file, "camera", index,
                     "COLMAP cannot represent an image name with whitespace, got '" + name + "'");
}

}  // namespace

std::vector<View> read_colmap(const std::filesystem::path& folder) {
  const auto model = model_folder(folder);
  if (!model) throw IoError(folder, "no COLMAP cameras.txt and images.txt here, in sparse/ or in sparse/0/");
  return read_images_txt(*model / "images.txt", read_cameras_txt(*model / "cameras.txt"));
}

void write_colmap(const std::filesystem::path& folder, const std::vector<View>& views) {
  // Everything is checked and formatted before the first file is touched.
  std::vector<Model> chosen;
  for (std::size_t i = 0; i < views.size(); ++i) {
    chosen.push_back(choose_model(folder / "cameras.txt", i, views[i].camera));
    check_name(folder / "images.txt", i, views[i].image_name);
  }
  std::ostringstream cameras, images;
  cameras << "# Camera list with one line of data per camera:\n"
          << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
          << "# Number of cameras: " << views.size() << '\n';
  images << "# Image list with two lines of data per image:\n"
         << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
         << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
         << "# Number of images: " << views.size() << ", mean observations per image: 0\n";
  for (std::size_t i = 0; i < views.size(); ++i) {
    const Camera& camera = views[i].camera;
    const std::size_t id = i + 1;
    // An unknown size (0) is written as 0: mvflow reads it back as unknown; COLMAP itself needs it.
    cameras << id << ' ' << model_info(chosen[i]).name << ' ' << camera.width() << ' ' << camera.height();
    for (double p : colmap_parameters(chosen[i], camera)) cameras << ' ' << format_number(p);
    cameras << '\n';
    Eigen::Quaterniond q(camera.R());
    if (q.w() < 0) q.coeffs() = -q.coeffs();  // the same rotation; one sign for reproducible files
    images << id << ' ' << format_number(q.w()) << ' ' << format_number(q.x()) << ' ' << format_number(q.y()) << ' '
           << format_number(q.z());
    for (int k = 0; k < 3; ++k) images << ' ' << format_number(camera.t()(k));
    images << ' ' << id << ' ' << views[i].image_name << "\n\n";  // empty POINTS2D line
  }
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) throw IoError(folder, "cannot create the folder: " + error.message());
  write_atomically(folder / "cameras.txt", false, [&](std::ostream& out) { out << cameras.str(); });
  write_atomically(folder / "images.txt", false, [&](std::ostream& out) { out << images.str(); });
}

}  // namespace mvflow::io
