// Synthetic scenes: determinism, Lambertian consistency across views, camera geometry, the
// initial mesh, and the `mvflow synth` command writing a folder the scene loader reads.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>

#include <tbb/task_arena.h>

#include "engine/model/mesh_stats.h"
#include "engine/model/surface_query.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "io/scene_io.h"
#include "stages/synth/synth_scene.h"
#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;

// A small scene that renders in well under a second.
SynthOptions small_options() {
  SynthOptions o;
  o.rig.views = 4;
  o.rig.width = 96;
  o.rig.height = 72;
  o.init.vertices = 300;
  return o;
}

IndexedMesh small_sphere(double amplitude = 0.08, int level = 3) {
  BuiltinShapeOptions shape;
  shape.level = level;
  shape.amplitude = amplitude;
  return make_bumpy_sphere(shape);
}

bool same_pixels(const Image& a, const Image& b) {
  return a.width() == b.width() && a.height() == b.height() &&
         std::equal(a.data(), a.data() + 3 * a.width() * a.height(), b.data());
}

TEST(Synth, SameSeedGivesIdenticalFilesWhateverTheThreadCount) {
  test::ScratchFolder folder;
  SynthOptions one = small_options();
  one.render.noise = 0.02;  // noise must not depend on which thread draws it
  const IndexedMesh truth = small_sphere();
  auto render_with = [&](int threads) {  // the caller chooses the threads (an arena)
    tbb::task_arena arena(threads);
    return arena.execute([&] { return make_synth_scene(truth, nullptr, one); });
  };
  const SynthScene a = render_with(1);
  const SynthScene b = render_with(2);
  const SynthScene c = render_with(2);
  ASSERT_EQ(a.images.size(), 4u);
  for (std::size_t i = 0; i < a.images.size(); ++i) {
    EXPECT_TRUE(same_pixels(a.images[i], b.images[i])) << "view " << i;
    EXPECT_TRUE(same_pixels(b.images[i], c.images[i])) << "view " << i;
    io::write_png(folder / "a.png", a.images[i]);
    io::write_png(folder / "b.png", b.images[i]);
    EXPECT_EQ(test::read_text(folder / "a.png"), test::read_text(folder / "b.png")) << "view " << i;
  }
  io::write_mesh(folder / "a.ply", a.initial);
  io::write_mesh(folder / "b.ply", b.initial);
  EXPECT_EQ(test::read_text(folder / "a.ply"), test::read_text(folder / "b.ply"));

  // A different seed changes the texture, hence the pixels.
  SynthOptions other = one;
  other.seed = 2;
  EXPECT_FALSE(same_pixels(make_synth_scene(truth, nullptr, other).images[0], a.images[0]));
}

// The colours a truth vertex shows in pairs of views where it is clearly visible: the mean and
// the 99th percentile of the per-pair max-channel difference, and the fraction above 0.15.
struct Agreement {
  std::size_t pairs = 0;
  double mean = 0.0, p99 = 0.0, above_015 = 0.0;
};

