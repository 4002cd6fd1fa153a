#include "io/opencv_decoder.h"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "engine/model/error.h"
#include "io/opencv_decoder_abi.h"

namespace mvflow::io {

namespace {

struct LoadedDecoder {
  mvflow_opencv_decode_function decode = nullptr;
  std::string failure;  // why no module could be loaded, when decode is null
};

// Every place the module may be, in order: the environment's choice alone when it is set; else
// beside the running program as the install lays it out (<bin>/../lib/mvflow/), the build tree,
// and the configured install prefix.
std::vector<std::string> module_candidates() {
  if (const char* chosen = std::getenv("MVFLOW_OPENCV_DECODER"); chosen && *chosen) return {chosen};
  std::vector<std::string> candidates;
  std::error_code error;
  const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error)
    candidates.push_back(
        (program.parent_path() / MVFLOW_OPENCV_DECODER_FROM_PROGRAM / MVFLOW_OPENCV_DECODER_NAME).lexically_normal().string());
  for (const char* fixed : {MVFLOW_OPENCV_DECODER_BUILT, MVFLOW_OPENCV_DECODER_INSTALLED})
    if (std::find(candidates.begin(), candidates.end(), fixed) == candidates.end()) candidates.emplace_back(fixed);
  return candidates;
}

LoadedDecoder load_decoder() {
  LoadedDecoder loaded;
  std::string tried;
  for (const std::string& candidate : module_candidates()) {
    // Never unloaded: OpenCV keeps threads and static state.
    void* module = dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!module) {
      const char* reason = dlerror();
      tried += "\n  " + (reason ? std::string(reason) : candidate + ": cannot be loaded");  // dlerror names the file
      continue;
    }
    const auto abi = reinterpret_cast<mvflow_opencv_decoder_abi_function>(dlsym(module, "mvflow_opencv_decoder_abi"));
    const auto decode = reinterpret_cast<mvflow_opencv_decode_function>(dlsym(module, "mvflow_opencv_decode"));
    if (!abi || !decode || abi() != MVFLOW_OPENCV_DECODER_ABI) {
      tried += "\n  " + candidate + ": not a decoder module of this mvflow version";
      continue;
    }
    loaded.decode = decode;
    return loaded;
  }
  loaded.failure = "mvflow decodes images other than PNG with its OpenCV decoder module, which cannot be loaded:" + tried +
                   "\n(MVFLOW_OPENCV_DECODER=PATH names the module, libmvflow_opencv_decoder.so)";
  return loaded;
}

const LoadedDecoder& decoder() {
  static const LoadedDecoder loaded = load_decoder();  // thread-safe, once
  return loaded;
}

// What the module's allocation callback needs, and what it leaves behind.
struct Allocation {
  const SizeCheck* check = nullptr;
  std::optional<Image> image;
  std::exception_ptr refusal;
};

float* allocate_image(void* context, int width, int height) {
  auto& allocation = *static_cast<Allocation*>(context);
  try {
    (*allocation.check)(width, height);
    allocation.image = Image::uninitialized(width, height);  // every value written by the module
    return allocation.image->data();
  } catch (...) {
    allocation.refusal = std::current_exception();
    return nullptr;
  }
}

}  // namespace

std::string opencv_decoder_summary() {
  std::string looked;
  for (const std::string& candidate : module_candidates()) {
    std::error_code error;
    if (std::filesystem::is_regular_file(candidate, error)) return "PNG by libpng, other formats by OpenCV (" + candidate + ")";
    looked += (looked.empty() ? "" : ", ") + candidate;
  }
  return "PNG by libpng; the OpenCV decoder module for other formats is missing (looked for " + looked + ")";
}

Image read_image_with_opencv(const std::filesystem::path& file, const SizeCheck& check) {
  const LoadedDecoder& loaded = decoder();
  if (!loaded.decode) throw Error(file.string() + ": " + loaded.failure);
  Allocation allocation;
  allocation.check = &check;
  char reason[512] = {};
  const int status = loaded.decode(file.c_str(), allocate_image, &allocation, reason, sizeof reason);
  if (status == 1 && allocation.refusal) std::rethrow_exception(allocation.refusal);
  if (status != 0 || !allocation.image) throw InputError(file, 0, std::string("cannot decode the image: ") + reason);
  return std::move(*allocation.image);
}

}  // namespace mvflow::io
