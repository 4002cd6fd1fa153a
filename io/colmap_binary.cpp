// COLMAP binary model: cameras.bin and images.bin in the layout of COLMAP's
// reconstruction_io_binary.cc (camera_io.h spells it out). The models and conventions are
// colmap_model.h's, shared with the text model, so equivalent files give identical views.
// Every value is read through BinaryReader: errors name the file and the byte, and no count is
// trusted before the rest of the file is known to be able to hold it.

#include <algorithm>
#include <climits>
#include <cstdint>
#include <map>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/binary_reader.h"
#include "io/camera_io.h"
#include "io/colmap_model.h"
#include "io/little_endian.h"

namespace mvflow::io {

namespace {

namespace fs = std::filesystem;

using colmap::Intrinsics;
using colmap::Model;
using colmap::ModelInfo;

// The smallest records: a camera with 3 parameters; an image with a one-byte (empty) NAME and no
// points. A point is x, y and a POINT3D_ID.
constexpr std::uint64_t kMinCameraBytes = 4 + 4 + 8 + 8 + 3 * 8;
constexpr std::uint64_t kMinImageBytes = 4 + 7 * 8 + 4 + 1 + 8;
constexpr std::uint64_t kPointBytes = 8 + 8 + 8;

std::string ordinal(const char* element, std::uint64_t index, std::uint64_t count) {
  return std::string(element) + " " + std::to_string(index + 1) + " of " + std::to_string(count);
}

int read_size(BinaryReader& in, const std::string& what) {
  const std::uint64_t at = in.offset();
  const auto value = in.read<std::uint64_t>(what);
  if (value > static_cast<std::uint64_t>(INT_MAX))
    in.fail_at(at,
               "expected an image size that fits in an int for " + what + ", got " + std::to_string(value));
  return static_cast<int>(value);
}

const ModelInfo& read_model(BinaryReader& in, const std::string& camera) {
  const std::uint64_t at = in.offset();
  const auto id = in.read<std::int32_t>("the model id of " + camera);
  if (const ModelInfo* info = colmap::find_model(id)) return *info;
  const char* name = colmap::colmap_model_name(id);
  const std::string supported = " (supported: " + colmap::supported_models(true) + ")";
  if (name)
    in.fail_at(
        at, "unsupported camera model " + std::to_string(id) + " (" + name + ") for " + camera + supported);
  in.fail_at(at, "unknown camera model id " + std::to_string(id) + " for " + camera +
                     " (COLMAP defines 0 to 17)" + supported);
}

std::map<std::uint32_t, Intrinsics> read_cameras_bin(const fs::path& file) {
  BinaryReader in(file);
  const auto count = in.read<std::uint64_t>("the number of cameras");
  in.check_count(count, kMinCameraBytes, 0, "the number of cameras");
  std::map<std::uint32_t, Intrinsics> cameras;
  std::map<std::uint32_t, std::uint64_t> defined_at;
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::string camera = ordinal("camera", i, count);
    const std::uint64_t start = in.offset();
    const auto id = in.read<std::uint32_t>("CAMERA_ID of " + camera);
    const ModelInfo& info = read_model(in, camera);
    const int width = read_size(in, "WIDTH of " + camera);
    const int height = read_size(in, "HEIGHT of " + camera);
    std::vector<double> parameters;
    for (const std::string& name : colmap::parameter_names(info))
      parameters.push_back(in.read_finite("'" + name + "' of " + camera));
    const std::string where = camera + " (CAMERA_ID " + std::to_string(id) + ")";
    if (!defined_at.emplace(id, start).second)
      in.fail_at(start, where + " is defined twice (first at byte " + std::to_string(defined_at[id]) + ")");
    try {
      cameras.emplace(id, colmap::make_intrinsics(info, parameters, width, height));
    } catch (const InputError& error) {
      in.fail_at(start, where + ": " + error.what());
    }
  }
  in.expect_end("the " + std::to_string(count) + " cameras");
  return cameras;
}

std::vector<View> read_images_bin(const fs::path& file, const std::map<std::uint32_t, Intrinsics>& cameras) {
  BinaryReader in(file);
  const auto count = in.read<std::uint64_t>("the number of images");
  in.check_count(count, kMinImageBytes, 0, "the number of images");
  std::vector<std::pair<long long, View>> images;
  std::map<std::uint32_t, std::uint64_t> defined_at;
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::string image = ordinal("image", i, count);
    const std::uint64_t start = in.offset();
    const auto id = in.read<std::uint32_t>("IMAGE_ID of " + image);
    const std::string where = image + " (IMAGE_ID " + std::to_string(id) + ")";
    const std::uint64_t pose_at = in.offset();
    Eigen::Vector4d q;
    Eigen::Vector3d t;
    for (int k = 0; k < 4; ++k) q[k] = in.read_finite(std::string("Q") + "WXYZ"[k] + " of " + image);
    for (int k = 0; k < 3; ++k) t[k] = in.read_finite(std::string("T") + "XYZ"[k] + " of " + image);
    const std::uint64_t camera_at = in.offset();
    const auto camera_id = in.read<std::uint32_t>("CAMERA_ID of " + image);
    const std::uint64_t name_at = in.offset();
    std::string name = in.read_null_terminated("NAME of " + image);
    if (name.empty()) in.fail_at(name_at, "expected the NAME of " + where + ", got an empty one");
    const std::uint64_t points_at = in.offset();
    const auto points = in.read<std::uint64_t>("the number of POINTS2D of " + image);
    in.check_count(points, kPointBytes, points_at, "the number of POINTS2D of " + image);
    in.skip(points, kPointBytes, "POINTS2D of " + image);  // mvflow uses no feature points

    if (!defined_at.emplace(id, start).second)
      in.fail_at(start, where + " is used twice (first at byte " + std::to_string(defined_at[id]) + ")");
    const auto camera = cameras.find(camera_id);
    if (camera == cameras.end())
      in.fail_at(camera_at, "unknown CAMERA_ID " + std::to_string(camera_id) + " for " + where +
                                " (not defined in cameras.bin)");
    Eigen::Matrix3d R;
    try {
      R = colmap::rotation_from_quaternion(q);
    } catch (const InputError& error) {
      in.fail_at(pose_at, where + ": " + error.what());
    }
    try {
      images.emplace_back(id, View{colmap::make_camera(camera->second, R, t), std::move(name)});
    } catch (const InputError& error) {
      in.fail_at(start, where + ": " + error.what());
    }
  }
  in.expect_end("the " + std::to_string(count) + " images");
  return colmap::views_by_image_id(std::move(images));
}

