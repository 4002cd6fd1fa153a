// Visibility, photo consistency g and its Savitzky–Golay gradient, against independent slow
// implementations and analytic scenes rendered in the test.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <ranges>
#include <string>

#include "engine/model/primitives.h"
#include "engine/model/surface_query.h"
#include "stages/flow/image_denoise.h"
#include "stages/flow/normals.h"
#include "stages/flow/photo_consistency.h"
#include "stages/flow/photo_gradient.h"
#include "stages/flow/photo_kernel.h"
#include "stages/flow/surface_patch.h"
#include "engine/model/option_check.h"
#include "stages/synth/synth_scene.h"
#include "stages/flow/visibility.h"
#include "photo_reference.h"
#include "test_support.h"

namespace mvflow {
namespace {

using test::pointers;
using test::slow_photo_consistency;
using test::slow_surface_patch_consistency;

// A smooth colour texture on the plane z = 0 (period ≈ 9–20 world units = pixels here).
Eigen::Vector3f plane_texture(double x, double y) {
  return {static_cast<float>(0.5 + 0.25 * std::sin(0.7 * x + 0.3 * y) + 0.2 * std::cos(0.45 * y - 0.2 * x)),
          static_cast<float>(0.5 + 0.3 * std::sin(0.33 * x - 0.61 * y + 1.0)),
          static_cast<float>(0.5 + 0.2 * std::cos(0.52 * x + 0.47 * y) + 0.2 * std::sin(0.29 * y))};
}

// A camera at \p centre looking at \p target (y down in the image).
Camera look_at(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, double focal, int width, int height) {
  const Eigen::Vector3d z = (target - centre).normalized();
  Eigen::Vector3d down = Eigen::Vector3d(0, -1, 0) - Eigen::Vector3d(0, -1, 0).dot(z) * z;
  if (down.norm() < 1e-6) down = Eigen::Vector3d(0, 0, -1) - Eigen::Vector3d(0, 0, -1).dot(z) * z;
  const Eigen::Vector3d y = down.normalized();
  const Eigen::Vector3d x = y.cross(z);
  Eigen::Matrix3d R;
  R.row(0) = x;
  R.row(1) = y;
  R.row(2) = z;
  Eigen::Matrix3d K;
  K << focal, 0, (width - 1) / 2.0, 0, focal, (height - 1) / 2.0, 0, 0, 1;
  return Camera(K, R, -R * centre, width, height);
}

// Renders the textured plane z = 0 by casting each pixel's ray.
Image render_plane(const Camera& camera) {
  Image image(camera.width(), camera.height());
  for (int v = 0; v < camera.height(); ++v)
    for (int u = 0; u < camera.width(); ++u) {
      const Ray ray = camera.ray(u, v);
      const double t = -ray.origin.z() / ray.direction.z();
      const Eigen::Vector3d X = ray.origin + t * ray.direction;
      image.set_pixel(u, v, plane_texture(X.x(), X.y()));
    }
  return image;
}



// Cameras on an arc of radius 3 around the origin, \p step radians apart at height \p height,
// looking at it (focal 60, 64×48), each with an image of uniform noise drawn from \p random.
struct RandomRig {
  std::vector<Camera> cameras;
  std::vector<Image> images;
};

RandomRig random_rig(int count, double step, double height, std::mt19937& random) {
  std::uniform_real_distribution<float> value(0, 1);
  RandomRig rig;
  for (int i = 0; i < count; ++i) {
    const double a = step * i;
    rig.cameras.push_back(look_at({3 * std::sin(a), height, 3 * std::cos(a)}, {0, 0, 0}, 60, 64, 48));
    Image image(64, 48);
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 64; ++x) image.set_pixel(x, y, {value(random), value(random), value(random)});
    rig.images.push_back(std::move(image));
  }
  return rig;
}

// A random unit normal: a surface patch's tangent plane at any tilt.
Eigen::Vector3d random_normal(std::mt19937& random) {
  std::normal_distribution<double> gaussian;
  Eigen::Vector3d N(gaussian(random), gaussian(random), gaussian(random));
  return N.normalized();
}

// photo_consistency against the slow reference at \p trials random points of the cube ±\p extent
// with the (2·half_patch + 1)² patch, all views of \p rig: the same usable views and g within 1e-6
// relative. Returns the largest relative difference; \p compared counts the points with defined g.
double compare_with_slow_reference(const RandomRig& rig, double extent, int trials, int half_patch,
                                   std::mt19937& random, int& compared) {
  const auto views = make_photo_views(rig.cameras, pointers(rig.images));
  std::vector<std::uint16_t> all(rig.cameras.size());
  std::iota(all.begin(), all.end(), std::uint16_t{0});
  std::uniform_real_distribution<double> coordinate(-extent, extent);
  double worst = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const Eigen::Vector3d X(coordinate(random), coordinate(random), coordinate(random));
    const PhotoValue fast = photo_consistency(X, all, views, {.half_patch = half_patch});
    const PhotoValue slow = slow_photo_consistency(X, rig.cameras, rig.images, all, half_patch);
    EXPECT_EQ(fast.views, slow.views) << "half patch " << half_patch;
    if (fast.views != slow.views || !slow.defined()) continue;
    ++compared;
    EXPECT_NEAR(fast.g, slow.g, 1e-6 * slow.g) << "half patch " << half_patch;
    worst = std::max(worst, std::abs(fast.g - slow.g) / slow.g);
  }
  return worst;
}

TEST(PhotoConsistency, EqualsSlowReferenceOnRandomImages) {
  std::mt19937 random(17);
  const RandomRig rig = random_rig(5, 0.4, 0.5, random);
  int compared = 0;
  const double worst = compare_with_slow_reference(rig, 0.8, 200, 2, random, compared);
  EXPECT_GT(compared, 150);
  // Measured: 2.3e-7 (the patch values interpolated in float and summed in float on shifted data;
  // 6e-8 with double sums, 1.3e-14 when they were interpolated in double).
  std::printf("[measured] largest relative difference from the slow reference: %.2g\n", worst);
}

TEST(PhotoConsistency, OtherPatchSizesEqualTheSlowReference) {
  std::mt19937 random(23);
  const RandomRig rig = random_rig(4, 0.5, 0.3, random);
  double worst = 0;
  int compared = 0;
  for (int h : {1, 3, 7}) worst = std::max(worst, compare_with_slow_reference(rig, 0.6, 60, h, random, compared));
  EXPECT_GT(compared, 60);
  std::printf("[measured] patches 3x3, 7x7, 15x15: largest relative difference from the slow reference %.2g\n", worst);
}

TEST(PhotoConsistency, EveryInstructionSetBuildGivesTheSameBits) {
  // The multiversioned 5×5 kernel: baseline, AVX2 and AVX-512 builds on random images and points.
  std::mt19937 random(5);
  const auto [cameras, images] = random_rig(6, 0.35, 0.4, random);
  const auto views = make_photo_views(cameras, pointers(images));
  const std::vector<std::uint16_t> all{0, 1, 2, 3, 4, 5};
  const auto builds = detail::photo_kernel_builds();
  std::printf("[measured] kernel builds this CPU runs:");
  for (const auto& build : builds) std::printf(" %s", build.name);
  std::printf("\n");
  std::uniform_real_distribution<double> coordinate(-0.8, 0.8);
  int defined = 0;
  std::vector<PhotoValue> reference_samples(61), samples(61);
  SurfacePatchLayout layout;
  int surface_defined = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::Vector3d X(coordinate(random), coordinate(random), coordinate(random));
    // The surface patch kernel too, laid out at X and read at a gradient sample beside it, with
    // patches of 3×3 up to 15×15 points (225, padded to 240).
    layout_surface_patch(X, random_normal(random), all, views, std::array{1, 2, 3, 7}[trial % 4], 1.5, layout);
    const Eigen::Vector3d beside = X + Eigen::Vector3d(-0.004, 0.002, 0.003);
    const PhotoValue surface = builds.front().surface(beside, layout, views);
    surface_defined += surface.defined();
    for (const auto& build : builds | std::views::drop(1)) {
      const PhotoValue other = build.surface(beside, layout, views);
      EXPECT_EQ(other.views, surface.views) << build.name;
      EXPECT_EQ(other.g, surface.g) << build.name;  // exact
    }
    const PhotoValue reference = builds.front().consistency(X, all, views);
    defined += reference.defined();
    builds.front().samples(X, 0.01, 10, all, views, reference_samples);
    if (reference.defined()) {
      EXPECT_EQ(reference_samples[0].g, reference.g);  // the centre, same bits
    }
    for (const auto& build : builds | std::views::drop(1)) {  // every other build against the baseline
      const PhotoValue other = build.consistency(X, all, views);
      EXPECT_EQ(other.views, reference.views) << build.name;
      EXPECT_EQ(other.g, reference.g) << build.name;  // exact
      build.samples(X, 0.01, 10, all, views, samples);
      for (std::size_t k = 0; k < (reference.defined() ? samples.size() : 1); ++k) {
        EXPECT_EQ(samples[k].views, reference_samples[k].views) << build.name;
        EXPECT_EQ(samples[k].g, reference_samples[k].g) << build.name;
      }
    }
  }
  EXPECT_GT(defined, 200);
  EXPECT_GT(surface_defined, 150);
  if (builds.size() < 2) GTEST_SKIP() << "only the baseline build runs on this CPU: nothing to compare it with";
}

