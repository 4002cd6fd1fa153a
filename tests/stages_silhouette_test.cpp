// Silhouettes: thresholding on the largest channel and disc dilation, against brute force.
#include <gtest/gtest.h>

#include <random>

#include "engine/model/camera.h"
#include "engine/model/error.h"
#include "stages/flow/silhouette.h"
#include "stages/flow/silhouette_constraint.h"

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

}  // namespace
}  // namespace mvflow
