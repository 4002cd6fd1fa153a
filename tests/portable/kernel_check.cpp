// The photo kernel on its own (the 5×5 pixel patch and surface patches), against a plain
// double-precision evaluation of SPEC §3, for every build of the kernel this CPU runs. Standalone (no GoogleTest, no oneTBB, OpenCV or Embree) so
// that tools/check_portable.sh can cross-compile it for arm64 from four engine sources and run
// it under qemu; the test suite runs the same program natively. Exits 1 on a mismatch.

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "engine/model/camera.h"
#include "engine/model/image.h"
#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_kernel.h"
#include "stages/flow/photo_views.h"
#include "stages/flow/surface_patch.h"

namespace mvflow {
namespace {

// photo_consistency.h: g within 1e-5 relative of a double-precision evaluation. The absolute
// floor only admits rounding where g is 0.
constexpr double kRelative = 1e-5;
constexpr double kAbsoluteFloor = 1e-12;

struct Scene {
  std::string name;
  std::vector<Camera> cameras;
  std::vector<Image> images;
  double extent;  // points are drawn from the cube ±extent (z within ±depth around the plane)
  double depth;
};

// A camera at \p centre looking at the origin, y down in the image.
Camera look_at(const Eigen::Vector3d& centre, double focal, int width, int height, Distortion distortion = {}) {
  const Eigen::Vector3d z = -centre.normalized();
  const Eigen::Vector3d y = (Eigen::Vector3d(0, -1, 0) - Eigen::Vector3d(0, -1, 0).dot(z) * z).normalized();
  Eigen::Matrix3d R;
  R.row(0) = y.cross(z);
  R.row(1) = y;
  R.row(2) = z;
  Eigen::Matrix3d K;
  K << focal, 0, (width - 1) / 2.0, 0, focal, (height - 1) / 2.0, 0, 0, 1;
  return Camera(K, R, -R * centre, width, height, distortion);
}

// Six cameras on an arc of radius 3 with images of uniform noise: large g, every patch different.
Scene noise_scene(std::mt19937& random, Distortion distortion, const char* name) {
  Scene scene{name, {}, {}, 0.8, 0.8};
  std::uniform_real_distribution<float> value(0, 1);
  for (int i = 0; i < 6; ++i) {
    const double a = 0.3 * i;
    scene.cameras.push_back(look_at({3 * std::sin(a), 0.4, 3 * std::cos(a)}, 60, 64, 48, distortion));
    Image image(64, 48);
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 64; ++x) image.set_pixel(x, y, {value(random), value(random), value(random)});
    scene.images.push_back(std::move(image));
  }
  return scene;
}

// Five cameras rendering a smooth colour texture on the plane z = 0: g small on the plane and
// growing off it, as on a surface being refined.
Scene plane_scene() {
  Scene scene{"textured plane", {}, {}, 0.6, 0.15};
  const auto texture = [](double x, double y) {
    return Eigen::Vector3f(static_cast<float>(0.5 + 0.25 * std::sin(7 * x + 3 * y) + 0.2 * std::cos(4.5 * y - 2 * x)),
                           static_cast<float>(0.5 + 0.3 * std::sin(3.3 * x - 6.1 * y + 1.0)),
                           static_cast<float>(0.5 + 0.2 * std::cos(5.2 * x + 4.7 * y) + 0.2 * std::sin(2.9 * y)));
  };
  for (int i = 0; i < 5; ++i) {
    const double a = 0.25 * (i - 2);
    const Camera camera = look_at({3 * std::sin(a), 0.5 * std::cos(2.0 * i), 3 * std::cos(a)}, 70, 80, 60);
    Image image(80, 60);
    for (int v = 0; v < 60; ++v)
      for (int u = 0; u < 80; ++u) {
        const Ray ray = camera.ray(u, v);
        const Eigen::Vector3d X = ray.origin - ray.origin.z() / ray.direction.z() * ray.direction;
        image.set_pixel(u, v, texture(X.x(), X.y()));
      }
    scene.cameras.push_back(camera);
    scene.images.push_back(std::move(image));
  }
  return scene;
}

// The pixel (u, v) of X in \p camera from K, R, t (and the radial model d = n·(1 + k1 r² + k2 r⁴));
// false when X is not in front of it.
bool reference_projection(const Camera& camera, const Eigen::Vector3d& X, double& u, double& v) {
  const Eigen::Vector3d c = camera.R() * X + camera.t();
  if (!(c.z() > 0)) return false;
  Eigen::Vector2d n(c.x() / c.z(), c.y() / c.z());
  if (camera.distortion().model == DistortionModel::Radial) {
    const auto& k = camera.distortion().coefficients;
    const double r2 = n.squaredNorm();
    n *= 1 + k[0] * r2 + k[1] * r2 * r2;
  }
  u = camera.K()(0, 0) * n.x() + camera.K()(0, 1) * n.y() + camera.K()(0, 2);
  v = camera.K()(1, 1) * n.y() + camera.K()(1, 2);
  return true;
}

// The bilinear value of channel ch at (u, v) in double.
double reference_bilinear(const Image& image, double u, double v, int ch) {
  const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
  const double a = u - x0, b = v - y0;
  return (1 - a) * (1 - b) * image.pixel(x0, y0)[ch] + a * (1 - b) * image.pixel(x0 + 1, y0)[ch] +
         (1 - a) * b * image.pixel(x0, y0 + 1)[ch] + a * b * image.pixel(x0 + 1, y0 + 1)[ch];
}

// SPEC §3's variance over the patches of the usable views (the two-pass formula), per point.
PhotoValue reference_variance(const std::vector<std::vector<double>>& patches, int points) {
  PhotoValue result;
  result.views = static_cast<int>(patches.size());
  if (patches.size() < 2) return result;
  const double m = static_cast<double>(patches.size());
  for (std::size_t k = 0; k < patches.front().size(); ++k) {
    double mean = 0, variance = 0;
    for (const auto& p : patches) mean += p[k] / m;
    for (const auto& p : patches) variance += (p[k] - mean) * (p[k] - mean) / (m - 1);
    result.g += variance / points;
  }
  return result;
}

// The reference: every patch value bilinear on its own in double, the variances by the two-pass
// formula.
PhotoValue reference_g(const Scene& scene, const Eigen::Vector3d& X) {
  std::vector<std::vector<double>> patches;
  for (std::size_t i = 0; i < scene.cameras.size(); ++i) {
    const Camera& camera = scene.cameras[i];
    double u, v;
    if (!reference_projection(camera, X, u, v)) continue;
    const int W = camera.width(), H = camera.height();
    if (u < 2 || v < 2 || u >= W - 3 || v >= H - 3) continue;
    const Image& image = scene.images[i];
    std::vector<double> patch;
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx)
        for (int ch = 0; ch < 3; ++ch) patch.push_back(reference_bilinear(image, u + dx, v + dy, ch));
    patches.push_back(std::move(patch));
  }
  return reference_variance(patches, 25);
}

