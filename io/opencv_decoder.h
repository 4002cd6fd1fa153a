#pragma once
// Images other than PNG, decoded by OpenCV in a module loaded on first use (io/opencv_decoder_abi.h).

#include <filesystem>
#include <functional>
#include <string>

#include "engine/model/image.h"

namespace mvflow::io {

//! Checks a decoded size before anything is allocated; throws to refuse it.
using SizeCheck = std::function<void(int width, int height)>;

//! Which decoders read images, and where the module is: for `mvflow --version`. Looks for the
//! module's file without loading it.
std::string opencv_decoder_summary();

//! Decodes \p file with OpenCV's imread (IMREAD_COLOR | IMREAD_ANYDEPTH): RGB, values in [0,1].
//! The module is the file $MVFLOW_OPENCV_DECODER names when it is set; else where the build put
//! it, then where `cmake --install` puts it (<prefix>/lib/mvflow/).
//! \throw InputError when OpenCV cannot decode the file; whatever \p check throws; Error when the
//!        module cannot be loaded (naming every place looked in).
Image read_image_with_opencv(const std::filesystem::path& file, const SizeCheck& check);

}  // namespace mvflow::io
