// `mvflow synth [--preset NAME] [options] -o DIR`: renders a synthetic scene folder with known
// ground truth (cameras, PNG photographs, truth.ply, init.ply, bbox.txt, synth.json).

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/model/error.h"
#include <tbb/task_arena.h>

#include "engine/model/parallel.h"
#include "io/atomic_write.h"
#include "io/camera_io.h"
#include "io/image_io.h"
#include "io/mask_files.h"
#include "io/mesh_io.h"
#include "io/number_text.h"
#include "stages/synth/synth_scene.h"
#include "tools/commands.h"

namespace mvflow::cli {

namespace {

namespace fs = std::filesystem;

// Everything the user can set, in command-line form. Presets are values of this struct.
struct Settings {
  std::string object = "bumpy-sphere";
  std::string texture;  // UV texture image for a mesh whose OBJ names none
  int level = 5;
  double amplitude = 0.08;
  double frequency = 5.0;
  double waist = 0.3;
  std::string albedo = "auto";
  double feature_size = 0.2;
  int octaves = 3;
  std::uint64_t seed = 1;
  double ambient = 0.35;
  double diffuse = 0.65;
  std::string light = "0.35,0.8,0.5";
  bool flat = false;
  bool masks = false;  // also write masks/<view>.png, the truth's exact silhouettes
  double specular = 0.0;
  double shininess = 40.0;
  double noise = 0.0;
  int supersample = 2;
  std::string background = "textured";
  double background_radius = 20.0;
  std::string rig = "ring";
  int views = 16;
  double distance = 3.0;
  std::string elevation = "-10,45";
  int width = 640;
  int height = 480;
  double fov = 60.0;
  double focal = 0.0;
  std::string init = "offset:0.01";
  int init_vertices = 800;
  double init_smoothing = 0.1;
  double bbox_margin = 0.05;
  std::string cameras = "middlebury";
  int threads = 0;
};

const char* kPresetHelp =
    "Scene presets (options given explicitly override the preset's values):\n"
    "  default  bumpy sphere (level 5, amplitude 0.08, frequency 5), solid texture, 16 views on a ring,\n"
    "           640x480, textured background, init offset:0.01 with 800 vertices, smoothing 0.1\n"
    "  bunny    the Stanford bunny (shared/data/models/bunny-lowres-npm.obj), solid texture,\n"
    "           20 views on a hemisphere from -20 to 60 degrees at distance 2.7, init 1000 vertices,\n"
    "           smoothing 0.04\n"
    "  peanut   a peanut with a concave waist (0.3) and small bumps (0.03), 20 views on a hemisphere\n"
    "  spot     Keenan Crane's cow (shared/data/models/spot/spot_triangulated.obj) with its own UV\n"
    "           texture (spot_texture.png), 20 views on a hemisphere, init 1000 vertices, smoothing 0.04\n"
    "The shared data folder is searched upwards from the working directory and from the program,\n"
    "or taken from $MVFLOW_DATA.";

std::map<std::string, Settings> presets() {
  std::map<std::string, Settings> p;
  p["default"] = Settings{};
  Settings hemisphere;
  hemisphere.rig = "hemisphere";
  hemisphere.views = 20;
  hemisphere.elevation = "-20,60";
  hemisphere.distance = 2.7;  // meshes fill less of their bounding sphere than a sphere does
  hemisphere.init_vertices = 1000;
  hemisphere.init_smoothing = 0.04;  // thin parts (ears, horns) would vanish at the default
  p["bunny"] = hemisphere;
  p["bunny"].object = "shared:models/bunny-lowres-npm.obj";
  p["peanut"] = hemisphere;
  p["peanut"].object = "peanut";
  p["peanut"].amplitude = 0.03;
  p["peanut"].init_smoothing = 0.1;
  p["spot"] = hemisphere;
  p["spot"].object = "shared:models/spot/spot_triangulated.obj";
  p["spot"].texture = "shared:models/spot/spot_texture.png";
  p["spot"].albedo = "uv";
  return p;
}

// "shared:REL" names a file of the shared data folder (../shared/data beside the repository).
fs::path resolve_shared(const std::string& name) {
  if (!name.starts_with("shared:")) return name;
  const fs::path relative = fs::path("shared") / "data" / name.substr(7);
  if (const char* data = std::getenv("MVFLOW_DATA")) {
    const fs::path candidate = fs::path(data) / name.substr(7);
    if (fs::exists(candidate)) return candidate;
  }
  std::error_code ignored;
  for (fs::path start : {fs::current_path(ignored), fs::read_symlink("/proc/self/exe", ignored).parent_path()})
    for (fs::path dir = start; !dir.empty(); dir = dir.parent_path()) {
      if (fs::exists(dir / relative)) return dir / relative;
      if (dir == dir.parent_path()) break;
    }
  throw IoError(relative, "not found (looked upwards from the working directory and from the program, and in "
                          "$MVFLOW_DATA); pass the file with --object (and --texture)");
}

// CLI11 validators: a non-empty string is the error message (exit 2, naming the option).
std::string parse_numbers(const std::string& text, std::size_t count, std::vector<double>& out) {
  out.clear();
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size()) return "expected " + std::to_string(count) + " comma-separated numbers";
    } catch (const std::exception&) {
      return "expected " + std::to_string(count) + " comma-separated numbers";
    }
  }
  if (out.size() != count) return "expected " + std::to_string(count) + " comma-separated numbers";
  return {};
}

