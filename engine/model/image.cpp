#include "engine/model/image.h"

#include <cassert>
#include <cmath>
#include <cstdlib>
#include <new>

#ifdef __linux__
#include <sys/mman.h>
#endif

#include "engine/model/error.h"

namespace mvflow {

namespace detail {

namespace {
constexpr std::size_t kHugePage = std::size_t{2} << 20;
}  // namespace

template <typename T>
void* PixelAllocator<T>::allocate_pixel_bytes(std::size_t bytes) {
#ifdef __linux__
  if (bytes >= kHugePage) {
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (!p) throw std::bad_alloc();
    madvise(p, rounded, MADV_HUGEPAGE);  // advice only: without huge pages it is ordinary memory
    return p;
  }
#endif
  void* p = std::malloc(bytes == 0 ? 1 : bytes);
  if (!p) throw std::bad_alloc();
  return p;
}

template <typename T>
void PixelAllocator<T>::free_pixel_bytes(void* p, std::size_t) noexcept {
  std::free(p);
}

template struct PixelAllocator<float>;

}  // namespace detail

Image::Image(int width, int height) : width_(width), height_(height) {
  MVFLOW_CHECK(width >= 0 && height >= 0, "image size must not be negative");
  rgb_.assign(static_cast<std::size_t>(width) * height * 3, 0.0f);
}

Image::Image(int width, int height, const std::vector<float>& rgb) : width_(width), height_(height) {
  MVFLOW_CHECK(width >= 0 && height >= 0, "image size must not be negative");
  MVFLOW_CHECK(rgb.size() == static_cast<std::size_t>(width) * height * 3,
               "image buffer size must be width*height*3");
  rgb_.assign(rgb.begin(), rgb.end());
}

Image Image::uninitialized(int width, int height) {
  MVFLOW_CHECK(width >= 0 && height >= 0, "image size must not be negative");
  Image image;
  image.width_ = width;
  image.height_ = height;
  image.rgb_.resize(static_cast<std::size_t>(width) * height * 3);  // default-initialized: not zeroed
  return image;
}

Eigen::Vector3f Image::pixel(int x, int y) const {
  assert(x >= 0 && y >= 0 && x < width_ && y < height_);
  const float* p = rgb_.data() + (static_cast<std::size_t>(y) * width_ + x) * 3;
  return {p[0], p[1], p[2]};
}

void Image::set_pixel(int x, int y, const Eigen::Vector3f& rgb) {
  assert(x >= 0 && y >= 0 && x < width_ && y < height_);
  float* p = rgb_.data() + (static_cast<std::size_t>(y) * width_ + x) * 3;
  p[0] = rgb.x();
  p[1] = rgb.y();
  p[2] = rgb.z();
}

Eigen::Vector3f Image::sample_bilinear(double u, double v) const {
  assert(u >= 0 && v >= 0 && u <= width_ - 1 && v <= height_ - 1);
  // Clamp the base so that the last row/column samples with weight 1 on itself.
  const int x0 = std::min(static_cast<int>(std::floor(u)), width_ - 2 < 0 ? 0 : width_ - 2);
  const int y0 = std::min(static_cast<int>(std::floor(v)), height_ - 2 < 0 ? 0 : height_ - 2);
  const float fx = static_cast<float>(u - x0);
  const float fy = static_cast<float>(v - y0);
  const int x1 = std::min(x0 + 1, width_ - 1);
  const int y1 = std::min(y0 + 1, height_ - 1);
  const Eigen::Vector3f top = (1 - fx) * pixel(x0, y0) + fx * pixel(x1, y0);
  const Eigen::Vector3f bottom = (1 - fx) * pixel(x0, y1) + fx * pixel(x1, y1);
  return (1 - fy) * top + fy * bottom;
}

}  // namespace mvflow