Agreement colour_agreement(const SynthScene& scene) {
  const SurfaceQuery truth(scene.truth);
  const auto normals = vertex_normals(scene.truth);
  std::vector<double> differences;
  for (std::size_t v = 0; v < scene.truth.positions.size(); ++v) {
    const Eigen::Vector3d& p = scene.truth.positions[v];
    std::vector<Eigen::Vector3f> seen;
    for (std::size_t i = 0; i < scene.views.size(); ++i) {
      const Camera& camera = scene.views[i].camera;
      const Eigen::Vector3d to_camera = camera.centre() - p;
      const double distance = to_camera.norm();
      if (normals[v].dot(to_camera / distance) < 0.5) continue;  // more than 60° from facing
      const Eigen::Vector3d start = p + 1e-4 * normals[v];
      if (truth.occluded(start, to_camera / distance, 0.0, distance)) continue;
      const Projection q = camera.project(p);
      const double margin = 5.0;
      if (q.u < margin || q.v < margin || q.u > camera.width() - 1 - margin || q.v > camera.height() - 1 - margin)
        continue;
      // Away from silhouettes: rays 2 px around the projection all meet the object near p.
      bool interior = true;
      for (const auto& [du, dv] : std::array<std::pair<double, double>, 4>{{{-2, 0}, {2, 0}, {0, -2}, {0, 2}}}) {
        const Ray ray = camera.ray(q.u + du, q.v + dv);
        const auto hit = truth.intersect(ray.origin, ray.direction);
        interior = interior && hit && std::abs(hit->distance - distance) < 0.1 * distance;
      }
      if (interior) seen.push_back(scene.images[i].sample_bilinear(q.u, q.v));
    }
    for (std::size_t a = 0; a < seen.size(); ++a)
      for (std::size_t b = a + 1; b < seen.size(); ++b)
        differences.push_back((seen[a] - seen[b]).cwiseAbs().maxCoeff());
  }
  Agreement result;
  result.pairs = differences.size();
  if (differences.empty()) return result;
  std::sort(differences.begin(), differences.end());
  result.mean = std::accumulate(differences.begin(), differences.end(), 0.0) / static_cast<double>(differences.size());
  result.p99 = differences[differences.size() * 99 / 100];
  result.above_015 = static_cast<double>(differences.end() - std::upper_bound(differences.begin(), differences.end(), 0.15)) /
                     static_cast<double>(differences.size());
  return result;
}

TEST(Synth, LambertianPointsLookTheSameInEveryViewButSpecularOnesDoNot) {
  SynthOptions o;
  o.rig.views = 8;
  o.rig.width = 320;
  o.rig.height = 240;
  o.init.vertices = 300;
  const IndexedMesh truth = small_sphere(0.08, 4);
  const Agreement lambertian = colour_agreement(make_synth_scene(truth, nullptr, o));
  std::printf("Lambertian: %zu view pairs, max-channel difference mean %.4f, 99th percentile %.4f, > 0.15: %.2f%%\n",
              lambertian.pairs, lambertian.mean, lambertian.p99, 100 * lambertian.above_015);
  ASSERT_GT(lambertian.pairs, 300u);
  // Differences come only from 8-bit rounding and from pixel-area filtering of the texture
  // seen at different scales.
  EXPECT_LT(lambertian.mean, 0.02);
  EXPECT_LT(lambertian.p99, 0.08);

  o.render.specular = 0.6;
  o.render.shininess = 20;
  const Agreement specular = colour_agreement(make_synth_scene(truth, nullptr, o));
  std::printf("Specular 0.6: %zu view pairs, mean %.4f, 99th percentile %.4f, > 0.15: %.2f%%\n", specular.pairs,
              specular.mean, specular.p99, 100 * specular.above_015);
  // The highlight moves with the viewer: some points differ by far more than any Lambertian pair.
  EXPECT_GT(specular.above_015, 0.02);
  EXPECT_GT(specular.p99, 2 * lambertian.p99);
}

TEST(Synth, CentreRayHitsTheSphereAtCameraDistanceMinusRadius) {
  const IndexedMesh sphere = small_sphere(0.0, 4);  // a plain icosphere of radius 1
  RigOptions rig;
  rig.views = 1;
  rig.elevation_min = rig.elevation_max = 0.0;
  rig.distance = 3.0;
  const double radius = 1.0;
  const Camera camera = make_rig(rig, Eigen::Vector3d::Zero(), radius).front().camera;
  EXPECT_NEAR((camera.centre() - Eigen::Vector3d::Zero()).norm(), 3.0, 1e-12);
  const SurfaceQuery query(sphere);
  const Ray ray = camera.ray(0.5 * (camera.width() - 1), 0.5 * (camera.height() - 1));
  const auto hit = query.intersect(ray.origin, ray.direction);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->distance, 3.0 - radius, 1e-4 * (3.0 - radius));
}

