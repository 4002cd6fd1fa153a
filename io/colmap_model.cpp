#include "io/colmap_model.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "engine/model/error.h"
#include "io/camera_io.h"
#include "io/number_text.h"

namespace mvflow::io {

namespace colmap {

const ModelInfo& model_info(Model model) {
  return *std::find_if(kModels.begin(), kModels.end(), [&](const ModelInfo& m) { return m.model == model; });
}

const ModelInfo* find_model(std::string_view name) {
  for (const ModelInfo& info : kModels)
    if (name == info.name) return &info;
  return nullptr;
}

const ModelInfo* find_model(int id) {
  for (const ModelInfo& info : kModels)
    if (id == info.id) return &info;
  return nullptr;
}

const char* colmap_model_name(int id) {
  // COLMAP's CameraModelId values (src/colmap/sensor/models.h), so that a model mvflow does not
  // read is refused by name.
  // clang-format off
  static constexpr std::array<const char*, 18> names{
      "SIMPLE_PINHOLE", "PINHOLE", "SIMPLE_RADIAL", "RADIAL", "OPENCV",                   // 0-4
      "OPENCV_FISHEYE", "FULL_OPENCV", "FOV", "SIMPLE_RADIAL_FISHEYE", "RADIAL_FISHEYE",  // 5-9
      "THIN_PRISM_FISHEYE", "RAD_TAN_THIN_PRISM_FISHEYE", "SIMPLE_DIVISION", "DIVISION",  // 10-13
      "SIMPLE_FISHEYE", "FISHEYE", "EUCM", "EQUIRECTANGULAR"};                            // 14-17
  // clang-format on
  return id >= 0 && id < static_cast<int>(names.size()) ? names[static_cast<std::size_t>(id)] : nullptr;
}

std::string supported_models(bool ids) {
  std::string text;
  for (const ModelInfo& info : kModels) {
    if (!text.empty()) text += ", ";
    if (ids) text += std::to_string(info.id) + " ";
    text += info.name;
  }
  return text;
}

std::vector<std::string> parameter_names(const ModelInfo& info) {
  std::vector<std::string> names;
  std::istringstream words(info.parameters);
  for (std::string name; words >> name;) names.push_back(name);
  return names;
}

Intrinsics make_intrinsics(const ModelInfo& info, const std::vector<double>& p, int width, int height) {
  MVFLOW_CHECK(p.size() == info.parameter_count, "make_intrinsics: wrong parameter count");
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
  result.width = width;
  result.height = height;
  // The camera checks K and the distortion; a reader reports its message where the camera was.
  make_camera(result, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  return result;
}

Eigen::Matrix3d rotation_from_quaternion(const Eigen::Vector4d& wxyz) {
  const double norm = wxyz.norm();
  if (norm == 0 || std::abs(norm - 1) > 1e-3)
    throw InputError("expected a unit quaternion QW QX QY QZ, got one of norm " + format_number(norm));
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized().toRotationMatrix();
}

Camera make_camera(const Intrinsics& in, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  return Camera(in.K, R, t, in.width, in.height, in.distortion);
}

Model choose_model(const std::filesystem::path& file, std::size_t index, const Camera& camera) {
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

std::vector<double> model_parameters(Model model, const Camera& camera) {
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

Eigen::Vector4d quaternion_of(const Camera& camera) {
  Eigen::Quaterniond q(camera.R());
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // the same rotation
  return {q.w(), q.x(), q.y(), q.z()};
}

std::vector<View> views_by_image_id(std::vector<std::pair<long long, View>> images) {
  std::sort(images.begin(), images.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<View> views;
  views.reserve(images.size());
  for (auto& image : images) views.push_back(std::move(image.second));
  return views;
}

}  // namespace colmap

std::optional<ColmapModel> find_colmap_model(const std::filesystem::path& folder) {
  std::error_code error;
  const auto has = [&](const std::filesystem::path& candidate, const char* cameras, const char* images) {
    return std::filesystem::is_regular_file(candidate / cameras, error) &&
           std::filesystem::is_regular_file(candidate / images, error);
  };
  for (const auto& candidate : {folder, folder / "sparse", folder / "sparse" / "0"}) {
    // COLMAP's own rule in one folder: the binary model before the text one.
    if (has(candidate, "cameras.bin", "images.bin"))
      return ColmapModel{candidate, CameraFormat::ColmapBinary};
    if (has(candidate, "cameras.txt", "images.txt")) return ColmapModel{candidate, CameraFormat::Colmap};
  }
  return std::nullopt;
}

}  // namespace mvflow::io
