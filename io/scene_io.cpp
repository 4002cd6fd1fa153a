#include "io/scene_io.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <regex>

#include "engine/model/error.h"
#include "io/image_io.h"
#include "io/mask_files.h"
#include "io/text_reader.h"

namespace mvflow::io {

namespace fs = std::filesystem;

namespace {

bool has_suffix(const std::string& name, const std::string& suffix) {
  return name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::vector<fs::path> files_with_suffix(const fs::path& folder, const std::string& suffix) {
  std::vector<fs::path> found;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.is_regular_file() && has_suffix(entry.path().filename().string(), suffix)) found.push_back(entry.path());
  std::sort(found.begin(), found.end());
  return found;
}

std::string list_names(const std::vector<fs::path>& files) {
  std::string text;
  for (const auto& f : files) text += (text.empty() ? "" : ", ") + f.filename().string();
  return text;
}

// Checks (and for size-less formats sets) each camera's image size from its file's header.
void attach_image_sizes(Scene& scene, const fs::path& camera_folder) {
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    View& view = scene.views[i];
    const auto image_path = find_image(camera_folder, view.image_name);
    if (!image_path)
      throw InputError(scene.camera_file, "view", i,
                       "image '" + view.image_name + "' not found (looked in " + camera_folder.string() +
                           " and " + (camera_folder / "images").string() + ")");
    const ImageSize size = read_image_size(*image_path);
    const Camera& camera = view.camera;
    if (camera.width() == 0 && camera.height() == 0) {
      view.camera = camera.with_image_size(size.width, size.height);
    } else if (camera.width() != size.width || camera.height() != size.height) {
      throw InputError(*image_path, 0,
                       "image is " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                           " pixels but its camera (view " + std::to_string(i) + " in " +
                           scene.camera_file.string() + ") expects " + std::to_string(camera.width()) + "x" +
                           std::to_string(camera.height()));
    }
    view.image_name = image_path->string();
  }
}

}  // namespace

SceneLocation locate_scene(const fs::path& path) {
  std::error_code error;
  if (!fs::exists(path, error)) throw IoError(path, "scene not found (expected a folder or a camera file)");
  if (fs::is_regular_file(path)) {
    const std::string name = path.filename().string();
    const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
    if (has_suffix(name, "_par.txt")) return {folder, path, CameraFormat::Middlebury};
    if (has_suffix(name, "_pm.txt")) return {folder, path, CameraFormat::PhotoModeler};
    // A named COLMAP file picks its model even where the folder holds both.
    if (name == "cameras.txt" || name == "images.txt") return {folder, folder, CameraFormat::Colmap};
    if (name == "cameras.bin" || name == "images.bin") return {folder, folder, CameraFormat::ColmapBinary};
    throw InputError(path, 0,
                     "not a camera file (expected *_par.txt, *_pm.txt, or COLMAP cameras/images .txt or .bin)");
  }
  if (auto colmap = find_colmap_model(path)) return {path, colmap->folder, colmap->format};
  const auto middlebury = files_with_suffix(path, "_par.txt");
  const auto photomodeler = files_with_suffix(path, "_pm.txt");
  if (middlebury.size() + photomodeler.size() > 1)
    throw InputError(path, 0,
                     "several camera files (" + list_names(middlebury) + (middlebury.empty() ? "" : " ") +
                         list_names(photomodeler) + "): pass the one to use instead of the folder");
  if (middlebury.size() == 1) return {path, middlebury.front(), CameraFormat::Middlebury};
  if (photomodeler.size() == 1) return {path, photomodeler.front(), CameraFormat::PhotoModeler};
  throw InputError(path, 0,
                   "no cameras found (expected COLMAP cameras.bin + images.bin or cameras.txt + images.txt "
                   "here or in sparse/ or sparse/0/, a Middlebury *_par.txt, or a PhotoModeler-style *_pm.txt)");
}

std::optional<fs::path> find_image(const fs::path& camera_folder, const std::string& image_name) {
  // The name comes from a camera file: one the file system refuses (too long, ...) is not found,
  // rather than a filesystem_error from the throwing overloads.
  const fs::path name(image_name);
  std::error_code error;
  if (name.is_absolute()) return fs::is_regular_file(name, error) ? std::optional(name) : std::nullopt;
  for (const fs::path& candidate : {camera_folder / name, camera_folder / "images" / name})
    if (fs::is_regular_file(candidate, error)) return candidate;
  return std::nullopt;
}

