#include "stages/eval/heldout_error.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "engine/model/error.h"
#include "engine/model/mesh_stats.h"
#include "engine/model/option_check.h"
#include "engine/model/parallel.h"
#include "engine/model/supersample.h"

namespace mvflow {

void HeldoutOptions::check() const {
  require_option(supersample >= 1 && supersample <= 8, "supersample", supersample, "[1, 8]");
  require_option(background.allFinite() && background.minCoeff() >= 0.0f && background.maxCoeff() <= 1.0f,
                 "background", background.transpose(), "R G B in [0, 1]");
  check_member(colouring, "colouring");
}

double HeldoutMetrics::mae() const {
  return scored_pixels == 0 ? std::numeric_limits<double>::quiet_NaN() : sum_absolute / (3.0 * scored_pixels);
}

double HeldoutMetrics::mse() const {
  return scored_pixels == 0 ? std::numeric_limits<double>::quiet_NaN() : sum_squared / (3.0 * scored_pixels);
}

double HeldoutMetrics::psnr() const {
  const double e = mse();
  if (std::isnan(e)) return e;
  return e == 0.0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(1.0 / e);
}

double HeldoutMetrics::silhouette_disagreement() const {
  return union_pixels == 0 ? 0.0
                           : static_cast<double>(disagreeing_pixels) / static_cast<double>(union_pixels);
}

HeldoutMetrics& HeldoutMetrics::operator+=(const HeldoutMetrics& other) {
  union_pixels += other.union_pixels;
  disagreeing_pixels += other.disagreeing_pixels;
  unseen_pixels += other.unseen_pixels;
  scored_pixels += other.scored_pixels;
  sum_absolute += other.sum_absolute;
  sum_squared += other.sum_squared;
  return *this;
}

HeldoutMetrics compare_with_photograph(const HeldoutRendering& rendering, const Image& photograph,
                                       const Mask& real_silhouette) {
  const int w = photograph.width(), h = photograph.height();
  const std::size_t pixels = static_cast<std::size_t>(w) * h;
  MVFLOW_CHECK(rendering.image.width() == w && rendering.image.height() == h,
               "rendering and photograph differ in size");
  MVFLOW_CHECK(rendering.silhouette.width == w && rendering.silhouette.height == h &&
                   rendering.unseen.size() == pixels,
               "rendered silhouette or unseen flags differ in size from the photograph");
  MVFLOW_CHECK(real_silhouette.width == w && real_silhouette.height == h,
               "real silhouette differs in size from the photograph");
  HeldoutMetrics m;
  const float* rendered = rendering.image.data();
  const float* real = photograph.data();
  for (std::size_t i = 0; i < pixels; ++i) {
    const bool in_rendered = rendering.silhouette.inside[i] != 0, in_real = real_silhouette.inside[i] != 0;
    if (!in_rendered && !in_real) continue;
    ++m.union_pixels;
    if (in_rendered != in_real) ++m.disagreeing_pixels;
    if (rendering.unseen[i]) {
      ++m.unseen_pixels;
      continue;
    }
    ++m.scored_pixels;
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(rendered[3 * i + c]) - static_cast<double>(real[3 * i + c]);
      m.sum_absolute += std::abs(d);
      m.sum_squared += d * d;
    }
  }
  return m;
}

namespace {

// An error about the scene, naming its camera file when it came from one.
InputError scene_error(const Scene& scene, const std::string& message) {
  return scene.camera_file.empty() ? InputError(message) : InputError(scene.camera_file, 0, message);
}

// The held-out list, checked against the scene before anything expensive happens.
std::vector<int> checked_held_out(const Scene& scene, std::vector<int> held_out,
                                  const HeldoutOptions& options) {
  options.check();
  if (held_out.empty()) throw InputError("no held-out view given");
  const int count = static_cast<int>(scene.size());
  for (int view : held_out)
    if (view < 0 || view >= count)
      throw scene_error(scene, "held-out view " + std::to_string(view) + " does not exist (the scene has " +
                                   std::to_string(count) + " views, 0.." + std::to_string(count - 1) + ")");
  std::sort(held_out.begin(), held_out.end());
  const auto twice = std::adjacent_find(held_out.begin(), held_out.end());
  if (twice != held_out.end())
    throw InputError("held-out view " + std::to_string(*twice) + " is listed twice");
  if (held_out.size() == scene.size())
    throw scene_error(scene, "every view is held out: no view is left to colour the mesh with");
  return held_out;
}

std::vector<Eigen::Vector3d> face_normals(const IndexedMesh& mesh) {
  std::vector<Eigen::Vector3d> normals;
  normals.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.positions[t[0]];
    const Eigen::Vector3d n = (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a);
    const double length = n.norm();
    normals.push_back(length > 0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero());
  }
  return normals;
}

}  // namespace

namespace {

// The mesh as flat arrays, refusing what cannot be rendered (the caller names the file).
IndexedMesh checked_mesh(const Mesh& mesh) {
  if (mesh.n_faces() == 0) throw InputError("the mesh to score has no faces");
  IndexedMesh flat = to_indexed(mesh);
  for (std::size_t v = 0; v < flat.positions.size(); ++v)
    if (!flat.positions[v].allFinite())
      throw InputError("the mesh to score has a non-finite coordinate at vertex " + std::to_string(v));
  return flat;
}

}  // namespace

