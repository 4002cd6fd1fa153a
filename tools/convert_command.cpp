// `mvflow convert IN OUT`: between mesh formats, or between camera formats.

#include <filesystem>

#include "engine/model/error.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "io/scene_io.h"
#include "tools/commands.h"

namespace mvflow::cli {

namespace {

namespace fs = std::filesystem;

struct ConvertArguments {
  std::string input;
  std::string output;
  std::string to;
  bool ascii = false;
};

bool is_mesh_path(const fs::path& path) {
  try {
    io::mesh_format_from_path(path);
    return true;
  } catch (const InputError&) {
    return false;
  }
}

io::CameraFormat output_camera_format(const ConvertArguments& args) {
  if (!args.to.empty()) return io::camera_format_from_name(args.to);
  const std::string name = fs::path(args.output).filename().string();
  if (name.ends_with("_par.txt")) return io::CameraFormat::Middlebury;
  if (name.ends_with("_pm.txt")) return io::CameraFormat::PhotoModeler;
  if (name == "cameras.bin") return io::CameraFormat::ColmapBinary;
  return io::CameraFormat::Colmap;  // a folder (or cameras.txt) receives cameras.txt + images.txt
}

int convert_mesh(const ConvertArguments& args, spdlog::logger& log) {
  const IndexedMesh mesh = io::read_mesh(args.input);
  io::MeshWriteOptions options;
  options.binary = !args.ascii;
  io::write_mesh(args.output, mesh, options);
  log.info("wrote {} ({} vertices, {} triangles)", args.output, mesh.positions.size(), mesh.triangles.size());
  return kOk;
}

int convert_cameras(const ConvertArguments& args, spdlog::logger& log) {
  const io::SceneLocation location = io::locate_scene(args.input);
  std::vector<View> views = io::read_cameras(location.camera_path, location.format);
  // Formats without image sizes (Middlebury) take them from the images, if present.
  const fs::path camera_folder =
      io::is_colmap(location.format) ? location.folder : location.camera_path.parent_path();
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (views[i].camera.width() > 0) continue;
    const auto image = io::find_image(camera_folder, views[i].image_name);
    if (!image)
      throw InputError(location.camera_path, "view", i,
                       "has no image size and its image '" + views[i].image_name +
                           "' was not found to read it from");
    const auto size = io::read_image_size(*image);
    views[i].camera = views[i].camera.with_image_size(size.width, size.height);
  }
  const io::CameraFormat format = output_camera_format(args);
  fs::path output = args.output;
  if (io::is_colmap(format) && (output.filename() == "cameras.txt" || output.filename() == "cameras.bin"))
    output = output.parent_path();
  if (io::is_colmap(format) && !output.empty()) fs::create_directories(output);
  io::write_cameras(output, views, format);
  log.info("wrote {} cameras to {} ({})", views.size(), output.string(), io::camera_format_name(format));
  // A binary model already in the folder would be read instead of the text one just written.
  if (io::is_colmap(format)) {
    const auto found = io::find_colmap_model(output.empty() ? fs::path(".") : output);
    if (found && found->format != format)
      log.warn("{} also holds a COLMAP {} model, which is read instead of the one just written",
               found->folder.string(), io::camera_format_name(found->format));
  }
  return kOk;
}

}  // namespace

void add_convert_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<ConvertArguments>();
  CLI::App* command = app.add_subcommand(
      "convert", "Convert a mesh (.ply .obj .off .stl .wrl) or a scene's cameras (Middlebury, COLMAP text or binary, "
      "PhotoModeler-style)");
  command->add_option("input", args->input, "Mesh file, or scene folder / camera file")->required();
  command->add_option("output", args->output,
                      "Mesh file (format from the extension), or camera output: *_par.txt, *_pm.txt, or a folder "
                      "for COLMAP (text; binary with --to colmap-bin or OUT = .../cameras.bin)")
      ->required();
  command
      ->add_option("--to", args->to,
                   "Camera output format: middlebury, colmap (text), colmap-bin (binary), photomodeler "
                   "(default: from OUT)")
      ->check(CLI::IsMember({"middlebury", "colmap", "colmap-bin", "photomodeler"}));
  command->add_flag("--ascii", args->ascii, "Write PLY/STL as ASCII instead of binary");
  command->callback([args, &runner] {
    runner = [args](spdlog::logger& log) {
      return is_mesh_path(args->input) ? convert_mesh(*args, log) : convert_cameras(*args, log);
    };
  });
}

}  // namespace mvflow::cli