TEST(PhotoConsistency, EveryBuildGivesTheSameBitsBeyondItsStackBuffers) {
  // More than 64 views and more than 32 samples per axis: the kernel's per-view buffers and its
  // sums move to the heap (a std::vector of AVX2 sums once came out 16-byte aligned there and
  // faulted); its tables of 32 + kLanes entries (offsets, totals) stay on the stack (34 samples
  // fill the baseline's exactly).
  std::mt19937 random(8);
  const auto [cameras, images] = random_rig(70, 0.09, 0.4, random);
  const auto views = make_photo_views(cameras, pointers(images));
  std::vector<std::uint16_t> all(cameras.size());
  std::iota(all.begin(), all.end(), std::uint16_t{0});
  const auto builds = detail::photo_kernel_builds();
  std::uniform_real_distribution<double> coordinate(-0.5, 0.5);
  constexpr int half = 17;
  std::vector<PhotoValue> reference(6 * half + 1), samples(6 * half + 1);
  SurfacePatchLayout layout;
  int defined = 0, surface_defined = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d X(coordinate(random), coordinate(random), coordinate(random));
    builds.front().samples(X, 0.004, half, all, views, reference);
    defined += reference[0].defined();
    layout_surface_patch(X, random_normal(random), all, views, 2, 1.5, layout);  // 70 views: heap buffers
    const PhotoValue surface = builds.front().surface(X, layout, views);
    surface_defined += surface.defined();
    for (const auto& build : builds | std::views::drop(1)) {
      const PhotoValue other = build.surface(X, layout, views);
      EXPECT_EQ(other.views, surface.views) << build.name;
      EXPECT_EQ(other.g, surface.g) << build.name;
    }
    EXPECT_EQ(reference[0].g, builds.front().consistency(X, all, views).g);
    for (const auto& build : builds | std::views::drop(1)) {
      build.samples(X, 0.004, half, all, views, samples);
      for (std::size_t k = 0; k < (reference[0].defined() ? samples.size() : 1); ++k) {
        EXPECT_EQ(samples[k].views, reference[k].views) << build.name;
        EXPECT_EQ(samples[k].g, reference[k].g) << build.name;
      }
    }
  }
  EXPECT_GT(defined, 15);
  EXPECT_GT(surface_defined, 10);
  if (builds.size() < 2) GTEST_SKIP() << "only the baseline build runs on this CPU: nothing to compare it with";
}

TEST(PhotoConsistency, VanishesForWholePixelTranslations) {
  // Fronto-parallel plane z = 0, cameras at height 100 with f = 100 (one world unit is one pixel
  // on the plane), centres apart by whole units: the images are exact shifts of each other.
  std::vector<Camera> cameras;
  std::vector<Image> images;
  Eigen::Matrix3d R = Eigen::Vector3d(1, -1, -1).asDiagonal();
  Eigen::Matrix3d K;
  K << 100, 0, 31.5, 0, 100, 23.5, 0, 0, 1;
  for (const Eigen::Vector3d& centre : {Eigen::Vector3d(0, 0, 100), Eigen::Vector3d(3, 0, 100),
                                       Eigen::Vector3d(-2, 5, 100), Eigen::Vector3d(7, -4, 100)}) {
    cameras.emplace_back(K, R, -R * centre, 64, 48);
    images.push_back(render_plane(cameras.back()));
  }
  const auto views = make_photo_views(cameras, pointers(images));
  const std::vector<std::uint16_t> all{0, 1, 2, 3};
  double worst = 0;
  for (double x = -10; x <= 10; x += 1.37)
    for (double y = -8; y <= 8; y += 1.13) {
      const PhotoValue value = photo_consistency({x, y, 0.0}, all, views);
      ASSERT_TRUE(value.defined());
      worst = std::max(worst, value.g);
    }
  EXPECT_LT(worst, 1e-6);
  // Off the plane the views disagree.
  EXPECT_GT(photo_consistency({0.5, 0.5, 10.0}, all, views).g, 1e-4);
}

TEST(PhotoConsistency, UndefinedWithFewerThanTwoUsableViews) {
  std::vector<Camera> cameras{look_at({0, 0, 3}, {0, 0, 0}, 60, 64, 48), look_at({0.5, 0, 3}, {0, 0, 0}, 60, 64, 48)};
  std::vector<Image> images{Image(64, 48), Image(64, 48)};
  const auto views = make_photo_views(cameras, pointers(images));
  EXPECT_FALSE(photo_consistency({0, 0, 0}, std::vector<std::uint16_t>{0}, views).defined());
  EXPECT_TRUE(photo_consistency({0, 0, 0}, std::vector<std::uint16_t>{0, 1}, views).defined());
  // Far to the side: the patch leaves the image in both views.
  EXPECT_EQ(photo_consistency({5, 0, 0}, std::vector<std::uint16_t>{0, 1}, views).views, 0);
}

// The independent occlusion reference: the open segment from → to against every triangle.
bool segment_hits(const IndexedMesh& mesh, const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  for (const auto& t : mesh.triangles) {
    const auto hit = test::ray_triangle_hit(from, to - from, mesh.positions[t[0]], mesh.positions[t[1]],
                                            mesh.positions[t[2]]);
    if (hit && *hit < 1) return true;
  }
  return false;
}

TEST(Visibility, EqualsBruteForceWithAnOccluder) {
  // A large sphere and a small one in front of it, seen by a ring of cameras.
  IndexedMesh scene = make_icosphere(1.0, 3);
  const IndexedMesh small = make_icosphere(0.3, 2, {0, 0, 1.6});
  const auto offset = static_cast<std::uint32_t>(scene.positions.size());
  scene.positions.insert(scene.positions.end(), small.positions.begin(), small.positions.end());
  for (const auto& t : small.triangles) scene.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const Mesh mesh = build_mesh(scene, "two spheres");

  std::vector<Camera> cameras;
  std::vector<Image> images;
  for (int i = 0; i < 8; ++i) {
    const double a = 2 * std::numbers::pi * i / 8 + 0.1;
    cameras.push_back(look_at({4 * std::sin(a), 0.7 * std::cos(3 * a), 4 * std::cos(a)}, {0, 0, 0.3}, 120, 160, 120));
    images.emplace_back(160, 120);
  }
  const auto views = make_photo_views(cameras, pointers(images));
  VertexFields fields;
  fields.resize(mesh.n_vertices(), views.size());
  compute_normals(mesh.topology, {0, static_cast<std::uint32_t>(mesh.n_vertices())}, fields);
  const SurfaceQuery surface(scene);
  double mean_edge = 0;
  for (auto e : mesh.topology.edges()) mean_edge += mesh.topology.calc_edge_length(e);
  mean_edge /= static_cast<double>(mesh.topology.n_edges());
  const VisibilityOptions options{.preferred_angle_degrees = 90.0};  // every view up to the limit
  compute_visibility(mesh.topology, {0, static_cast<std::uint32_t>(mesh.n_vertices())}, views, surface, mean_edge,
                     options, fields);

  const double cos_max = std::cos(options.max_angle_degrees * std::numbers::pi / 180);
  int occluded_somewhere = 0, visible_pairs = 0;
  for (std::uint32_t v = 0; v < mesh.n_vertices(); ++v) {
    const Eigen::Vector3d P = scene.positions[v], N = fields.normal[v];
    std::vector<std::uint16_t> expected;
    for (std::uint16_t i = 0; i < cameras.size(); ++i) {
      const Projection p = cameras[i].project(P);
      if (p.depth <= 0 || p.u < 2 || p.v < 2 || p.u >= 160 - 3 || p.v >= 120 - 3) continue;
      const Eigen::Vector3d to_camera = cameras[i].centre() - P;
      if (N.dot(to_camera) <= cos_max * to_camera.norm()) continue;
      if (segment_hits(scene, P + options.ray_offset * mean_edge * N, cameras[i].centre())) {
        ++occluded_somewhere;
        continue;
      }
      expected.push_back(i);
    }
    const std::span<const std::uint16_t> visible = fields.visible(v);
    const std::vector<std::uint16_t> found(visible.begin(), visible.end());
    EXPECT_EQ(found, expected) << "vertex " << v;
    visible_pairs += static_cast<int>(expected.size());
  }
  EXPECT_GT(occluded_somewhere, 50);  // the small sphere really hides part of the large one
  EXPECT_GT(visible_pairs, 1000);
}

// Cameras around the textured plane z = 0, tilted by up to 35°.
struct PlaneScene {
  std::vector<Camera> cameras;
  std::vector<Image> images;
  std::vector<PhotoView> views;
  std::vector<std::uint16_t> all;
};

PlaneScene tilted_plane_scene() {
  PlaneScene scene;
  for (int i = 0; i < 5; ++i) {
    const double tilt = i == 0 ? 0.0 : 35.0 * std::numbers::pi / 180, turn = 2 * std::numbers::pi * i / 4;
    const Eigen::Vector3d centre(100 * std::sin(tilt) * std::cos(turn), 100 * std::sin(tilt) * std::sin(turn),
                                 100 * std::cos(tilt));
    scene.cameras.push_back(look_at(centre, {0, 0, 0}, 100, 96, 96));
    scene.all.push_back(static_cast<std::uint16_t>(i));
  }
  for (const auto& c : scene.cameras) scene.images.push_back(render_plane(c));
  scene.views = make_photo_views(scene.cameras, pointers(scene.images));
  return scene;
}

