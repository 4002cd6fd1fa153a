// PhotoModeler-style camera files: the parameters of the thesis's Photo class (§2.1, §B.1) as a
// plain text layout (README "Formats").
//
// Layout: lines starting with '#' (after optional whitespace) and blank lines are ignored; every
// other line is one camera with 16 whitespace-separated fields, in the order of the thesis's
// Photo constructor:
//   centerX centerY centerZ omega phi kappa pixelSizeX pixelSizeY focalLength
//   principalPointX principalPointY K1 K2 imageWidth imageHeight imageFile
// imageFile is the rest of the line (it may contain spaces; surrounding whitespace is dropped).
// Units: centre in world units; omega, phi, kappa in degrees; pixel sizes, focal length and
// principal point in mm; K1 in mm⁻², K2 in mm⁻⁴; imageWidth, imageHeight in pixels (0 = unknown).
//
// Semantics (thesis equations):
// - (2.3) Pc = R·(Pw − T), T = (centerX, centerY, centerZ), R = Rκ·Rφ·Rω with the photogrammetric
//   rotations Rω = [1 0 0; 0 cosω sinω; 0 −sinω cosω], Rφ = [cosφ 0 −sinφ; 0 1 0; sinφ 0 cosφ],
//   Rκ = [cosκ sinκ 0; −sinκ cosκ 0; 0 0 1] (about x, y, z by omega, phi, kappa).
// - (2.1, 2.2) undistorted image-plane coordinates x = f·Xc/Zc, y = f·Yc/Zc in mm, Zc > 0 in front.
// - (2.4, 2.5) pixel (xim, yim) ↔ image-plane (xd, yd) = (−(xim − ox)·sx, −(yim − oy)·sy), with
//   ox = principalPointX/sx − 0.5, oy = principalPointY/sy − 0.5: the principal point is measured
//   in mm from the top-left corner of the image, and mvflow's pixel (0,0) is the centre of the
//   top-left pixel.
// - (2.6, 2.7) (xd, yd) are the observed (distorted) coordinates; the true ones are
//   x = xd·(1 + K1 r² + K2 r⁴), y = yd·(1 + K1 r² + K2 r⁴), r² = xd² + yd².
//
// In mvflow's Camera: K = [f/sx 0 ox; 0 f/sy oy; 0 0 1], R_mvflow = diag(−1, −1, 1)·R (absorbs the
// sign flips of 2.4/2.5, so the focal lengths in K are positive), t = −R_mvflow·T, and the
// InverseRadial distortion with k1 = K1·f², k2 = K2·f⁴. Derivation: mvflow's normalized
// coordinates are n = (−Xc/Zc, −Yc/Zc) = −(x, y)/f, and its distorted ones d = −(xd, yd)/f; then
// u = (f/sx)·d.x + ox = ox − xd/sx, which is (2.4) solved for xim, and (2.6) divided by −f reads
// n = d·(1 + K1 f² |d|² + K2 f⁴ |d|⁴).
//
// The writer cannot recover the physical pixel size from a Camera (only f/sx is determined), so
// it assumes a pixel width of 5 µm: sx = 0.005 mm, f = 0.005·fx, sy = f/fy (any sx gives the same
// projection; 5 µm is a typical sensor pitch that keeps f and K1, K2 in familiar ranges).

#include <Eigen/Geometry>
#include <array>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <numbers>
#include <ostream>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/number_text.h"
#include "io/camera_io.h"
#include "io/text_reader.h"

