// `mvflow info SCENE [--mesh FILE]`: what a scene holds, before anything runs on it.

#include <algorithm>
#include <fmt/format.h>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/model/error.h"
#include "engine/model/mesh_stats.h"
#include "io/atomic_write.h"
#include "io/mesh_io.h"
#include "io/scene_io.h"
#include "tools/commands.h"

namespace mvflow::cli {

namespace {

struct InfoArguments {
  std::string scene;
  std::string mesh;
  std::string json;
  bool decode = false;
  int grid = 3;
};

const char* distortion_name(DistortionModel model) {
  switch (model) {
    case DistortionModel::None: return "none";
    case DistortionModel::Radial: return "radial";
    case DistortionModel::OpenCV: return "opencv";
    case DistortionModel::InverseRadial: return "inverse-radial (thesis 2.6)";
  }
  return "?";
}

nlohmann::json camera_summary(const Scene& scene) {
  std::map<std::string, int> sizes, models;
  double fx_min = 1e300, fx_max = -1e300, skew_max = 0;
  for (const auto& view : scene.views) {
    const Camera& c = view.camera;
    sizes[fmt::format("{}x{}", c.width(), c.height())]++;
    models[distortion_name(c.distortion().model)]++;
    fx_min = std::min(fx_min, c.K()(0, 0));
    fx_max = std::max(fx_max, c.K()(0, 0));
    skew_max = std::max(skew_max, std::abs(c.K()(0, 1)));
  }
  return {{"count", scene.views.size()}, {"format", scene.camera_format},
          {"file", scene.camera_file.string()}, {"image_sizes", sizes},
          {"focal_px_min", fx_min}, {"focal_px_max", fx_max}, {"max_abs_skew", skew_max},
          {"distortion", models}};
}

nlohmann::json mesh_summary(const std::string& file, const Mesh& mesh, const MeshBuildReport& report) {
  const MeshStats s = compute_mesh_stats(mesh);
  return {{"file", file},
          {"vertices", s.vertices},
          {"faces", s.faces},
          {"edges", s.edges},
          {"boundary_edges", s.boundary_edges},
          {"boundary_loops", s.boundary_loops},
          {"non_manifold_vertices", s.non_manifold_vertices},
          {"non_manifold_faces_skipped", report.rejected_faces},
          {"isolated_vertices", s.isolated_vertices},
          {"components", s.components},
          {"euler_characteristic", s.euler_characteristic},
          // Euler's formula assumes a manifold surface; elsewhere the genus means nothing.
          {"genus", s.is_manifold() ? nlohmann::json(s.genus) : nlohmann::json(nullptr)},
          {"shortest_edge", s.shortest_edge},
          {"longest_edge", s.longest_edge},
          {"mean_edge", s.mean_edge},
          {"bounding_box", {{"min", {s.bounding_box.min.x(), s.bounding_box.min.y(), s.bounding_box.min.z()}},
                            {"max", {s.bounding_box.max.x(), s.bounding_box.max.y(), s.bounding_box.max.z()}}}}};
}

// Views that see the centre of each cell of a grid×grid×grid split of the box.
std::vector<int> view_coverage(const Scene& scene, const BoundingBox& box, int grid) {
  std::vector<int> counts;
  for (int k = 0; k < grid; ++k)
    for (int j = 0; j < grid; ++j)
      for (int i = 0; i < grid; ++i) {
        const Eigen::Vector3d fraction((i + 0.5) / grid, (j + 0.5) / grid, (k + 0.5) / grid);
        const Eigen::Vector3d p = box.min + fraction.cwiseProduct(box.size());
        int seen = 0;
        for (const auto& view : scene.views) {
          const Projection q = view.camera.project(p);
          seen += q.depth > 0 && view.camera.in_image(q.u, q.v);
        }
        counts.push_back(seen);
      }
  return counts;
}

std::string format_box(const nlohmann::json& box) {
  const auto& lo = box["min"];
  const auto& hi = box["max"];
  return fmt::format("({:.6g}, {:.6g}, {:.6g}) to ({:.6g}, {:.6g}, {:.6g})", lo[0].get<double>(),
                     lo[1].get<double>(), lo[2].get<double>(), hi[0].get<double>(), hi[1].get<double>(),
                     hi[2].get<double>());
}

void print_text(const nlohmann::json& info, int grid) {
  const auto& c = info["cameras"];
  fmt::print("scene      {}\n", info["scene"].get<std::string>());
  fmt::print("cameras    {} ({}, {})\n", c["count"].get<int>(), c["format"].get<std::string>(),
             c["file"].get<std::string>());
  for (const auto& [size, count] : c["image_sizes"].items()) fmt::print("  images   {} × {}\n", count.get<int>(), size);
  fmt::print("  focal    {:.6g} .. {:.6g} px, max |skew| {:.3g}\n", c["focal_px_min"].get<double>(),
             c["focal_px_max"].get<double>(), c["max_abs_skew"].get<double>());
  for (const auto& [model, count] : c["distortion"].items())
    fmt::print("  lens     {} × {}\n", count.get<int>(), model);
  if (info.contains("mesh")) {
    const auto& m = info["mesh"];
    fmt::print("mesh       {}\n", m["file"].get<std::string>());
    fmt::print("  size     {} vertices, {} faces, {} edges\n", m["vertices"].get<long>(), m["faces"].get<long>(),
               m["edges"].get<long>());
    const std::string genus = m["genus"].is_null() ? "n/a (non-manifold)" : std::to_string(m["genus"].get<long>());
    fmt::print("  topology {} component(s), total genus {}, Euler characteristic {}, {} boundary edge(s) in {} loop(s)\n",
               m["components"].get<long>(), genus, m["euler_characteristic"].get<long>(),
               m["boundary_edges"].get<long>(), m["boundary_loops"].get<long>());
    fmt::print("  manifold {} non-manifold vertex(es), {} face(s) skipped as non-manifold, {} isolated vertex(es)\n",
               m["non_manifold_vertices"].get<long>(), m["non_manifold_faces_skipped"].get<long>(),
               m["isolated_vertices"].get<long>());
    fmt::print("  edges    shortest {:.6g}, longest {:.6g}, mean {:.6g}\n", m["shortest_edge"].get<double>(),
               m["longest_edge"].get<double>(), m["mean_edge"].get<double>());
    fmt::print("  box      {}\n", format_box(m["bounding_box"]));
  } else {
    fmt::print("mesh       none (pass --mesh FILE, or put init.ply in the scene folder)\n");
  }
  const auto& b = info["bounding_box"];
  if (b.contains("min")) {
    fmt::print("box        {} ({})\n", format_box(b), b["source"].get<std::string>());
    fmt::print("coverage   views seeing each cell of a {}×{}×{} split of the box, one z-slab per block:\n", grid,
               grid, grid);
    const auto& counts = info["coverage"];
    for (int k = 0; k < grid; ++k) {
      for (int j = grid - 1; j >= 0; --j) {
        std::string row = "    ";
        for (int i = 0; i < grid; ++i) row += fmt::format("{:4d}", counts[(k * grid + j) * grid + i].get<int>());
        fmt::print("{}\n", row);
      }
      if (k + 1 < grid) fmt::print("\n");
    }
  } else {
    fmt::print("box        unknown (add bbox.txt to the scene folder)\n");
  }
}

int run_info(const InfoArguments& args, spdlog::logger& log) {
  io::SceneLoadOptions options;
  options.decode_images = args.decode;
  const Scene scene = io::load_scene(args.scene, options);
  log.debug("loaded {} views from {}", scene.size(), scene.camera_file.string());

  nlohmann::json info;
  info["scene"] = scene.folder.string();
  info["cameras"] = camera_summary(scene);

  std::string mesh_file = args.mesh;
  if (mesh_file.empty() && scene.mesh_file) mesh_file = scene.mesh_file->string();
  BoundingBox box = scene.bounding_box;
  std::string box_source = scene.bounding_box_source;
  if (!mesh_file.empty()) {
    MeshBuildReport report;
    const Mesh mesh = io::load_mesh(mesh_file, &report);
    if (report.rejected_faces > 0)
      log.warn("{}: {} face(s) would make the mesh non-manifold and were skipped (first: face {})", mesh_file,
               report.rejected_faces, report.first_rejected.front());
    info["mesh"] = mesh_summary(mesh_file, mesh, report);
    if (scene.bounding_box_source.starts_with("estimated")) {
      box = compute_mesh_stats(mesh).bounding_box;
      box_source = "the mesh";
    }
  }
  if (!box.is_empty()) {
    info["bounding_box"] = {{"min", {box.min.x(), box.min.y(), box.min.z()}},
                            {"max", {box.max.x(), box.max.y(), box.max.z()}},
                            {"source", box_source}};
    info["coverage"] = view_coverage(scene, box, args.grid);
  } else {
    info["bounding_box"] = nlohmann::json::object();
  }
  print_text(info, args.grid);
  if (!args.json.empty())
    io::write_atomically(args.json, false, [&](std::ostream& out) { out << info.dump(2) << '\n'; });
  return kOk;
}

}  // namespace

void add_info_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<InfoArguments>();
  CLI::App* command = app.add_subcommand("info", "Print what a scene holds: cameras, images, mesh, coverage");
  command->add_option("scene", args->scene, "Scene folder, or a camera file inside one")->required();
  command->add_option("--mesh", args->mesh, "Mesh to describe (default: the scene's init.* if any)");
  command->add_option("--json", args->json, "Also write the summary as JSON to this file");
  command->add_flag("--decode", args->decode, "Decode every image now (default: check sizes from headers)");
  command->add_option("--grid", args->grid, "Cells per axis of the coverage table")
      ->check(CLI::Range(1, 10))
      ->capture_default_str();
  command->callback([args, &runner] { runner = [args](spdlog::logger& log) { return run_info(*args, log); }; });
}

}  // namespace mvflow::cli
