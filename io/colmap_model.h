#pragma once
// COLMAP's camera models and conventions, shared by the text model (colmap.cpp) and the binary
// model (colmap_binary.cpp) so that equivalent files give identical cameras. Internal to mvflow_io.
//
// Conventions converted here:
// - the quaternion (QW, QX, QY, QZ) is Hamilton and maps world to camera, like mvflow's R;
// - COLMAP puts the centre of the top-left pixel at (0.5, 0.5), mvflow at (0, 0): cx = cx_colmap − 0.5;
// - COLMAP's distortion models act on normalized coordinates exactly like mvflow's Radial
//   (SIMPLE_RADIAL, RADIAL) and OpenCV (OPENCV) models.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "engine/model/camera.h"

namespace mvflow::io::colmap {

//! The camera models mvflow reads and writes.
enum class Model { SimplePinhole, Pinhole, SimpleRadial, Radial, OpenCV };

struct ModelInfo {
  Model model;
  int id;                       //!< COLMAP's CameraModelId, the number cameras.bin stores
  const char* name;             //!< COLMAP's model name, the word cameras.txt stores
  const char* parameters;       //!< parameter names in COLMAP's order, for error messages
  std::size_t parameter_count;  //!< the number of names in `parameters`
};

inline constexpr std::array<ModelInfo, 5> kModels{{
    {Model::SimplePinhole, 0, "SIMPLE_PINHOLE", "f cx cy", 3},
    {Model::Pinhole, 1, "PINHOLE", "fx fy cx cy", 4},
    {Model::SimpleRadial, 2, "SIMPLE_RADIAL", "f cx cy k", 4},
    {Model::Radial, 3, "RADIAL", "f cx cy k1 k2", 5},
    {Model::OpenCV, 4, "OPENCV", "fx fy cx cy k1 k2 p1 p2", 8},
}};

const ModelInfo& model_info(Model model);
//! The supported model named \p name, or nullptr.
const ModelInfo* find_model(std::string_view name);
//! The supported model with COLMAP id \p id, or nullptr.
const ModelInfo* find_model(int id);
//! COLMAP's name for any model id it defines (0 SIMPLE_PINHOLE … 17 EQUIRECTANGULAR), or nullptr.
const char* colmap_model_name(int id);
//! "SIMPLE_PINHOLE, PINHOLE, ..." or, with \p ids, "0 SIMPLE_PINHOLE, 1 PINHOLE, ...".
std::string supported_models(bool ids);
//! The names in info.parameters, in order.
std::vector<std::string> parameter_names(const ModelInfo& info);

//! Intrinsics of one COLMAP camera, already in mvflow's pixel convention.
struct Intrinsics {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Distortion distortion;
  int width = 0;
  int height = 0;
};

//! \param parameters info.parameter_count values in COLMAP's order and pixel convention
//! \throw InputError (without a file) when the camera is invalid (e.g. a zero focal length);
//! readers add where it was.
Intrinsics make_intrinsics(const ModelInfo& info, const std::vector<double>& parameters, int width,
                           int height);
//! The rotation of a unit quaternion (QW, QX, QY, QZ), normalized first as COLMAP does.
//! \throw InputError (without a file) when its norm is 0 or differs from 1 by more than 1e-3.
Eigen::Matrix3d rotation_from_quaternion(const Eigen::Vector4d& wxyz);
//! The view's camera. \throw InputError (without a file) as Camera's constructor does.
Camera make_camera(const Intrinsics& intrinsics, const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

//! The COLMAP model that represents \p camera: PINHOLE, SIMPLE_RADIAL, RADIAL or OPENCV.
//! \throw InputError naming \p file and camera \p index for a skewed camera or the inverse radial model.
Model choose_model(const std::filesystem::path& file, std::size_t index, const Camera& camera);
//! The parameters of \p camera in \p model, COLMAP's order and pixel convention.
std::vector<double> model_parameters(Model model, const Camera& camera);
//! (QW, QX, QY, QZ) of camera.R(), with QW ≥ 0: one sign for reproducible files.
Eigen::Vector4d quaternion_of(const Camera& camera);

//! The views of (IMAGE_ID, view) pairs in IMAGE_ID order, COLMAP's order for both file kinds.
std::vector<View> views_by_image_id(std::vector<std::pair<long long, View>> images);

}  // namespace mvflow::io::colmap
