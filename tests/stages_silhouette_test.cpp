// Silhouettes: thresholding on the largest channel and disc dilation, against brute force.
#include <gtest/gtest.h>

#include <random>

#include "stages/silhouette.h"

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

}  // namespace
}  // namespace mvflow