// A surface patch laid out by hand (stages/flow/surface_patch.h's layout, without the engine
// sources that lay it out): per view in front of X a 5×5 grid of offsets 1.3 pixels apart,
// turned and squeezed by the view's own angle and factor, as an oblique view's would be.
SurfacePatchLayout hand_layout(const Scene& scene, const Eigen::Vector3d& X) {
  SurfacePatchLayout layout;
  layout.half_patch = 2;
  layout.points = 25;
  layout.padded_points = kSurfacePatchLanes * 2;
  for (std::size_t i = 0; i < scene.cameras.size(); ++i) {
    double u, v;
    if (!reference_projection(scene.cameras[i], X, u, v)) continue;
    layout.views.push_back(static_cast<std::uint16_t>(i));
    const double angle = 0.4 * static_cast<double>(i), squeeze = 1.0 - 0.12 * static_cast<double>(i);
    float bounds[4] = {1e30f, -1e30f, 1e30f, -1e30f};
    for (int b = -2; b <= 2; ++b)
      for (int a = -2; a <= 2; ++a) {
        const double x = 1.3 * a, y = 1.3 * squeeze * b;
        const auto du = static_cast<float>(std::cos(angle) * x - std::sin(angle) * y);
        const auto dv = static_cast<float>(std::sin(angle) * x + std::cos(angle) * y);
        layout.du.push_back(du);
        layout.dv.push_back(dv);
        bounds[0] = std::min(bounds[0], du), bounds[1] = std::max(bounds[1], du);
        bounds[2] = std::min(bounds[2], dv), bounds[3] = std::max(bounds[3], dv);
      }
    const float last_du = layout.du.back(), last_dv = layout.dv.back();  // the padding repeats the last point
    layout.du.resize(layout.views.size() * layout.padded_points, last_du);
    layout.dv.resize(layout.views.size() * layout.padded_points, last_dv);
    layout.bounds.insert(layout.bounds.end(), bounds, bounds + 4);
  }
  return layout;
}

