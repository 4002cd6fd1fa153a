#include "stages/hull/hull_mesh.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "engine/model/surface_query.h"
#include "stages/hull/isotropic_remeshing.h"
#include "stages/hull/mesh_cleanup.h"
#include "stages/hull/neck_cutting.h"
#include "stages/hull/scalar_grid.h"

namespace mvflow {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double surface_area(const IndexedMesh& mesh) {
  double twice = 0.0;
  for (const auto& t : mesh.triangles)
    twice += (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]).norm();
  return 0.5 * twice;
}

}  // namespace

void HullMeshOptions::check() const {
  check_member(carving, "carving");
  check_member(extraction, "extraction");
  require_option(vertices >= 20, "vertices", vertices, ">= 20");
  require_option(smoothing >= 0.0 && smoothing <= 100.0, "smoothing", smoothing, "[0, 100] grid samples");
  require_option(neck_edge >= 0.0 && neck_edge <= 0.8, "neck_edge", neck_edge, "[0, 0.8]");
  require_option(remeshing_iterations >= 2, "remeshing_iterations", remeshing_iterations, ">= 2");
}

HullMeshResult make_hull_mesh(const std::vector<Camera>& cameras, const std::vector<Mask>& silhouettes,
                              const BoundingBox& box, const HullMeshOptions& options) {
  options.check();
  HullMeshResult result;
  auto start = std::chrono::steady_clock::now();
  const ScalarGrid grid = gaussian_blur(carve_visual_hull(cameras, silhouettes, box, options.carving), options.smoothing);
  result.grid_size = grid.size;
  result.grid_spacing = grid.spacing;
  result.inside_samples = static_cast<std::size_t>(std::count_if(
      grid.values.begin(), grid.values.end(), [&](float f) { return f > options.extraction.level; }));
  result.seconds_carving = seconds_since(start);
  if (result.inside_samples == 0)
    throw InputError("hull: the visual hull is empty: no point of the bounding box lies inside the silhouette in "
                     "every view that sees it (check the silhouettes, the bounding box and the cameras)");

  start = std::chrono::steady_clock::now();
  IndexedMesh surface = extract_iso_surface(grid, options.extraction);
  result.extracted_vertices = surface.positions.size();
  surface = largest_component(surface, &result.extracted_components);
  result.kept_vertices = surface.positions.size();
  result.seconds_extraction = seconds_since(start);

  // Straight from the fine surface: the first round's collapses do what a decimation would, in
  // a fraction of the time of quadric decimation. The meshes settle at a mean edge a little
  // below the target length, so the second half of the rounds scales the length by the ratio of
  // the count reached to the target count. Not by its square root, as V ∝ 1/L² would suggest:
  // edges already within the split/collapse bounds stay as they are, so the count answers a
  // change of length much less (measured on the Middlebury hulls: about as 1/L).
  start = std::chrono::steady_clock::now();
  const SurfaceQuery reference(surface);
  MeshBuildReport built;
  Mesh mesh = build_mesh(surface, "hull surface", &built);
  MVFLOW_CHECK(built.rejected_faces == 0, "hull: the extracted surface is not manifold");
  const auto target = static_cast<double>(options.vertices);
  IsotropicRemeshingOptions remeshing;
  remeshing.target_edge = edge_length_for_vertices(surface_area(surface), static_cast<std::size_t>(options.vertices));
  remeshing.iterations = options.remeshing_iterations / 2;
  remesh_isotropic(mesh.topology, reference, remeshing);
  remeshing.target_edge *= static_cast<double>(mesh.n_vertices()) / target;
  remeshing.iterations = options.remeshing_iterations - remeshing.iterations;
  remesh_isotropic(mesh.topology, reference, remeshing);
  // Each cut leaves caps to be remeshed; a few passes catch the necks that only show then.
  for (int pass = 0; pass < 5; ++pass) {
    const std::size_t cuts = cut_thin_necks(mesh.topology, options.neck_edge * remeshing.target_edge);
    if (cuts == 0) break;
    result.neck_cuts += cuts;
    remeshing.iterations = 3;
    remesh_isotropic(mesh.topology, reference, remeshing);
  }
  result.target_edge = remeshing.target_edge;
  result.mesh = to_indexed(mesh);
  result.seconds_remeshing = seconds_since(start);
  MVFLOW_CHECK(enclosed_volume(result.mesh) > 0.0, "hull: the surface is not oriented outwards");
  return result;
}

}  // namespace mvflow