TEST(Synth, ObjectFillsAGoodPartOfTheFrame) {
  SynthOptions o;  // the default rig on the default bumpy sphere
  o.rig.views = 2;
  o.render.background = BackgroundKind::Black;
  const IndexedMesh truth = make_bumpy_sphere({});
  const SynthScene scene = make_synth_scene(truth, nullptr, o);
  const SurfaceQuery query(truth);
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    const Camera& camera = scene.views[i].camera;
    std::size_t covered = 0, lit = 0;
    for (int y = 0; y < camera.height(); ++y)
      for (int x = 0; x < camera.width(); ++x) {
        const Ray ray = camera.ray(x, y);
        covered += query.intersect(ray.origin, ray.direction).has_value();
        lit += scene.images[i].pixel(x, y).maxCoeff() > 0;
      }
    const double pixels = static_cast<double>(camera.width()) * camera.height();
    const double coverage = covered / pixels, non_black = lit / pixels;
    std::printf("view %zu: silhouette covers %.1f%% of the image, non-black pixels %.1f%%\n", i, 100 * coverage,
                100 * non_black);
    EXPECT_GT(coverage, 0.15);
    EXPECT_LT(coverage, 0.70);
    // The rendered silhouette matches the geometric one (anti-aliased edge pixels aside).
    EXPECT_NEAR(non_black, coverage, 0.01);
  }
}

TEST(Synth, PeanutIsClosedGenusZeroAndNotConvex) {
  BuiltinShapeOptions shape;
  shape.level = 4;
  shape.amplitude = 0.0;
  const IndexedMesh peanut = make_peanut(shape);
  const MeshStats stats = compute_mesh_stats(build_mesh(peanut, "peanut"));
  EXPECT_TRUE(stats.is_closed());
  EXPECT_TRUE(stats.is_manifold());
  EXPECT_EQ(stats.genus, 0);
  // The midpoint of two points on the two lobes lies outside: the waist is concave.
  const SurfaceQuery query(peanut);
  const auto surface_point = [&](const Eigen::Vector3d& direction) -> Eigen::Vector3d {
    return query.intersect(Eigen::Vector3d::Zero(), direction.normalized())->distance * direction.normalized();
  };
  const Eigen::Vector3d middle = 0.5 * (surface_point({0.6, 0.8, 0}) + surface_point({-0.6, 0.8, 0}));
  EXPECT_GT(middle.norm(), surface_point({0, 1, 0}).norm() + 0.02);
}

TEST(Synth, NormalizationFitsAUnitBoxAndIsRecorded) {
  IndexedMesh mesh = test::octahedron();
  for (auto& p : mesh.positions) p = 5.0 * p + Eigen::Vector3d(10, -3, 2);
  const Normalization n = normalize_to_unit_box(mesh);
  EXPECT_NEAR(n.scale, 0.2, 1e-12);
  EXPECT_TRUE(n.centre.isApprox(Eigen::Vector3d(10, -3, 2)));
  EXPECT_NEAR(radius_about_origin(mesh), 1.0, 1e-12);
}

TEST(Synth, PinchedVertexIsSplitSoTheSurfaceBecomesManifold) {
  // Two tetrahedra touching at vertex 0 (like the cow's pinched vertex).
  IndexedMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 1}, {-1, 0, 0}, {0, -1, 0}, {-1, -1, -1}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}, {0, 5, 4}, {0, 4, 6}, {0, 6, 5}, {4, 5, 6}};
  MeshBuildReport before;
  build_mesh(mesh, "pinched", &before);
  EXPECT_GT(before.rejected_faces, 0u);
  EXPECT_EQ(split_pinched_vertices(mesh), 1u);
  MeshBuildReport after;
  const MeshStats stats = compute_mesh_stats(build_mesh(mesh, "split", &after));
  EXPECT_EQ(after.rejected_faces, 0u);
  EXPECT_TRUE(stats.is_closed());
  EXPECT_EQ(stats.components, 2u);
  EXPECT_EQ(mesh.positions[7], mesh.positions[0]);  // nothing moved
  EXPECT_EQ(split_pinched_vertices(mesh), 0u);
}

// Distances from the initial mesh's vertices to the truth.
struct InitDistances {
  double mean = 0.0, coefficient_of_variation = 0.0, max = 0.0;
};

