#pragma once
// A scalar field sampled on a regular cubic lattice: what the visual hull computes and the
// iso-surface extraction reads.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

namespace mvflow {

struct ScalarGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  //!< world position of sample (0, 0, 0)
  double spacing = 1.0;                              //!< distance between neighbouring samples, > 0
  std::array<int, 3> size{0, 0, 0};                  //!< samples along x, y and z
  std::vector<float> values;                         //!< size[0]·size[1]·size[2]; x fastest, then y, then z

  std::size_t count() const {
    return static_cast<std::size_t>(size[0]) * static_cast<std::size_t>(size[1]) * static_cast<std::size_t>(size[2]);
  }
  std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * static_cast<std::size_t>(size[1]) + static_cast<std::size_t>(j)) *
               static_cast<std::size_t>(size[0]) +
           static_cast<std::size_t>(i);
  }
  float at(int i, int j, int k) const { return values[index(i, j, k)]; }
  Eigen::Vector3d point(int i, int j, int k) const { return origin + spacing * Eigen::Vector3d(i, j, k); }
};

//! \p grid convolved with a Gaussian of standard deviation \p sigma samples (truncated at 3σ,
//! renormalized; beyond the grid the outer layer is repeated), one axis after the other. Keeps
//! a linear field linear, so a flat iso-surface stays where it was, while creases round off and
//! features thinner than about σ vanish. sigma 0 returns the grid unchanged. Parallel over
//! lines; the result does not depend on the thread count.
//! \throw InputError when \p sigma is negative, not finite or above 100.
ScalarGrid gaussian_blur(const ScalarGrid& grid, double sigma);

}  // namespace mvflow
