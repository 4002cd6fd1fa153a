// Silhouettes: thresholding on the largest channel and disc dilation, against brute force; the
// visual-hull constraint and the rim fit against the analytic silhouettes of spheres.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include <Eigen/Geometry>

#include "engine/model/camera.h"
#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "stages/flow/silhouette.h"
#include "engine/model/primitives.h"
#include "engine/model/surface_query.h"
#include "stages/flow/silhouette_constraint.h"
#include "stages/flow/silhouette_rims.h"

namespace mvflow {
namespace {

Mask random_mask(int w, int h, double density, unsigned seed) {
  std::mt19937 random(seed);
  std::bernoulli_distribution object(density);
  Mask mask(w, h);
  for (auto& b : mask.inside) b = object(random);
  return mask;
}

Mask dilate_brute_force(const Mask& mask, int r) {
  Mask out(mask.width, mask.height);
  for (int y = 0; y < mask.height; ++y)
    for (int x = 0; x < mask.width; ++x)
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= mask.width || yy >= mask.height || dx * dx + dy * dy > r * r) continue;
          if (mask.at(xx, yy)) out.inside[static_cast<std::size_t>(y) * mask.width + x] = 1;
        }
  return out;
}

TEST(Silhouette, DilationEqualsBruteForceDisc) {
  for (int radius : {1, 2, 5, 10}) {
    const Mask mask = random_mask(47, 31, 0.01, 7u + radius);
    EXPECT_EQ(dilate_mask(mask, radius).inside, dilate_brute_force(mask, radius).inside) << "radius " << radius;
  }
}

TEST(Silhouette, DilatingASinglePixelGivesADiscOfTheRightArea) {
  Mask mask(101, 101);
  mask.inside[50 * 101 + 50] = 1;
  // Lattice points in a disc of radius 10: 317 (Gauss circle problem, N(10) = 317).
  EXPECT_EQ(dilate_mask(mask, 10).count(), 317u);
  EXPECT_EQ(dilate_mask(mask, 0).count(), 1u);
}

TEST(Silhouette, ThresholdUsesTheLargestChannel) {
  Image image(3, 1);
  image.set_pixel(0, 0, {0.1f, 0.1f, 0.1f});
  image.set_pixel(1, 0, {0.0f, 0.3f, 0.0f});  // dark in red and blue, bright in green
  image.set_pixel(2, 0, {0.19f, 0.19f, 0.19f});  // exactly at the threshold: background
  const Mask mask = threshold_silhouette(image, SilhouetteOptions{.threshold = 0.19, .dilate = 0});
  EXPECT_FALSE(mask.at(0, 0));
  EXPECT_TRUE(mask.at(1, 0));
  EXPECT_FALSE(mask.at(2, 0));
  EXPECT_EQ(mask_from_image(image).count(), 3u);
}

// One camera 5 units in front of the origin looking down +z (focal 100 px, 101×101 pixels), whose
// silhouette is the disc of radius 20 pixels around the image centre: on the plane z = 0 the
// pixel u = 50 + 20·x, so the hull's cross-section there is the disc |(x, y)| ≤ 1.
struct DiscScene {
  Camera camera{(Eigen::Matrix3d() << 100, 0, 50, 0, 100, 50, 0, 0, 1).finished(), Eigen::Matrix3d::Identity(),
                Eigen::Vector3d(0, 0, 5), 101, 101};
  Image image{101, 101};
  std::vector<Camera> cameras{camera};
  std::vector<PhotoView> views = make_photo_views(cameras, {&image});
  Mask disc() const {
    Mask mask(101, 101);
    for (int y = 0; y < 101; ++y)
      for (int x = 0; x < 101; ++x) mask.inside[y * 101 + x] = (x - 50) * (x - 50) + (y - 50) * (y - 50) <= 400;
    return mask;
  }
};

TEST(SilhouetteConstraint, AdmitsWhatProjectsIntoTheSilhouetteOrOutsideTheImage) {
  const DiscScene s;
  const SilhouetteConstraint inside(s.views, {s.disc()});
  EXPECT_TRUE(inside.admits({0.5, 0.0, 0.0}));
  EXPECT_TRUE(inside.admits({0.0, -0.99, 0.0}));
  EXPECT_FALSE(inside.admits({1.1, 0.0, 0.0}));   // u = 72: outside the disc
  EXPECT_FALSE(inside.admits({0.8, 0.8, 0.0}));   // radius 1.13
  EXPECT_TRUE(inside.admits({10.0, 0.0, 0.0}));   // u = 250: the view does not see it
  EXPECT_TRUE(inside.admits({1.5, 0.0, -10.0}));  // behind the camera
}

