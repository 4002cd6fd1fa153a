// The photographs' noise (stages/flow/image_noise.h): Immerkær's estimate against known cases; and
// the blur that removes it (stages/flow/image_denoise.h) against analytic and measured noise.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <tuple>
#include <vector>

#include "engine/model/image.h"
#include "engine/model/option_check.h"
#include "stages/flow/image_denoise.h"
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

// The 1-D Gaussian taps at the integers within ⌈3σ⌉, normalised: written here from the formula,
// not taken from the code under test.
std::vector<double> reference_taps(double sigma) {
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  std::vector<double> taps;
  for (int i = -radius; i <= radius; ++i) taps.push_back(std::exp(-(i * i) / (2.0 * sigma * sigma)));
  double sum = 0.0;
  for (double w : taps) sum += w;
  for (double& w : taps) w /= sum;
  return taps;
}

TEST(ImageDenoise, AnImpulseBecomesTheKernelAndAConstantStays) {
  const int size = 21, centre = 10;
  const double sigma = 1.3;
  std::vector<float> rgb(size * size * 3, 0.0f);
  for (int c = 0; c < 3; ++c) rgb[(centre * size + centre) * 3 + c] = static_cast<float>(c + 1);
  const Image blurred = gaussian_blur(Image(size, size, rgb), sigma);
  const std::vector<double> w = reference_taps(sigma);
  const int radius = static_cast<int>(w.size() / 2);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const int dx = x - centre, dy = y - centre;
      const double expected = std::abs(dx) <= radius && std::abs(dy) <= radius ? w[dx + radius] * w[dy + radius] : 0.0;
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(blurred.data()[(y * size + x) * 3 + c], (c + 1) * expected, 1e-7) << x << ", " << y;
    }
  // A constant stays constant up to the border (the border pixel repeats).
  const Image flat = gaussian_blur(Image(9, 7, std::vector<float>(9 * 7 * 3, 0.25f)), 2.0);
  for (std::size_t i = 0; i < 9 * 7 * 3; ++i) EXPECT_NEAR(flat.data()[i], 0.25f, 1e-7);
  // Any image against the 2-D convolution written out here, the border pixel repeated: images
  // taller and shorter than the kernel (the blur keeps only 2R + 1 blurred rows at a time).
  for (const auto& [w, h, s] : {std::tuple{13, 17, 0.9}, std::tuple{8, 3, 1.6}}) {
    std::mt19937 random(static_cast<unsigned>(w * h));
    std::uniform_real_distribution<float> value(0.0f, 1.0f);
    std::vector<float> pixels(static_cast<std::size_t>(w) * h * 3);
    for (float& p : pixels) p = value(random);
    const Image result = gaussian_blur(Image(w, h, pixels), s);
    const std::vector<double> t = reference_taps(s);
    const int r = static_cast<int>(t.size() / 2);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) {
          double expected = 0.0;
          for (int j = -r; j <= r; ++j)
            for (int i = -r; i <= r; ++i)
              expected += t[i + r] * t[j + r] *
                          pixels[(static_cast<std::size_t>(std::clamp(y + j, 0, h - 1)) * w + std::clamp(x + i, 0, w - 1)) * 3 + c];
          EXPECT_NEAR(result.data()[(static_cast<std::size_t>(y) * w + x) * 3 + c], expected, 1e-6) << w << "x" << h << " " << x << ", " << y;
        }
  }
  // σ ≤ 0: the image as given.
  const Image same = gaussian_blur(blurred, 0.0);
  EXPECT_TRUE(std::equal(same.data(), same.data() + size * size * 3, blurred.data()));
}

