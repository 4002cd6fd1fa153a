#include "stages/eval/mesh_render.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <cmath>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "engine/model/parallel.h"
#include "engine/model/supersample.h"
#include "engine/model/surface_query.h"

namespace mvflow {

void MeshRenderOptions::check() const {
  require_option(supersample >= 1 && supersample <= 8, "supersample", supersample, "[1, 8]");
}

MeshRendering render_mesh(const Mesh& mesh, const Camera& camera, const MeshRenderOptions& options) {
  options.check();
  if (options.shading == MeshShading::Coloured && mesh.colors.size() != mesh.n_vertices())
    throw InputError("coloured rendering needs per-vertex colours (a PLY written by mvflow refine has them)");
  const IndexedMesh flat = to_indexed(mesh);
  const SurfaceQuery surface(flat);
  MeshRendering result{Image(camera.width(), camera.height()),
                       std::vector<float>(static_cast<std::size_t>(camera.width()) * camera.height(), 0.0f)};
  const int n = options.supersample;
  parallel::parallel_for(0, camera.height(), [&](int v) {
    for (int u = 0; u < camera.width(); ++u) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      int hits = 0;
      for_each_subpixel_ray(camera, u, v, n, [&](const Ray& ray) {
          const auto hit = surface.intersect(ray.origin, ray.direction);
          if (!hit) {
            sum += options.background;
            return;
          }
          ++hits;
          const auto& t = flat.triangles[hit->face];
          const double b1 = hit->barycentric.x(), b2 = hit->barycentric.y(), b0 = 1 - b1 - b2;
          if (options.shading == MeshShading::Coloured) {
            sum += static_cast<float>(b0) * flat.colors[t[0]] + static_cast<float>(b1) * flat.colors[t[1]] +
                   static_cast<float>(b2) * flat.colors[t[2]];
          } else {
            const Eigen::Vector3d& a = flat.positions[t[0]];
            const Eigen::Vector3d normal = (flat.positions[t[1]] - a).cross(flat.positions[t[2]] - a).normalized();
            const float light = static_cast<float>(std::abs(normal.dot(ray.direction)));
            sum += Eigen::Vector3f::Constant(0.15f + 0.85f * light);
          }
        });
      result.image.set_pixel(u, v, sum / static_cast<float>(n * n));
      result.coverage[static_cast<std::size_t>(v) * camera.width() + u] = static_cast<float>(hits) / (n * n);
    }
  });
  return result;
}

}  // namespace mvflow
