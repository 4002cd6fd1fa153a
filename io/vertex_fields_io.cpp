#include "io/vertex_fields_io.h"

#include <algorithm>
#include <cstdio>
#include <limits>

#include "engine/model/error.h"
#include "io/atomic_write.h"
#include "io/little_endian.h"
#include "io/number_text.h"

namespace mvflow::io {

std::string vertex_fields_file_name(int iteration) {
  char name[32];
  std::snprintf(name, sizeof name, "iteration_%04d.ply", iteration);
  return name;
}

void write_vertex_fields(const std::filesystem::path& file, const IterationVertexFields& state) {
  MVFLOW_CHECK(state.mesh != nullptr && state.fields != nullptr, "write_vertex_fields: no mesh or fields");
  const TriMesh& mesh = *state.mesh;
  const VertexFields& fields = *state.fields;
  const std::size_t n = mesh.n_vertices();
  MVFLOW_CHECK(fields.size() == n && fields.normal.size() == n && fields.visible_count.size() == n &&
                   fields.patch_kind.size() == n,
               "write_vertex_fields: the fields are not sized for the mesh");
  MVFLOW_CHECK(state.damping_scale.empty() || state.damping_scale.size() == n,
               "write_vertex_fields: the damping scales are not sized for the mesh");
  MVFLOW_CHECK(state.moving_speed.size() == n, "write_vertex_fields: the moving speeds are not sized for the mesh");
  MVFLOW_CHECK(state.moved.empty() || state.moved.size() == n,
               "write_vertex_fields: the moves are not sized for the mesh");

  std::string bytes =
      "ply\nformat binary_little_endian 1.0\ncomment mvflow per-vertex fields\ncomment "
      "iteration " +
      std::to_string(state.iteration) + "\ncomment time_step " + format_number(state.time_step) + "\nelement vertex " +
      std::to_string(n) + "\n";
  for (const char* name : {"x", "y", "z", "nx", "ny", "nz", "g", "mean_curvature", "grad_g_normal",
                           "speed_normal", "damping", "moved"})
    bytes += std::string("property double ") + name + "\n";
  bytes += "property uchar defined\nproperty uchar views\nproperty uchar patch\nelement face " +
           std::to_string(mesh.n_faces()) + "\nproperty list uchar int vertex_indices\nend_header\n";

  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  bytes.reserve(bytes.size() + n * (12 * 8 + 3) + mesh.n_faces() * 13);
  for (std::size_t v = 0; v < n; ++v) {
    const auto p = mesh.point(TriMesh::VertexHandle(static_cast<int>(v)));
    const Eigen::Vector3d& normal = fields.normal[v];
    const std::uint8_t defined = fields.defined[v];
    const double values[] = {
        p[0],
        p[1],
        p[2],
        normal.x(),
        normal.y(),
        normal.z(),
        (defined & kPhotoDefined) ? fields.photo_consistency[v] : nan,
        (defined & kCurvatureDefined) ? fields.mean_curvature[v] : nan,
        (defined & kGradientDefined) ? fields.photo_gradient[v].dot(normal) : nan,
        state.moving_speed[v],
        state.damping_scale.empty() ? 1.0 : state.damping_scale[v],
        state.moved.empty() ? 0.0 : state.moved[v],
    };
    for (const double value : values) append_little_endian(bytes, value);
    append_little_endian(bytes, defined);
    append_little_endian(bytes, static_cast<std::uint8_t>(std::min<unsigned>(fields.visible_count[v], 255u)));
    append_little_endian(bytes, static_cast<std::uint8_t>(fields.patch_kind[v]));
  }
  for (const auto& triangle : triangles_of(mesh)) {
    append_little_endian(bytes, std::uint8_t{3});
    for (const std::uint32_t corner : triangle)
      append_little_endian(bytes, static_cast<std::int32_t>(corner));
  }
  write_atomically(file, true, [&](std::ostream& out) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
}

}  // namespace mvflow::io