TEST(PhotoConsistency, MinimumAlongTheNormalIsAtTheSurface) {
  const PlaneScene scene = tilted_plane_scene();
  const double edge = 4.0, dx = edge / 40;  // "shortest edge" of 4 pixels, Δx = e/40
  int points = 0, at_surface = 0, rising = 0;
  for (double x = -12; x <= 12; x += 3.1)
    for (double y = -12; y <= 12; y += 2.9) {
      ++points;
      double best_t = 0, best_g = 1e300;
      for (int s = -40; s <= 40; ++s) {
        const double g = photo_consistency({x, y, s * dx}, scene.all, scene.views).g;
        if (g < best_g) best_g = g, best_t = s * dx;
      }
      at_surface += std::abs(best_t) <= dx + 1e-12;
      // And g rises on both sides over about one edge.
      const double g_above = photo_consistency({x, y, edge}, scene.all, scene.views).g;
      const double g_below = photo_consistency({x, y, -edge}, scene.all, scene.views).g;
      rising += g_above > best_g && g_below > best_g;
    }
  EXPECT_GE(at_surface, 0.9 * points) << at_surface << " of " << points;
  EXPECT_GE(rising, 0.95 * points);
  std::printf("[measured] minimum of g within ±Δx of the plane at %d of %d points; rising both sides at %d\n",
              at_surface, points, rising);
}

TEST(PhotoGradient, PointsAwayFromTheSurfaceNearIt) {
  const PlaneScene scene = tilted_plane_scene();
  const double edge = 4.0;
  const PhotoGradientStage stage;
  // Vertices placed above and below the plane; all views visible.
  IndexedMesh cloud = make_grid(24.0, 6);
  std::vector<double> heights;
  IndexedMesh points;
  for (const auto& p : cloud.positions)
    for (double t : {-1.0, -0.5, 0.5, 1.0}) {
      points.positions.push_back(p - Eigen::Vector3d(12, 12, 0) + Eigen::Vector3d(0, 0, t * edge));
      heights.push_back(t);
    }
  Mesh mesh;
  for (const auto& p : points.positions) mesh.topology.add_vertex(to_openmesh(p));
  VertexFields fields;
  fields.resize(mesh.n_vertices(), scene.views.size());
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    fields.visible_count[v] = static_cast<std::uint16_t>(scene.all.size());
    std::copy(scene.all.begin(), scene.all.end(), fields.visible_views.begin() + v * fields.view_capacity);
  }
  stage.run(mesh.topology, {0, static_cast<std::uint32_t>(mesh.n_vertices())}, scene.views,
            stage.sample_spacing(edge), fields);
  int away = 0;
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    ASSERT_TRUE(fields.defined[v] & kGradientDefined);
    away += fields.photo_gradient[v].z() * heights[v] > 0;
  }
  EXPECT_GE(away, 0.9 * static_cast<double>(mesh.n_vertices())) << away << " of " << mesh.n_vertices();
  std::printf("[measured] ∇g points away from the plane at %d of %zu points (±0.5 and ±1 edge)\n", away,
              mesh.n_vertices());
}

TEST(PhotoGradient, ExactOnALinearField) {
  // g itself is not linear in X, but the Savitzky–Golay sum is: check the stage's arithmetic by
  // comparing with the same sum written out here.
  const PlaneScene scene = tilted_plane_scene();
  PhotoGradientOptions whole_pixel;  // written out below with image patches
  whole_pixel.photo.surface_patch = SurfacePatchUse::Off;
  const PhotoGradientStage stage(whole_pixel);
  const Eigen::Vector3d X(1.3, -2.1, 0.7);
  const double dx = 0.05;
  Mesh mesh;
  mesh.topology.add_vertex(to_openmesh(X));
  VertexFields fields;
  fields.resize(1, scene.views.size());
  fields.visible_count[0] = static_cast<std::uint16_t>(scene.all.size());
  std::copy(scene.all.begin(), scene.all.end(), fields.visible_views.begin());
  stage.run(mesh.topology, {0, 1}, scene.views, dx, fields);
  for (int axis = 0; axis < 3; ++axis) {
    double expected = 0;
    for (int s = -10; s <= 10; ++s) {
      Eigen::Vector3d sample = X;
      sample[axis] += s * dx;
      expected += stage.coefficients()[s + 10] * photo_consistency(sample, scene.all, scene.views).g;
    }
    // The stage projects X + s·dx·e_a as P·X + s·dx·P_a (linear in s): the same up to rounding.
    EXPECT_NEAR(fields.photo_gradient[0][axis], expected / dx, 1e-12 * (1 + std::abs(expected / dx)));
    std::printf("[measured] axis %d: stage %.17g, written out %.17g\n", axis, fields.photo_gradient[0][axis],
                expected / dx);
  }
  EXPECT_EQ(fields.photo_consistency[0], photo_consistency(X, scene.all, scene.views).g);
}

// The rendered bumpy sphere of `mvflow synth` (16 ring views of 320×240), its truth as the mesh.
struct SphereScene {
  Mesh truth;
  std::vector<Camera> cameras;
  std::vector<Image> images;
  std::vector<PhotoView> views;
  VertexFields fields;  // normals and visibility of the truth's vertices
  double shortest_edge = 0;
};

const SphereScene& sphere_scene() {
  static const SphereScene cached = [] {
    SphereScene s;
    SynthOptions options;
    options.rig.width = 320;
    options.rig.height = 240;
    options.init.vertices = 100;
    BuiltinShapeOptions shape;
    shape.level = 4;
    const IndexedMesh truth = make_builtin_object("bumpy-sphere", shape);
    SynthScene synth = make_synth_scene(truth, nullptr, options);
    s.truth = build_mesh(truth, "truth");
    for (const auto& view : synth.views) s.cameras.push_back(view.camera);
    s.images = std::move(synth.images);
    s.views = make_photo_views(s.cameras, pointers(s.images));
    const IndexRange all{0, static_cast<std::uint32_t>(s.truth.n_vertices())};
    s.fields.resize(s.truth.n_vertices(), s.views.size());
    compute_normals(s.truth.topology, all, s.fields);
    double mean_edge = 0;
    s.shortest_edge = 1e300;
    for (auto e : s.truth.topology.edges()) {
      mean_edge += s.truth.topology.calc_edge_length(e);
      s.shortest_edge = std::min(s.shortest_edge, s.truth.topology.calc_edge_length(e));
    }
    mean_edge /= static_cast<double>(s.truth.topology.n_edges());
    const SurfaceQuery surface(truth);
    compute_visibility(s.truth.topology, all, s.views, surface, mean_edge, VisibilityOptions{}, s.fields);
    return s;
  }();
  return cached;
}

TEST(PhotoConsistency, EqualsSlowReferenceOnARenderedObject) {
  // Photo-consistent points (the truth's vertices, small g) and points a shortest edge off the
  // surface, each with its own visible views: the kernel (float interpolation, float sums on shifted data)
  // against the double-precision reference.
  const SphereScene& s = sphere_scene();
  double worst = 0, smallest = 1e300;
  int compared = 0;
  for (std::uint32_t v = 0; v < s.truth.n_vertices(); v += 2) {
    const std::span<const std::uint16_t> visible_span = s.fields.visible(v);
    const std::vector<std::uint16_t> visible(visible_span.begin(), visible_span.end());
    for (double t : {0.0, 1.0}) {
      const Eigen::Vector3d X = s.truth.position(v) + t * s.shortest_edge * s.fields.normal[v];
      const PhotoValue slow = slow_photo_consistency(X, s.cameras, s.images, visible);
      const PhotoValue fast = photo_consistency(X, visible, s.views);
      ASSERT_EQ(fast.views, slow.views);
      if (!slow.defined()) continue;
      ++compared;
      EXPECT_NEAR(fast.g, slow.g, 1e-5 * slow.g) << "vertex " << v;
      worst = std::max(worst, std::abs(fast.g - slow.g) / slow.g);
      smallest = std::min(smallest, slow.g);
    }
  }
  EXPECT_GT(compared, 1000);
  // Measured: 2.5e-6 at g down to 3.7e-6, with double sums as with float ones (1e-13 when the
  // values were interpolated in double).
  std::printf("[measured] rendered bumpy sphere: largest relative difference from the slow reference %.2g "
              "(%d points, smallest g %.2g)\n", worst, compared, smallest);
}

// Where the minimum of g lies along the normal of every truth vertex seen by ≥ 2 views: g scanned
// over ±1 shortest edge in steps of Δx = e_min/40. \p g_along(v, P, N, k·Δx·N) gives g at
// P + k·Δx·N for vertex v (called for k = −40..40 in order).
struct MinimumScan {
  int vertices = 0, within = 0, within2 = 0, within4 = 0, rising = 0;
  double median_offset = 0;  // in Δx
  void print(const char* what) const {
    std::printf("[measured] rendered bumpy sphere%s: minimum of g within ±Δx of the surface at %d of %d vertices "
                "(%.1f %%), ±2Δx %.1f %%, ±4Δx %.1f %%, median offset %.0f Δx; g higher one edge away on both "
                "sides at %.1f %%\n",
                what, within, vertices, 100.0 * within / vertices, 100.0 * within2 / vertices,
                100.0 * within4 / vertices, median_offset, 100.0 * rising / vertices);
  }
};