TEST(SilhouetteConstraint, StopsMovesOutOfTheHullButNotMovesOfPointsAlreadyOutside) {
  const DiscScene s;
  const SilhouetteConstraint inside(s.views, {s.disc()});
  const Eigen::Vector3d centre(0, 0, 0);
  EXPECT_EQ(inside.limit_move(centre, {0.9, 0, 0}), Eigen::Vector3d(0.9, 0, 0));  // stays inside
  EXPECT_EQ(inside.limit_move(centre, {1.6, 0, 0}), Eigen::Vector3d(0.8, 0, 0));  // halved once
  // From 0.9 toward 2.4: the halvings reach 1.65, 1.275, 1.0875 (outside) and 0.99375 (u = 69.875,
  // the disc's last pixel).
  const Eigen::Vector3d from(0.9, 0, 0), to(2.4, 0, 0);
  EXPECT_EQ(inside.limit_move(from, to), from + 0.0625 * (to - from));
  // From 0.99 every halving (1.695 .. 1.034, u ≥ 70.7) is outside: the vertex stays.
  EXPECT_EQ(inside.limit_move({0.99, 0, 0}, to), Eigen::Vector3d(0.99, 0, 0));
  EXPECT_EQ(inside.limit_move({2, 0, 0}, {3, 0, 0}), Eigen::Vector3d(3, 0, 0));  // already outside: free
  EXPECT_THROW(SilhouetteConstraint(s.views, {}), Error);
  EXPECT_THROW(SilhouetteConstraint(s.views, {Mask(100, 101)}), Error);
}

// The rim of a sphere of radius R around the origin seen from DiscScene's camera (centre
// (0, 0, −5), focal 100 px): the circle where N·(X − C) = 0, i.e. z = −R²/5; its point on the
// +x side, its image distance from the principal point (100·R/√(25 − R²)), and how many pixels
// that distance grows per unit of radius there (d/dδ of the projection of X·(1 + δ/R)).
struct SphereRim {
  Eigen::Vector3d point, normal;
  double image_radius, pixels_per_unit;
  explicit SphereRim(double R) {
    const double z = -R * R / 5, x = std::sqrt(R * R - z * z);
    point = {x, 0, z};
    normal = point / R;
    image_radius = 100 * R / std::sqrt(25 - R * R);
    pixels_per_unit = 100 * x * 5 / (R * (z + 5) * (z + 5));
  }
};

// DiscScene's mask has pixels up to 20 from the centre: the boundary along +x lies at 20.5 px.
constexpr double kDiscBoundary = 20.5;

SilhouetteRimOptions whole_step(double dead_zone) {
  SilhouetteRimOptions options;
  options.fit = RimFit::On;
  options.step = 1.0;
  options.dead_zone_pixels = dead_zone;
  return options;
}

TEST(SilhouetteRims, MoveARimOutwardOrInwardOntoTheBoundaryWithinHalfAPixel) {
  const DiscScene s;
  const std::vector<Mask> masks{s.disc()};
  for (const double R : {0.9, 1.1}) {  // image radius 18.30 px (inside the disc), 22.55 px (outside)
    const SphereRim rim(R);
    const double pixels = kDiscBoundary - rim.image_radius;  // + outward
    const double move = rim_move(rim.point, rim.normal, s.views, masks, nullptr, 1.0, whole_step(0.0));
    // The walk finds the boundary in half-pixel steps: within half a pixel of the analytic one.
    EXPECT_NEAR(move * rim.pixels_per_unit, pixels, 0.5) << "R = " << R;
    EXPECT_GT(std::abs(move), 0.0);
    // The dead zone is taken off the distance; the step scales the move. (The stage measures the
    // pixels per unit over about one pixel: within 1 % of the analytic derivative.)
    SilhouetteRimOptions options = whole_step(1.0);
    options.step = 0.2;
    const double damped = rim_move(rim.point, rim.normal, s.views, masks, nullptr, 1.0, options);
    const double expected = 0.2 * (move - std::copysign(1.0, move) / rim.pixels_per_unit);
    EXPECT_NEAR(damped, expected, 0.01 * std::abs(expected)) << "R = " << R;
  }
}

TEST(SilhouetteRims, LeaveWhatIsNoRimNearTheBoundaryOrHidden) {
  const DiscScene s;
  const std::vector<Mask> masks{s.disc()};
  const SphereRim rim(0.9);
  // Facing the camera: not a rim.
  EXPECT_EQ(rim_move({0, 0, -0.9}, {0, 0, -1}, s.views, masks, nullptr, 1.0, whole_step(0.0)), 0.0);
  // Tilted 20° from the rim: beyond the 8° rim angle.
  const Eigen::Vector3d tilted = Eigen::AngleAxisd(20 * std::numbers::pi / 180, Eigen::Vector3d::UnitY()) * rim.normal;
  EXPECT_EQ(rim_move(rim.point, tilted, s.views, masks, nullptr, 1.0, whole_step(0.0)), 0.0);
  // The boundary 2.2 px away lies within a 3-pixel dead zone.
  EXPECT_EQ(rim_move(rim.point, rim.normal, s.views, masks, nullptr, 1.0, whole_step(3.0)), 0.0);
  // Beyond the search distance: R = 0.7 is 14.3 px out, 6.2 px inside the boundary.
  const SphereRim far(0.7);
  EXPECT_EQ(rim_move(far.point, far.normal, s.views, masks, nullptr, 1.0, whole_step(0.0)), 0.0);
  // A ball halfway to the camera hides the rim: this view's outline is not made by it.
  const Eigen::Vector3d centre = 0.5 * (rim.point + Eigen::Vector3d(0, 0, -5));
  const SurfaceQuery occluder(make_icosphere(0.2, 2, centre));
  EXPECT_EQ(rim_move(rim.point, rim.normal, s.views, masks, &occluder, 0.01, whole_step(0.0)), 0.0);
  const SurfaceQuery aside(make_icosphere(0.2, 2, Eigen::Vector3d(-2, 0, -2)));
  EXPECT_GT(rim_move(rim.point, rim.normal, s.views, masks, &aside, 0.01, whole_step(0.0)), 0.0);
  // The views counted are those whose outline the point makes: one here, none when hidden.
  int rim_views = -1;
  rim_move(rim.point, rim.normal, s.views, masks, &aside, 0.01, whole_step(0.0), &rim_views);
  EXPECT_EQ(rim_views, 1);
  rim_move(rim.point, rim.normal, s.views, masks, &occluder, 0.01, whole_step(0.0), &rim_views);
  EXPECT_EQ(rim_views, 0);
  rim_move(rim.point, rim.normal, s.views, masks, nullptr, 1.0, whole_step(3.0), &rim_views);
  EXPECT_EQ(rim_views, 1);  // within the dead zone: no move, but the silhouette still observes it
  SilhouetteRimOptions bad = whole_step(0.0);
  bad.search_pixels = 0.0;
  EXPECT_THROW(bad.check(), OptionError);
}

