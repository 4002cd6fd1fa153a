#pragma once
// An RGB photograph in memory: float values in [0,1], interleaved RGB, rows top to bottom,
// contiguous, so a 5×5 patch read touches five short runs of memory.

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace mvflow {

class Image {
 public:
  Image() = default;
  //! A black image of the given size.
  Image(int width, int height);
  //! Takes ownership of \p rgb (#width·#height·3 floats, interleaved RGB, row-major).
  Image(int width, int height, std::vector<float> rgb);

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return width_ == 0 || height_ == 0; }
  const float* data() const { return rgb_.data(); }
  float* data() { return rgb_.data(); }

  //! Pixel (x, y) as RGB; no bounds check beyond a debug assert.
  Eigen::Vector3f pixel(int x, int y) const;
  void set_pixel(int x, int y, const Eigen::Vector3f& rgb);

  //! Bilinear sample at (u, v), pixel centres at integers (SPEC §2).
  //! \pre 0 ≤ u ≤ width−1 and 0 ≤ v ≤ height−1 (callers test visibility first)
  Eigen::Vector3f sample_bilinear(double u, double v) const;

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<float> rgb_;
};

}  // namespace mvflow