HeldoutRenderer::HeldoutRenderer(const Scene& scene, const Mesh& mesh, std::vector<int> held_out,
                                 const HeldoutOptions& options)
    : scene_(scene),
      held_out_(checked_held_out(scene, std::move(held_out), options)),
      options_(options),
      flat_(checked_mesh(mesh)),
      face_normals_(face_normals(flat_)),
      mean_edge_(edge_lengths(mesh.topology).mean),
      surface_(flat_) {
  // The colouring views are every view not held out: the one place that decides it.
  for (int i = 0; i < static_cast<int>(scene.size()); ++i) {
    if (std::binary_search(held_out_.begin(), held_out_.end(), i)) continue;
    const Camera& camera = scene.views[static_cast<std::size_t>(i)].camera;
    const Image& image = scene.image(static_cast<std::size_t>(i));
    if (image.width() != camera.width() || image.height() != camera.height())
      throw InputError(scene.views[static_cast<std::size_t>(i)].image_name, 0,
                       "the image's size differs from its camera's");
    colouring_indices_.push_back(i);
    colouring_views_.push_back({&camera, &image, camera.projection_matrix(),
                                camera.distortion().is_identity(), camera.width(), camera.height()});
  }
}

HeldoutRendering HeldoutRenderer::render(int view) const {
  MVFLOW_CHECK(std::binary_search(held_out_.begin(), held_out_.end(), view),
               "view " + std::to_string(view) + " is not held out, so it may not be scored");
  const Camera& camera = scene_.views[static_cast<std::size_t>(view)].camera;
  const int w = camera.width(), h = camera.height();
  HeldoutRendering r{Image(w, h), Mask(w, h), std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h, 0)};
  const int n = options_.supersample;
  const int rays = n * n;

  const auto render_row = [&](int y) {
    for (int x = 0; x < w; ++x) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      int valued = 0, hits = 0, unseen = 0;
      for_each_subpixel_ray(camera, x, y, n, [&](const Ray& ray) {
          const auto hit = surface_.intersect(ray.origin, ray.direction);
          if (!hit) {
            sum += options_.background;
            ++valued;
            return;
          }
          ++hits;
          const auto& t = flat_.triangles[hit->face];
          const double b1 = hit->barycentric.x(), b2 = hit->barycentric.y();
          // The point from the triangle's own positions: on its plane, up to rounding.
          const Eigen::Vector3d point =
              (1 - b1 - b2) * flat_.positions[t[0]] + b1 * flat_.positions[t[1]] + b2 * flat_.positions[t[2]];
          // The side the held-out camera sees, whatever the face's orientation.
          Eigen::Vector3d normal = face_normals_[hit->face];
          if (normal.dot(ray.direction) > 0) normal = -normal;
          const PointColour c =
              colour_surface_point(point, normal, colouring_views_, surface_, mean_edge_, options_.colouring);
          if (c.views == 0) {
            ++unseen;
            return;
          }
          sum += c.colour;
          ++valued;
        });
      const std::size_t index = static_cast<std::size_t>(y) * w + x;
      r.silhouette.inside[index] = 2 * hits >= rays;
      r.unseen[index] = 2 * unseen >= rays;
      r.image.set_pixel(x, y,
                        r.unseen[index] || valued == 0 ? options_.background : Eigen::Vector3f(sum / valued));
    }
  };
  parallel::parallel_for(0, h, render_row);  // in the caller's arena: the result does not depend on it
  return r;
}

namespace {

// Dark blue → red → yellow as t goes 0 → 0.5 → 1.
Eigen::Vector3f error_colour(double t) {
  t = std::clamp(t, 0.0, 1.0);
  const Eigen::Vector3f blue(0.0f, 0.0f, 0.35f), red(1.0f, 0.0f, 0.0f), yellow(1.0f, 1.0f, 0.0f);
  if (t < 0.5) return blue + static_cast<float>(2 * t) * (red - blue);
  return red + static_cast<float>(2 * t - 1) * (yellow - red);
}

}  // namespace

Image heldout_panel(const Image& photograph, const HeldoutRendering& rendering, const Mask& real_silhouette,
                    double error_scale) {
  MVFLOW_CHECK(error_scale > 0, "the error scale must be positive");
  const int w = photograph.width(), h = photograph.height();
  MVFLOW_CHECK(rendering.image.width() == w && rendering.image.height() == h && real_silhouette.width == w &&
                   real_silhouette.height == h && rendering.unseen.size() == static_cast<std::size_t>(w) * h,
               "the panel's images differ in size");
  const Eigen::Vector3f magenta(1.0f, 0.0f, 1.0f);
  Image panel(3 * w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const Eigen::Vector3f real = photograph.pixel(x, y), rendered = rendering.image.pixel(x, y);
      panel.set_pixel(x, y, real);
      panel.set_pixel(w + x, y, rendering.unseen[i] ? magenta : rendered);
      Eigen::Vector3f error = Eigen::Vector3f::Zero();
      if (rendering.unseen[i])
        error = magenta;
      else if (rendering.silhouette.inside[i] || real_silhouette.inside[i])
        error = error_colour((rendered - real).cwiseAbs().mean() / error_scale);
      panel.set_pixel(2 * w + x, y, error);
    }
  return panel;
}

}  // namespace mvflow
