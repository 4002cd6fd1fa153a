#pragma once
// Scene folders. A SCENE argument is a folder, or a camera file inside one:
// - COLMAP: cameras.bin + images.bin or cameras.txt + images.txt in the folder, in sparse/ or in
//   sparse/0/ (the first of these holding a model; binary before text in one folder, see
//   find_colmap_model; naming cameras.txt or cameras.bin picks that model);
// - Middlebury: one `*_par.txt`;
// - PhotoModeler-style: one `*_pm.txt` (README "Formats").
// Images are looked up beside the camera file, then in an `images/` folder beside it.
// An initial mesh `init.{ply,obj,off,stl,wrl}` in the folder is picked up if present.
// The bounding box comes from `bbox.txt` (six numbers: min x y z, max x y z), else from a
// Middlebury README's "bounding box" lines, else it is estimated from the cameras.

#include <filesystem>
#include <optional>

#include "engine/model/scene.h"
#include "io/camera_io.h"

namespace mvflow::io {

struct SceneLocation {
  std::filesystem::path folder;
  std::filesystem::path camera_path;  //!< the camera file (COLMAP: the folder holding the model's files)
  CameraFormat format = CameraFormat::Middlebury;
};

//! Finds the camera file of a scene. \throw InputError naming what was looked for, or listing
//! the candidates when there are several.
SceneLocation locate_scene(const std::filesystem::path& path);

struct SceneLoadOptions {
  //! Decode every image now (otherwise images decode on first use; sizes are still checked
  //! from the file headers).
  bool decode_images = false;
  //! A folder of mask files for Scene::masks (io::mask_store: every file found now); empty: none.
  std::filesystem::path mask_folder;
};

//! Loads cameras, checks that every image exists and has its camera's size, finds the initial
//! mesh and the bounding box. \throw InputError / IoError naming the file and what was expected.
Scene load_scene(const std::filesystem::path& path, const SceneLoadOptions& options = {});

//! The folder where a view's image was found, or nullopt (searched as load_scene does).
std::optional<std::filesystem::path> find_image(const std::filesystem::path& camera_folder,
                                                const std::string& image_name);

//! Reads `bbox.txt`-style text (six numbers). \throw InputError.
BoundingBox read_bounding_box(const std::filesystem::path& file);
//! The box a Middlebury README states: the first two lines "(x y z)" after a line holding
//! "bounding box". nullopt when the file does not exist or states no box. \throw InputError.
std::optional<BoundingBox> read_middlebury_readme_box(const std::filesystem::path& readme);

//! A box that every camera sees: the point nearest to all optical axes (least squares) and a
//! half size from the narrowest field of view at that distance. Empty when it cannot be found.
BoundingBox estimate_bounding_box(const std::vector<View>& views);

}  // namespace mvflow::io
