// `mvflow hull SCENE -o OUT`: an initial mesh from the object's silhouettes (its visual hull),
// closed, manifold and with edges of nearly one length, for `mvflow refine`.

#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <cmath>
#include <fmt/format.h>
#include <vector>

#include "engine/model/error.h"
#include "engine/model/mesh_stats.h"
#include "engine/model/parallel.h"
#include "io/atomic_write.h"
#include "io/image_io.h"
#include "io/mask_files.h"
#include "io/mesh_io.h"
#include "io/scene_io.h"
#include "stages/hull/hull_mesh.h"
#include "stages/hull/mesh_cleanup.h"
#include "stages/flow/silhouette.h"
#include "stages/flow/silhouette_holes.h"
#include "tools/commands.h"
#include "tools/hull_options.h"

namespace mvflow::cli {

namespace {

struct HullCommand {
  HullArguments carving;
  std::string output;
  bool ascii = false;
};

// The views the hull is carved from: every view but the excluded ones, in scene order.
std::vector<std::size_t> used_views(const HullArguments& args, const Scene& scene) {
  for (int view : args.excluded_views)
    if (view < 0 || static_cast<std::size_t>(view) >= scene.size())
      throw InputError(scene.folder, 0, "excluded view " + std::to_string(view) + " does not exist (the scene has " +
                                            std::to_string(scene.size()) + " views, 0.." +
                                            std::to_string(static_cast<int>(scene.size()) - 1) + ")");
  std::vector<std::size_t> used;
  for (std::size_t i = 0; i < scene.size(); ++i)
    if (std::find(args.excluded_views.begin(), args.excluded_views.end(), static_cast<int>(i)) ==
        args.excluded_views.end())
      used.push_back(i);
  if (used.size() < 2) throw InputError(scene.folder, 0, "fewer than 2 views are left to carve with");
  return used;
}

BoundingBox bounding_box(const HullArguments& args, const Scene& scene, spdlog::logger& log) {
  if (args.bbox.empty()) {
    if (scene.bounding_box.is_empty())
      throw InputError(scene.folder, 0, "no bounding box (no bbox.txt, no Middlebury README, and none could be "
                                        "estimated from the cameras): pass --bbox MINX MINY MINZ MAXX MAXY MAXZ");
    log.info("bounding box from {}", scene.bounding_box_source);
    return scene.bounding_box;
  }
  BoundingBox box;
  box.min = {args.bbox[0], args.bbox[1], args.bbox[2]};
  box.max = {args.bbox[3], args.bbox[4], args.bbox[5]};
  if (!box.min.allFinite() || !box.max.allFinite() || !(box.min.array() < box.max.array()).all())
    throw InputError("--bbox: expected MINX MINY MINZ MAXX MAXY MAXZ with every minimum below its maximum");
  return box;
}

//! One silhouette per view, from the mask files or by thresholding the photographs, dilated,
//! with its small holes filled.
std::vector<Mask> silhouettes(const HullArguments& args, const Scene& scene, const std::vector<std::size_t>& used,
                              spdlog::logger& log) {
  std::vector<Mask> masks;
  masks.reserve(used.size());
  for (const std::size_t i : used) {
    const View& view = scene.views[i];
    if (!args.masks.empty()) {
      const auto file = io::find_mask_file(args.masks, view, i);
      masks.push_back(dilate_mask(mask_from_image(io::read_mask_image(file, view, i)), args.silhouette.dilate));
    } else {
      masks.push_back(threshold_silhouette(scene.image(i), args.silhouette));
    }
    const auto max_hole = static_cast<std::size_t>(args.fill_holes * static_cast<double>(masks.back().inside.size()));
    masks.back() = fill_silhouette_holes(masks.back(), max_hole);
    const double fraction = static_cast<double>(masks.back().count()) / static_cast<double>(masks.back().inside.size());
    log.debug("view {} ({}): silhouette covers {:.1f} % of the image", i, view.image_name, 100.0 * fraction);
    if (fraction == 0.0)
      log.warn("view {} ({}): the silhouette is empty, so this view carves away everything it sees", i,
               view.image_name);
  }
  return masks;
}

//! Writes \p masks as black-and-white PNGs named after the views' images, readable by --masks.
void save_masks(const std::filesystem::path& folder, const Scene& scene, const std::vector<std::size_t>& used,
                const std::vector<Mask>& masks) {
  std::filesystem::create_directories(folder);
  for (std::size_t k = 0; k < masks.size(); ++k)
    io::write_png(folder / io::mask_file_name(scene.views[used[k]]), mask_image(masks[k]));
}

}  // namespace

CarvedHull carve_hull(const HullArguments& args, spdlog::logger& log) {
  if (!args.save_masks.empty()) io::prepare_output_folder(args.save_masks);
  const Scene scene = io::load_scene(args.scene);
  const BoundingBox box = bounding_box(args, scene, log);
  const std::vector<std::size_t> used = used_views(args, scene);
  const std::vector<Mask> masks = silhouettes(args, scene, used, log);
  if (!args.save_masks.empty()) save_masks(args.save_masks, scene, used, masks);
  std::vector<Camera> cameras;
  for (const std::size_t i : used) cameras.push_back(scene.views[i].camera);

  CarvedHull carved;
  carved.views = used.size();
  tbb::task_arena arena(args.threads > 0 ? args.threads : tbb::task_arena::automatic);
  parallel::execute(arena, [&] { carved.hull = make_hull_mesh(cameras, masks, box, args.options); });
  return carved;
}

namespace {

int run_hull(const HullCommand& command, spdlog::logger& log) {
  const HullArguments& args = command.carving;
  io::mesh_format_from_path(command.output);  // a bad extension fails now, not after the carving
  io::check_writable(command.output);        // ... and so does an output that could not be saved
  const auto start = std::chrono::steady_clock::now();
  const CarvedHull carved = carve_hull(args, log);
  const HullMeshResult& hull = carved.hull;

  io::MeshWriteOptions write_options;
  write_options.binary = !command.ascii;
  io::write_mesh(command.output, hull.mesh, write_options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const Mesh mesh = build_mesh(hull.mesh, command.output);
  const MeshStats stats = compute_mesh_stats(mesh);
  fmt::print("silhouettes {} views, {}", carved.views,
             args.masks.empty() ? fmt::format("threshold {}", args.silhouette.threshold)
                                : fmt::format("mask files from {}", args.masks));
  fmt::print(", dilated by {} px, holes up to {} % of the image filled\n", args.silhouette.dilate, 100 * args.fill_holes);
  fmt::print("grid        {} x {} x {} samples, spacing {:.4g}, {} inside ({:.2f} s)\n", hull.grid_size[0],
             hull.grid_size[1], hull.grid_size[2], hull.grid_spacing, hull.inside_samples, hull.seconds_carving);
  const double kept = static_cast<double>(hull.kept_vertices) / static_cast<double>(hull.extracted_vertices);
  fmt::print("surface     {} vertices in {} component(s), the largest ({:.1f} % of the vertices) kept ({:.2f} s)\n",
             hull.extracted_vertices, hull.extracted_components, 100.0 * kept, hull.seconds_extraction);
  if (kept < 0.9)
    log.warn("the carved hull fell apart: the largest piece holds only {:.1f} % of the surface (check the silhouettes "
             "and the bounding box)",
             100.0 * kept);
  fmt::print("mesh        {} vertices, {} faces, {} components, genus {}, {}, {}, {} thin neck(s) cut ({:.2f} s)\n",
             stats.vertices, stats.faces, stats.components, stats.genus, stats.is_closed() ? "closed" : "OPEN",
             stats.is_manifold() ? "manifold" : "NON-MANIFOLD", hull.neck_cuts, hull.seconds_remeshing);
  fmt::print("edges       shortest {:.4g}, mean {:.4g}, longest {:.4g} (shortest/mean {:.2f})\n", stats.shortest_edge,
             stats.mean_edge, stats.longest_edge, stats.shortest_edge / stats.mean_edge);
  fmt::print("volume      {:.6g}\n", enclosed_volume(hull.mesh));
  log.info("wrote {} in {:.2f} s", command.output, seconds);
  return kOk;
}

}  // namespace

void add_hull_options(CLI::App& command, HullArguments& args) {
  CLI::Option* masks = command.add_option(
      "--masks", args.masks,
      "Folder of mask images, one per view, matched by file-name stem (non-zero = object); default: threshold the "
      "photographs");
  command.add_option("--save-masks", args.save_masks,
                     "Also write the silhouettes used (after dilation and hole filling) as PNGs into this folder, named like the views' "
                     "images, so they can be checked, edited and passed to --masks");
  command.add_option("--threshold", args.silhouette.threshold,
                     "A pixel is object when its largest channel exceeds this (on [0,1]); 0.19 suits the Middlebury "
                     "black backgrounds")
      ->check(CLI::Range(0.0, 0.999999))
      ->capture_default_str()
      ->excludes(masks);
  command.add_option("--dilate", args.silhouette.dilate,
                     "Dilate every silhouette by a disc of this radius in pixels, for a conservative hull (Middlebury: 10)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  command.add_option("--fill-holes", args.fill_holes,
                     "Fill background regions enclosed by the silhouette (shadows that the threshold missed) up to this "
                     "fraction of the image area, after the dilation; larger ones are taken as see-through openings")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  command.add_option("--bbox", args.bbox, "MINX MINY MINZ MAXX MAXY MAXZ: carve inside this box (default: the scene's)")
      ->expected(6);
  command.add_option("--resolution", args.options.carving.resolution, "Grid samples along the box's longest side")
      ->check(CLI::Range(8, 1024))
      ->capture_default_str();
  command.add_option("--min-views", args.options.carving.min_views,
                     "A point seen by fewer views (in front of the camera, inside the image) is carved away")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  command.add_option("--smoothing", args.options.smoothing,
                     "Gaussian blur of the carved field, sigma in grid samples: rounds the hull's creases off and removes "
                     "tunnels and bridges thinner than a voxel")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  command.add_option("--vertices", args.options.vertices, "Target vertex count of the mesh")
      ->check(CLI::Range(20, 10000000))
      ->capture_default_str();
  command.add_option("--neck-edge", args.options.neck_edge,
                     "Cut the mesh along loops of three edges around necks and handles thinner than the mesh, where an "
                     "edge stays shorter than this fraction of the target length (0 = never cut)")
      ->check(CLI::Range(0.0, 0.8))
      ->capture_default_str();
  command.add_option("--remesh-iterations", args.options.remeshing_iterations, "Rounds of isotropic remeshing")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  command.add_option("--threads", args.threads, "Worker threads (0 = all cores; the mesh does not depend on it)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command.add_option("--exclude-views", args.excluded_views,
                     "0-based views not to carve with (held out: their photographs are never read)")
      ->delimiter(',');
}

void add_hull_command(CLI::App& app, Runner& runner) {
  auto command = std::make_shared<HullCommand>();
  CLI::App* c = app.add_subcommand(
      "hull",
      "Initial mesh from silhouettes: the visual hull carved on a grid inside the bounding box, its surface "
      "extracted (marching tetrahedra on a signed distance to the silhouette outlines), the largest piece "
      "remeshed isotropically to about --vertices vertices with edges of nearly one length, necks thinner than "
      "the mesh cut; closed, manifold, outward normals");
  c->add_option("scene", command->carving.scene, "Scene folder, or a camera file inside one")->required();
  c->add_option("-o,--output", command->output, "Mesh to write; format from the extension, written atomically")
      ->required();
  add_hull_options(*c, command->carving);
  c->add_flag("--ascii", command->ascii, "Write PLY/STL as ASCII instead of binary");
  c->callback([command, &runner] { runner = [command](spdlog::logger& log) { return run_hull(*command, log); }; });
}

}  // namespace mvflow::cli