// \p extra checks the parsed values and returns an error message, or "" when they are fine.
CLI::Validator numbers(std::size_t count, const std::string& name,
                       std::function<std::string(const std::vector<double>&)> extra) {
  return CLI::Validator(
      [count, extra](std::string& text) {
        std::vector<double> values;
        const std::string error = parse_numbers(text, count, values);
        return error.empty() ? extra(values) : error;
      },
      name);
}

std::string check_elevation(const std::vector<double>& v) {
  if (!(v[0] >= -85 && v[0] <= v[1] && v[1] <= 85)) return "expected MIN,MAX with -85 <= MIN <= MAX <= 85 degrees";
  return {};
}

std::string check_light(const std::vector<double>& v) {
  if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) || (v[0] == 0 && v[1] == 0 && v[2] == 0))
    return "expected a non-zero direction X,Y,Z";
  return {};
}

struct InitSpec {
  InitialMeshKind kind = InitialMeshKind::Offset;
  double amount = 0.01;
};

std::string parse_init(const std::string& text, InitSpec& spec) {
  const auto colon = text.find(':');
  const std::string kind = text.substr(0, colon);
  if (text == "hull") {
    spec.kind = InitialMeshKind::Hull;
    return {};
  }
  if ((kind != "offset" && kind != "noise") || colon == std::string::npos)
    return "expected offset:D, noise:D (D relative to the bounding-box diagonal) or hull";
  spec.kind = kind == "offset" ? InitialMeshKind::Offset : InitialMeshKind::Noise;
  try {
    std::size_t used = 0;
    spec.amount = std::stod(text.substr(colon + 1), &used);
    if (used != text.size() - colon - 1) return "expected offset:D or noise:D with D a number";
  } catch (const std::exception&) {
    return "expected offset:D or noise:D with D a number";
  }
  if (!(spec.amount >= 0 && spec.amount <= 0.5)) return "D must be in [0, 0.5]";
  return {};
}