template <class GAlong>
MinimumScan scan_minimum_along_normals(const SphereScene& s, GAlong g_along) {
  const double dx = s.shortest_edge / 40;
  MinimumScan scan;
  std::vector<double> offsets;
  for (std::uint32_t v = 0; v < s.truth.n_vertices(); ++v) {
    if (s.fields.visible_count[v] < 2) continue;
    ++scan.vertices;
    const Eigen::Vector3d P = s.truth.position(v), N = s.fields.normal[v];
    int best = 0;
    double best_g = 1e300, g_low = 0, g_high = 0;
    for (int k = -40; k <= 40; ++k) {
      const PhotoValue value = g_along(v, P, N, P + k * dx * N);
      if (!value.defined()) continue;
      if (value.g < best_g) best_g = value.g, best = k;
      if (k == -40) g_low = value.g;
      if (k == 40) g_high = value.g;
    }
    scan.within += std::abs(best) <= 1;
    scan.within2 += std::abs(best) <= 2;
    scan.within4 += std::abs(best) <= 4;
    offsets.push_back(best);
    scan.rising += g_low > best_g && g_high > best_g;
  }
  std::sort(offsets.begin(), offsets.end());
  if (!offsets.empty()) scan.median_offset = offsets[offsets.size() / 2];
  return scan;
}

TEST(PhotoConsistency, MinimumAlongTheNormalOnARenderedObject) {
  // For every truth vertex seen by ≥ 2 views, with the vertex's own views: where is the minimum?
  const SphereScene& s = sphere_scene();
  const MinimumScan scan = scan_minimum_along_normals(
      s, [&](std::uint32_t v, const Eigen::Vector3d&, const Eigen::Vector3d&, const Eigen::Vector3d& X) {
        return photo_consistency(X, s.fields.visible(v), s.views);
      });
  scan.print("");
  // Measured: 54.5 % within ±Δx, 74.6 % within ±2Δx, 91.2 % within ±4Δx, median −1 Δx, 100 %
  // rising; Δx = e_min/40 is about 0.14 pixel in these 320×240 images, so ±Δx asks for
  // sub-pixel agreement.
  EXPECT_GT(scan.vertices, 1000);
  EXPECT_GE(scan.within, 0.45 * scan.vertices);
  EXPECT_GE(scan.within2, 0.65 * scan.vertices);
  EXPECT_GE(scan.within4, 0.85 * scan.vertices);
  EXPECT_LE(std::abs(scan.median_offset), 1.0);
  EXPECT_GE(scan.rising, 0.9 * scan.vertices);
}

TEST(SurfacePatch, MinimumAlongTheNormalOnARenderedObject) {
  // The same scan with surface patches laid out at each truth vertex (its normal), moved along the
  // normal as the gradient's samples move it.
  const SphereScene& s = sphere_scene();
  const PhotoConsistencyOptions defaults;
  SurfacePatchLayout layout;
  std::uint32_t laid_out = std::numeric_limits<std::uint32_t>::max();
  const MinimumScan scan = scan_minimum_along_normals(
      s, [&](std::uint32_t v, const Eigen::Vector3d& P, const Eigen::Vector3d& N, const Eigen::Vector3d& X) {
        if (v != laid_out) {
          layout_surface_patch(P, N, s.fields.visible(v), s.views, 2, defaults.surface_patch_spacing, layout);
          laid_out = v;
        }
        return surface_patch_consistency(X, layout, s.views);
      });
  scan.print(", surface patches");
  // Measured: 98.3 % within ±Δx, 100 % within ±2Δx, median −1 Δx, 100 % rising (whole-pixel
  // patches on the same vertices: 54.5 %, 74.6 %, −1 Δx, 100 %).
  EXPECT_GT(scan.vertices, 1000);
  EXPECT_GE(scan.within, 0.9 * scan.vertices);
  EXPECT_GE(scan.within2, 0.97 * scan.vertices);
  EXPECT_LE(std::abs(scan.median_offset), 1.0);
  EXPECT_GE(scan.rising, 0.95 * scan.vertices);
}

// Fields for probe points near truth vertices: probe p sees the views of vertex source[p].
VertexFields probe_fields(const SphereScene& s, const std::vector<std::uint32_t>& source) {
  VertexFields fields;
  fields.resize(source.size(), s.views.size());
  for (std::size_t p = 0; p < source.size(); ++p) {
    const std::span<const std::uint16_t> visible = s.fields.visible(source[p]);
    fields.visible_count[p] = static_cast<std::uint16_t>(visible.size());
    std::copy(visible.begin(), visible.end(), fields.visible_views.begin() + p * fields.view_capacity);
  }
  return fields;
}

TEST(PhotoGradient, MatchesTheSlowReferenceOnARenderedObject) {
  // ∇g of the stage (float interpolation, samples projected linearly in s) against the same
  // Savitzky–Golay sum over the double-precision reference at each sample point.
  const SphereScene& s = sphere_scene();
  PhotoGradientOptions whole_pixel;  // the reference reads image patches
  whole_pixel.photo.surface_patch = SurfacePatchUse::Off;
  const PhotoGradientStage stage(whole_pixel);
  const double dx = stage.sample_spacing(s.shortest_edge);
  Mesh probes;
  std::vector<std::uint32_t> source;
  for (std::uint32_t v = 0; v < s.truth.n_vertices(); v += 25) {
    if (s.fields.visible_count[v] < 2) continue;
    probes.topology.add_vertex(to_openmesh(s.truth.position(v) + 0.5 * s.shortest_edge * s.fields.normal[v]));
    source.push_back(v);
  }
  VertexFields fields = probe_fields(s, source);
  stage.run(probes.topology, {0, static_cast<std::uint32_t>(probes.n_vertices())}, s.views, dx, fields);
  double worst = 0;
  int compared = 0;
  for (std::size_t p = 0; p < probes.n_vertices(); ++p) {
    if (!(fields.defined[p] & kGradientDefined)) continue;
    const std::span<const std::uint16_t> visible_span = fields.visible(p);
    const std::vector<std::uint16_t> visible(visible_span.begin(), visible_span.end());
    const Eigen::Vector3d expected =
        test::slow_photo_gradient(stage, probes.position(p), dx, s.cameras, s.images, visible);
    ++compared;
    const double error = (fields.photo_gradient[p] - expected).norm() / expected.norm();
    EXPECT_LT(error, 1e-5) << "probe " << p;
    worst = std::max(worst, error);
  }
  EXPECT_GT(compared, 50);
  // Measured: 2.2e-6 (6.1e-7 with double sums).
  std::printf("[measured] rendered bumpy sphere: ∇g against the slow reference, largest relative difference %.2g "
              "(%d probes)\n", worst, compared);
}

TEST(PhotoGradient, PointsAwayFromARenderedObject) {
  // Points half an edge and one edge off the surface along the normal, with the vertex's views:
  // ∇g should point away from the surface.
  const SphereScene& s = sphere_scene();
  const PhotoGradientStage stage;
  Mesh probes;
  std::vector<std::uint32_t> source;
  std::vector<double> side;
  for (std::uint32_t v = 0; v < s.truth.n_vertices(); v += 3) {
    if (s.fields.visible_count[v] < 2) continue;
    for (double t : {-1.0, -0.5, 0.5, 1.0}) {
      probes.topology.add_vertex(to_openmesh(s.truth.position(v) + t * s.shortest_edge * s.fields.normal[v]));
      source.push_back(v);
      side.push_back(t);
    }
  }
  VertexFields fields = probe_fields(s, source);
  stage.run(probes.topology, {0, static_cast<std::uint32_t>(probes.n_vertices())}, s.views,
            stage.sample_spacing(s.shortest_edge), fields);
  int defined = 0, away = 0;
  for (std::size_t p = 0; p < probes.n_vertices(); ++p) {
    if (!(fields.defined[p] & kGradientDefined)) continue;
    ++defined;
    away += fields.photo_gradient[p].dot(s.fields.normal[source[p]]) * side[p] > 0;
  }
  std::printf("[measured] rendered bumpy sphere: ∇g points away from the surface at %d of %d probes (%.1f %%)\n",
              away, defined, 100.0 * away / defined);
  EXPECT_GT(defined, 1000);
  EXPECT_GE(away, 0.85 * defined);  // measured 91.2 %
}

// ---- Surface patches (stages/flow/surface_patch.h) ----

// The textured plane z = 0 seen at 0°, 35°, 60° and 65° from its normal (focal 100 at distance
// 100: one world unit per pixel of a frontal view; the 60° view foreshortens by 2).
PlaneScene oblique_plane_scene() {
  PlaneScene scene;
  const double degrees = std::numbers::pi / 180;
  const std::array<std::pair<double, double>, 4> rig{{{0.0, 0.0}, {35.0, 0.0}, {60.0, 90.0}, {65.0, 200.0}}};
  for (const auto& [tilt, turn] : rig) {
    const Eigen::Vector3d centre(100 * std::sin(tilt * degrees) * std::cos(turn * degrees),
                                 100 * std::sin(tilt * degrees) * std::sin(turn * degrees), 100 * std::cos(tilt * degrees));
    scene.cameras.push_back(look_at(centre, {0, 0, 0}, 100, 96, 96));
    scene.all.push_back(static_cast<std::uint16_t>(scene.all.size()));
  }
  for (const auto& c : scene.cameras) scene.images.push_back(render_plane(c));
  scene.views = make_photo_views(scene.cameras, pointers(scene.images));
  return scene;
}

