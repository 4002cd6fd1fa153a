// The photographs' noise (stages/flow/image_noise.h): Immerkær's estimate against known cases.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "engine/model/image.h"
#include "engine/model/option_check.h"
#include "stages/flow/image_noise.h"
#include "stages/flow/stopping.h"

namespace mvflow {
namespace {

// A 640×480 image whose three channels are a + b·x + c·y (different per channel) plus, when
// sigma > 0, the same Gaussian noise of that σ in every channel (so the grey value's noise is σ).
Image ramp(double sigma, unsigned seed = 1) {
  const int width = 640, height = 480;
  std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3);
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, sigma > 0 ? sigma : 1.0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double n = sigma > 0 ? noise(random) : 0.0;
      float* p = rgb.data() + (static_cast<std::size_t>(y) * width + x) * 3;
      p[0] = static_cast<float>(0.2 + 0.0005 * x + 0.0003 * y + n);
      p[1] = static_cast<float>(0.6 - 0.0002 * x + 0.0001 * y + n);
      p[2] = static_cast<float>(0.4 + 0.0004 * y + n);
    }
  return Image(width, height, rgb);
}

TEST(ImageNoise, APlaneHasNoneAndGaussianNoiseIsRecovered) {
  // The mask cancels any planar intensity: only the float rounding of the values is left.
  EXPECT_LT(estimate_image_noise(ramp(0.0)), 1e-6);
  // E|Σ M·n| = σ·‖M‖·√(2/π) with ‖M‖ = 6: the estimate is σ on average (the flattest tenth: some
  // 30 000 responses, chosen by a gradient independent of them on noise; within 3 %).
  for (const double sigma : {0.002, 0.01, 0.03}) {
    const double estimate = estimate_image_noise(ramp(sigma, static_cast<unsigned>(1000 * sigma)));
    EXPECT_NEAR(estimate / sigma, 1.0, 0.03) << sigma;
  }
  EXPECT_EQ(estimate_image_noise(Image(2, 5)), 0.0);
  EXPECT_EQ(estimate_image_noise(Image()), 0.0);
}

// Fine texture answers the mask as noise does: on an image whose left half is a fine sinusoidal
// texture and whose right half is a plane, the whole-image mean reads the texture; the flattest
// pixels (the plane's) read the noise alone.
TEST(ImageNoise, TextureIsNotReadAsNoise) {
  const int width = 640, height = 480;
  const auto half_textured = [&](double sigma, unsigned seed) {
    std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3);
    std::mt19937 random(seed);
    std::normal_distribution<double> noise(0.0, sigma > 0 ? sigma : 1.0);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const double texture = x < width / 2 ? 0.4 * std::sin(1.3 * x) * std::sin(0.9 * y) : 0.0;
        const double value = 0.5 + 0.0003 * x + texture + (sigma > 0 ? noise(random) : 0.0);
        std::fill_n(rgb.data() + (static_cast<std::size_t>(y) * width + x) * 3, 3, static_cast<float>(value));
      }
    return Image(width, height, rgb);
  };
  // The mask's mean over the whole clean image: what the estimate would read without the choice.
  const Image clean = half_textured(0.0, 1);
  double whole = 0.0;
  for (int y = 1; y + 1 < height; ++y)
    for (int x = 1; x + 1 < width; ++x) {
      const auto at = [&](int dx, int dy) { return static_cast<double>(clean.data()[((y + dy) * width + x + dx) * 3]); };
      whole += std::abs(at(-1, -1) + at(1, -1) + at(-1, 1) + at(1, 1) - 2 * (at(0, -1) + at(0, 1) + at(-1, 0) + at(1, 0)) +
                        4 * at(0, 0));
    }
  whole *= std::sqrt(std::numbers::pi / 2.0) / (6.0 * (width - 2) * (height - 2));
  EXPECT_GT(whole, 0.015);  // more than either σ below
  EXPECT_LT(estimate_image_noise(clean), 1e-6);
  for (const double sigma : {0.002, 0.01}) {
    const double estimate = estimate_image_noise(half_textured(sigma, static_cast<unsigned>(1000 * sigma)));
    EXPECT_NEAR(estimate / sigma, 1.0, 0.05) << sigma;
  }
}

