#pragma once
// Albedo for synthetic scenes: a procedural solid texture (a colour for every 3-D point, so it
// needs no parameterization and looks the same from every view), and lookup in a mesh's own
// UV texture image.

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "engine/model/image.h"

namespace mvflow {

struct SolidTextureOptions {
  std::uint64_t seed = 1;     //!< the same seed gives the same texture, on every platform
  double feature_size = 0.2;  //!< size of the largest blobs, in world units (> 0)
  int octaves = 3;            //!< noise octaves, each half the size of the previous one (1..8)
  //! \throw InputError naming the field when a value is out of range.
  void check() const;
};

//! Multi-octave gradient (Perlin) noise, three independent fields on one lattice (one per
//! channel, sharing the cell search and the fade weights), mapped to strongly contrasting
//! colours. Deterministic from the seed: the lattice hash is our own integer hash.
class SolidTexture {
 public:
  explicit SolidTexture(const SolidTextureOptions& options);
  //! RGB in [0.04, 0.96] at world point \p p. Thread-safe (const, no state).
  Eigen::Vector3f colour(const Eigen::Vector3d& p) const;

 private:
  static constexpr int kMaxOctaves = 8;
  double frequency_;
  int octaves_;
  std::array<std::uint32_t, kMaxOctaves> salts_{};           // one lattice hash per octave
  std::array<Eigen::Vector3d, kMaxOctaves> offsets_{};       // so octaves' lattices do not align
  Eigen::Vector3d noise(const Eigen::Vector3d& q, std::uint32_t salt) const;
};

//! Bilinear lookup in a texture image at OBJ texture coordinates ((0,0) bottom-left,
//! (1,1) top-right; clamped to the border).
Eigen::Vector3f sample_uv(const Image& texture, const Eigen::Vector2f& uv);

//! A 64-bit mix of \p a and \p b (SplitMix64 finalizer): seeds derived from (seed, view, row)
//! are independent of the order in which threads run.
std::uint64_t mix_seed(std::uint64_t a, std::uint64_t b);

}  // namespace mvflow
