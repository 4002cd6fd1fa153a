#include "stages/eval/photo_slice.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

#include "engine/model/error.h"
#include "engine/model/mesh_stats.h"
#include "engine/model/option_check.h"
#include "engine/model/parallel.h"
#include "engine/model/surface_query.h"
#include "stages/flow/normals.h"
#include "stages/flow/surface_patch.h"

namespace mvflow {

void PhotoSliceOptions::check() const {
  require_option(axis >= 0 && axis <= 2, "axis", axis, "0, 1 or 2");
  require_option(position >= 0 && position <= 1, "position", position, "[0, 1]");
  require_option(resolution >= 2 && resolution <= 20000, "resolution", resolution, "[2, 20000]");
  require_option(margin >= 0, "margin", margin, ">= 0");
  check_member(visibility, "visibility");
  check_member(photo, "photo");
}

std::vector<std::array<Eigen::Vector3d, 2>> plane_cross_section(const TriMesh& mesh, int axis, double value) {
  std::vector<std::array<Eigen::Vector3d, 2>> segments;
  for (auto f : mesh.faces()) {
    std::array<Eigen::Vector3d, 3> p;
    int corner = 0;
    for (auto v : mesh.fv_range(f)) p[corner++] = to_eigen(mesh.point(v));
    // Crossing points on the edges whose ends lie on opposite sides (a vertex exactly on the
    // plane counts as above, so each crossing is found once).
    std::vector<Eigen::Vector3d> crossings;
    for (int e = 0; e < 3; ++e) {
      const Eigen::Vector3d& a = p[e];
      const Eigen::Vector3d& b = p[(e + 1) % 3];
      const double da = a[axis] - value, db = b[axis] - value;
      if ((da < 0) != (db < 0)) crossings.push_back(a + (da / (da - db)) * (b - a));
    }
    if (crossings.size() == 2) segments.push_back({crossings[0], crossings[1]});
  }
  return segments;
}

PhotoSlice compute_photo_slice(const TriMesh& mesh, const std::vector<PhotoView>& views,
                               const PhotoSliceOptions& options) {
  options.check();
  if (mesh.n_faces() == 0) throw InputError("slice: the mesh has no faces");
  BoundingBox box = bounding_box_of(mesh);
  const Eigen::Vector3d grow = options.margin * box.size();
  box.min -= grow;
  box.max += grow;

  PhotoSlice slice;
  const int a = options.axis, u = (a + 1) % 3, w = (a + 2) % 3;
  const double extent_u = box.size()[u], extent_w = box.size()[w];
  slice.step = std::max(extent_u, extent_w) / (options.resolution - 1);
  slice.width = std::max(2, static_cast<int>(std::round(extent_u / slice.step)) + 1);
  slice.height = std::max(2, static_cast<int>(std::round(extent_w / slice.step)) + 1);
  slice.u_axis = Eigen::Vector3d::Unit(u);
  slice.v_axis = Eigen::Vector3d::Unit(w);
  slice.origin = box.min;
  const double plane_value = box.min[a] + options.position * box.size()[a];
  slice.origin[a] = plane_value;
  slice.g.assign(static_cast<std::size_t>(slice.width) * slice.height, std::numeric_limits<double>::quiet_NaN());

  const SurfaceQuery surface(mesh);
  VertexFields fields;
  std::vector<std::uint16_t> all_views(views.size());
  for (std::size_t i = 0; i < views.size(); ++i) all_views[i] = static_cast<std::uint16_t>(i);
  // The nearest vertex gives the views (NearestVertex) and the surface patch's normal.
  const bool nearest_vertex =
      options.views == SliceViews::NearestVertex || options.photo.surface_patch != SurfacePatchUse::Off;
  if (nearest_vertex) {
    fields.resize(mesh.n_vertices(), views.size());
    const IndexRange everything{0, static_cast<std::uint32_t>(mesh.n_vertices())};
    compute_normals(mesh, everything, fields);
    if (options.views == SliceViews::NearestVertex)
      compute_visibility(mesh, everything, views, surface, edge_lengths(mesh).mean, options.visibility, fields);
  }

  parallel::parallel_for(0, slice.height, [&](int j) {
    SurfacePatchLayout layout;
    for (int i = 0; i < slice.width; ++i) {
      const Eigen::Vector3d X = slice.point(i, j);
      std::span<const std::uint16_t> used(all_views);
      std::uint32_t best = 0;
      if (nearest_vertex) {
        // The nearest corner of the nearest face stands in for the nearest vertex.
        const ClosestPoint nearest = surface.closest_point(X);
        double best_distance = std::numeric_limits<double>::infinity();
        for (auto v : mesh.fv_range(TriMesh::FaceHandle(static_cast<int>(nearest.face)))) {
          const double d = (to_eigen(mesh.point(v)) - X).squaredNorm();
          if (d < best_distance) best_distance = d, best = static_cast<std::uint32_t>(v.idx());
        }
      }
      if (options.views == SliceViews::NearestVertex)
        used = std::span<const std::uint16_t>(fields.visible_views.data() + best * fields.view_capacity,
                                              fields.visible_count[best]);
      // fields.normal is sized only when a nearest vertex was looked for.
      const Eigen::Vector3d normal = nearest_vertex ? fields.normal[best] : Eigen::Vector3d::Zero();
      const PhotoValue value = photo_consistency_at_surface(X, normal, used, views, options.photo, layout);
      if (value.defined()) slice.g[static_cast<std::size_t>(j) * slice.width + i] = value.g;
    }
  });

  for (const auto& segment : plane_cross_section(mesh, a, plane_value)) {
    std::array<Eigen::Vector2d, 2> s;
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3d d = (segment[k] - slice.origin) / slice.step;
      s[k] = {d[u], d[w]};
    }
    slice.cross_section.push_back(s);
  }
  return slice;
}

}  // namespace mvflow
