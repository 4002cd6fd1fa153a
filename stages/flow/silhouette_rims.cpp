#include "stages/flow/silhouette_rims.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "stages/flow/silhouette_constraint.h"
#include "stages/flow/silhouette_holes.h"

namespace mvflow {

void SilhouetteRimOptions::check() const {
  require_option(rim_angle_degrees > 0 && rim_angle_degrees < 90, "rim_angle_degrees", rim_angle_degrees, "(0, 90)");
  require_option(dead_zone_pixels >= 0 && dead_zone_pixels < search_pixels, "dead_zone_pixels", dead_zone_pixels,
                 "[0, search_pixels)");
  require_option(search_pixels <= 64, "search_pixels", search_pixels, "(dead_zone_pixels, 64]");
  require_option(step > 0 && step <= 1, "step", step, "(0, 1]");
  require_option(ray_offset >= 0, "ray_offset", ray_offset, ">= 0");
  require_option(fill_holes >= 0 && fill_holes <= 1, "fill_holes", fill_holes, "[0, 1]");
  require_option(dark_border_fraction > 0 && dark_border_fraction <= 1, "dark_border_fraction", dark_border_fraction,
                 "(0, 1]");
}

namespace {

// Pixels from (u, v) to where the mask changes from its value at (u, v), walking along the unit
// image direction \p dir in half-pixel steps (the boundary is taken half a step before the first
// changed pixel); −1 when it does not change within \p search pixels or the walk leaves the image.
double pixels_to_boundary(const Mask& mask, double u, double v, const Eigen::Vector2d& dir, bool inside,
                          double search) {
  for (double t = 0.5; t <= search; t += 0.5) {
    const long x = std::lround(u + t * dir.x()), y = std::lround(v + t * dir.y());
    if (x < 0 || y < 0 || x >= mask.width || y >= mask.height) return -1.0;
    if (mask.at(static_cast<int>(x), static_cast<int>(y)) != inside) return t - 0.25;
  }
  return -1.0;
}

}  // namespace

bool dark_background(const std::vector<PhotoView>& views, double threshold, double fraction) {
  if (views.empty()) return false;
  for (const PhotoView& view : views) {
    const Image& image = *view.image;
    std::size_t border = 0, dark = 0;
    const auto count = [&](int x, int y) {
      ++border;
      if (image.pixel(x, y).maxCoeff() <= threshold) ++dark;
    };
    for (int x = 0; x < image.width(); ++x) {
      count(x, 0);
      if (image.height() > 1) count(x, image.height() - 1);
    }
    for (int y = 1; y + 1 < image.height(); ++y) {
      count(0, y);
      if (image.width() > 1) count(image.width() - 1, y);
    }
    if (border == 0 || static_cast<double>(dark) < fraction * static_cast<double>(border)) return false;
  }
  return true;
}

bool fits_rims(const std::vector<PhotoView>& views, double threshold, const SilhouetteRimOptions& options) {
  switch (options.fit) {
    case RimFit::On: return true;
    case RimFit::Off: return false;
    case RimFit::Auto: return dark_background(views, threshold, options.dark_border_fraction);
  }
  return false;
}

std::vector<Mask> rim_silhouettes(const std::vector<PhotoView>& views, const SilhouetteOptions& threshold,
                                  const SilhouetteRimOptions& options) {
  SilhouetteOptions exact = threshold;
  exact.dilate = 0;  // the boundary itself, not a conservative margin
  std::vector<Mask> masks = threshold_silhouettes(views, exact);
  for (Mask& mask : masks)
    mask = fill_silhouette_holes(mask, static_cast<std::size_t>(options.fill_holes * static_cast<double>(mask.inside.size())));
  return masks;
}

double rim_move(const Eigen::Vector3d& X, const Eigen::Vector3d& N, const std::vector<PhotoView>& views,
                const std::vector<Mask>& masks, const SurfaceQuery* surface, double mean_edge,
                const SilhouetteRimOptions& options, int* rim_views) {
  const double sin_rim = std::sin(options.rim_angle_degrees * std::numbers::pi / 180.0);
  double total = 0.0;
  int rims = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const PhotoView& view = views[i];
    const Eigen::Vector3d ray = X - view.camera->centre();
    const double distance = ray.norm();
    if (!(distance > 0) || std::abs(N.dot(ray)) > sin_rim * distance) continue;
    const Projection p = view.project(X);
    if (!(p.depth > 0)) continue;
    // Where N points in the image, and how many pixels one world unit along N covers there.
    const double probe = p.depth / view.camera->focal_pixels();  // about one pixel
    const Projection q = view.project(X + probe * N);
    Eigen::Vector2d dir(q.u - p.u, q.v - p.v);
    const double pixels_per_unit = dir.norm() / probe;
    if (!(pixels_per_unit > 0) || !std::isfinite(pixels_per_unit)) continue;
    dir /= dir.norm();
    const Mask& mask = masks[i];
    const long x = std::lround(p.u), y = std::lround(p.v);
    if (x < 0 || y < 0 || x >= mask.width || y >= mask.height) continue;
    const bool inside = mask.at(static_cast<int>(x), static_cast<int>(y));
    // Inside the silhouette the boundary lies outward (along N), outside it inward.
    const double sign = inside ? 1.0 : -1.0;
    const double pixels = pixels_to_boundary(mask, p.u, p.v, sign * dir, inside, options.search_pixels);
    if (pixels < 0) continue;
    if (surface) {  // a hidden rim does not make this view's outline
      const Eigen::Vector3d origin = X + options.ray_offset * mean_edge * N;
      if (surface->occluded(origin, view.camera->centre() - origin, 0.0, 1.0)) continue;
    }
    total += sign * std::max(0.0, pixels - options.dead_zone_pixels) / pixels_per_unit;
    ++rims;
  }
  if (rim_views) *rim_views = rims;
  return rims > 0 ? options.step * total / rims : 0.0;
}

void fit_silhouette_rims(const TriMesh& mesh, IndexRange vertices, const std::vector<PhotoView>& views,
                         const std::vector<Mask>& masks, const SurfaceQuery* surface, double mean_edge,
                         const SilhouetteRimOptions& options, const VertexFields& fields,
                         std::vector<Eigen::Vector3d>& new_positions, std::vector<std::uint8_t>* on_rim) {
  MVFLOW_CHECK(masks.size() == views.size(), "silhouette rims: one mask per view");
  MVFLOW_CHECK(new_positions.size() == mesh.n_vertices(), "silhouette rims: one new position per vertex");
  MVFLOW_CHECK(!on_rim || on_rim->size() == mesh.n_vertices(), "silhouette rims: one rim flag per vertex");
  for (std::uint32_t v = vertices.begin; v < vertices.end; ++v) {
    const Eigen::Vector3d P = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
    const Eigen::Vector3d& N = fields.normal[v];
    int rim_views = 0;
    new_positions[v] = (fields.defined[v] & kNormalDefined)
                           ? P + rim_move(P, N, views, masks, surface, mean_edge, options, &rim_views) * N
                           : P;
    if (on_rim) (*on_rim)[v] = rim_views > 0;
  }
}

}  // namespace mvflow
