#pragma once
// An RGB photograph in memory: float values in [0,1], interleaved RGB, rows top to bottom,
// contiguous, so a 5×5 patch read touches five short runs of memory.

#include <Eigen/Core>
#include <cstddef>
#include <new>
#include <utility>
#include <vector>

namespace mvflow {

namespace detail {
//! Allocates the pixel buffers: a buffer of 2 MiB or more in whole transparent huge pages where
//! the system offers them (Linux, madvise), for first touching a photograph's fresh pages one 4 KiB
//! page at a time took about as long as decoding it (24 VGA images: 0.32 s against 0.05–0.2 s);
//! and elements left uninitialized unless given a value, so a buffer about to be overwritten is
//! not zeroed first.
template <typename T>
struct PixelAllocator {
  using value_type = T;
  PixelAllocator() = default;
  template <typename U>
  PixelAllocator(const PixelAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(allocate_pixel_bytes(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { free_pixel_bytes(p, n * sizeof(T)); }
  template <typename U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Arguments>
  void construct(U* p, Arguments&&... arguments) {
    ::new (static_cast<void*>(p)) U(std::forward<Arguments>(arguments)...);
  }
  friend bool operator==(const PixelAllocator&, const PixelAllocator&) { return true; }

 private:
  static void* allocate_pixel_bytes(std::size_t bytes);
  static void free_pixel_bytes(void* p, std::size_t bytes) noexcept;
};
}  // namespace detail

class Image {
 public:
  Image() = default;
  //! A black image of the given size.
  Image(int width, int height);
  //! Copies \p rgb (#width·#height·3 floats, interleaved RGB, row-major).
  Image(int width, int height, const std::vector<float>& rgb);
  //! An image of the given size whose values are unspecified until written: for a caller that
  //! writes every pixel (a decoder, a resampler).
  static Image uninitialized(int width, int height);

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
  std::vector<float, detail::PixelAllocator<float>> rgb_;
};

}  // namespace mvflow
