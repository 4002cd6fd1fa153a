// `mvflow render SCENE MESH --view I -o OUT.png`: see a mesh through one of the scene's cameras.

#include <fmt/format.h>

#include "engine/model/error.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "io/scene_io.h"
#include "stages/eval/mesh_render.h"
#include "tools/commands.h"

namespace mvflow::cli {

namespace {

struct RenderArguments {
  std::string scene;
  std::string mesh;
  std::string output;
  int view = 0;
  std::string shading = "shaded";
  bool side_by_side = false;
  MeshRenderOptions options;
};

int run_render(const RenderArguments& args, spdlog::logger& log) {
  const Scene scene = io::load_scene(args.scene);
  if (args.view < 0 || args.view >= static_cast<int>(scene.size()))
    throw InputError(args.scene, 0,
                     fmt::format("--view {} does not exist (the scene has views 0..{})", args.view, scene.size() - 1));
  const Mesh mesh = io::load_mesh(args.mesh);
  MeshRenderOptions options = args.options;
  options.shading = args.shading == "colour" ? MeshShading::Coloured : MeshShading::Shaded;
  const Camera& camera = scene.views[static_cast<std::size_t>(args.view)].camera;
  const MeshRendering rendering = render_mesh(mesh, camera, options);
  Image out = rendering.image;
  if (args.side_by_side) {  // photograph | rendering
    const Image& photo = scene.image(static_cast<std::size_t>(args.view));
    out = Image(2 * camera.width(), camera.height());
    for (int y = 0; y < camera.height(); ++y)
      for (int x = 0; x < camera.width(); ++x) {
        out.set_pixel(x, y, photo.pixel(x, y));
        out.set_pixel(camera.width() + x, y, rendering.image.pixel(x, y));
      }
  }
  io::write_png(args.output, out);
  double covered = 0;
  for (float c : rendering.coverage) covered += c;
  fmt::print("rendered   {} in view {} ({}x{}), mesh covers {:.1f} % of the image\n", args.mesh, args.view,
             camera.width(), camera.height(), 100.0 * covered / static_cast<double>(rendering.coverage.size()));
  log.info("wrote {}", args.output);
  return kOk;
}

}  // namespace

void add_render_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<RenderArguments>();
  CLI::App* c = app.add_subcommand("render", "Render a mesh through one of the scene's cameras (PNG)");
  c->add_option("scene", args->scene, "Scene folder, or a camera file inside one")->required();
  c->add_option("mesh", args->mesh, "Mesh to render")->required();
  c->add_option("--view", args->view, "0-based view index")->capture_default_str();
  c->add_option("-o,--output", args->output, "PNG to write")->required();
  c->add_option("--shading", args->shading, "shaded (grey, light at the camera) or colour (per-vertex colours)")
      ->check(CLI::IsMember({"shaded", "colour"}))
      ->capture_default_str();
  c->add_option("--supersample", args->options.supersample, "N: N×N rays per pixel")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  c->add_flag("--side-by-side", args->side_by_side, "Put the photograph left of the rendering");
  c->callback([args, &runner] { runner = [args](spdlog::logger& log) { return run_render(*args, log); }; });
}

}  // namespace mvflow::cli
