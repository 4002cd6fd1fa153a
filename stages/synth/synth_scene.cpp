#include "stages/synth/synth_scene.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "engine/model/parallel.h"
#include "stages/hull/hull_mesh.h"

namespace mvflow {

namespace {

// Independent streams for the independent random choices, all from one user seed.
enum SeedStream : std::uint64_t { kSurfaceTexture = 1, kBackgroundTexture = 2, kPixelNoise = 3, kInitNoise = 4 };

// The exact silhouette of the truth in a view: a pixel is object when the ray through its centre
// meets the truth, whatever the background and the texture. Parallel over rows.
Mask truth_silhouette(const SurfaceQuery& truth, const Camera& camera) {
  Mask mask(camera.width(), camera.height());
  parallel::parallel_for(tbb::blocked_range<int>(0, camera.height()), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y)
      for (int x = 0; x < camera.width(); ++x) {
        const Ray ray = camera.ray(x, y);
        mask.inside[static_cast<std::size_t>(y) * camera.width() + x] = truth.intersect(ray.origin, ray.direction).has_value();
      }
  });
  return mask;
}

// The visual hull of the truth's exact \p silhouettes, remeshed to the initial mesh's vertex count.
IndexedMesh hull_initial_mesh(const SynthScene& scene, const std::vector<Mask>& silhouettes, int vertices) {
  std::vector<Camera> cameras;
  for (const View& view : scene.views) cameras.push_back(view.camera);
  HullMeshOptions options;
  options.vertices = vertices;
  return make_hull_mesh(cameras, silhouettes, scene.bounding_box, options).mesh;
}

}  // namespace

void SynthOptions::check() const {
  require_option(feature_size > 0 && feature_size <= 100, "feature_size", feature_size, "(0, 100]");
  require_option(octaves >= 1 && octaves <= 8, "octaves", octaves, "[1, 8]");
  require_option(background_radius > 1 && background_radius < 1e6, "background_radius", background_radius,
                 "(1, 1e6) object radii");
  require_option(bbox_margin >= 0 && bbox_margin <= 10, "bbox_margin", bbox_margin, "[0, 10]");
  check_member(render, "render");
  check_member(rig, "rig");
  check_member(init, "init");
}

const std::vector<std::string>& builtin_object_names() {
  static const std::vector<std::string> names{"bumpy-sphere", "peanut"};
  return names;
}

bool is_builtin_object(const std::string& name) {
  const auto& names = builtin_object_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

IndexedMesh make_builtin_object(const std::string& name, const BuiltinShapeOptions& options) {
  if (name == "bumpy-sphere") return make_bumpy_sphere(options);
  if (name == "peanut") return make_peanut(options);
  throw InputError("synth: unknown built-in object '" + name + "' (expected bumpy-sphere or peanut)");
}

SynthRenderer make_synth_renderer(const IndexedMesh& truth, std::shared_ptr<const Image> uv_texture,
                                  const SynthOptions& options, const Eigen::Vector3d& centre, double radius,
                                  bool* uv_albedo) {
  options.check();
  const bool has_uv = uv_texture && truth.texcoords.size() == 3 * truth.triangles.size();
  if (options.albedo == AlbedoKind::Uv && !has_uv)
    throw InputError("synth: --albedo uv needs a mesh with texture coordinates and its texture image");
  const bool use_uv = has_uv && options.albedo != AlbedoKind::Solid;
  if (uv_albedo) *uv_albedo = use_uv;

  SurfaceAlbedo albedo;
  if (use_uv) {
    albedo.uv_texture = std::move(uv_texture);
  } else {
    albedo.solid = std::make_shared<SolidTexture>(
        SolidTextureOptions{mix_seed(options.seed, kSurfaceTexture), options.feature_size * radius, options.octaves});
  }
  BackgroundSphere background;
  background.centre = centre;
  // Far enough that it never comes near the object, and always around every camera.
  background.radius = std::max(options.background_radius, 2.0 * options.rig.distance) * radius;
  // Blobs about one object radius across, seen from ~20 radii: a cluttered but smooth backdrop.
  background.texture = std::make_shared<SolidTexture>(
      SolidTextureOptions{mix_seed(options.seed, kBackgroundTexture), 0.05 * background.radius, options.octaves});
  RenderOptions render = options.render;
  render.seed = mix_seed(options.seed, kPixelNoise);
  return SynthRenderer(truth, std::move(albedo), std::move(background), render);
}

SynthScene make_synth_scene(const IndexedMesh& truth, std::shared_ptr<const Image> uv_texture,
                            const SynthOptions& options) {
  options.check();
  SynthScene scene;
  scene.truth = truth;
  BoundingBox box;
  for (const auto& p : truth.positions) box.extend(p);
  scene.centre = box.centre();
  scene.radius = 0.0;
  for (const auto& p : truth.positions) scene.radius = std::max(scene.radius, (p - scene.centre).norm());
  const double margin = options.bbox_margin * box.diagonal();
  scene.bounding_box.min = box.min.array() - margin;
  scene.bounding_box.max = box.max.array() + margin;

  // The initial mesh first: it rejects an open or non-manifold truth before seconds of rendering.
  // A hull needs the views, so it comes last.
  InitialMeshOptions init = options.init;
  init.seed = mix_seed(options.seed, kInitNoise);
  if (init.kind != InitialMeshKind::Hull) scene.initial = make_initial_mesh(truth, init);

  scene.views = make_rig(options.rig, scene.centre, scene.radius);
  const SynthRenderer renderer =
      make_synth_renderer(truth, std::move(uv_texture), options, scene.centre, scene.radius, &scene.uv_albedo);
  scene.images.reserve(scene.views.size());
  for (std::size_t i = 0; i < scene.views.size(); ++i) scene.images.push_back(renderer.render(scene.views[i].camera, i));
  std::vector<Mask> silhouettes;
  if (options.masks || init.kind == InitialMeshKind::Hull)
    for (const View& view : scene.views) silhouettes.push_back(truth_silhouette(renderer.surface(), view.camera));
  if (init.kind == InitialMeshKind::Hull) scene.initial = hull_initial_mesh(scene, silhouettes, init.vertices);
  if (options.masks) scene.silhouettes = std::move(silhouettes);
  return scene;
}

}  // namespace mvflow