SynthOptions to_options(const Settings& s) {
  SynthOptions o;
  o.seed = s.seed;
  o.albedo = s.albedo == "uv" ? AlbedoKind::Uv : s.albedo == "solid" ? AlbedoKind::Solid : AlbedoKind::Auto;
  o.feature_size = s.feature_size;
  o.octaves = s.octaves;
  o.masks = s.masks;
  o.background_radius = s.background_radius;
  o.bbox_margin = s.bbox_margin;
  std::vector<double> v;
  parse_numbers(s.light, 3, v);
  o.render.light = {v[0], v[1], v[2]};
  o.render.ambient = s.ambient;
  o.render.diffuse = s.diffuse;
  o.render.smooth_shading = !s.flat;
  o.render.specular = s.specular;
  o.render.shininess = s.shininess;
  o.render.noise = s.noise;
  o.render.supersample = s.supersample;
  o.render.background = s.background == "black" ? BackgroundKind::Black : BackgroundKind::Textured;
  o.rig.kind = s.rig == "hemisphere" ? RigKind::Hemisphere : RigKind::Ring;
  o.rig.views = s.views;
  o.rig.distance = s.distance;
  parse_numbers(s.elevation, 2, v);
  o.rig.elevation_min = v[0];
  o.rig.elevation_max = v[1];
  o.rig.width = s.width;
  o.rig.height = s.height;
  o.rig.fov = s.fov;
  o.rig.focal = s.focal;
  InitSpec init;
  parse_init(s.init, init);
  o.init.kind = init.kind;
  o.init.amount = init.amount;
  o.init.vertices = s.init_vertices;
  o.init.smoothing = s.init_smoothing;
  return o;
}

BuiltinShapeOptions shape_options(const Settings& s) {
  BuiltinShapeOptions shape;
  shape.level = s.level;
  shape.amplitude = s.amplitude;
  shape.frequency = s.frequency;
  shape.waist = s.waist;
  return shape;
}

struct SynthArguments {
  std::string preset = "default";
  std::string output;
  Settings settings;
  // Copies the preset's value into settings for every option the user did not give.
  std::vector<std::function<void(const Settings&, Settings&)>> fill_from_preset;
};

template <typename T>
CLI::Option* bind_option(CLI::App* command, SynthArguments& args, const std::string& flags, T Settings::*field,
                  const std::string& help) {
  CLI::Option* option = command->add_option(flags, args.settings.*field, help)->capture_default_str();
  args.fill_from_preset.push_back([option, field](const Settings& preset, Settings& s) {
    if (option->count() == 0) s.*field = preset.*field;
  });
  return option;
}

struct LoadedObject {
  IndexedMesh mesh;
  std::shared_ptr<const Image> texture;
  Normalization normalization;
  std::string mesh_file, texture_file;
};

LoadedObject load_object(const Settings& s, spdlog::logger& log) {
  LoadedObject object;
  if (is_builtin_object(s.object)) {
    object.mesh = make_builtin_object(s.object, shape_options(s));
    return object;
  }
  const fs::path file = resolve_shared(s.object);
  if (!fs::exists(file))
    throw IoError(file, "object not found (expected a built-in object: bumpy-sphere, peanut; or a mesh file)");
  object.mesh = io::read_mesh(file);
  object.mesh_file = file.string();
  object.normalization = normalize_to_unit_box(object.mesh);
  if (const std::size_t added = split_pinched_vertices(object.mesh))
    log.warn("{}: {} pinched (non-manifold) vertex(es) split so the surface is manifold", file.string(), added);
  fs::path texture;
  if (!s.texture.empty()) texture = resolve_shared(s.texture);
  else if (!object.mesh.texture_file.empty()) texture = file.parent_path() / object.mesh.texture_file;
  if (!texture.empty() && s.albedo != "solid" && object.mesh.has_texcoords()) {
    object.texture = std::make_shared<const Image>(io::read_image(texture));
    object.texture_file = texture.string();
  } else if (!texture.empty() && !object.mesh.has_texcoords()) {
    log.warn("{}: no texture coordinates, so the texture {} is not used", file.string(), texture.string());
  }
  object.mesh.texture_file.clear();
  return object;
}