InitDistances init_distances(const IndexedMesh& init, const IndexedMesh& truth) {
  const SurfaceQuery query(truth);
  std::vector<double> d;
  for (const auto& p : init.positions) d.push_back(query.closest_point(p).distance);
  InitDistances r;
  r.mean = std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(d.size());
  double variance = 0.0;
  for (double x : d) variance += (x - r.mean) * (x - r.mean);
  r.coefficient_of_variation = std::sqrt(variance / static_cast<double>(d.size())) / r.mean;
  r.max = *std::max_element(d.begin(), d.end());
  return r;
}

TEST(Synth, InitialMeshIsClosedCoarseAndNotAShiftedCopy) {
  const IndexedMesh truth = make_bumpy_sphere({});
  double diagonal = 0.0;
  {
    BoundingBox box;
    for (const auto& p : truth.positions) box.extend(p);
    diagonal = box.diagonal();
  }
  for (const auto kind : {InitialMeshKind::Offset, InitialMeshKind::Noise}) {
    InitialMeshOptions options;
    options.kind = kind;
    options.amount = 0.01;
    options.vertices = 800;
    const IndexedMesh init = make_initial_mesh(truth, options);
    const MeshStats stats = compute_mesh_stats(build_mesh(init, "init"));
    EXPECT_TRUE(stats.is_closed());
    EXPECT_TRUE(stats.is_manifold());
    EXPECT_EQ(stats.genus, 0);
    EXPECT_NEAR(static_cast<double>(init.positions.size()), 800.0, 8.0);
    const InitDistances d = init_distances(init, truth);
    std::printf("%s: %zu vertices, distance to truth mean %.4f (%.2f x D x diagonal), CV %.2f, max %.4f\n",
                kind == InitialMeshKind::Offset ? "offset:0.01" : "noise:0.01", init.positions.size(), d.mean,
                d.mean / (0.01 * diagonal), d.coefficient_of_variation, d.max);
    // Of the order of D × diagonal (the lost bumps add to the offset), and not a constant shift.
    EXPECT_GT(d.mean, 0.2 * 0.01 * diagonal);
    EXPECT_LT(d.mean, 8.0 * 0.01 * diagonal);
    EXPECT_GT(d.coefficient_of_variation, 0.25);
  }
}

TEST(Synth, OffsetInitLosesTheBumps) {
  // Radial deviation from the best sphere: the truth's bumps must mostly vanish in the init.
  const auto spread = [](const IndexedMesh& m) {
    std::vector<double> r;
    for (const auto& p : m.positions) r.push_back(p.norm());
    const double mean = std::accumulate(r.begin(), r.end(), 0.0) / static_cast<double>(r.size());
    double s = 0.0;
    for (double x : r) s += (x - mean) * (x - mean);
    return std::sqrt(s / static_cast<double>(r.size()));
  };
  const IndexedMesh truth = make_bumpy_sphere({});
  const IndexedMesh init = make_initial_mesh(truth, {});
  std::printf("radial spread: truth %.4f, offset init %.4f\n", spread(truth), spread(init));
  EXPECT_LT(spread(init), 0.35 * spread(truth));
}

// ----- the command ---------------------------------------------------------------------------

using test::CommandResult;

CommandResult run(const std::string& arguments) { return test::run_mvflow(arguments); }

const std::string kSmall = " --views 4 --width 160 --height 120 --init-vertices 400";