TEST(SurfacePatch, ObliqueViewsAgreeOnATexturedPlaneWhereWholePixelPatchesDoNot) {
  // On the plane every view samples the same texture points: g is only the bilinear
  // interpolation's error. The thesis's 5×5 pixel patch covers twice the surface along the 60° view's
  // foreshortened axis, so its views disagree.
  const PlaneScene scene = oblique_plane_scene();
  SurfacePatchLayout layout;
  double surface_sum = 0, image_sum = 0;
  int points = 0, lower = 0;
  for (double x = -8; x <= 8; x += 2.3)
    for (double y = -8; y <= 8; y += 2.1) {
      const Eigen::Vector3d X(x, y, 0);
      layout_surface_patch(X, Eigen::Vector3d::UnitZ(), scene.all, scene.views, 2, 2.0, layout);
      const PhotoValue surface = surface_patch_consistency(X, layout, scene.views);
      const PhotoValue image = photo_consistency(X, scene.all, scene.views);
      ASSERT_EQ(surface.views, 4);
      ASSERT_EQ(image.views, 4);
      surface_sum += surface.g;
      image_sum += image.g;
      lower += surface.g < 0.2 * image.g;
      ++points;
    }
  EXPECT_LT(surface_sum, 0.1 * image_sum);
  EXPECT_EQ(lower, points);
  std::printf("[measured] mean g on the plane: surface patch %.3g, 5x5 pixel patch %.3g (%.1f%%)\n",
              surface_sum / points, image_sum / points, 100 * surface_sum / image_sum);
}

TEST(SurfacePatch, MinimumAlongTheNormalIsAtTheSurface) {
  // The patch laid out at a point of the plane and moved along the normal, as the gradient's samples move.
  const PlaneScene scene = oblique_plane_scene();
  SurfacePatchLayout layout;
  const double dx = 0.1;
  int points = 0, at_surface = 0, rising = 0;
  for (double x = -8; x <= 8; x += 3.1)
    for (double y = -8; y <= 8; y += 2.9) {
      ++points;
      const Eigen::Vector3d X(x, y, 0);
      layout_surface_patch(X, Eigen::Vector3d::UnitZ(), scene.all, scene.views, 2, 2.0, layout);
      double best_t = 0, best_g = 1e300;
      for (int s = -40; s <= 40; ++s) {
        const double g = surface_patch_consistency(X + Eigen::Vector3d(0, 0, s * dx), layout, scene.views).g;
        if (g < best_g) best_g = g, best_t = s * dx;
      }
      at_surface += std::abs(best_t) <= dx + 1e-12;
      rising += surface_patch_consistency(X + Eigen::Vector3d(0, 0, 3), layout, scene.views).g > best_g &&
                surface_patch_consistency(X - Eigen::Vector3d(0, 0, 3), layout, scene.views).g > best_g;
    }
  EXPECT_GE(at_surface, 0.9 * points) << at_surface << " of " << points;
  EXPECT_EQ(rising, points);
}

TEST(SurfacePatch, EqualsTheExactProjectionOfItsTangentPoints) {
  // Brute force in double: the 25 tangent-plane points X + d·(a·t₁ + b·t₂), d = 2 × the smallest
  // depth / focal, each projected by the camera and read bilinearly, the views whose points all
  // have their 2×2 support inside the image, SPEC §3's variance.
  const PlaneScene scene = oblique_plane_scene();
  const Eigen::Vector3d N = Eigen::Vector3d(0.3, -0.2, 1).normalized();
  Eigen::Vector3d t1, t2;
  surface_patch_frame(N, t1, t2);
  ASSERT_NEAR(t1.dot(N), 0, 1e-15);
  ASSERT_NEAR(t2.dot(N), 0, 1e-15);
  ASSERT_NEAR(t1.dot(t2), 0, 1e-15);
  SurfacePatchLayout layout;
  int compared = 0, partial = 0;
  for (double x = -40; x <= 40; x += 4.7)
    for (double y = -30; y <= 30; y += 5.3) {
      const Eigen::Vector3d X(x, y, 0.5);
      layout_surface_patch(X, N, scene.all, scene.views, 2, 2.0, layout);
      double footprint = 1e300;
      for (const Camera& c : scene.cameras) footprint = std::min(footprint, c.project(X).depth / c.focal_pixels());
      std::vector<std::vector<double>> patches;
      for (std::size_t i = 0; i < scene.cameras.size(); ++i) {
        std::vector<double> patch;
        bool inside = true;
        for (int b = -2; b <= 2 && inside; ++b)
          for (int a = -2; a <= 2 && inside; ++a) {
            const Projection p = scene.cameras[i].project(X + 2 * footprint * (a * t1 + b * t2));
            const int x0 = static_cast<int>(std::floor(p.u)), y0 = static_cast<int>(std::floor(p.v));
            inside = x0 >= 0 && y0 >= 0 && x0 + 1 < 96 && y0 + 1 < 96;
            if (!inside) break;
            const double fx = p.u - x0, fy = p.v - y0;
            const Image& im = scene.images[i];
            for (int c = 0; c < 3; ++c)
              patch.push_back((1 - fx) * (1 - fy) * im.pixel(x0, y0)[c] + fx * (1 - fy) * im.pixel(x0 + 1, y0)[c] +
                              (1 - fx) * fy * im.pixel(x0, y0 + 1)[c] + fx * fy * im.pixel(x0 + 1, y0 + 1)[c]);
          }
        if (inside) patches.push_back(patch);
      }
      const PhotoValue value = surface_patch_consistency(X, layout, scene.views);
      ASSERT_EQ(value.views, static_cast<int>(patches.size())) << X.transpose();
      partial += patches.size() < scene.cameras.size();
      if (patches.size() < 2) continue;
      const double m = static_cast<double>(patches.size());
      double g = 0;
      for (std::size_t k = 0; k < 75; ++k) {
        double mean = 0;
        for (const auto& p : patches) mean += p[k] / m;
        for (const auto& p : patches) g += (p[k] - mean) * (p[k] - mean) / (m - 1) / 25.0;
      }
      EXPECT_NEAR(value.g, g, 1e-6 + 1e-4 * g) << X.transpose();
      ++compared;
    }
  EXPECT_GT(compared, 100);
  EXPECT_GT(partial, 10);  // the border case: some views' patches leave their image
}

// Six views of random images on an arc around the origin, as the surface patch tests use them.
struct SixViewRig {
  explicit SixViewRig(std::mt19937& random)
      : rig(random_rig(6, 0.35, 0.4, random)), views(make_photo_views(rig.cameras, pointers(rig.images))) {}
  SixViewRig(const SixViewRig&) = delete;  // views point into rig.images
  SixViewRig& operator=(const SixViewRig&) = delete;
  RandomRig rig;
  std::vector<PhotoView> views;
  std::vector<std::uint16_t> all{0, 1, 2, 3, 4, 5};
};

TEST(SurfacePatch, EqualsTheDoubleReferenceOnRandomImages) {
  // SPEC §3's bound for the surface patch's float interpolation and float sums on shifted data:
  // against the same laid-out points read and summed in double, on random images (the worst
  // case: every pixel differs from its neighbours), patches 3×3, 5×5, 7×7 and 15×15.
  std::mt19937 random(29);
  const auto& [rig, views, all] = SixViewRig(random);
  std::uniform_real_distribution<double> coordinate(-0.7, 0.7);
  SurfacePatchLayout layout;
  double worst = 0;
  int compared = 0;
  for (int h : {1, 2, 3, 7})
    for (int trial = 0; trial < 150; ++trial) {
      const Eigen::Vector3d X(coordinate(random), coordinate(random), coordinate(random));
      layout_surface_patch(X, random_normal(random), all, views, h, 1.5, layout);
      const Eigen::Vector3d sample = X + Eigen::Vector3d(0.003, -0.002, 0.001);  // as a gradient sample
      const PhotoValue fast = surface_patch_consistency(sample, layout, views);
      const PhotoValue slow = slow_surface_patch_consistency(sample, layout, rig.cameras, rig.images);
      ASSERT_EQ(fast.views, slow.views) << "h " << h << " at " << X.transpose();
      if (!slow.defined()) continue;
      ++compared;
      EXPECT_NEAR(fast.g, slow.g, 1e-6 + 1e-5 * slow.g) << "h " << h;
      worst = std::max(worst, std::abs(fast.g - slow.g) / slow.g);
    }
  EXPECT_GT(compared, 300);
  std::printf("[measured] surface patches on random images: largest relative difference from the double "
              "reference %.2g (%d points)\n", worst, compared);
}