// The surface patch's reference: per laid-out view, X's projection plus each offset, read in
// double; a view counts when every point's 2×2 support lies in its image.
PhotoValue reference_surface_g(const Scene& scene, const Eigen::Vector3d& X, const SurfacePatchLayout& layout) {
  std::vector<std::vector<double>> patches;
  for (std::size_t k = 0; k < layout.views.size(); ++k) {
    const Camera& camera = scene.cameras[layout.views[k]];
    double u, v;
    if (!reference_projection(camera, X, u, v)) continue;
    std::vector<double> patch;
    bool inside = true;
    for (int i = 0; i < layout.points && inside; ++i) {
      const std::size_t e = k * static_cast<std::size_t>(layout.padded_points) + static_cast<std::size_t>(i);
      const double pu = u + layout.du[e], pv = v + layout.dv[e];
      // Inside as the kernel decides it, from its float positions (surface_patch.h).
      const double x0 = std::floor(u) + std::floor(static_cast<float>(u - std::floor(u)) + layout.du[e]);
      const double y0 = std::floor(v) + std::floor(static_cast<float>(v - std::floor(v)) + layout.dv[e]);
      inside = x0 >= 0 && y0 >= 0 && x0 + 1 <= camera.width() - 1 && y0 + 1 <= camera.height() - 1;
      for (int ch = 0; ch < 3 && inside; ++ch) patch.push_back(reference_bilinear(scene.images[layout.views[k]], pu, pv, ch));
    }
    if (inside) patches.push_back(std::move(patch));
  }
  return reference_variance(patches, layout.points);
}

// As make_photo_views(cameras, images) builds them: photo_views.cpp also holds the scene
// overload, which needs oneTBB, and this program links no library but the C++ runtime.
std::vector<PhotoView> photo_views(const Scene& scene) {
  std::vector<PhotoView> views;
  for (std::size_t i = 0; i < scene.cameras.size(); ++i) {
    const Camera& camera = scene.cameras[i];
    views.push_back({&camera, &scene.images[i], camera.projection_matrix(), camera.distortion().is_identity(),
                     camera.width(), camera.height()});
  }
  return views;
}

std::vector<std::uint16_t> all_views(const std::vector<PhotoView>& views) {
  std::vector<std::uint16_t> ids(views.size());
  std::iota(ids.begin(), ids.end(), std::uint16_t{0});
  return ids;
}

// One point of the cube ±extent (z within ±depth), its coordinates drawn in a fixed order: GCC
// evaluated the arguments of Vector3d(draw(), draw(), draw()) in another order on arm64 than on
// x86-64, which gave other points there.
Eigen::Vector3d draw_point(std::mt19937& random, const Scene& scene) {
  std::uniform_real_distribution<double> lateral(-scene.extent, scene.extent), depth(-scene.depth, scene.depth);
  const double x = lateral(random);
  const double y = lateral(random);
  return {x, y, depth(random)};
}

struct Tally {
  int compared = 0, defined = 0, failed = 0;
  double worst = 0;  // largest relative difference from the reference
  // FNV-1a over the bits of every kernel value: tools/check_portable.sh compares the baseline
  // build's on arm64 with x86-64's (the same inputs need not give the same bits there: Eigen's
  // NEON products fuse multiply-adds, so the cameras' matrices may differ in the last bit).
  std::uint64_t fingerprint = 14695981039346656037ull;
  void mix(std::uint64_t word) {
    for (int byte = 0; byte < 8; ++byte) fingerprint = (fingerprint ^ ((word >> (8 * byte)) & 0xFF)) * 1099511628211ull;
  }
  void mix(const PhotoValue& value) {
    mix(std::bit_cast<std::uint64_t>(value.g));
    mix(static_cast<std::uint64_t>(value.views));
  }
};

// One kernel value against the reference: the same usable views and g within tolerance.
void compare(const PhotoValue& kernel, const PhotoValue& reference, const std::string& what, Tally& tally) {
  ++tally.compared;
  tally.mix(kernel);
  bool ok = kernel.views == reference.views;
  if (ok && reference.defined()) {
    ++tally.defined;
    const double difference = std::abs(kernel.g - reference.g);
    ok = difference <= kRelative * reference.g + kAbsoluteFloor;
    if (reference.g > 0) tally.worst = std::max(tally.worst, difference / reference.g);
  }
  if (!ok && ++tally.failed <= 5)
    std::printf("  MISMATCH %s: kernel g %.17g (%d views), reference g %.17g (%d views)\n", what.c_str(), kernel.g,
                kernel.views, reference.g, reference.views);
}