// White noise of σ keeps σ·Σw² after the blur (the 2-D kernel's Σ(w_x w_y)² = (Σw²)²): the gain
// against the formula, against the continuous Gaussian's 1/(2√π σ) for a wide kernel, and against
// the measured standard deviation of blurred noise.
TEST(ImageDenoise, TheNoiseGainIsWhatBlurredWhiteNoiseKeeps) {
  for (const double sigma : {0.5, 0.82, 1.7}) {
    double expected = 0.0;
    for (double w : reference_taps(sigma)) expected += w * w;
    EXPECT_NEAR(gaussian_noise_gain(sigma), expected, 1e-15) << sigma;
  }
  // (0.3 % above it: cut at 3σ and normalised, the taps are slightly larger.)
  EXPECT_NEAR(gaussian_noise_gain(3.0) * 2.0 * std::sqrt(std::numbers::pi) * 3.0, 1.0, 0.004);
  EXPECT_EQ(gaussian_noise_gain(0.0), 1.0);
  const int width = 640, height = 480;
  std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3);
  std::mt19937 random(11);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (float& value : rgb) value = static_cast<float>(0.5 + noise(random));
  for (const double sigma : {0.6, 0.82, 1.5}) {
    const Image blurred = gaussian_blur(Image(width, height, rgb), sigma);
    double sum = 0.0, squares = 0.0;
    std::size_t n = 0;
    for (int y = 8; y < height - 8; ++y)  // away from the repeated border
      for (int x = 8; x < width - 8; ++x)
        for (int c = 0; c < 3; ++c, ++n) {
          const double v = blurred.data()[(static_cast<std::size_t>(y) * width + x) * 3 + c];
          sum += v;
          squares += v * v;
        }
    const double deviation = std::sqrt(squares / n - (sum / n) * (sum / n));
    EXPECT_NEAR(deviation / (0.01 * gaussian_noise_gain(sigma)), 1.0, 0.02) << sigma;
  }
}

TEST(ImageDenoise, TheChosenBlurBringsTheNoiseToTheReference) {
  EXPECT_EQ(denoise_sigma_for(0.0015, 0.002), 0.0);  // at or below the reference: none
  EXPECT_EQ(denoise_sigma_for(0.002, 0.002), 0.0);
  for (const double noise : {0.003, 0.0058, 0.02}) {
    const double sigma = denoise_sigma_for(noise, 0.002);
    EXPECT_GT(sigma, 0.0);
    EXPECT_NEAR(gaussian_noise_gain(sigma), 0.002 / noise, 1e-9) << noise;
    EXPECT_LE(noise * gaussian_noise_gain(sigma), 0.002 * (1 + 1e-12)) << noise;
  }
  EXPECT_EQ(denoise_sigma_for(10.0, 0.002), 8.0);  // beyond what any blur here removes: the widest
  EXPECT_THROW((DenoiseOptions{.noise_reference = 0.0}).check(), OptionError);
  EXPECT_THROW((DenoiseOptions{.noise_reference = NAN}).check(), OptionError);
  // On a noisy ramp: the blurred image minus the blurred clean ramp (the blur is linear) is the
  // noise left, measured here.
  const Image noisy = ramp(0.0058, 21), clean = ramp(0.0);
  const double sigma = denoise_sigma_for(0.0058, 0.002);
  const Image a = gaussian_blur(noisy, sigma), b = gaussian_blur(clean, sigma);
  double squares = 0.0;
  std::size_t n = 0;
  for (int y = 8; y < a.height() - 8; ++y)
    for (int x = 8; x < a.width() - 8; ++x, ++n) {
      const double d = a.data()[(static_cast<std::size_t>(y) * a.width() + x) * 3] - b.data()[(static_cast<std::size_t>(y) * a.width() + x) * 3];
      squares += d * d;
    }
  EXPECT_NEAR(std::sqrt(squares / n), 0.002, 0.00006);
}

TEST(ImageDenoise, BlurredViewsKeepTheirCamerasAndBlurEveryImage) {
  const std::vector<Image> images = {ramp(0.01, 31), ramp(0.01, 32)};
  Eigen::Matrix3d K;
  K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  const std::vector<Camera> cameras = {Camera(K, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 2), 640, 480),
                                       Camera(K, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.5, 0, 2), 640, 480)};
  std::vector<const Image*> pointers = {&images[0], &images[1]};
  const std::vector<PhotoView> views = make_photo_views(cameras, pointers);
  const auto level = blurred_views(views, 0.9);
  ASSERT_EQ(level->views.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const Image expected = gaussian_blur(images[i], 0.9);
    EXPECT_TRUE(std::equal(expected.data(), expected.data() + 640 * 480 * 3, level->views[i].image->data())) << i;
    EXPECT_EQ(level->views[i].projection, views[i].projection);
    EXPECT_NE(level->views[i].image, views[i].image);
  }
}

}  // namespace
}  // namespace mvflow