// The gradient's samples against one evaluation per sample with `evaluate` (a build's
// surface_patch_consistency), bit for bit, slot by slot: every slot, or only slot 0 when g(X) is
// undefined and `every_slot` is false (where surface_samples need not write the others).
template <typename Evaluate>
void expect_each_slot_is_one_evaluation(const std::vector<PhotoValue>& samples, const Eigen::Vector3d& X, double spacing,
                                        int half, Evaluate evaluate, bool every_slot, const std::string& where) {
  for_each_gradient_sample(X, spacing, half, [&](std::size_t slot, const Eigen::Vector3d& point) {
    const PhotoValue one = evaluate(point);
    EXPECT_EQ(samples[slot].views, one.views) << "slot " << slot << where;
    EXPECT_EQ(std::bit_cast<std::uint64_t>(samples[slot].g), std::bit_cast<std::uint64_t>(one.g))
        << "slot " << slot << ": " << samples[slot].g << " against " << one.g << where;
    return every_slot || samples[0].defined();
  });
}

// Every build's surface_samples against one surface evaluation per sample of that build and
// against the baseline build: bit for bit, slot by slot (only slot 0 when g(X) is undefined).
void expect_samples_bits(const Eigen::Vector3d& X, double spacing, int half, const SurfacePatchLayout& layout,
                         const std::vector<PhotoView>& views, const std::string& where) {
  const auto builds = detail::photo_kernel_builds();
  std::vector<PhotoValue> baseline(static_cast<std::size_t>(6 * half + 1)), samples(baseline.size());
  builds.front().surface_samples(X, spacing, half, layout, views, baseline);
  for (const auto& build : builds) {
    std::fill(samples.begin(), samples.end(), PhotoValue{-1.0, -1});
    build.surface_samples(X, spacing, half, layout, views, samples);
    const std::string in_build = std::string(" in ") + build.name + where;
    expect_each_slot_is_one_evaluation(
        samples, X, spacing, half, [&](const Eigen::Vector3d& point) { return build.surface(point, layout, views); },
        false, in_build);
    for_each_gradient_sample(X, spacing, half, [&](std::size_t slot, const Eigen::Vector3d&) {
      EXPECT_EQ(std::bit_cast<std::uint64_t>(samples[slot].g), std::bit_cast<std::uint64_t>(baseline[slot].g))
          << build.name << " against baseline, slot " << slot << where;
      return samples[0].defined();
    });
  }
}

TEST(SurfacePatch, SamplesAcrossTheLanesGiveTheBitsOfOneEvaluationPerSample) {
  // The AVX-512 build runs the gradient's samples across its lanes when every view spreads them
  // over less than 3 pixels (one 5×5-pixel window per point and view), else one evaluation per
  // sample: on random images, patches 3×3 to 7×7, points near the images' borders (some samples'
  // patches leave some images), spacings that put the samples within 3 pixels, near 3 and beyond,
  // Savitzky–Golay half windows of 1, 10 (the default) and 11 (more samples than the stack buffers
  // hold), and points at an image's border within the samples' reach. The across-lanes path is also
  // called alone, to count where it ran.
  std::mt19937 random(37);
  const auto& [rig, views, all] = SixViewRig(random);
  std::uniform_real_distribution<double> coordinate(-0.7, 0.7);
  const int default_half = PhotoGradientOptions{}.savitzky_golay.half_window();
  const auto across_lanes = detail::photo_kernel_builds().back().surface_samples_across_lanes;
  SurfacePatchLayout layout;
  int narrow = 0, wide = 0, near_the_limit = 0, defined = 0, ran_across = 0, mixed_views = 0;
  const auto check = [&](const Eigen::Vector3d& X, const Eigen::Vector3d& N, int h, double spacing, int half) {
    layout_surface_patch(X, N, all, views, h, 1.5, layout);
    // The samples' spread in pixels over the laid-out views.
    double spread = 0;
    for (const std::uint16_t k : layout.views) {
      double low[2] = {INFINITY, INFINITY}, high[2] = {-INFINITY, -INFINITY};
      for_each_gradient_sample(X, spacing, half, [&](std::size_t, const Eigen::Vector3d& point) {
        const Projection p = rig.cameras[k].project(point);
        low[0] = std::min(low[0], p.u), high[0] = std::max(high[0], p.u);
        low[1] = std::min(low[1], p.v), high[1] = std::max(high[1], p.v);
        return true;
      });
      spread = std::max({spread, high[0] - low[0], high[1] - low[1]});
    }
    narrow += spread < 2.5, wide += spread > 3.5, near_the_limit += spread >= 2.5 && spread <= 3.5;
    defined += surface_patch_consistency(X, layout, views).defined();
    const std::string where =
        " (h " + std::to_string(h) + ", spacing " + std::to_string(spacing) + ", half " + std::to_string(half) + ")";
    expect_samples_bits(X, spacing, half, layout, views, where);
    if (across_lanes == nullptr) return;
    std::vector<PhotoValue> samples(static_cast<std::size_t>(6 * half + 1));
    if (!across_lanes(X, spacing, half, layout, views, samples)) return;
    ++ran_across;
    // Samples that use different numbers of views: the lanes' masks at work.
    mixed_views += std::ranges::any_of(samples, [&](const PhotoValue& p) { return p.views != samples[0].views; });
    expect_each_slot_is_one_evaluation(
        samples, X, spacing, half,
        [&](const Eigen::Vector3d& point) { return surface_patch_consistency(point, layout, views); }, true,
        " across the lanes" + where);
  };
  for (const int half : {default_half, 1, 11})
    for (int h : {1, 2, 3}) {
      if (half != default_half && h != 2) continue;
      for (const double spacing : {0.001, 0.004, 0.007, 0.008, 0.009, 0.02})
        for (int trial = 0; trial < 40 && !HasFailure(); ++trial)
          check(Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random)), random_normal(random), h,
                spacing, half);
    }
  // Points whose patch meets an image's border within the samples' reach, so that some samples can
  // use that view and others cannot.
  std::uniform_real_distribution<double> unit(0, 1);
  for (int trial = 0; trial < 120 && !HasFailure(); ++trial) {
    const Camera& camera = rig.cameras[static_cast<std::size_t>(trial % 6)];
    const double edge = 0.5 + 2.5 * unit(random);  // pixels from the left or the top border
    const bool left = trial % 12 < 6;
    const Ray ray = camera.ray(left ? edge : 5 + 50 * unit(random), left ? 5 + 38 * unit(random) : edge);
    check(ray.origin + 3.0 * ray.direction, random_normal(random), 1, 0.004, default_half);
  }
  EXPECT_GT(narrow, 100);
  EXPECT_GT(near_the_limit, 50);
  EXPECT_GT(wide, 100);
  EXPECT_GT(defined, 300);
  std::printf("[measured] samples spread over < 2.5 px: %d, 2.5–3.5 px: %d, > 3.5 px: %d\n", narrow, near_the_limit, wide);
  if (across_lanes == nullptr) {
    std::printf("[measured] this CPU has no AVX-512 build: the across-lanes path was not run\n");
  } else {
    std::printf("[measured] across the lanes: %d evaluations, %d with samples on different view counts\n", ran_across,
                mixed_views);
    EXPECT_GT(ran_across, 200);
    EXPECT_GT(mixed_views, 20);
  }
}

TEST(PhotoConsistency, EveryBuildsSamplesAtTheImagesBordersAreOneEvaluationEach) {
  // The 5×5 kernel locates an axis's patches kLanes samples at a time, and the SSE2 build tests the
  // range on the truncated pixel coordinates: every build's samples, slot by slot, against one
  // photo_consistency_5x5 of that build per sample (PhotoView::project and patch_inside), at
  // points whose samples' patches cross each of an image's four borders, at points behind one
  // camera, and on images 5 to 8 pixels wide, where at most a few pixels (or none) can hold a patch.
  std::mt19937 random(41);
  std::uniform_real_distribution<double> unit(0, 1);
  const int half = PhotoGradientOptions{}.savitzky_golay.half_window();
  int partial = 0, compared = 0;
  const auto check = [&](const std::vector<PhotoView>& views, std::span<const std::uint16_t> ids,
                         const Eigen::Vector3d& X, double spacing, const std::string& where) {
    for (const auto& build : detail::photo_kernel_builds()) {
      std::vector<PhotoValue> samples(static_cast<std::size_t>(6 * half + 1), PhotoValue{-1.0, -1});
      build.samples(X, spacing, half, ids, views, samples);
      expect_each_slot_is_one_evaluation(
          samples, X, spacing, half, [&](const Eigen::Vector3d& point) { return build.consistency(point, ids, views); },
          false, std::string(" in ") + build.name + where);
      compared += samples[0].defined();
      partial += samples[0].defined() &&
                 std::ranges::any_of(samples, [&](const PhotoValue& p) { return p.views != samples[0].views; });
    }
  };
  for (const int width : {64, 5, 6, 7, 8}) {
    const int height = width == 64 ? 48 : width;
    std::vector<Camera> cameras;
    std::vector<Image> images;
    for (int i = 0; i < 4; ++i) {
      const double a = 0.3 * i;
      cameras.push_back(look_at({3 * std::sin(a), 0.4, 3 * std::cos(a)}, {0, 0, 0}, 60.0 * width / 64, width, height));
      Image image(width, height);
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
          image.set_pixel(x, y, {static_cast<float>(unit(random)), static_cast<float>(unit(random)),
                                 static_cast<float>(unit(random))});
      images.push_back(std::move(image));
    }
    const auto views = make_photo_views(cameras, pointers(images));
    const std::vector<std::uint16_t> ids{0, 1, 2, 3};
    const std::string size = " (" + std::to_string(width) + "×" + std::to_string(height) + ")";
    for (int trial = 0; trial < 160 && !HasFailure(); ++trial) {
      // A pixel 0.5–4.5 pixels inside one of the four borders of one camera, the other coordinate anywhere.
      const Camera& camera = cameras[static_cast<std::size_t>(trial % 4)];
      const double inside = 0.5 + 4 * unit(random);
      const double along_u = unit(random) * width, along_v = unit(random) * height;
      const int border = (trial / 4) % 4;
      const double u = border == 0 ? inside : border == 1 ? width - inside : along_u;
      const double v = border == 2 ? inside : border == 3 ? height - inside : along_v;
      const Ray ray = camera.ray(u, v);
      // Spacings that spread the samples over about 1 and 4 pixels of that view.
      check(views, ids, ray.origin + 3.0 * ray.direction, trial % 2 == 0 ? 0.002 : 0.008, size);
    }
    // Behind camera 0, in front of the others: samples of camera 0's lanes have z ≤ 0.
    for (int trial = 0; trial < 10 && !HasFailure(); ++trial) {
      const Eigen::Vector3d behind = cameras[0].centre() + 0.02 * (cameras[0].centre() - Eigen::Vector3d::Zero()) +
                                     0.01 * Eigen::Vector3d(unit(random), unit(random), unit(random));
      check(views, ids, behind, 0.004, size + " behind camera 0");
    }
  }
  EXPECT_GT(compared, 300);
  EXPECT_GT(partial, 100);
  std::printf("[measured] samples at the borders: %d defined centres, %d with samples on other view counts\n",
              compared, partial);
}

