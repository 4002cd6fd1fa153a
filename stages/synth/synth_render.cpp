#include "stages/synth/synth_render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <cmath>
#include <utility>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "engine/model/parallel.h"
#include "engine/model/supersample.h"

namespace mvflow {

namespace {

// A per-row stream of standard normal numbers: SplitMix64 plus Box–Muller, so the sequence is
// the same on every platform (std::normal_distribution's is not).
class RowNoise {
 public:
  explicit RowNoise(std::uint64_t seed) : state_(seed) {}
  double next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = (static_cast<double>(bits() >> 11) + 1.0) * 0x1.0p-53;  // (0, 1]
    const double u2 = static_cast<double>(bits() >> 11) * 0x1.0p-53;
    const double r = std::sqrt(-2.0 * std::log(u1)), a = 2.0 * 3.14159265358979323846 * u2;
    spare_ = r * std::sin(a);
    has_spare_ = true;
    return r * std::cos(a);
  }

 private:
  std::uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
  std::uint64_t bits() { return state_ = mix_seed(state_, 0x5EED); }
};

}  // namespace

void RenderOptions::check() const {
  require_option(supersample >= 1 && supersample <= 8, "supersample", supersample, "[1, 8]");
  require_option(ambient >= 0, "ambient", ambient, ">= 0");
  require_option(diffuse >= 0 && ambient + diffuse <= 4, "diffuse", diffuse, ">= 0 with ambient + diffuse <= 4");
  require_option(light.allFinite() && light.norm() > 0, "light", light.transpose(), "a finite non-zero direction");
  require_option(specular >= 0 && specular <= 1, "specular", specular, "[0, 1]");
  require_option(shininess >= 1 && shininess <= 10000, "shininess", shininess, "[1, 10000]");
  require_option(noise >= 0 && noise <= 1, "noise", noise, "[0, 1]");
}

std::vector<Eigen::Vector3d> vertex_normals(const IndexedMesh& mesh) {
  std::vector<Eigen::Vector3d> normals(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.positions[t[0]];
    const Eigen::Vector3d n = (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a);  // |n| = 2·area
    for (auto v : t) normals[v] += n;
  }
  for (auto& n : normals)
    if (n.norm() > 0) n.normalize();
  return normals;
}

SynthRenderer::SynthRenderer(const IndexedMesh& mesh, SurfaceAlbedo albedo, BackgroundSphere background,
                             RenderOptions options)
    : mesh_(mesh),
      albedo_(std::move(albedo)),
      background_(std::move(background)),
      options_(options),
      light_(options.light.normalized()),
      vertex_normals_(vertex_normals(mesh)),
      query_(mesh.positions, mesh.triangles) {
  options_.check();
  if (albedo_.uv_texture) {
    if (mesh_.texcoords.size() != 3 * mesh_.triangles.size())
      throw InputError("render: UV albedo needs texture coordinates on every triangle corner");
    if (albedo_.uv_texture->empty()) throw InputError("render: the UV texture image is empty");
  } else if (!albedo_.solid) {
    throw InputError("render: no albedo (neither a solid texture nor a UV texture)");
  }
  if (options_.background == BackgroundKind::Textured && !background_.texture)
    throw InputError("render: a textured background needs a texture");
  face_normals_.reserve(mesh_.triangles.size());
  for (const auto& t : mesh_.triangles) {
    const Eigen::Vector3d& a = mesh_.positions[t[0]];
    const Eigen::Vector3d n = (mesh_.positions[t[1]] - a).cross(mesh_.positions[t[2]] - a);
    face_normals_.push_back(n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero());
  }
}

Eigen::Vector3f SynthRenderer::shade(std::uint32_t face, const Eigen::Vector2d& barycentric,
                                     const Eigen::Vector3d& eye) const {
  const auto& t = mesh_.triangles[face];
  const double u = barycentric.x(), v = barycentric.y(), w = 1.0 - u - v;
  const Eigen::Vector3d point = w * mesh_.positions[t[0]] + u * mesh_.positions[t[1]] + v * mesh_.positions[t[2]];
  Eigen::Vector3d normal = face_normals_[face];
  if (options_.smooth_shading) {
    const Eigen::Vector3d n = w * vertex_normals_[t[0]] + u * vertex_normals_[t[1]] + v * vertex_normals_[t[2]];
    if (n.norm() > 0) normal = n.normalized();
  }
  Eigen::Vector3f albedo;
  if (albedo_.uv_texture) {
    const std::size_t c = 3 * static_cast<std::size_t>(face);
    const Eigen::Vector2f uv = static_cast<float>(w) * mesh_.texcoords[c] + static_cast<float>(u) * mesh_.texcoords[c + 1] +
                               static_cast<float>(v) * mesh_.texcoords[c + 2];
    albedo = sample_uv(*albedo_.uv_texture, uv);
  } else {
    albedo = albedo_.solid->colour(point);
  }
  const double lambert = std::max(0.0, normal.dot(light_));
  Eigen::Vector3f colour = albedo * static_cast<float>(options_.ambient + options_.diffuse * lambert);
  if (options_.specular > 0 && lambert > 0) {
    const Eigen::Vector3d half = (light_ + (eye - point).normalized()).normalized();
    const double highlight = options_.specular * std::pow(std::max(0.0, normal.dot(half)), options_.shininess);
    colour.array() += static_cast<float>(highlight);
  }
  return colour;
}

Eigen::Vector3f SynthRenderer::trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
  if (const auto hit = query_.intersect(origin, direction)) return shade(hit->face, hit->barycentric, origin);
  if (options_.background == BackgroundKind::Black) return Eigen::Vector3f::Zero();
  // The camera is inside the background sphere, so the far root is the one in front of it.
  const Eigen::Vector3d o = origin - background_.centre;
  const double b = direction.dot(o), c = o.squaredNorm() - background_.radius * background_.radius;
  const double t = -b + std::sqrt(std::max(0.0, b * b - c));
  return 0.9f * background_.texture->colour(origin + t * direction);
}

void SynthRenderer::render_rows(const Camera& camera, std::size_t view_index, int first, int last,
                                Image& image) const {
  const int n = options_.supersample;
  const float weight = 1.0f / static_cast<float>(n * n);
  for (int y = first; y < last; ++y) {
    RowNoise noise(mix_seed(mix_seed(options_.seed, view_index), static_cast<std::uint64_t>(y)));
    for (int x = 0; x < image.width(); ++x) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      for_each_subpixel_ray(camera, x, y, n, [&](const Ray& ray) { sum += trace(ray.origin, ray.direction); });
      Eigen::Vector3f colour = sum * weight;
      if (options_.noise > 0)
        for (int c = 0; c < 3; ++c) colour[c] += static_cast<float>(options_.noise * noise.next());
      image.set_pixel(x, y, colour);
    }
  }
}

Image SynthRenderer::render(const Camera& camera, std::size_t view_index) const {
  MVFLOW_CHECK(camera.width() > 0 && camera.height() > 0, "render: the camera has no image size");
  Image image(camera.width(), camera.height());
  // In the caller's arena (its thread count); the image does not depend on it.
  parallel::parallel_for(tbb::blocked_range<int>(0, image.height()), [&](const tbb::blocked_range<int>& rows) {
    render_rows(camera, view_index, rows.begin(), rows.end(), image);
  });
  return image;
}

}  // namespace mvflow