// A photograph's black background (clipped, exactly 0) is its flattest part but says nothing about
// the noise: the estimate reads the rest. Here three quarters of the image are black.
TEST(ImageNoise, AClippedBackgroundIsNotRead) {
  const Image noisy = ramp(0.01, 9);
  std::vector<float> rgb(noisy.data(), noisy.data() + static_cast<std::size_t>(noisy.width()) * noisy.height() * 3);
  for (int y = 0; y < noisy.height(); ++y)
    for (int x = 0; x < noisy.width(); ++x)
      if (x < noisy.width() / 2 || y < noisy.height() / 2)
        std::fill_n(rgb.data() + (static_cast<std::size_t>(y) * noisy.width() + x) * 3, 3, 0.0f);
  EXPECT_NEAR(estimate_image_noise(Image(noisy.width(), noisy.height(), rgb)) / 0.01, 1.0, 0.05);
  EXPECT_EQ(estimate_image_noise(Image(8, 8)), 0.0);  // all black: nothing to read
}

TEST(ImageNoise, TheViewsNoiseIsTheMedianOfTheirs) {
  const std::vector<Image> images = {ramp(0.01, 3), ramp(0.002, 4), ramp(0.03, 5), ramp(0.005, 6)};
  std::vector<double> each;
  std::vector<PhotoView> views(images.size());
  for (std::size_t i = 0; i < images.size(); ++i) {
    views[i].image = &images[i];
    each.push_back(estimate_image_noise(images[i]));
  }
  EXPECT_EQ(estimate_views_noise({}), 0.0);
  // Four views: the lower middle one (σ 0.005); three (the first three): the middle (σ 0.01).
  EXPECT_EQ(estimate_views_noise(views), each[3]);
  views.pop_back();
  EXPECT_EQ(estimate_views_noise(views), each[0]);
}

TEST(ImageNoise, NoisierPhotographsRaiseTheSettledToleranceByTheSquareRoot) {
  const StoppingOptions off{.settled_noise_reference = 0.0};  // the tolerance as given, whatever the noise
  EXPECT_EQ(settled_tolerance_for_noise(off, 0.01), off.settled_tolerance);
  const StoppingOptions options{.settled_tolerance = 0.002, .settled_noise_reference = 0.001};
  EXPECT_EQ(settled_tolerance_for_noise(options, 0.0), 0.002);
  EXPECT_EQ(settled_tolerance_for_noise(options, 0.001), 0.002);  // at the reference: unchanged
  EXPECT_DOUBLE_EQ(settled_tolerance_for_noise(options, 0.004), 0.004);
  EXPECT_DOUBLE_EQ(settled_tolerance_for_noise(options, 0.009), 0.006);
  EXPECT_EQ(settled_tolerance_for_noise({.settled_tolerance = 0.002, .settled_noise_reference = 0.0}, 0.009), 0.002);
  EXPECT_EQ(settled_tolerance_for_noise({.settled_tolerance = 0.0}, 0.009), 0.0);  // the rule off stays off
  EXPECT_THROW((StoppingOptions{.settled_noise_reference = -0.001}).check(), OptionError);
  EXPECT_THROW((StoppingOptions{.settled_noise_reference = INFINITY}).check(), OptionError);
}

// The default reference (0.002, README "Convergence") against what the estimate reads on 8-bit
// images: a plane rounded to 8 bits reads far below it, so it keeps the tolerance as given; with
// σ = 0.01 of noise the rounding changes the estimate by little and the tolerance rises by √(σ̂/0.002).
TEST(ImageNoise, CleanEightBitImagesKeepTheToleranceNoisyOnesRaiseIt) {
  const auto eight_bit = [](const Image& image) {
    std::vector<float> rgb(image.data(), image.data() + static_cast<std::size_t>(image.width()) * image.height() * 3);
    for (float& value : rgb) value = std::round(std::clamp(value, 0.0f, 1.0f) * 255.0f) / 255.0f;
    return Image(image.width(), image.height(), rgb);
  };
  const double clean = estimate_image_noise(eight_bit(ramp(0.0)));
  EXPECT_LT(clean, 0.0005);
  const StoppingOptions options;
  EXPECT_EQ(settled_tolerance_for_noise(options, clean), options.settled_tolerance);
  const double noisy = estimate_image_noise(eight_bit(ramp(0.01, 7)));
  EXPECT_NEAR(noisy, 0.01, 0.0005);
  EXPECT_NEAR(settled_tolerance_for_noise(options, noisy), 0.0025 * std::sqrt(noisy / 0.002), 1e-12);
}

}  // namespace
}  // namespace mvflow
