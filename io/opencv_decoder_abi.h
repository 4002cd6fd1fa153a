#pragma once
// The C interface between mvflow and its OpenCV decoder module (io/opencv_decoder/decoder_module.cpp),
// which mvflow loads only when it reads an image that is not a PNG: loading OpenCV's codecs costs
// 0.13 s (io/png_codec.h).

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

//! Bumped whenever the functions below change: a module of another version is not used.
#define MVFLOW_OPENCV_DECODER_ABI 1

//! Returns \p width x \p height interleaved RGB floats for the decoder to fill, or null to refuse
//! the image (the caller keeps its reason).
typedef float* (*mvflow_allocate_rgb)(void* context, int width, int height);

//! MVFLOW_OPENCV_DECODER_ABI of the module.
typedef int (*mvflow_opencv_decoder_abi_function)(void);

//! Decodes \p path as imread(IMREAD_COLOR | IMREAD_ANYDEPTH) does and writes RGB values scaled
//! to [0,1] into the buffer \p allocate returns. Returns 0 on success, 1 when \p allocate refused,
//! 2 when OpenCV cannot decode the file (the reason, NUL-terminated, in \p error).
typedef int (*mvflow_opencv_decode_function)(const char* path, mvflow_allocate_rgb allocate, void* context,
                                             char* error, size_t error_size);

#ifdef __cplusplus
}
#endif
