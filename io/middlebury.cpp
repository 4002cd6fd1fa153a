// Middlebury `*_par.txt` camera files (Seitz et al. 2006): the count, then one line per image
// `name k11 k12 k13 k21 k22 k23 k31 k32 k33 r11 r12 r13 r21 r22 r23 r31 r32 r33 t1 t2 t3`,
// projection K·[R|t]. The files' "image origin is top-left" is taken as mvflow's convention
// (pixel (0,0) = centre of the top-left pixel), so no half-pixel shift is applied.

#include <Eigen/LU>
#include <Eigen/SVD>
#include <array>
#include <charconv>
#include <limits>
#include <ostream>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/number_text.h"
#include "io/camera_io.h"
#include "io/text_reader.h"

namespace mvflow::io {

namespace {

constexpr std::size_t field_count = 22;
constexpr std::array<const char*, field_count> field_names{
    "name", "k11", "k12", "k13", "k21", "k22", "k23", "k31", "k32", "k33", "r11",
    "r12",  "r13", "r21", "r22", "r23", "r31", "r32", "r33", "t1",  "t2",  "t3"};

// The published files give R with ~17 digits but only approximately orthonormal
// (dinoSR_par.txt: ‖RRᵀ − I‖ ≈ 2e-6, beyond Camera's 1e-6 tolerance). A deviation up to 1e-4 is
// calibration round-off: replace R by the nearest rotation (polar decomposition via SVD).
// Deviations up to 1e-9 are left alone so that well-formed files round-trip bit for bit; larger
// ones than 1e-4 are left for Camera to reject as "not a rotation".
Eigen::Matrix3d nearly_orthonormal(const Eigen::Matrix3d& R) {
  const double deviation = (R * R.transpose() - Eigen::Matrix3d::Identity()).norm();
  if (deviation <= 1e-9 || deviation > 1e-4 || R.determinant() <= 0) return R;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

std::size_t read_count(TextReader& reader) {
  reader.require_content_line("the number of cameras");
  const auto tokens = split_whitespace(reader.line());
  if (tokens.size() != 1)
    reader.fail("expected the number of cameras alone on the first line, got " +
                std::to_string(tokens.size()) + " fields");
  const long long count = parse_integer(reader, tokens[0], "the number of cameras");
  if (count == 0) reader.fail("expected a positive number of cameras, got 0");
  return static_cast<std::size_t>(count);
}

View read_camera_line(const TextReader& reader, int width, int height) {
  const auto tokens = split_whitespace(reader.line());
  if (tokens.size() != field_count)
    reader.fail("expected 22 fields: name k11..k33 r11..r33 t1..t3, got " + std::to_string(tokens.size()));
  std::array<double, field_count> values{};
  for (std::size_t i = 1; i < field_count; ++i)
    values[i] = parse_double(reader, tokens[i], std::string("'") + field_names[i] + "'");
  Eigen::Matrix3d K, R;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) {
      K(row, col) = values[1 + 3 * row + col];
      R(row, col) = values[10 + 3 * row + col];
    }
  const Eigen::Vector3d t(values[19], values[20], values[21]);
  try {
    return {Camera(K, nearly_orthonormal(R), t, width, height), std::string(tokens[0])};
  } catch (const InputError& error) {
    reader.fail(error.what());
  }
}

void check_representable(const std::filesystem::path& file, std::size_t index, const View& view) {
  if (!view.camera.distortion().is_identity())
    throw InputError(file, "camera", index, "Middlebury files cannot represent lens distortion");
  const auto& name = view.image_name;
  // A name starting with '#' would read back as a comment line.
  if (name.empty() || name.front() == '#' || name.find_first_of(" \t\r\n\f\v") != std::string::npos)
    throw InputError(
        file, "camera", index,
        "Middlebury files need an image name without whitespace (not starting with '#'), got '" + name + "'");
}

}  // namespace

std::vector<View> read_middlebury(const std::filesystem::path& file, int width, int height) {
  MVFLOW_CHECK(width >= 0 && height >= 0, "read_middlebury: negative image size");
  TextReader reader(file);
  const std::size_t count = read_count(reader);
  std::vector<View> views;
  views.reserve(std::min<std::size_t>(count, 4096));  // the count is untrusted input
  while (views.size() < count) {
    if (!reader.next_content_line())
      throw InputError(
          file, reader.line_number() + 1,
          "expected " + std::to_string(count) + " cameras, file ends after " + std::to_string(views.size()));
    views.push_back(read_camera_line(reader, width, height));
  }
  if (reader.next_content_line())
    reader.fail("expected " + std::to_string(count) + " cameras as the first line says, found more lines");
  return views;
}

void write_middlebury(const std::filesystem::path& file, const std::vector<View>& views) {
  for (std::size_t i = 0; i < views.size(); ++i) check_representable(file, i, views[i]);
  write_atomically(file, false, [&](std::ostream& out) {
    out << views.size() << '\n';
    for (const View& view : views) {
      const Camera& camera = view.camera;
      out << view.image_name;
      for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) out << ' ' << format_number(camera.K()(row, col));
      for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) out << ' ' << format_number(camera.R()(row, col));
      for (int i = 0; i < 3; ++i) out << ' ' << format_number(camera.t()(i));
      out << '\n';
    }
  });
}

}  // namespace mvflow::io
