#include "stages/flow/image_denoise.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "engine/model/option_check.h"
#include "engine/model/parallel.h"

namespace mvflow {

namespace {

constexpr double kLargestSigma = 8.0;

// The normalised taps w_{−R..R} of the Gaussian, R = ⌈3σ⌉.
std::vector<double> gaussian_taps(double sigma) {
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  std::vector<double> taps(2 * static_cast<std::size_t>(radius) + 1);
  double sum = 0.0;
  for (int i = -radius; i <= radius; ++i) sum += taps[static_cast<std::size_t>(i + radius)] = std::exp(-0.5 * i * i / (sigma * sigma));
  for (double& w : taps) w /= sum;
  return taps;
}

}  // namespace

void DenoiseOptions::check() const {
  require_option(noise_reference > 0.0 && std::isfinite(noise_reference), "noise_reference", noise_reference,
                 "> 0 and finite");
}

double gaussian_noise_gain(double sigma) {
  if (!(sigma > 0.0)) return 1.0;
  double sum = 0.0;
  for (double w : gaussian_taps(sigma)) sum += w * w;
  return sum;
}

double denoise_sigma_for(double noise, double reference) {
  if (!(noise > reference)) return 0.0;
  const double target = reference / noise;
  if (gaussian_noise_gain(kLargestSigma) >= target) return kLargestSigma;
  // The gain falls with σ (a wider kernel averages more pixels); 50 halvings: far below a bit of σ.
  double low = 0.0, high = kLargestSigma;
  for (int i = 0; i < 50; ++i) {
    const double mid = 0.5 * (low + high);
    (gaussian_noise_gain(mid) > target ? low : high) = mid;
  }
  return high;
}

Image gaussian_blur(const Image& image, double sigma) {
  if (!(sigma > 0.0) || image.empty()) return image;
  const std::vector<double> taps = gaussian_taps(sigma);
  const auto radius = static_cast<std::ptrdiff_t>(taps.size() / 2);
  const std::size_t width = static_cast<std::size_t>(image.width()), height = static_cast<std::size_t>(image.height());
  const std::size_t row_values = width * 3;
  const auto clamp_row = [&](std::ptrdiff_t y) {
    return static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(y, 0, static_cast<std::ptrdiff_t>(height) - 1));
  };
  // Rows blurred into doubles (each row padded with its border pixels), then columns back to
  // float, whole rows at a time: one rounding per value, the taps summed in one fixed order. Only
  // the 2R + 1 blurred rows a column sum reads are kept, in a ring: a 24-megapixel photograph
  // would need 576 MB of doubles at once.
  std::vector<double> ring(taps.size() * row_values);
  std::vector<double> padded((width + 2 * static_cast<std::size_t>(radius)) * 3);
  const auto blur_row = [&](std::size_t y) {
    const float* source = image.data() + y * row_values;
    for (std::size_t x = 0; x < padded.size() / 3; ++x) {
      const std::size_t from = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(
          static_cast<std::ptrdiff_t>(x) - radius, 0, static_cast<std::ptrdiff_t>(width) - 1));
      for (std::size_t c = 0; c < 3; ++c) padded[x * 3 + c] = source[from * 3 + c];
    }
    double* row = ring.data() + (y % taps.size()) * row_values;
    for (std::size_t i = 0; i < row_values; ++i) {
      double sum = 0.0;
      for (std::size_t k = 0; k < taps.size(); ++k) sum += taps[k] * padded[i + k * 3];
      row[i] = sum;
    }
  };
  Image blurred = Image::uninitialized(image.width(), image.height());  // every value written below
  std::vector<double> sum(row_values);
  std::size_t blurred_rows = 0;  // rows 0 .. blurred_rows − 1 have been blurred (the last 2R + 1 are in the ring)
  for (std::size_t y = 0; y < height; ++y) {
    for (const std::size_t last = clamp_row(static_cast<std::ptrdiff_t>(y) + radius); blurred_rows <= last; ++blurred_rows)
      blur_row(blurred_rows);
    std::fill(sum.begin(), sum.end(), 0.0);
    for (std::size_t k = 0; k < taps.size(); ++k) {
      const double* row = ring.data() + (clamp_row(static_cast<std::ptrdiff_t>(y + k) - radius) % taps.size()) * row_values;
      for (std::size_t i = 0; i < row_values; ++i) sum[i] += taps[k] * row[i];
    }
    float* target = blurred.data() + y * row_values;
    for (std::size_t i = 0; i < row_values; ++i) target[i] = static_cast<float>(sum[i]);
  }
  return blurred;
}

std::unique_ptr<ImageLevel> blurred_views(const std::vector<PhotoView>& views, double sigma) {
  auto level = std::make_unique<ImageLevel>();
  level->cameras.reserve(views.size());
  for (const PhotoView& view : views) level->cameras.push_back(*view.camera);
  level->images.resize(views.size());
  parallel::parallel_for(std::size_t{0}, views.size(),
                         [&](std::size_t i) { level->images[i] = gaussian_blur(*views[i].image, sigma); });
  attach_views(*level);
  return level;
}

}  // namespace mvflow