TEST(SurfacePatch, ReadsTheImagesLastPixelWithoutPassingIt) {
  // A patch whose bottom right point's support holds the image's last pixel (W − 1, H − 1): the
  // kernel reads that pixel's right neighbour from earlier floats (nothing lies after it). Only
  // AddressSanitizer sees a read past the image (the extra float would land in the lane that is
  // never summed), so tools/check.sh runs this test under it; it reported the 16-byte read when
  // the kernel's end-of-image case was disabled. Two views, hand-made offsets of 0.6 px.
  std::mt19937 random(31);
  const RandomRig rig = random_rig(2, 0.0, 0.0, random);  // one camera, two images
  const auto views = make_photo_views(rig.cameras, pointers(rig.images));
  const Camera& first = rig.cameras[0];
  int at_last_pixel = 0;
  for (const double fraction : {0.05, 0.5, 0.95}) {
    // X on the first view's ray through the pixel whose patch's bottom right point falls in the
    // last pixel's 2×2 support (x0 = W − 2, y0 = H − 2).
    const double u = first.width() - 2 - 0.6 + fraction, v = first.height() - 2 - 0.6 + fraction;
    const Ray ray = first.ray(u, v);
    const Eigen::Vector3d X = ray.origin + 3.0 * ray.direction;
    SurfacePatchLayout layout;
    layout.half_patch = 1;
    layout.points = 9;
    layout.padded_points = kSurfacePatchLanes;
    layout.views = {0, 1};
    for (int k = 0; k < 2; ++k) {
      for (int b = -1; b <= 1; ++b)
        for (int a = -1; a <= 1; ++a) {
          layout.du.push_back(0.6f * a);
          layout.dv.push_back(0.6f * b);
        }
      const float last_du = layout.du.back(), last_dv = layout.dv.back();  // the padding repeats the last point
      layout.du.resize((k + 1) * kSurfacePatchLanes, last_du);
      layout.dv.resize((k + 1) * kSurfacePatchLanes, last_dv);
      layout.bounds.insert(layout.bounds.end(), {-0.6f, 0.6f, -0.6f, 0.6f});
    }
    const Projection p = first.project(X);
    at_last_pixel += std::floor(p.u + 0.6f) == first.width() - 2 && std::floor(p.v + 0.6f) == first.height() - 2;
    const PhotoValue slow = slow_surface_patch_consistency(X, layout, rig.cameras, rig.images);
    for (const auto& build : detail::photo_kernel_builds()) {
      const PhotoValue fast = build.surface(X, layout, views);
      ASSERT_EQ(fast.views, slow.views) << build.name;
      EXPECT_NEAR(fast.g, slow.g, 1e-6 + 1e-5 * slow.g) << build.name;
    }
    EXPECT_EQ(slow.views, 2);
    // The gradient's samples within a pixel: AVX-512 reads their 5×5-pixel windows, moved inside
    // the image at its corner.
    expect_samples_bits(X, 1e-4, 10, layout, views, " at the last pixel");
  }
  EXPECT_EQ(at_last_pixel, 3);
}

TEST(SurfacePatch, TheGradientStagePointsAwayFromThePlane) {
  PhotoGradientOptions options;
  options.photo.surface_patch = SurfacePatchUse::On;
  const PhotoGradientStage stage(options);
  const PlaneScene scene = oblique_plane_scene();
  const double edge = 4.0;
  Mesh mesh;
  std::vector<double> heights;
  for (double x = -8; x <= 8; x += 4)
    for (double y = -8; y <= 8; y += 4)
      for (const double t : {-1.0, -0.5, 0.5, 1.0}) {
        mesh.topology.add_vertex(to_openmesh(Eigen::Vector3d(x, y, t * edge)));
        heights.push_back(t);
      }
  VertexFields fields;
  fields.resize(mesh.n_vertices(), scene.views.size());
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    fields.normal[v] = Eigen::Vector3d::UnitZ();
    fields.visible_count[v] = static_cast<std::uint16_t>(scene.all.size());
    std::copy(scene.all.begin(), scene.all.end(), fields.visible_views.begin() + v * fields.view_capacity);
  }
  stage.run(mesh.topology, {0, static_cast<std::uint32_t>(mesh.n_vertices())}, scene.views, stage.sample_spacing(edge),
            fields);
  int away = 0;
  SurfacePatchLayout layout;
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    ASSERT_TRUE(fields.defined[v] & kGradientDefined);
    away += fields.photo_gradient[v].z() * heights[v] > 0;
    // g is the surface patch's, laid out at the vertex.
    const Eigen::Vector3d X = to_eigen(mesh.topology.point(TriMesh::VertexHandle(static_cast<int>(v))));
    layout_surface_patch(X, Eigen::Vector3d::UnitZ(), scene.all, scene.views, 2, options.photo.surface_patch_spacing, layout);
    EXPECT_EQ(fields.photo_consistency[v], surface_patch_consistency(X, layout, scene.views).g);
  }
  // As PhotoGradient.PointsAwayFromTheSurfaceNearIt with whole-pixel patches (measured 95 of 100).
  EXPECT_GE(away, 0.9 * static_cast<double>(mesh.n_vertices())) << away << " of " << mesh.n_vertices();
  std::printf("[measured] surface patches: ∇g points away from the plane at %d of %zu points\n", away,
              mesh.n_vertices());
}

TEST(SurfacePatch, OptionsOutOfRangeAreRefused) {
  PhotoConsistencyOptions options;
  EXPECT_EQ(options.surface_patch, SurfacePatchUse::Oblique);
  EXPECT_EQ(options.surface_patch_angle_degrees, 60.0);
  options.surface_patch = SurfacePatchUse::On;
  EXPECT_NO_THROW(options.check());
  options.normalize = true;
  EXPECT_THROW(options.check(), OptionError);
  options.surface_patch = SurfacePatchUse::Oblique;  // normalized patches stay image patches
  EXPECT_NO_THROW(options.check());
  options.normalize = false;
  for (const double spacing : {0.0, -1.0, 8.5, std::nan("")}) {
    options.surface_patch_spacing = spacing;
    EXPECT_THROW(options.check(), OptionError) << spacing;
  }
  options.surface_patch_spacing = 1.5;
  for (const double angle : {0.0, -10.0, 90.5, std::nan("")}) {
    options.surface_patch_angle_degrees = angle;
    EXPECT_THROW(options.check(), OptionError) << angle;
  }
  // The command line's names, both ways.
  for (const SurfacePatchUse use : {SurfacePatchUse::Off, SurfacePatchUse::Oblique, SurfacePatchUse::On})
    EXPECT_EQ(surface_patch_use_from_string(to_string(use)), use);
  EXPECT_STREQ(to_string(SurfacePatchUse::Oblique), "oblique");
  EXPECT_THROW(surface_patch_use_from_string("yes"), InputError);
  EXPECT_THROW(surface_patch_use_from_string(""), InputError);
}

