// The held-out-view error: the ground truth scores better than a perturbed mesh on views it never
// saw; the metrics against hand computation; the colouring never reads a held-out photograph;
// the colour of a surface point; determinism and bad input.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <tbb/task_arena.h>

#include "engine/model/error.h"
#include "engine/model/primitives.h"
#include "stages/eval/heldout_error.h"
#include "stages/synth/synth_scene.h"

namespace mvflow {
namespace {

// A small rendered scene: bumpy sphere, 16 ring views of 320×240 on a black background, and the
// synthetic initial mesh (truth smoothed, pushed out by 1 % of the diagonal, 300 vertices).
struct SmallScene {
  std::vector<View> views;
  std::vector<Image> images;
  Mesh truth;
  Mesh initial;
};

const SmallScene& small_scene() {
  static const SmallScene cached = [] {
    SynthOptions options;
    options.rig.views = 16;
    options.rig.width = 320;
    options.rig.height = 240;
    options.render.background = BackgroundKind::Black;
    options.init.vertices = 300;
    BuiltinShapeOptions shape;
    shape.level = 4;
    const IndexedMesh truth = make_builtin_object("bumpy-sphere", shape);
    SynthScene synth = make_synth_scene(truth, nullptr, options);
    return SmallScene{synth.views, synth.images, build_mesh(truth, "truth"),
                      build_mesh(synth.initial, "initial")};
  }();
  return cached;
}

// A scene over \p images (the small scene's cameras).
Scene make_scene(const std::vector<Image>& images) { return in_memory_scene(small_scene().views, images); }

Image noise_image(int width, int height, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  Image image(width, height);
  for (int i = 0; i < 3 * width * height; ++i) image.data()[i] = value(random);
  return image;
}

bool same_pixels(const Image& a, const Image& b) {
  return a.width() == b.width() && a.height() == b.height() &&
         std::equal(a.data(), a.data() + 3 * a.width() * a.height(), b.data());
}

// The synthetic background is exactly black, so a low threshold finds every object pixel.
const SilhouetteOptions kSynthSilhouette{.threshold = 0.02, .dilate = 0};

HeldoutMetrics score(const Scene& scene, const Mesh& mesh, const std::vector<int>& views) {
  const HeldoutRenderer renderer(scene, mesh, views);
  HeldoutMetrics all;
  for (int view : views) {
    const Image& photo = scene.image(static_cast<std::size_t>(view));
    all +=
        compare_with_photograph(renderer.render(view), photo, threshold_silhouette(photo, kSynthSilhouette));
  }
  return all;
}

TEST(Heldout, TruthScoresClearlyBetterThanThePerturbedInitialMesh) {
  const Scene scene = make_scene(small_scene().images);
  const std::vector<int> views{3, 10};
  const HeldoutMetrics truth = score(scene, small_scene().truth, views);
  const HeldoutMetrics initial = score(scene, small_scene().initial, views);
  std::printf("truth:   MAE %.5f, PSNR %.2f dB, silhouette %.5f, unseen %zu of %zu\n", truth.mae(),
              truth.psnr(), truth.silhouette_disagreement(), truth.unseen_pixels, truth.union_pixels);
  std::printf("initial: MAE %.5f, PSNR %.2f dB, silhouette %.5f, unseen %zu of %zu\n", initial.mae(),
              initial.psnr(), initial.silhouette_disagreement(), initial.unseen_pixels, initial.union_pixels);
  ASSERT_GT(truth.scored_pixels, 10000u);  // the object fills a good part of two 320×240 views
  EXPECT_EQ(truth.scored_pixels + truth.unseen_pixels, truth.union_pixels);
  EXPECT_LT(truth.unseen_pixels, truth.union_pixels / 100);  // 15 ring views see almost everything
  // The truth predicts the photographs much better than the initial mesh (what remains for the
  // truth: bilinear resampling, anti-aliasing at the edges, shading from smooth normals).
  EXPECT_LT(truth.mae(), 0.25 * initial.mae());
  EXPECT_GT(truth.psnr(), initial.psnr() + 10.0);
  EXPECT_LT(truth.silhouette_disagreement(), 0.25 * initial.silhouette_disagreement());
}

TEST(Heldout, RenderingComparedWithItselfHasNoError) {
  const Scene scene = make_scene(small_scene().images);
  const HeldoutRenderer renderer(scene, small_scene().truth, {5});
  const HeldoutRendering r = renderer.render(5);
  const HeldoutMetrics m = compare_with_photograph(r, r.image, r.silhouette);
  ASSERT_GT(m.scored_pixels, 0u);
  EXPECT_EQ(m.union_pixels, r.silhouette.count());
  EXPECT_EQ(m.disagreeing_pixels, 0u);
  EXPECT_EQ(m.silhouette_disagreement(), 0.0);
  EXPECT_EQ(m.mae(), 0.0);
  EXPECT_TRUE(std::isinf(m.psnr()));
}

TEST(Heldout, ConstantOffsetGivesItsMaeAndPsnr) {
  const Scene scene = make_scene(small_scene().images);
  const HeldoutRenderer renderer(scene, small_scene().truth, {5});
  const HeldoutRendering r = renderer.render(5);
  Image shifted = r.image;
  const float offset = 0.1f;
  for (int i = 0; i < 3 * shifted.width() * shifted.height(); ++i) shifted.data()[i] += offset;
  const HeldoutMetrics m = compare_with_photograph(r, shifted, r.silhouette);
  // |a − (a + 0.1f)| in float: 0.1 up to rounding of a + 0.1f (≤ 2^-24·1.1).
  EXPECT_NEAR(m.mae(), 0.1, 1e-6);
  EXPECT_NEAR(m.psnr(), 20.0, 1e-4);  // 10·log10(1 / 0.1²)
  EXPECT_EQ(m.silhouette_disagreement(), 0.0);
}

TEST(Heldout, MetricsOfAHandComputedCase) {
  // 2×2 pixels: rendered silhouette {(0,0), (1,0)}, real {(1,0), (0,1)}, (0,0) unseen.
  HeldoutRendering r{Image(2, 2), Mask(2, 2), {1, 0, 0, 0}};
  r.silhouette.inside = {1, 1, 0, 0};
  Mask real(2, 2);
  real.inside = {0, 1, 1, 0};
  Image photo(2, 2);
  r.image.set_pixel(0, 0, {0.9f, 0.9f, 0.9f});  // unseen: not scored whatever its value
  r.image.set_pixel(1, 0, {0.5f, 0.5f, 0.5f});
  photo.set_pixel(1, 0, {0.2f, 0.5f, 0.8f});  // |Δ| = 0.3, 0, 0.3
  photo.set_pixel(0, 1, {0.6f, 0.6f, 0.6f});  // rendered background 0: |Δ| = 0.6 ×3
  photo.set_pixel(1, 1, {1.0f, 1.0f, 1.0f});  // outside both silhouettes: ignored
  const HeldoutMetrics m = compare_with_photograph(r, photo, real);
  EXPECT_EQ(m.union_pixels, 3u);
  EXPECT_EQ(m.disagreeing_pixels, 2u);
  EXPECT_EQ(m.unseen_pixels, 1u);
  EXPECT_EQ(m.scored_pixels, 2u);
  EXPECT_NEAR(m.silhouette_disagreement(), 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(m.mae(), (0.3 + 0.3 + 3 * 0.6) / 6, 1e-6);
  const double mse = (0.09 + 0.09 + 3 * 0.36) / 6;
  EXPECT_NEAR(m.mse(), mse, 1e-6);
  EXPECT_NEAR(m.psnr(), 10 * std::log10(1 / mse), 1e-5);
  // Pooling two comparisons pools their pixels.
  HeldoutMetrics twice = m;
  twice += m;
  EXPECT_NEAR(twice.mae(), m.mae(), 1e-12);
  EXPECT_EQ(twice.union_pixels, 6u);
}

TEST(Heldout, ColouringNeverReadsAHeldOutPhotograph) {
  const SmallScene& s = small_scene();
  const std::vector<int> held_out{2, 7};
  std::vector<Image> noisy = s.images;
  noisy[2] = noise_image(320, 240, 1);
  noisy[7] = noise_image(320, 240, 2);
  const Scene clean_scene = make_scene(s.images), noisy_scene = make_scene(noisy);
  const HeldoutRenderer clean(clean_scene, s.initial, held_out), dirty(noisy_scene, s.initial, held_out);
  EXPECT_EQ(clean.colouring_views(), (std::vector<int>{0, 1, 3, 4, 5, 6, 8, 9, 10, 11, 12, 13, 14, 15}));
  for (int view : held_out)
    EXPECT_TRUE(same_pixels(clean.render(view).image, dirty.render(view).image)) << view;

  // The check is sensitive: noise in a colouring view next to view 2 does change its rendering.
  std::vector<Image> other = s.images;
  other[3] = noise_image(320, 240, 3);
  const Scene other_scene = make_scene(other);
  EXPECT_FALSE(
      same_pixels(clean.render(2).image, HeldoutRenderer(other_scene, s.initial, held_out).render(2).image));
}

TEST(Heldout, SameImageWhateverTheThreadCount) {
  const Scene scene = make_scene(small_scene().images);
  // The caller chooses the threads (an arena); the stage only splits its rows.
  auto render_with = [&](int threads) {
    tbb::task_arena arena(threads);
    return arena.execute([&] { return HeldoutRenderer(scene, small_scene().initial, {4}).render(4); });
  };
  const HeldoutRendering a = render_with(1);
  const HeldoutRendering b = render_with(2);
  EXPECT_TRUE(same_pixels(a.image, b.image));
  EXPECT_EQ(a.silhouette.inside, b.silhouette.inside);
  EXPECT_EQ(a.unseen, b.unseen);
}

TEST(Heldout, PixelsNoOtherViewSeesAreCountedNotScored) {
  // Hold out every view but 0: view 8, on the other side of the ring, sees mostly points that
  // view 0 cannot see.
  const Scene scene = make_scene(small_scene().images);
  std::vector<int> held_out;
  for (int i = 1; i < 16; ++i) held_out.push_back(i);
  const HeldoutRenderer renderer(scene, small_scene().truth, held_out);
  EXPECT_EQ(renderer.colouring_views(), std::vector<int>{0});
  const HeldoutRendering r = renderer.render(8);
  const Image& photo = scene.image(8);
  const HeldoutMetrics m = compare_with_photograph(r, photo, threshold_silhouette(photo, kSynthSilhouette));
  EXPECT_GT(m.unseen_pixels, m.union_pixels / 2);
  EXPECT_EQ(m.scored_pixels + m.unseen_pixels, m.union_pixels);
  for (std::size_t i = 0; i < r.unseen.size(); ++i)
    if (r.unseen[i]) {
      ASSERT_TRUE(r.silhouette.inside[i]) << i;  // unseen pixels are on the mesh
      ASSERT_EQ(r.image.pixel(static_cast<int>(i % 320), static_cast<int>(i / 320)), Eigen::Vector3f::Zero());
    }
  // The panel paints them magenta in the rendering and the error map.
  const Image panel = heldout_panel(photo, r, threshold_silhouette(photo, kSynthSilhouette));
  ASSERT_EQ(panel.width(), 3 * 320);
  const auto first =
      static_cast<std::size_t>(std::find(r.unseen.begin(), r.unseen.end(), 1) - r.unseen.begin());
  const int x = static_cast<int>(first % 320), y = static_cast<int>(first / 320);
  EXPECT_EQ(panel.pixel(320 + x, y), Eigen::Vector3f(1, 0, 1));
  EXPECT_EQ(panel.pixel(640 + x, y), Eigen::Vector3f(1, 0, 1));
  EXPECT_EQ(panel.pixel(x, y), photo.pixel(x, y));
}

TEST(Heldout, BadViewsAreInputErrors) {
  const Scene scene = make_scene(small_scene().images);
  const Mesh& mesh = small_scene().truth;
  try {
    HeldoutRenderer(scene, mesh, {3, 16});
    FAIL() << "view 16 of 16 accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("view 16 does not exist"), std::string::npos) << message;
    EXPECT_NE(message.find("16 views"), std::string::npos) << message;
  }
  EXPECT_THROW(HeldoutRenderer(scene, mesh, {-1}), InputError);
  EXPECT_THROW(HeldoutRenderer(scene, mesh, {}), InputError);
  EXPECT_THROW(HeldoutRenderer(scene, mesh, {4, 4}), InputError);
  std::vector<int> all(16);
  for (int i = 0; i < 16; ++i) all[static_cast<std::size_t>(i)] = i;
  EXPECT_THROW(HeldoutRenderer(scene, mesh, all), InputError);
  // Scoring a view that coloured the mesh is a misuse.
  EXPECT_THROW(HeldoutRenderer(scene, mesh, {3}).render(4), Error);
}

// --- The colour of one surface point ---

// A camera on +z at \p distance looking at the origin, 64×64.
Camera camera_on_z(double distance) {
  Eigen::Matrix3d K;
  K << 80, 0, 31.5, 0, 80, 31.5, 0, 0, 1;
  const Eigen::Matrix3d R = Eigen::Vector3d(1, -1, -1).asDiagonal();  // looks down −z
  return Camera(K, R, -R * Eigen::Vector3d(0, 0, distance), 64, 64);
}

TEST(PointColouring, MeanOfTheViewsThatSeeThePoint) {
  const IndexedMesh sphere = make_icosphere(1.0, 3);
  const SurfaceQuery surface(sphere);
  const Camera near = camera_on_z(4.0), far = camera_on_z(6.0);
  const Image a = noise_image(64, 64, 5), b = noise_image(64, 64, 6);
  const std::vector<Camera> cameras{near, far};  // the views point into it
  const std::vector<PhotoView> views = make_photo_views(cameras, {&a, &b});
  // Where the near camera's central ray meets the mesh.
  const Ray ray = near.ray(31.5, 31.5);
  const auto hit = surface.intersect(ray.origin, ray.direction);
  ASSERT_TRUE(hit);
  const Eigen::Vector3d point = ray.origin + hit->distance * ray.direction;
  const Eigen::Vector3d normal(0, 0, 1);
  const PointColour c = colour_surface_point(point, normal, views, surface, 0.1);
  EXPECT_EQ(c.views, 2);
  const Projection pa = near.project(point), pb = far.project(point);
  const Eigen::Vector3f expected = 0.5f * (a.sample_bilinear(pa.u, pa.v) + b.sample_bilinear(pb.u, pb.v));
  EXPECT_LT((c.colour - expected).norm(), 1e-6f);

  // The back of the sphere faces away from both cameras.
  EXPECT_EQ(colour_surface_point(-point, -normal, views, surface, 0.1).views, 0);
  // 67° from the pole the directions to the cameras are 81° (near) and 76° (far) from the normal.
  const double theta = 67.0 * std::numbers::pi / 180.0;
  const Eigen::Vector3d grazing(std::sin(theta), 0, std::cos(theta));
  EXPECT_EQ(colour_surface_point(grazing, grazing, views, surface, 0.1).views, 0);
  EXPECT_EQ(colour_surface_point(grazing, grazing, views, surface, 0.1, {.max_angle_degrees = 85.0}).views,
            2);
}

TEST(PointColouring, OccludedViewsDoNotColour) {
  // A small sphere in front of the big one hides its front pole from the camera on +z.
  IndexedMesh scene = make_icosphere(1.0, 3);
  const IndexedMesh blocker = make_icosphere(0.2, 2, Eigen::Vector3d(0, 0, 2));
  const auto base = static_cast<std::uint32_t>(scene.positions.size());
  scene.positions.insert(scene.positions.end(), blocker.positions.begin(), blocker.positions.end());
  for (auto t : blocker.triangles) scene.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  const SurfaceQuery surface(scene);
  const Camera camera = camera_on_z(4.0);
  const Image image = noise_image(64, 64, 7);
  const std::vector<Camera> cameras{camera};
  const std::vector<PhotoView> views = make_photo_views(cameras, {&image});
  const Eigen::Vector3d pole(0, 0, 1);
  EXPECT_EQ(colour_surface_point(pole, pole, views, surface, 0.1).views, 0);
  const Eigen::Vector3d side = Eigen::Vector3d(0.6, 0, 0.8);  // the blocker's shadow misses it
  EXPECT_EQ(colour_surface_point(side, side, views, surface, 0.1).views, 1);
}

}  // namespace
}  // namespace mvflow