namespace mvflow::io {

namespace {

constexpr std::size_t field_count = 16;
// clang-format off
constexpr std::array<const char*, field_count> field_names{
    "centerX", "centerY", "centerZ", "omega", "phi", "kappa",
    "pixelSizeX", "pixelSizeY", "focalLength", "principalPointX", "principalPointY",
    "K1", "K2", "imageWidth", "imageHeight", "imageFile"};
// clang-format on

// Assumed by the writer: the file needs a physical pixel size that a Camera does not carry.
constexpr double written_pixel_size_mm = 0.005;

constexpr double radians(double degrees) {
  return degrees * (std::numbers::pi / 180.0);
}
constexpr double degrees(double radians) {
  return radians * (180.0 / std::numbers::pi);
}

// R = Rκ·Rφ·Rω, the passive photogrammetric rotations (thesis eq. 2.3, [1]).
Eigen::Matrix3d rotation_from_angles(double omega, double phi, double kappa) {
  const double co = std::cos(omega), so = std::sin(omega);
  const double cp = std::cos(phi), sp = std::sin(phi);
  const double ck = std::cos(kappa), sk = std::sin(kappa);
  Eigen::Matrix3d r_omega, r_phi, r_kappa;
  r_omega << 1, 0, 0, 0, co, so, 0, -so, co;
  r_phi << cp, 0, -sp, 0, 1, 0, sp, 0, cp;
  r_kappa << ck, sk, 0, -sk, ck, 0, 0, 0, 1;
  return r_kappa * r_phi * r_omega;
}

// The inverse of rotation_from_angles, phi in [−90°, 90°]. Its third row is
// (sinφ, −cosφ·sinω, cosφ·cosω) and its first column (cosκ·cosφ, −sinκ·cosφ, sinφ). ω is read from
// the third row, and κ from what is left, Rκ = R·(Rφ·Rω)ᵀ, so that κ absorbs the error of ω near
// gimbal lock (cosφ ≈ 0, where only ω ∓ κ is determined and ω = 0 is taken).
Eigen::Vector3d angles_from_rotation(const Eigen::Matrix3d& R) {
  const double cos_phi = std::hypot(R(0, 0), R(1, 0));
  const double phi = std::atan2(R(2, 0), cos_phi);
  const double omega = cos_phi < 1e-12 ? 0.0 : std::atan2(-R(2, 1), R(2, 2));
  const Eigen::Matrix3d r_kappa = R * rotation_from_angles(omega, phi, 0.0).transpose();
  return {omega, phi, std::atan2(r_kappa(0, 1), r_kappa(0, 0))};
}

const Eigen::Matrix3d& flip_xy() {
  static const Eigen::Matrix3d flip = Eigen::Vector3d(-1, -1, 1).asDiagonal();
  return flip;
}

double parse_positive(const TextReader& reader, std::string_view token, std::size_t field) {
  const double value = parse_double(reader, token, std::string("'") + field_names[field] + "'");
  if (!(value > 0))
    reader.fail(std::string("expected a positive ") + field_names[field] + " (mm), got '" +
                std::string(token) + "'");
  return value;
}

int parse_size(const TextReader& reader, std::string_view token, std::size_t field) {
  const long long value = parse_integer(reader, token, std::string("'") + field_names[field] + "'");
  if (value > INT_MAX)
    reader.fail(std::string("expected an image size that fits in an int for ") + field_names[field]);
  return static_cast<int>(value);
}

View read_camera_line(const TextReader& reader) {
  const auto tokens = split_whitespace(reader.line());
  if (tokens.size() < field_count)
    reader.fail(
        "expected 16 fields: centerX centerY centerZ omega phi kappa pixelSizeX pixelSizeY focalLength "
        "principalPointX principalPointY K1 K2 imageWidth imageHeight imageFile, got " +
        std::to_string(tokens.size()));
  std::array<double, 13> v{};
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = parse_double(reader, tokens[i], std::string("'") + field_names[i] + "'");
  const double sx = parse_positive(reader, tokens[6], 6);
  const double sy = parse_positive(reader, tokens[7], 7);
  const double f = parse_positive(reader, tokens[8], 8);
  const int width = parse_size(reader, tokens[13], 13);
  const int height = parse_size(reader, tokens[14], 14);
  // The image file is the rest of the line: from the 16th token to the end of the last one.
  const char* name_begin = tokens[15].data();
  const char* name_end = tokens.back().data() + tokens.back().size();
  std::string name(name_begin, name_end);

  const Eigen::Vector3d T(v[0], v[1], v[2]);
  const Eigen::Matrix3d R = flip_xy() * rotation_from_angles(radians(v[3]), radians(v[4]), radians(v[5]));
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  K(0, 0) = f / sx;
  K(1, 1) = f / sy;
  K(0, 2) = v[9] / sx - 0.5;
  K(1, 2) = v[10] / sy - 0.5;
  const Distortion distortion{DistortionModel::InverseRadial,
                              {v[11] * f * f, v[12] * f * f * f * f, 0.0, 0.0}};
  try {
    return {Camera(K, R, -R * T, width, height, distortion), std::move(name)};
  } catch (const InputError& error) {
    reader.fail(error.what());
  }
}

// The thesis's K1, K2 (mm⁻², mm⁻⁴) for a camera of focal length f mm; throws when the camera's
// distortion is not the thesis's model.
std::array<double, 2> thesis_distortion(const std::filesystem::path& file, std::size_t index,
                                        const Camera& camera, double f) {
  const Distortion& d = camera.distortion();
  if (d.is_identity()) return {0.0, 0.0};
  if (d.model != DistortionModel::InverseRadial)
    throw InputError(
        file, "camera", index,
        "PhotoModeler-style files cannot represent this distortion model (only the inverse radial "
        "model of thesis eq. 2.6/2.7)");
  return {d.coefficients[0] / (f * f), d.coefficients[1] / (f * f * f * f)};
}

void check_representable(const std::filesystem::path& file, std::size_t index, const View& view) {
  const Eigen::Matrix3d& K = view.camera.K();
  const auto cannot = [&](const std::string& what) {
    return InputError(file, "camera", index, "PhotoModeler-style files cannot represent " + what);
  };
  if (K(0, 1) != 0) throw cannot("a skewed camera (K12 = " + format_number(K(0, 1)) + ")");
  if (!(K(0, 0) > 0 && K(1, 1) > 0)) throw cannot("a negative focal length");
  const auto& name = view.image_name;
  const bool padded = !name.empty() && (std::isspace(static_cast<unsigned char>(name.front())) ||
                                        std::isspace(static_cast<unsigned char>(name.back())));
  // The reader trims the name.
  if (name.empty() || padded || name.find_first_of("\r\n") != std::string::npos)
    throw cannot("an empty image name, one with a line break, or one starting or ending with whitespace ('" +
                 name + "')");
}

void write_camera_line(std::ostream& out, const std::filesystem::path& file, std::size_t index,
                       const View& view) {
  const Camera& camera = view.camera;
  const Eigen::Matrix3d& K = camera.K();
  const double sx = written_pixel_size_mm;
  const double f = sx * K(0, 0);
  const double sy = f / K(1, 1);
  const auto [k1, k2] = thesis_distortion(file, index, camera, f);
  const Eigen::Vector3d angles = angles_from_rotation(flip_xy() * camera.R());
  const Eigen::Vector3d& T = camera.centre();
  // clang-format off
  const std::array<double, 13> values{
      T.x(), T.y(), T.z(), degrees(angles[0]), degrees(angles[1]), degrees(angles[2]),
      sx, sy, f, (K(0, 2) + 0.5) * sx, (K(1, 2) + 0.5) * sy, k1, k2};
  // clang-format on
  for (double value : values) out << format_number(value) << ' ';
  out << camera.width() << ' ' << camera.height() << ' ' << view.image_name << '\n';
}

}  // namespace

std::vector<View> read_photomodeler(const std::filesystem::path& file) {
  TextReader reader(file);
  std::vector<View> views;
  while (reader.next_content_line()) views.push_back(read_camera_line(reader));
  return views;
}

void write_photomodeler(const std::filesystem::path& file, const std::vector<View>& views) {
  // Every camera is checked before the file is touched (thesis_distortion throws for a model
  // the format lacks; its value is not needed here).
  for (std::size_t i = 0; i < views.size(); ++i) {
    check_representable(file, i, views[i]);
    thesis_distortion(file, i, views[i].camera, 1.0);
  }
  write_atomically(file, false, [&](std::ostream& out) {
    out << "# PhotoModeler-style cameras (thesis §2.1, §B.1), one per line:\n"
        << "# centerX centerY centerZ omega phi kappa pixelSizeX pixelSizeY focalLength principalPointX "
           "principalPointY K1 K2 imageWidth imageHeight imageFile\n"
        << "# angles in degrees; sizes, focal length, principal point in mm (pixel size 5 um assumed); "
           "K1 in mm^-2, K2 in mm^-4\n";
    for (std::size_t i = 0; i < views.size(); ++i) write_camera_line(out, file, i, views[i]);
  });
}

}  // namespace mvflow::io