// g at \p points random points and the 6·half + 1 gradient samples at the first \p sampled of
// them, through \p build; the samples' centre must equal g(X) bit for bit.
Tally check_build(const Scene& scene, const detail::PhotoKernelBuild& build, int points, int sampled, int half) {
  const std::vector<PhotoView> views = photo_views(scene);
  const std::vector<std::uint16_t> ids = all_views(views);
  std::mt19937 random(7);  // the same points for every build
  const double spacing = 0.004;  // Δx: about a twelfth of a pixel here
  std::vector<PhotoValue> samples(6 * half + 1);
  Tally tally;
  for (int p = 0; p < points; ++p) {
    const Eigen::Vector3d X = draw_point(random, scene);
    const PhotoValue g = build.consistency(X, ids, views);
    compare(g, reference_g(scene, X), "g at point " + std::to_string(p), tally);
    const SurfacePatchLayout layout = hand_layout(scene, X);
    compare(build.surface(X, layout, views), reference_surface_g(scene, X, layout),
            "surface patch g at point " + std::to_string(p), tally);
    if (p >= sampled) continue;
    build.samples(X, spacing, half, ids, views, samples);
    ++tally.compared;
    if (samples[0].g != g.g || samples[0].views != g.views) {
      ++tally.failed;
      std::printf("  MISMATCH sample 0 at point %d is not g(X) bit for bit\n", p);
    }
    if (!g.defined()) continue;  // then only sample 0 is written
    for_each_gradient_sample(X, spacing, half, [&](std::size_t slot, const Eigen::Vector3d& point) {
      if (slot > 0)
        compare(samples[slot], reference_g(scene, point),
                "sample " + std::to_string(slot) + " (half " + std::to_string(half) + ") at point " + std::to_string(p),
                tally);
      return true;
    });
  }
  return tally;
}

// The g values of every build at the same points, bit for bit (photo_kernel.h).
int compare_builds(const Scene& scene, const std::vector<detail::PhotoKernelBuild>& builds) {
  if (builds.size() < 2) return 0;
  const std::vector<PhotoView> views = photo_views(scene);
  const std::vector<std::uint16_t> ids = all_views(views);
  std::mt19937 random(11);
  std::vector<PhotoValue> first(61), other(61);
  int differing = 0;
  for (int p = 0; p < 50; ++p) {
    const Eigen::Vector3d X = draw_point(random, scene);
    builds[0].samples(X, 0.004, 10, ids, views, first);
    const SurfacePatchLayout layout = hand_layout(scene, X);
    const PhotoValue surface = builds[0].surface(X, layout, views);
    for (std::size_t b = 1; b < builds.size(); ++b) {
      const PhotoValue other_surface = builds[b].surface(X, layout, views);
      differing += other_surface.g != surface.g || other_surface.views != surface.views;
      builds[b].samples(X, 0.004, 10, ids, views, other);
      const std::size_t written = first[0].defined() ? 61 : 1;
      for (std::size_t s = 0; s < written; ++s)
        if (first[s].g != other[s].g || first[s].views != other[s].views) ++differing;
    }
  }
  return differing;
}

const char* architecture() {
#if defined(__aarch64__)
  return "aarch64";
#elif defined(__x86_64__)
  return "x86-64";
#elif defined(__i386__)
  return "x86";
#else
  return "other";
#endif
}

int run() {
  const std::vector<detail::PhotoKernelBuild> builds = detail::photo_kernel_builds();
  std::printf("kernel_check: %s, photo kernel %s\n", architecture(), photo_kernel_summary().c_str());
  std::mt19937 random(1);
  Distortion radial;
  radial.model = DistortionModel::Radial;
  radial.coefficients = {-0.08, 0.01, 0, 0};
  const std::vector<Scene> scenes = {noise_scene(random, {}, "noise"), plane_scene(),
                                     noise_scene(random, radial, "noise, radial distortion")};
  int passed = 0, failed = 0;
  std::vector<Tally> all(builds.size());  // per build: the fingerprint over every scene
  for (const Scene& scene : scenes) {
    for (std::size_t b = 0; b < builds.size(); ++b) {
      const detail::PhotoKernelBuild& build = builds[b];
      // half 10: the 61 samples of SPEC §3; half 3: 6 per axis, not a whole number of 4 or 8 lanes.
      for (const int half : {10, 3}) {
        const Tally tally = check_build(scene, build, 200, 20, half);
        all[b].mix(tally.fingerprint);
        const bool ok = tally.failed == 0;
        (ok ? passed : failed)++;
        std::printf("%s %s, %s build, half %d: %d values (%d defined) against the double reference, "
                    "largest relative difference %.2g\n",
                    ok ? "PASS" : "FAIL", scene.name.c_str(), build.name, half, tally.compared, tally.defined,
                    tally.worst);
      }
    }
    if (builds.size() > 1) {
      const int differing = compare_builds(scene, builds);
      (differing == 0 ? passed : failed)++;
      std::printf("%s %s: %zu builds give the same bits (%d values differ)\n", differing == 0 ? "PASS" : "FAIL",
                  scene.name.c_str(), builds.size(), differing);
    }
  }
  for (std::size_t b = 0; b < builds.size(); ++b)
    std::printf("fingerprint of the %s build: %016llx\n", builds[b].name,
                static_cast<unsigned long long>(all[b].fingerprint));
  std::printf("kernel_check: %d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}

}  // namespace
}  // namespace mvflow

int main() {
  try {
    return mvflow::run();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "kernel_check: %s\n", error.what());
    return 2;
  }
}