// SurfacePatchUse::Oblique: a vertex lays its patch on the surface exactly when one of its views is
// farther than the angle from its normal, and then g and ∇g are those of surface patches
// everywhere (On), else those of image patches (Off), bit for bit.
TEST(SurfacePatch, ObliqueVerticesAloneUseSurfacePatches) {
  const PlaneScene scene = oblique_plane_scene();  // views at 0°, 35°, 60° and 65° from the normal
  const Eigen::Vector3d X(1.3, -0.7, 0), N = Eigen::Vector3d::UnitZ();
  PhotoConsistencyOptions oblique;
  const auto uses = [&](std::vector<std::uint16_t> ids, double angle) {
    oblique.surface_patch_angle_degrees = angle;
    return uses_surface_patch(X, N, ids, scene.views, oblique);
  };
  EXPECT_FALSE(uses({0, 1}, 60));
  EXPECT_FALSE(uses({0, 1, 2}, 60.5));  // 60° is not beyond 60.5°
  EXPECT_TRUE(uses({0, 1, 2}, 59.5));
  EXPECT_TRUE(uses({0, 3}, 60));
  EXPECT_FALSE(uses({0, 3}, 66));
  EXPECT_TRUE(uses({1}, 30));
  EXPECT_FALSE(uses({}, 1));
  oblique.surface_patch_angle_degrees = 60;
  EXPECT_FALSE(uses_surface_patch(X, Eigen::Vector3d::Zero(), scene.all, scene.views, oblique));  // no normal
  oblique.normalize = true;
  EXPECT_FALSE(uses_surface_patch(X, N, scene.all, scene.views, oblique));
  oblique.normalize = false;
  PhotoConsistencyOptions on = oblique, off = oblique;
  on.surface_patch = SurfacePatchUse::On;
  off.surface_patch = SurfacePatchUse::Off;
  EXPECT_TRUE(uses_surface_patch(X, N, std::vector<std::uint16_t>{0, 1}, scene.views, on));
  EXPECT_FALSE(uses_surface_patch(X, N, scene.all, scene.views, off));

  // The gradient stage over a few points above and below the plane, seen by views 0–1 (frontal
  // enough: image patches) or by views 0–3 (the 65° view: surface patches).
  Mesh mesh;
  for (double x = -6; x <= 6; x += 3)
    for (const double z : {-1.5, 0.0, 2.0}) mesh.topology.add_vertex(to_openmesh(Eigen::Vector3d(x, 0.4 * x, z)));
  const auto run = [&](const PhotoConsistencyOptions& photo) {
    VertexFields fields;
    fields.resize(mesh.n_vertices(), scene.views.size());
    for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
      fields.normal[v] = N;
      fields.visible_count[v] = v % 2 ? 4 : 2;
      std::copy(scene.all.begin(), scene.all.end(), fields.visible_views.begin() + v * fields.view_capacity);
    }
    PhotoGradientOptions options;
    options.photo = photo;
    const PhotoGradientStage stage(options);
    stage.run(mesh.topology, {0, static_cast<std::uint32_t>(mesh.n_vertices())}, scene.views, stage.sample_spacing(4.0),
              fields);
    return fields;
  };
  const VertexFields mixed = run(oblique), surface = run(on), image = run(off);
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    const VertexFields& expected = v % 2 ? surface : image;
    ASSERT_TRUE(mixed.defined[v] & kGradientDefined) << v;
    EXPECT_EQ(mixed.photo_consistency[v], expected.photo_consistency[v]) << v;
    EXPECT_EQ(mixed.photo_gradient[v], expected.photo_gradient[v]) << v;
    // The two kinds of patch differ here, so the comparison tells them apart.
    EXPECT_NE(surface.photo_consistency[v], image.photo_consistency[v]) << v;
  }
  // g alone at the surface follows the same rule.
  SurfacePatchLayout layout;
  layout_surface_patch(X, N, scene.all, scene.views, 2, oblique.surface_patch_spacing, layout);
  EXPECT_EQ(photo_consistency_at_surface(X, N, scene.all, scene.views, oblique, layout).g,
            surface_patch_consistency(X, layout, scene.views).g);
  const std::vector<std::uint16_t> frontal{0, 1};
  EXPECT_EQ(photo_consistency_at_surface(X, N, frontal, scene.views, oblique, layout).g,
            photo_consistency(X, frontal, scene.views).g);
}

TEST(SurfacePatch, TheGradientStageRecordsEachVertexsKindAndItsSwitches) {
  const PlaneScene scene = oblique_plane_scene();  // views at 0°, 35°, 60° and 65° from the normal
  Mesh mesh;
  for (double x = -6; x <= 6; x += 3) mesh.topology.add_vertex(to_openmesh(Eigen::Vector3d(x, 0.4 * x, 0.5)));
  VertexFields fields;
  fields.resize(mesh.n_vertices(), scene.views.size());
  const auto run = [&](auto with_the_65_degree_view) {  // views 0–1 (image patch) or 0–3 (surface patch)
    for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
      fields.normal[v] = Eigen::Vector3d::UnitZ();
      fields.visible_count[v] = with_the_65_degree_view(v) ? 4 : 2;
      std::copy(scene.all.begin(), scene.all.end(), fields.visible_views.begin() + v * fields.view_capacity);
    }
    const PhotoGradientStage stage{PhotoGradientOptions{}};  // Oblique at 60°
    stage.run(mesh.topology, {0, static_cast<std::uint32_t>(mesh.n_vertices())}, scene.views, stage.sample_spacing(4.0),
              fields);
  };
  const auto odd = [](std::size_t v) { return v % 2 == 1; };
  const auto even = [](std::size_t v) { return v % 2 == 0; };
  const auto expect = [&](auto surface, auto switched, const char* when) {
    for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
      EXPECT_EQ(fields.patch_kind[v], surface(v) ? PatchKind::Surface : PatchKind::Image) << when << ", vertex " << v;
      EXPECT_EQ((fields.defined[v] & kPatchSwitched) != 0, switched(v)) << when << ", vertex " << v;
    }
  };
  ASSERT_EQ(fields.patch_kind[0], PatchKind::Undecided);
  run(odd);
  expect(odd, [](std::size_t) { return false; }, "first evaluation");  // nothing to switch from
  run(odd);
  expect(odd, [](std::size_t) { return false; }, "the same views again");
  run(even);
  expect(even, [](std::size_t) { return true; }, "the other views");
  run([](std::size_t v) { return v == 0 || v == 1; });
  expect([](std::size_t v) { return v == 0 || v == 1; }, [](std::size_t v) { return v == 1 || (v != 0 && v % 2 == 0); },
         "vertices 0 and 1 with the 65° view");
  fields.resize(mesh.n_vertices(), scene.views.size());  // a new topology
  EXPECT_EQ(fields.patch_kind[1], PatchKind::Undecided);
}

// The refinement's blurred copies serve the whole-pixel image patches only (DenoiseOptions): with
// other photographs given for the surface patches, a vertex that lays its patch on the surface
// gets exactly what it gets when every view is those photographs, and a vertex with an image
// patch exactly what it gets without them; likewise g alone (compute_photo_consistency).
TEST(SurfacePatch, SurfacePatchesReadTheirOwnPhotographs) {
  const PlaneScene scene = oblique_plane_scene();  // views at 0°, 35°, 60° and 65° from the normal
  const auto blurred = blurred_views(scene.views, 1.2);
  Mesh mesh;
  for (double x = -6; x <= 6; x += 3) mesh.topology.add_vertex(to_openmesh(Eigen::Vector3d(x, 0.4 * x, 0.5)));
  const auto odd = [](std::size_t v) { return v % 2 == 1; };  // with the 65° view: a surface patch
  const auto run = [&](const std::vector<PhotoView>& views, const std::vector<PhotoView>* surface_views) {
    VertexFields fields;
    fields.resize(mesh.n_vertices(), scene.views.size());
    for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
      fields.normal[v] = Eigen::Vector3d::UnitZ();
      fields.visible_count[v] = odd(v) ? 4 : 2;
      std::copy(scene.all.begin(), scene.all.end(), fields.visible_views.begin() + v * fields.view_capacity);
    }
    const IndexRange all{0, static_cast<std::uint32_t>(mesh.n_vertices())};
    const PhotoGradientStage stage{PhotoGradientOptions{}};  // Oblique at 60°
    stage.run(mesh.topology, all, views, stage.sample_spacing(4.0), fields, surface_views);
    VertexFields g_only = fields;
    compute_photo_consistency(mesh.topology, all, views, PhotoConsistencyOptions{}, g_only, surface_views);
    return std::pair{fields, g_only};
  };
  const auto [mixed, mixed_g] = run(blurred->views, &scene.views);  // image patches blurred, surface ones not
  const auto [given, given_g] = run(scene.views, nullptr);
  const auto [all_blurred, all_blurred_g] = run(blurred->views, nullptr);
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) {
    ASSERT_TRUE(mixed.defined[v] & kGradientDefined) << v;
    EXPECT_EQ(mixed.patch_kind[v], odd(v) ? PatchKind::Surface : PatchKind::Image) << v;
    const VertexFields& expected = odd(v) ? given : all_blurred;
    const VertexFields& expected_g = odd(v) ? given_g : all_blurred_g;
    EXPECT_EQ(mixed.photo_consistency[v], expected.photo_consistency[v]) << v;
    EXPECT_EQ(mixed.photo_gradient[v], expected.photo_gradient[v]) << v;
    EXPECT_EQ(mixed_g.photo_consistency[v], expected_g.photo_consistency[v]) << v;
    // ... and the blur changed the value, so the test tells the two apart.
    const VertexFields& other = odd(v) ? all_blurred : given;
    EXPECT_NE(mixed.photo_consistency[v], other.photo_consistency[v]) << v;
  }
}

}  // namespace
}  // namespace mvflow
