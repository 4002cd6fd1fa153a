#include "stages/synth/synth_texture.h"

#include <algorithm>
#include <cmath>

#include "engine/model/error.h"
#include "engine/model/option_check.h"

namespace mvflow {

namespace {

double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
double lerp(double t, double a, double b) { return a + t * (b - a); }

// Ken Perlin's improved-noise gradients: the 12 edge directions of a cube (4 repeated to make
// 16), looked up rather than branched on, since random hashes defeat branch prediction.
constexpr double kGradients[16][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                                      {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1},
                                      {1, 1, 0}, {-1, 1, 0}, {0, -1, 1}, {0, -1, -1}};

double gradient(std::uint32_t hash, double x, double y, double z) {
  const double* g = kGradients[hash & 15u];
  return g[0] * x + g[1] * y + g[2] * z;
}

// Murmur3's finalizer over the cell coordinates: 32 well-mixed bits per lattice corner, 4 of
// them per channel pick its gradient.
std::uint32_t corner_hash(std::int64_t x, std::int64_t y, std::int64_t z, std::uint32_t salt) {
  std::uint32_t h = static_cast<std::uint32_t>(x) * 0x8DA6B343u ^ static_cast<std::uint32_t>(y) * 0xD8163841u ^
                    static_cast<std::uint32_t>(z) * 0xCB1AB31Fu ^ salt;
  h ^= h >> 16;
  h *= 0x85EBCA6Bu;
  h ^= h >> 13;
  h *= 0xC2B2AE35u;
  h ^= h >> 16;
  return h;
}

// Pushes a roughly zero-centred value towards ±1 so colours are strongly contrasted.
float contrast(double n) {
  const double k = 5.0 * n;
  return static_cast<float>(0.04 + 0.92 * (0.5 + 0.5 * k / (1.0 + std::abs(k))));
}

}  // namespace

std::uint64_t mix_seed(std::uint64_t a, std::uint64_t b) {
  std::uint64_t z = a + 0x9E3779B97F4A7C15ull * (b + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

void SolidTextureOptions::check() const {
  require_option(feature_size > 0 && std::isfinite(feature_size), "feature_size", feature_size, "> 0 and finite");
  require_option(octaves >= 1 && octaves <= 8, "octaves", octaves, "[1, 8]");
}

SolidTexture::SolidTexture(const SolidTextureOptions& options)
    : frequency_(1.0 / options.feature_size), octaves_(options.octaves) {
  options.check();
  std::uint64_t state = options.seed;
  for (int o = 0; o < kMaxOctaves; ++o) {
    state = mix_seed(state, static_cast<std::uint64_t>(o));
    salts_[static_cast<std::size_t>(o)] = static_cast<std::uint32_t>(state >> 32);
    for (int a = 0; a < 3; ++a) {
      state = mix_seed(state, 100u + static_cast<std::uint64_t>(a));
      offsets_[static_cast<std::size_t>(o)][a] = static_cast<double>(state >> 11) * 0x1.0p-53 * 1024.0;
    }
  }
}

Eigen::Vector3d SolidTexture::noise(const Eigen::Vector3d& q, std::uint32_t salt) const {
  const double fx = std::floor(q.x()), fy = std::floor(q.y()), fz = std::floor(q.z());
  const auto X = static_cast<std::int64_t>(fx), Y = static_cast<std::int64_t>(fy), Z = static_cast<std::int64_t>(fz);
  const double x = q.x() - fx, y = q.y() - fy, z = q.z() - fz;
  const double u = fade(x), v = fade(y), w = fade(z);
  // corner[c][k]: channel c's gradient term at corner k = dx + 2·dy + 4·dz.
  std::array<std::array<double, 8>, 3> corner{};
  for (int k = 0; k < 8; ++k) {
    const int dx = k & 1, dy = (k >> 1) & 1, dz = (k >> 2) & 1;
    const std::uint32_t h = corner_hash(X + dx, Y + dy, Z + dz, salt);
    for (int c = 0; c < 3; ++c)
      corner[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)] =
          gradient(h >> (4 * c), x - dx, y - dy, z - dz);
  }
  Eigen::Vector3d result;
  for (int c = 0; c < 3; ++c) {
    const auto& g = corner[static_cast<std::size_t>(c)];
    result[c] = lerp(w, lerp(v, lerp(u, g[0], g[1]), lerp(u, g[2], g[3])),
                     lerp(v, lerp(u, g[4], g[5]), lerp(u, g[6], g[7])));
  }
  return result;
}

Eigen::Vector3f SolidTexture::colour(const Eigen::Vector3d& p) const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double amplitude = 1.0, frequency = frequency_;
  for (int o = 0; o < octaves_; ++o) {
    const auto i = static_cast<std::size_t>(o);
    sum += amplitude * noise(frequency * p + offsets_[i], salts_[i]);
    amplitude *= 0.5;
    frequency *= 2.0;
  }
  return {contrast(sum.x()), contrast(sum.y()), contrast(sum.z())};
}

Eigen::Vector3f sample_uv(const Image& texture, const Eigen::Vector2f& uv) {
  // OBJ's v axis points up; pixel rows go down. Pixel centres sit at (i + 0.5) / size.
  const double u = std::clamp(static_cast<double>(uv.x()) * texture.width() - 0.5, 0.0, texture.width() - 1.0);
  const double v =
      std::clamp((1.0 - static_cast<double>(uv.y())) * texture.height() - 0.5, 0.0, texture.height() - 1.0);
  return texture.sample_bilinear(u, v);
}

}  // namespace mvflow
