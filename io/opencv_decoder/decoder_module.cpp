// The OpenCV decoder module: a shared module that mvflow loads with dlopen when it first reads an
// image that is not a PNG (TIFF, JPEG, BMP, PNM), so that a run on PNG photographs never loads
// OpenCV's codecs and the hundred-odd libraries they depend on (io/png_codec.h).

#include <algorithm>
#include <cstring>
#include <string>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "io/opencv_decoder_abi.h"

namespace {

int fail(const std::string& reason, char* error, size_t error_size) {
  if (error_size > 0) {
    const size_t n = std::min(reason.size(), error_size - 1);
    std::memcpy(error, reason.data(), n);
    error[n] = '\0';
  }
  return 2;
}

}  // namespace

extern "C" __attribute__((visibility("default"))) int mvflow_opencv_decoder_abi() { return MVFLOW_OPENCV_DECODER_ABI; }

extern "C" __attribute__((visibility("default"))) int mvflow_opencv_decode(const char* path, mvflow_allocate_rgb allocate,
                                                                          void* context, char* error, size_t error_size) {
  try {
    cv::Mat decoded = cv::imread(path, cv::IMREAD_COLOR | cv::IMREAD_ANYDEPTH);
    if (decoded.empty()) return fail("unreadable, truncated or not an image format OpenCV reads", error, error_size);
    double scale = 1.0;
    switch (decoded.depth()) {
      case CV_8U: scale = 1.0 / 255.0; break;
      case CV_16U: scale = 1.0 / 65535.0; break;
      case CV_32F: scale = 1.0; break;
      default: return fail("unsupported pixel depth (expected 8-bit, 16-bit or float)", error, error_size);
    }
    float* buffer = allocate(context, decoded.cols, decoded.rows);
    if (!buffer) return 1;
    // Straight into the caller's buffer, then blue and red swapped in place: no second copy.
    cv::Mat target(decoded.rows, decoded.cols, CV_32FC3, buffer);
    decoded.convertTo(target, CV_32FC3, scale);
    const size_t n = static_cast<size_t>(decoded.cols) * static_cast<size_t>(decoded.rows);
    for (size_t i = 0; i < n; ++i, buffer += 3) std::swap(buffer[0], buffer[2]);
    return 0;
  } catch (const cv::Exception& exception) {
    // OpenCV refuses some files by throwing (its own size limit, assertions in its decoders).
    return fail(exception.err, error, error_size);
  } catch (const std::exception& exception) {
    return fail(exception.what(), error, error_size);
  }
}