void check_name(const fs::path& file, std::size_t index, const std::string& name) {
  if (name.empty() || name.find('\0') != std::string::npos)
    throw InputError(file, "camera", index,
                     "COLMAP cannot represent an empty image name or one with a NUL byte");
}

}  // namespace

std::vector<View> read_colmap_binary(const std::filesystem::path& folder) {
  for (const fs::path& model : {folder, folder / "sparse", folder / "sparse" / "0"})
    if (fs::is_regular_file(model / "cameras.bin") && fs::is_regular_file(model / "images.bin"))
      return read_images_bin(model / "images.bin", read_cameras_bin(model / "cameras.bin"));
  throw IoError(folder, "no COLMAP cameras.bin and images.bin here, in sparse/ or in sparse/0/");
}

void write_colmap_binary(const std::filesystem::path& folder, const std::vector<View>& views) {
  // Everything is checked and encoded before the first file is touched.
  if (views.size() > UINT32_MAX)
    throw InputError(folder / "images.bin", 0, "COLMAP cannot represent more than 2^32 - 1 images");
  std::vector<Model> chosen;
  for (std::size_t i = 0; i < views.size(); ++i) {
    chosen.push_back(colmap::choose_model(folder / "cameras.bin", i, views[i].camera));
    check_name(folder / "images.bin", i, views[i].image_name);
  }
  std::string cameras, images, points;
  append_little_endian<std::uint64_t>(cameras, views.size());
  append_little_endian<std::uint64_t>(images, views.size());
  for (std::size_t i = 0; i < views.size(); ++i) {
    const Camera& camera = views[i].camera;
    const auto id = static_cast<std::uint32_t>(i + 1);  // one COLMAP camera per view
    append_little_endian(cameras, id);
    append_little_endian<std::int32_t>(cameras, colmap::model_info(chosen[i]).id);
    // An unknown size (0) is written as 0, as write_colmap does.
    append_little_endian<std::uint64_t>(cameras, static_cast<std::uint64_t>(camera.width()));
    append_little_endian<std::uint64_t>(cameras, static_cast<std::uint64_t>(camera.height()));
    for (double p : colmap::model_parameters(chosen[i], camera)) append_little_endian(cameras, p);

    append_little_endian(images, id);
    const Eigen::Vector4d q = colmap::quaternion_of(camera);
    for (int k = 0; k < 4; ++k) append_little_endian(images, q[k]);
    for (int k = 0; k < 3; ++k) append_little_endian(images, camera.t()(k));
    append_little_endian(images, id);
    images.append(views[i].image_name).push_back('\0');
    append_little_endian<std::uint64_t>(images, 0);  // no POINTS2D
  }
  append_little_endian<std::uint64_t>(points, 0);  // COLMAP's reader needs the file; no points
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) throw IoError(folder, "cannot create the folder: " + error.message());
  write_atomically(folder / "cameras.bin", true, [&](std::ostream& out) { out << cameras; });
  write_atomically(folder / "images.bin", true, [&](std::ostream& out) { out << images; });
  write_atomically(folder / "points3D.bin", true, [&](std::ostream& out) { out << points; });
}

}  // namespace mvflow::io