// Middlebury READMEs state the box as two lines "(x y z)".
std::optional<BoundingBox> read_middlebury_readme_box(const fs::path& readme) {
  if (!fs::is_regular_file(readme)) return std::nullopt;
  TextReader reader(readme);
  const std::regex triple(R"(^\s*\(\s*([-+0-9.eE]+)\s+([-+0-9.eE]+)\s+([-+0-9.eE]+)\s*\)\s*$)");
  bool after_heading = false;
  std::vector<Eigen::Vector3d> corners;
  while (reader.next_line() && corners.size() < 2) {
    if (reader.line().find("bounding box") != std::string::npos) after_heading = true;
    std::smatch match;
    if (after_heading && std::regex_match(reader.line(), match, triple))
      corners.emplace_back(parse_double(reader, match[1].str(), "x"), parse_double(reader, match[2].str(), "y"),
                           parse_double(reader, match[3].str(), "z"));
  }
  if (corners.size() != 2) return std::nullopt;
  BoundingBox box;
  box.extend(corners[0]);
  box.extend(corners[1]);
  return box;
}

BoundingBox read_bounding_box(const fs::path& file) {
  TextReader reader(file);
  std::vector<double> values;
  while (reader.next_content_line())
    for (auto token : split_whitespace(reader.line())) {
      if (values.size() == 6) reader.fail("expected six numbers (min x y z, max x y z), found more");
      values.push_back(parse_double(reader, token, "a bounding-box coordinate"));
    }
  if (values.size() != 6)
    throw InputError(file, reader.line_number(),
                     "expected six numbers (min x y z, max x y z), found " + std::to_string(values.size()));
  BoundingBox box;
  box.min = {values[0], values[1], values[2]};
  box.max = {values[3], values[4], values[5]};
  if (box.is_empty()) throw InputError(file, 0, "bounding box minimum exceeds its maximum");
  return box;
}

BoundingBox estimate_bounding_box(const std::vector<View>& views) {
  // Least-squares point nearest to all optical axes: Σ (I − d dᵀ)(X − C) = 0.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& view : views) {
    const Eigen::Vector3d d = view.camera.viewing_direction();
    const Eigen::Matrix3d projector = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += projector;
    b += projector * view.camera.centre();
  }
  BoundingBox box;
  if (views.size() < 2 || std::abs(A.determinant()) < 1e-12) return box;
  const Eigen::Vector3d centre = A.ldlt().solve(b);
  double half_size = std::numeric_limits<double>::infinity();
  for (const auto& view : views) {
    const Camera& c = view.camera;
    const double depth = c.project(centre).depth;
    if (depth <= 0 || c.width() == 0) return box;
    const double half_view = 0.5 * std::min(c.width() / c.K()(0, 0), c.height() / c.K()(1, 1));
    half_size = std::min(half_size, depth * half_view / std::sqrt(3.0));
  }
  box.extend(centre - Eigen::Vector3d::Constant(half_size));
  box.extend(centre + Eigen::Vector3d::Constant(half_size));
  return box;
}

Scene load_scene(const fs::path& path, const SceneLoadOptions& options) {
  const SceneLocation location = locate_scene(path);
  Scene scene;
  scene.folder = location.folder;
  scene.camera_file = location.camera_path;
  scene.camera_format = camera_format_name(location.format);
  scene.views = read_cameras(location.camera_path, location.format);
  if (scene.views.empty()) throw InputError(location.camera_path, 0, "the camera file holds no camera");
  const fs::path camera_folder = is_colmap(location.format) ? location.folder : location.camera_path.parent_path();
  attach_image_sizes(scene, camera_folder.empty() ? fs::path(".") : camera_folder);

  std::vector<fs::path> image_files;
  for (const auto& view : scene.views) image_files.emplace_back(view.image_name);
  std::vector<ImageSize> sizes;
  for (const auto& view : scene.views) sizes.push_back({view.camera.width(), view.camera.height()});
  scene.images = std::make_shared<ImageStore>(scene.views.size(), [image_files, sizes](std::size_t i) {
    Image image = read_image(image_files[i]);
    if (image.width() != sizes[i].width || image.height() != sizes[i].height)
      throw InputError(image_files[i], 0, "decoded size differs from the size in the file header");
    return image;
  });
  if (options.decode_images)
    for (std::size_t i = 0; i < scene.views.size(); ++i) scene.images->get(i);
  if (!options.mask_folder.empty()) scene.masks = mask_store(options.mask_folder, scene);

  for (const char* name : {"init.ply", "init.obj", "init.off", "init.stl", "init.wrl"})
    if (fs::is_regular_file(scene.folder / name)) {
      scene.mesh_file = scene.folder / name;
      break;
    }

  if (fs::is_regular_file(scene.folder / "bbox.txt")) {
    scene.bounding_box = read_bounding_box(scene.folder / "bbox.txt");
    scene.bounding_box_source = (scene.folder / "bbox.txt").string();
  } else if (auto box = read_middlebury_readme_box(scene.folder / "README.txt")) {
    scene.bounding_box = *box;
    scene.bounding_box_source = (scene.folder / "README.txt").string();
  } else {
    scene.bounding_box = estimate_bounding_box(scene.views);
    scene.bounding_box_source = "estimated from the cameras' optical axes and fields of view";
  }
  return scene;
}

}  // namespace mvflow::io