TEST(SynthCommand, DefaultPresetWritesASceneTheLoaderReads) {
  test::ScratchFolder folder;
  const fs::path dir = folder / "scene";
  const CommandResult r = run("synth --preset default" + kSmall + " -o " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* file : {"synth_par.txt", "view_000.png", "view_003.png", "truth.ply", "init.ply", "bbox.txt",
                           "synth.json"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;

  const Scene scene = io::load_scene(dir);
  ASSERT_EQ(scene.size(), 4u);
  EXPECT_EQ(scene.camera_format, "middlebury");
  EXPECT_EQ(scene.views[0].camera.width(), 160);
  EXPECT_EQ(scene.views[0].camera.height(), 120);
  ASSERT_TRUE(scene.mesh_file);
  EXPECT_EQ(scene.mesh_file->filename(), "init.ply");
  EXPECT_NE(scene.bounding_box_source.find("bbox.txt"), std::string::npos) << scene.bounding_box_source;

  const IndexedMesh truth = io::read_mesh(dir / "truth.ply");
  const IndexedMesh init = io::read_mesh(dir / "init.ply");
  EXPECT_EQ(truth.positions.size(), 10242u);  // level-5 icosphere
  EXPECT_NEAR(static_cast<double>(init.positions.size()), 400.0, 4.0);
  for (const auto& p : truth.positions) {
    EXPECT_TRUE((p.array() > scene.bounding_box.min.array()).all());
    EXPECT_TRUE((p.array() < scene.bounding_box.max.array()).all());
  }
  const std::string json = test::read_text(dir / "synth.json");
  EXPECT_NE(json.find("\"seed\": 1"), std::string::npos) << json;
  EXPECT_NE(json.find("\"views\": 4"), std::string::npos) << json;

  // Running again gives the same bytes.
  const fs::path again = folder / "again";
  ASSERT_EQ(run("synth --preset default" + kSmall + " -o " + again.string()).exit_code, 0);
  for (const char* file : {"view_001.png", "truth.ply", "init.ply", "bbox.txt", "synth.json", "synth_par.txt"})
    EXPECT_EQ(test::read_text(dir / file), test::read_text(again / file)) << file;
}

TEST(SynthCommand, ColmapCamerasAndPresetOverrides) {
  test::ScratchFolder folder;
  const fs::path dir = folder / "scene";
  const CommandResult r = run("synth --preset peanut --views 3 --width 64 --height 48 --level 3 --init noise:0.02 "
                              "--init-vertices 200 --cameras colmap -o " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "cameras.txt"));
  EXPECT_FALSE(fs::exists(dir / "synth_par.txt"));
  const Scene scene = io::load_scene(dir);
  EXPECT_EQ(scene.size(), 3u);
  EXPECT_EQ(scene.camera_format, "colmap");
  const std::string json = test::read_text(dir / "synth.json");
  EXPECT_NE(json.find("\"rig\": \"hemisphere\""), std::string::npos) << json;  // from the preset
  EXPECT_NE(json.find("\"spec\": \"noise:0.02\""), std::string::npos) << json;  // overridden
}

TEST(SynthCommand, UvTexturedSpotWhenTheSharedDataIsThere) {
  const fs::path spot = fs::path(MVFLOW_SHARED_DATA) / "models" / "spot" / "spot_triangulated.obj";
  if (!fs::exists(spot)) GTEST_SKIP() << spot << " not found";
  test::ScratchFolder folder;
  const fs::path dir = folder / "spot";
  const CommandResult r = run("synth --preset spot --views 2 --width 80 --height 60 --init-vertices 300 --object " +
                              spot.string() + " --texture " + (spot.parent_path() / "spot_texture.png").string() +
                              " -o " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(test::read_text(dir / "synth.json").find("\"used\": \"uv\""), std::string::npos);
  EXPECT_EQ(io::read_mesh(dir / "truth.ply").positions.size(), 2930u);
}

TEST(SynthCommand, BadOptionsExitTwoAndMissingFilesExitOne) {
  test::ScratchFolder folder;
  const std::string out = " -o " + (folder / "x").string();
  for (const std::string bad : {"--views 0", "--init bogus:1", "--elevation 10", "--elevation 40,10", "--light 0,0,0", "--preset nope", "--noise -1",
                                "--albedo paint"}) {
    const CommandResult r = run("synth " + bad + out);
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
    const std::string option = bad.substr(0, bad.find(' '));
    EXPECT_NE(r.output.find(option), std::string::npos) << bad << ": " << r.output;
  }
  const CommandResult missing = run("synth --object " + (folder / "missing.obj").string() + out);
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("missing.obj"), std::string::npos) << missing.output;
  EXPECT_EQ(run("synth --help").exit_code, 0);
}

}  // namespace
}  // namespace mvflow
