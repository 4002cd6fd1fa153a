#include "io/mask_files.h"

#include <algorithm>
#include <cctype>
#include <set>
#include <vector>

#include "engine/model/error.h"
#include "io/image_io.h"

namespace mvflow::io {

namespace fs = std::filesystem;

namespace {

bool is_image_extension(const fs::path& file) {
  static const std::set<std::string> kExtensions{".png", ".pgm", ".ppm", ".pbm", ".bmp",
                                                 ".jpg", ".jpeg", ".tif", ".tiff"};
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return kExtensions.count(extension) > 0;
}

std::string describe(const View& view, std::size_t index) {
  return "view " + std::to_string(index) + " (" + fs::path(view.image_name).filename().string() + ")";
}

}  // namespace

fs::path mask_file_name(const View& view) { return fs::path(view.image_name).stem().string() + ".png"; }

fs::path find_mask_file(const fs::path& folder, const View& view, std::size_t index) {
  if (!fs::is_directory(folder)) throw IoError(folder, "the mask folder does not exist or is not a folder");
  const fs::path stem = fs::path(view.image_name).stem();
  std::vector<fs::path> candidates;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.is_regular_file() && entry.path().stem() == stem && is_image_extension(entry.path()))
      candidates.push_back(entry.path());
  std::sort(candidates.begin(), candidates.end());
  if (candidates.empty())
    throw InputError(folder / mask_file_name(view), 0,
                     "no mask for " + describe(view, index) + "; expected an image named " + stem.string() +
                         " with an image extension (.png, .pgm, .jpg, .tif, ...) in the mask folder");
  if (candidates.size() > 1) {
    std::string names;
    for (const auto& c : candidates) names += (names.empty() ? "" : ", ") + c.filename().string();
    throw InputError(folder, 0, "several masks for " + describe(view, index) + ": " + names + "; keep one");
  }
  return candidates.front();
}

Image read_mask_image(const fs::path& file, const View& view, std::size_t index) {
  Image image = read_image(file);
  const Camera& camera = view.camera;
  if (image.width() != camera.width() || image.height() != camera.height())
    throw InputError(file, 0,
                     "the mask is " + std::to_string(image.width()) + "x" + std::to_string(image.height()) +
                         " pixels, but " + describe(view, index) + " is " + std::to_string(camera.width()) + "x" +
                         std::to_string(camera.height()));
  return image;
}

std::shared_ptr<ImageStore> mask_store(const fs::path& folder, const Scene& scene) {
  std::vector<fs::path> files;
  for (std::size_t i = 0; i < scene.size(); ++i) files.push_back(find_mask_file(folder, scene.views[i], i));
  return std::make_shared<ImageStore>(scene.size(), [files, views = scene.views](std::size_t i) {
    return read_mask_image(files[i], views[i], i);
  });
}

}  // namespace mvflow::io