TEST(SilhouetteRims, RunByDefaultOnlyWhenEveryViewsBorderIsDark) {
  // A bright object in the middle of a 20×10 image; its border has 2·20 + 2·8 = 56 pixels.
  const auto view_of = [](const Image& image) {
    const Camera camera((Eigen::Matrix3d() << 20, 0, 10, 0, 20, 5, 0, 0, 1).finished(), Eigen::Matrix3d::Identity(),
                        Eigen::Vector3d(0, 0, 5), image.width(), image.height());
    return camera;
  };
  Image dark(20, 10), lit(20, 10);
  for (int y = 3; y < 7; ++y)
    for (int x = 5; x < 15; ++x) {
      dark.set_pixel(x, y, Eigen::Vector3f(0.9f, 0.9f, 0.9f));
      lit.set_pixel(x, y, Eigen::Vector3f(0.9f, 0.9f, 0.9f));
    }
  for (int x = 0; x < 3; ++x) lit.set_pixel(x, 0, Eigen::Vector3f(0.1f, 0.5f, 0.1f));  // 3 of 56 lit: 94.6 % dark
  const std::vector<Camera> cameras{view_of(dark), view_of(lit)};
  const std::vector<PhotoView> both = make_photo_views(cameras, {&dark, &lit});
  const std::vector<PhotoView> only_dark = make_photo_views({cameras[0]}, {&dark});
  EXPECT_TRUE(dark_background(only_dark, 0.19, 0.95));
  EXPECT_FALSE(dark_background(both, 0.19, 0.95));  // one view is not dark enough all round
  EXPECT_TRUE(dark_background(both, 0.19, 0.94));
  EXPECT_TRUE(dark_background(both, 0.5, 0.95));    // 0.5 is not above 0.5
  EXPECT_FALSE(dark_background({}, 0.19, 0.95));
  SilhouetteRimOptions options;
  EXPECT_EQ(options.fit, RimFit::Auto);
  EXPECT_TRUE(fits_rims(only_dark, 0.19, options));
  EXPECT_FALSE(fits_rims(both, 0.19, options));
  options.fit = RimFit::On;
  EXPECT_TRUE(fits_rims(both, 0.19, options));
  options.fit = RimFit::Off;
  EXPECT_FALSE(fits_rims(only_dark, 0.19, options));
}

TEST(SilhouetteRims, FillTheHolesOfThresholdedSilhouettesAndIgnoreTheDilation) {
  // A 20×20 bright square with a dark 2×2 hole in a 40×40 image.
  Image image(40, 40);
  for (int y = 10; y < 30; ++y)
    for (int x = 10; x < 30; ++x)
      if (!(x >= 19 && x < 21 && y >= 19 && y < 21)) image.set_pixel(x, y, Eigen::Vector3f(0.8f, 0.8f, 0.8f));
  const Camera camera((Eigen::Matrix3d() << 40, 0, 20, 0, 40, 20, 0, 0, 1).finished(), Eigen::Matrix3d::Identity(),
                      Eigen::Vector3d(0, 0, 5), 40, 40);
  const std::vector<Camera> cameras{camera};
  const std::vector<PhotoView> views = make_photo_views(cameras, {&image});
  SilhouetteRimOptions options;
  const std::vector<Mask> masks = rim_silhouettes(views, SilhouetteOptions{.threshold = 0.19, .dilate = 3}, options);
  EXPECT_EQ(masks.at(0).count(), 400u);  // the square, its hole filled, not dilated
  options.fill_holes = 0.0;
  EXPECT_EQ(rim_silhouettes(views, SilhouetteOptions{.threshold = 0.19, .dilate = 3}, options).at(0).count(), 396u);
}

}  // namespace
}  // namespace mvflow