nlohmann::json record(const SynthArguments& args, const Settings& s, const LoadedObject& object,
                      const SynthScene& scene) {
  const auto vec = [](const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  nlohmann::json j;
  j["preset"] = args.preset;
  j["object"] = {{"name", s.object},
                 {"mesh_file", object.mesh_file},
                 {"texture_file", object.texture_file},
                 {"normalization", {{"formula", "p' = scale * (p - centre)"},
                                    {"centre", vec(object.normalization.centre)},
                                    {"scale", object.normalization.scale}}},
                 {"level", s.level},
                 {"amplitude", s.amplitude},
                 {"frequency", s.frequency},
                 {"waist", s.waist},
                 {"vertices", scene.truth.positions.size()},
                 {"faces", scene.truth.triangles.size()},
                 {"centre", vec(scene.centre)},
                 {"radius", scene.radius}};
  j["albedo"] = {{"requested", s.albedo}, {"used", scene.uv_albedo ? "uv" : "solid"},
                 {"feature_size", s.feature_size}, {"octaves", s.octaves}};
  j["seed"] = s.seed;
  j["masks"] = s.masks;
  j["render"] = {{"ambient", s.ambient},   {"diffuse", s.diffuse},       {"light", s.light},
                 {"shading", s.flat ? "flat" : "smooth"},               {"specular", s.specular},
                 {"shininess", s.shininess}, {"noise", s.noise},      {"supersample", s.supersample},
                 {"background", s.background}, {"background_radius", s.background_radius}};
  j["cameras"] = {{"rig", s.rig},     {"views", s.views},   {"distance", s.distance},
                  {"elevation", s.elevation}, {"width", s.width}, {"height", s.height},
                  {"fov", s.fov},     {"focal", s.focal},   {"focal_pixels", to_options(s).rig.focal_pixels()},
                  {"format", s.cameras}};
  j["init"] = {{"spec", s.init},
               {"vertices_requested", s.init_vertices},
               {"smoothing", s.init_smoothing},
               {"vertices", scene.initial.positions.size()},
               {"faces", scene.initial.triangles.size()}};
  j["bounding_box"] = {{"min", vec(scene.bounding_box.min)}, {"max", vec(scene.bounding_box.max)},
                       {"margin", s.bbox_margin}};
  return j;
}

void write_scene(const fs::path& folder, const SynthScene& scene, const Settings& s, const nlohmann::json& json) {
  fs::create_directories(folder);
  // A previous synth run into this folder may have left the other camera format behind, which
  // would make the scene ambiguous to the loader.
  if (fs::exists(folder / "synth.json")) {
    for (const char* stale : {"synth_par.txt", "cameras.txt", "images.txt"}) fs::remove(folder / stale);
  }
  for (std::size_t i = 0; i < scene.views.size(); ++i) io::write_png(folder / scene.views[i].image_name, scene.images[i]);
  if (!scene.silhouettes.empty()) fs::create_directories(folder / "masks");
  for (std::size_t i = 0; i < scene.silhouettes.size(); ++i)
    io::write_png(folder / "masks" / io::mask_file_name(scene.views[i]), mask_image(scene.silhouettes[i]));
  if (s.cameras == "colmap") io::write_colmap(folder, scene.views);
  else io::write_middlebury(folder / "synth_par.txt", scene.views);
  io::write_mesh(folder / "truth.ply", scene.truth);
  io::write_mesh(folder / "init.ply", scene.initial);
  io::write_atomically(folder / "bbox.txt", false, [&](std::ostream& out) {
    std::string text;
    for (const auto& p : {scene.bounding_box.min, scene.bounding_box.max})
      for (int a = 0; a < 3; ++a) {
        io::append_number(text, p[a]);
        text += a < 2 ? ' ' : '\n';
      }
    out << text;
  });
  io::write_atomically(folder / "synth.json", false, [&](std::ostream& out) { out << json.dump(2) << '\n'; });
}

int run_synth(SynthArguments& args, spdlog::logger& log) {
  const auto all = presets();
  Settings s = args.settings;
  for (const auto& fill : args.fill_from_preset) fill(all.at(args.preset), s);
  const SynthOptions options = to_options(s);
  options.check();

  io::prepare_output_folder(args.output);  // before the rendering, not after it
  const LoadedObject object = load_object(s, log);
  const auto start = std::chrono::steady_clock::now();
  SynthScene scene;
  try {
    tbb::task_arena arena(s.threads > 0 ? s.threads : tbb::task_arena::automatic);
    parallel::execute(arena, [&] { scene = make_synth_scene(object.mesh, object.texture, options); });
  } catch (const InputError& e) {
    if (object.mesh_file.empty()) throw;
    throw InputError(object.mesh_file, 0, e.what());  // e.g. an open mesh: name the file
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The texture coordinates belong to the UV texture, which the scene folder does not carry.
  scene.truth.texcoords.clear();
  log.info("rendered {} views of {}x{} ({}x{} samples per pixel) and the initial mesh in {:.2f} s",
           scene.views.size(), s.width, s.height, s.supersample, s.supersample, seconds);
  write_scene(args.output, scene, s, record(args, s, object, scene));
  log.info("wrote {}: truth {} vertices, init {} vertices, albedo {}", args.output, scene.truth.positions.size(),
           scene.initial.positions.size(), scene.uv_albedo ? "uv" : "solid");
  return kOk;
}

}  // namespace

void add_synth_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<SynthArguments>();
  CLI::App* c = app.add_subcommand("synth", "Render a synthetic scene with known ground truth into a folder");
  c->footer(kPresetHelp);
  c->add_option("-o,--output", args->output, "Scene folder to write (created if missing)")->required();
  c->add_option("--preset", args->preset, "Starting values: default, bunny, peanut, spot (see below)")
      ->check(CLI::IsMember({"default", "bunny", "peanut", "spot"}))
      ->capture_default_str();
  SynthArguments& a = *args;
  bind_option(c, a, "--object", &Settings::object, "bumpy-sphere, peanut, or a closed mesh file (normalized to a unit box)");
  bind_option(c, a, "--texture", &Settings::texture, "UV texture image of the mesh (default: the OBJ material's map_Kd)");
  bind_option(c, a, "--level", &Settings::level, "Built-ins: icosphere subdivision level (10*4^L+2 vertices)")
      ->check(CLI::Range(1, 7));
  bind_option(c, a, "--amplitude", &Settings::amplitude, "Built-ins: bump height relative to the radius")
      ->check(CLI::Range(0.0, 0.5));
  bind_option(c, a, "--frequency", &Settings::frequency, "Built-ins: bumps per radian")->check(CLI::Range(0.01, 40.0));
  bind_option(c, a, "--waist", &Settings::waist, "Peanut: waist radius relative to the ends")->check(CLI::Range(0.2, 1.0));
  bind_option(c, a, "--albedo", &Settings::albedo, "auto (uv when the mesh has a texture), uv, or solid")
      ->check(CLI::IsMember({"auto", "uv", "solid"}));
  bind_option(c, a, "--feature-size", &Settings::feature_size, "Solid texture: largest blob size, x object radius")
      ->check(CLI::Range(0.001, 100.0));
  bind_option(c, a, "--octaves", &Settings::octaves, "Solid texture: noise octaves")->check(CLI::Range(1, 8));
  bind_option(c, a, "--seed", &Settings::seed, "Seed of the textures, the pixel noise and init noise");
  bind_option(c, a, "--ambient", &Settings::ambient, "Ambient light (fraction of the albedo)")->check(CLI::Range(0.0, 2.0));
  bind_option(c, a, "--diffuse", &Settings::diffuse, "Directional light's Lambertian weight")->check(CLI::Range(0.0, 2.0));
  bind_option(c, a, "--light", &Settings::light, "Direction towards the light, X,Y,Z")->check(numbers(3, "X,Y,Z", check_light));
  {
    CLI::Option* masks = c->add_flag("--masks", args->settings.masks,
                                     "Also write masks/<view>.png: the truth's exact silhouettes (for refine --masks)");
    args->fill_from_preset.push_back([masks](const Settings& p, Settings& s) {
      if (masks->count() == 0) s.masks = p.masks;
    });
  }
  {
    CLI::Option* flat = c->add_flag("--flat", args->settings.flat, "Shade with face normals (default: smooth)");
    args->fill_from_preset.push_back([flat](const Settings& p, Settings& s) {
      if (flat->count() == 0) s.flat = p.flat;
    });
  }
  bind_option(c, a, "--specular", &Settings::specular, "Weight of a white Blinn-Phong lobe (0 = Lambertian)")
      ->check(CLI::Range(0.0, 1.0));
  bind_option(c, a, "--shininess", &Settings::shininess, "Blinn-Phong exponent")->check(CLI::Range(1.0, 10000.0));
  bind_option(c, a, "--noise", &Settings::noise, "Sigma of Gaussian pixel noise, on [0,1] values")->check(CLI::Range(0.0, 1.0));
  bind_option(c, a, "--supersample", &Settings::supersample, "N: NxN rays per pixel")->check(CLI::Range(1, 8));
  bind_option(c, a, "--background", &Settings::background, "textured (a far textured sphere) or black")
      ->check(CLI::IsMember({"textured", "black"}));
  bind_option(c, a, "--background-radius", &Settings::background_radius, "Background sphere radius, x object radius")
      ->check(CLI::Range(1.5, 1e5));
  bind_option(c, a, "--rig", &Settings::rig, "ring (elevations alternate MIN/MAX) or hemisphere (Fibonacci spiral)")
      ->check(CLI::IsMember({"ring", "hemisphere"}));
  bind_option(c, a, "--views", &Settings::views, "Number of cameras")->check(CLI::Range(1, 1000));
  bind_option(c, a, "--distance", &Settings::distance, "Camera distance to the object centre, x object radius")
      ->check(CLI::Range(1.01, 1e5));
  bind_option(c, a, "--elevation", &Settings::elevation, "MIN,MAX degrees above the horizon (-85..85)")->check(numbers(2, "MIN,MAX", check_elevation));
  bind_option(c, a, "--width", &Settings::width, "Image width in pixels")->check(CLI::Range(8, 8192));
  bind_option(c, a, "--height", &Settings::height, "Image height in pixels")->check(CLI::Range(8, 8192));
  bind_option(c, a, "--fov", &Settings::fov, "Horizontal field of view in degrees (unless --focal)")->check(CLI::Range(1.0, 170.0));
  bind_option(c, a, "--focal", &Settings::focal, "Focal length in pixels (0 = from --fov)")->check(CLI::Range(0.0, 1e6));
  bind_option(c, a, "--init", &Settings::init,
              "Initial mesh: offset:D (smoothed, pushed out by D x diagonal), noise:D, or hull (the visual hull of "
              "the truth's exact silhouettes in the rendered views, as mvflow hull makes it)")
      ->check(CLI::Validator(
          [](std::string& text) {
            InitSpec spec;
            return parse_init(text, spec);
          },
          "offset:D|noise:D|hull"));
  bind_option(c, a, "--init-vertices", &Settings::init_vertices, "Initial mesh vertex count (decimation target)")
      ->check(CLI::Range(20, 10000000));
  bind_option(c, a, "--init-smoothing", &Settings::init_smoothing, "offset: smoothing length, x bounding-box diagonal")
      ->check(CLI::Range(0.0, 0.5));
  bind_option(c, a, "--bbox-margin", &Settings::bbox_margin, "bbox.txt margin on every side, x diagonal")
      ->check(CLI::Range(0.0, 10.0));
  bind_option(c, a, "--cameras", &Settings::cameras, "Camera files: middlebury (synth_par.txt) or colmap")
      ->check(CLI::IsMember({"middlebury", "colmap"}));
  bind_option(c, a, "--threads", &Settings::threads, "Render threads (0 = all; the images do not depend on it)")
      ->check(CLI::Range(0, 1024));
  c->callback([args, &runner] { runner = [args](spdlog::logger& log) { return run_synth(*args, log); }; });
}

}  // namespace mvflow::cli
