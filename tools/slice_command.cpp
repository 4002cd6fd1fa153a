// `mvflow slice SCENE --mesh FILE -o OUT.png`: g on a plane through the object (thesis figures
// 5.4–5.6), colour-mapped, with the mesh's cross-section drawn on top.

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "io/scene_io.h"
#include "stages/eval/photo_slice.h"
#include "tools/commands.h"

namespace mvflow::cli {

namespace {

struct SliceArguments {
  std::string scene;
  std::string mesh;
  std::string output;
  std::string axis = "z";
  std::string views = "nearest";
  std::string surface_patch = to_string(PhotoConsistencyOptions{}.surface_patch);  // refine's default
  bool linear = false;
  PhotoSliceOptions options;
};

// Blue (low) → cyan → yellow → red (high), t in [0, 1].
Eigen::Vector3f colour_map(double t) {
  auto ramp = [t](double centre) { return static_cast<float>(std::clamp(1.5 - std::abs(4 * t - centre), 0.0, 1.0)); };
  return {ramp(3), ramp(2), ramp(1)};
}

void draw_segment(Image& image, Eigen::Vector2d a, Eigen::Vector2d b, const Eigen::Vector3f& colour) {
  const int steps = std::max(1, static_cast<int>(std::ceil(2 * (b - a).cwiseAbs().maxCoeff())));
  for (int s = 0; s <= steps; ++s) {
    const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(s) / steps);
    const int x = static_cast<int>(std::lround(p.x())), y = image.height() - 1 - static_cast<int>(std::lround(p.y()));
    if (x >= 0 && y >= 0 && x < image.width() && y < image.height()) image.set_pixel(x, y, colour);
  }
}

int run_slice(const SliceArguments& args, spdlog::logger& log) {
  const Scene scene = io::load_scene(args.scene);
  std::string mesh_file = args.mesh;
  if (mesh_file.empty() && scene.mesh_file) mesh_file = scene.mesh_file->string();
  if (mesh_file.empty()) throw InputError(args.scene, 0, "no mesh: pass --mesh FILE or put init.ply in the scene folder");
  const Mesh mesh = io::load_mesh(mesh_file);
  PhotoSliceOptions options = args.options;
  options.axis = args.axis == "x" ? 0 : args.axis == "y" ? 1 : 2;
  options.views = args.views == "all" ? SliceViews::All : SliceViews::NearestVertex;
  const PhotoSlice slice = compute_photo_slice(mesh.topology, make_photo_views(scene), options);

  // Colour scale: log10 g between the 2nd and 98th percentiles of the defined samples (g spans
  // orders of magnitude; a few extreme samples should not flatten the picture).
  std::vector<double> defined;
  for (double g : slice.g)
    if (!std::isnan(g)) defined.push_back(args.linear ? g : std::log10(g + 1e-12));
  if (defined.empty()) throw InputError(args.scene, 0, "no point of the slice is seen by two views");
  std::sort(defined.begin(), defined.end());
  const double low = defined[defined.size() * 2 / 100], high = defined[defined.size() * 98 / 100];
  Image image(slice.width, slice.height);
  for (int j = 0; j < slice.height; ++j)
    for (int i = 0; i < slice.width; ++i) {
      const double g = slice.at(i, j);
      if (std::isnan(g)) continue;  // stays black: undefined
      const double value = args.linear ? g : std::log10(g + 1e-12);
      image.set_pixel(i, slice.height - 1 - j, colour_map(high > low ? std::clamp((value - low) / (high - low), 0.0, 1.0) : 0.5));
    }
  for (const auto& segment : slice.cross_section) draw_segment(image, segment[0], segment[1], {1, 1, 1});
  io::write_png(args.output, image);

  fmt::print("slice      {} = {:.6g} ({} × {} samples, step {:.4g})\n", args.axis, slice.origin[options.axis],
             slice.width, slice.height, slice.step);
  fmt::print("g          {:.4g} .. {:.4g} ({} scale, 2nd..98th percentile), {:.1f} % undefined (black)\n",
             args.linear ? low : std::pow(10, low), args.linear ? high : std::pow(10, high),
             args.linear ? "linear" : "log", 100.0 * (1.0 - static_cast<double>(defined.size()) / slice.g.size()));
  fmt::print("section    {} segments (white)\n", slice.cross_section.size());
  log.info("wrote {}", args.output);
  return kOk;
}

}  // namespace

void add_slice_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<SliceArguments>();
  CLI::App* command = app.add_subcommand(
      "slice", "Picture of the photo consistency g on a plane through the object, with the mesh's cross-section");
  command->add_option("scene", args->scene, "Scene folder, or a camera file inside one")->required();
  command->add_option("--mesh", args->mesh, "Mesh whose cross-section is drawn (default: the scene's init.*)");
  command->add_option("-o,--output", args->output, "PNG to write")->required();
  command->add_option("--axis", args->axis, "The plane is normal to this axis")
      ->check(CLI::IsMember({"x", "y", "z"}))
      ->capture_default_str();
  command->add_option("--position", args->options.position,
                      "Where along the axis, as a fraction of the mesh's box (with margin)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  command->add_option("--resolution", args->options.resolution, "Samples along the longer side")
      ->check(CLI::Range(2, 20000))
      ->capture_default_str();
  command->add_option("--margin", args->options.margin, "Region = mesh box grown by this fraction per side")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command->add_option("--views", args->views,
                      "nearest: each point uses the visible views of the nearest vertex (as the flow does); "
                      "all: every view whose patch fits")
      ->check(CLI::IsMember({"nearest", "all"}))
      ->capture_default_str();
  command->add_option("--patch", args->options.photo.half_patch, "Patch half size (2 = 5×5)")
      ->check(CLI::Range(1, 7))
      ->capture_default_str();
  command->add_option("--surface-patch", args->surface_patch,
                      "Patches laid on the nearest vertex's tangent plane (on), where one of its views is beyond "
                      "--surface-patch-angle (oblique), or whole-pixel image patches (off), as refine --surface-patch")
      ->check(CLI::IsMember({"off", "oblique", "on"}))
      ->capture_default_str();
  command->add_option("--surface-patch-angle", args->options.photo.surface_patch_angle_degrees,
                      "--surface-patch oblique: a nearest vertex with a view farther than this from its normal "
                      "(degrees) lays the patch on the surface (valid: (0, 90])")
      ->capture_default_str();
  command->add_option("--surface-patch-spacing", args->options.photo.surface_patch_spacing,
                      "Surface patch: spacing of its points in pixels of the finest view (valid: (0, 8])")
      ->capture_default_str();
  command->add_flag("--linear", args->linear, "Linear colour scale instead of log10");
  command->callback([args, &runner] {
    // The photo options' ranges are their check()'s; a value out of range is refused now, under
    // its flag (exit 2), as refine does.
    args->options.photo.surface_patch = surface_patch_use_from_string(args->surface_patch);
    try {
      args->options.photo.check();
    } catch (const OptionError& e) {
      if (e.option() == "half_patch") throw CLI::ValidationError("--patch", e.what());
      if (e.option() == "surface_patch_spacing") throw CLI::ValidationError("--surface-patch-spacing", e.what());
      if (e.option() == "surface_patch_angle_degrees") throw CLI::ValidationError("--surface-patch-angle", e.what());
      throw CLI::ValidationError(e.what());
    }
    runner = [args](spdlog::logger& log) { return run_slice(*args, log); };
  });
}

}  // namespace mvflow::cli
