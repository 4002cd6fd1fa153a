// COLMAP text model: cameras.txt (`CAMERA_ID MODEL WIDTH HEIGHT PARAMS...`) and images.txt (two
// lines per image: `IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME`, then the POINTS2D line).
// The models and conventions are colmap_model.h's, shared with the binary model.
// The reader returns views sorted by IMAGE_ID (COLMAP writes images in no guaranteed order).

#include <algorithm>
#include <array>
#include <climits>
#include <map>
#include <sstream>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/number_text.h"
#include "io/camera_io.h"
#include "io/colmap_model.h"
#include "io/text_reader.h"

namespace mvflow::io {

namespace {

namespace fs = std::filesystem;

using colmap::Intrinsics;
using colmap::Model;
using colmap::ModelInfo;

int parse_size(const TextReader& reader, std::string_view token, const std::string& what) {
  const long long value = parse_integer(reader, token, what);
  if (value > INT_MAX) reader.fail("expected an image size that fits in an int for " + what);
  return static_cast<int>(value);
}

const ModelInfo& find_model(const TextReader& reader, std::string_view name) {
  if (const ModelInfo* info = colmap::find_model(name)) return *info;
  reader.fail("unsupported camera model '" + std::string(name) + "' (supported: " +
              colmap::supported_models(false) + ")");
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
  const auto names = colmap::parameter_names(info);
  std::vector<double> parameters;
  for (std::size_t i = 0; i < names.size(); ++i)
    parameters.push_back(parse_double(reader, tokens[4 + i], "'" + names[i] + "'"));
  const int width = parse_size(reader, tokens[2], "WIDTH");
  const int height = parse_size(reader, tokens[3], "HEIGHT");
  Intrinsics intrinsics;
  try {
    intrinsics = colmap::make_intrinsics(info, parameters, width, height);
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
  try {
    const Eigen::Matrix3d R = colmap::rotation_from_quaternion(q);
    return {image_id, View{colmap::make_camera(camera->second, R, t), std::string(tokens[9])}};
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
  return colmap::views_by_image_id(std::move(images));
}

void check_name(const fs::path& file, std::size_t index, const std::string& name) {
  if (name.empty() || name.find_first_of(" \t\r\n\f\v") != std::string::npos)
    throw InputError(file, "camera", index,
                     "COLMAP cannot represent an image name with whitespace, got '" + name + "'");
}

}  // namespace

std::vector<View> read_colmap(const std::filesystem::path& folder) {
  for (const fs::path& model : {folder, folder / "sparse", folder / "sparse" / "0"})
    if (fs::is_regular_file(model / "cameras.txt") && fs::is_regular_file(model / "images.txt"))
      return read_images_txt(model / "images.txt", read_cameras_txt(model / "cameras.txt"));
  throw IoError(folder, "no COLMAP cameras.txt and images.txt here, in sparse/ or in sparse/0/");
}

void write_colmap(const std::filesystem::path& folder, const std::vector<View>& views) {
  // Everything is checked and formatted before the first file is touched.
  std::vector<Model> chosen;
  for (std::size_t i = 0; i < views.size(); ++i) {
    chosen.push_back(colmap::choose_model(folder / "cameras.txt", i, views[i].camera));
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
    cameras << id << ' ' << colmap::model_info(chosen[i]).name << ' ' << camera.width() << ' '
            << camera.height();
    for (double p : colmap::model_parameters(chosen[i], camera)) cameras << ' ' << format_number(p);
    cameras << '\n';
    const Eigen::Vector4d q = colmap::quaternion_of(camera);
    images << id;
    for (int k = 0; k < 4; ++k) images << ' ' << format_number(q[k]);
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
