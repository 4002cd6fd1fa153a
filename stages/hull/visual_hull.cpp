#include "stages/hull/visual_hull.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "engine/model/parallel.h"

namespace mvflow {

namespace {

//! The lower envelope of the parabolas (x − q)² + f[q] over the feature positions q (those with
//! a finite f), evaluated at every x in [0, n): Felzenszwalb & Huttenlocher, "Distance transforms
//! of sampled functions", Theory of Computing 8 (2012), algorithm 1. Non-features (f = ∞) are
//! left out of the envelope, so no ∞ − ∞ arises. A line without any feature stays ∞.
void squared_distance_1d(const std::vector<double>& f, int n, std::vector<double>& out, std::vector<int>& parabola,
                         std::vector<double>& boundary) {
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (!std::isfinite(f[q])) continue;
    double s = -std::numeric_limits<double>::infinity();
    while (k >= 0) {
      const int p = parabola[k];
      s = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * (q - p));
      if (s > boundary[k]) break;
      --k;
    }
    ++k;
    parabola[k] = q;
    boundary[k] = k == 0 ? -std::numeric_limits<double>::infinity() : s;
  }
  if (k < 0) {
    std::fill(out.begin(), out.begin() + n, std::numeric_limits<double>::infinity());
    return;
  }
  boundary[k + 1] = std::numeric_limits<double>::infinity();
  int j = 0;
  for (int x = 0; x < n; ++x) {
    while (boundary[j + 1] < x) ++j;
    const double dx = x - parabola[j];
    out[x] = dx * dx + f[parabola[j]];
  }
}

//! Squared Euclidean distance from every pixel centre to the nearest pixel whose mask value is
//! \p feature (∞ when there is none): columns, then rows.
std::vector<double> squared_distance_to(const Mask& mask, bool feature) {
  const int w = mask.width, h = mask.height;
  std::vector<double> d(static_cast<std::size_t>(w) * h);
  for (std::size_t i = 0; i < d.size(); ++i)
    d[i] = (mask.inside[i] != 0) == feature ? 0.0 : std::numeric_limits<double>::infinity();
  const int longest = std::max(w, h);
  std::vector<double> line(longest), out(longest), boundary(longest + 1);
  std::vector<int> parabola(longest);
  for (int x = 0; x < w; ++x) {
    for (int y = 0; y < h; ++y) line[y] = d[static_cast<std::size_t>(y) * w + x];
    squared_distance_1d(line, h, out, parabola, boundary);
    for (int y = 0; y < h; ++y) d[static_cast<std::size_t>(y) * w + x] = out[y];
  }
  for (int y = 0; y < h; ++y) {
    double* row = d.data() + static_cast<std::size_t>(y) * w;
    std::copy(row, row + w, line.begin());
    squared_distance_1d(line, w, out, parabola, boundary);
    std::copy(out.begin(), out.begin() + w, row);
  }
  return d;
}

//! Signed distance from \p X to the box: > 0 inside (to the nearest face), < 0 outside.
double box_distance(const BoundingBox& box, const Eigen::Vector3d& X) {
  const Eigen::Vector3d outside = (box.min - X).cwiseMax(X - box.max);  // > 0 beyond a face
  const double largest = outside.maxCoeff();
  return largest <= 0.0 ? -largest : -outside.cwiseMax(0.0).norm();
}

}  // namespace

void VisualHullOptions::check() const {
  require_option(resolution >= 8 && resolution <= 1024, "resolution", resolution, "[8, 1024]");
  require_option(min_views >= 1, "min_views", min_views, ">= 1");
}

float SilhouetteDistance::sample(double u, double v) const {
  u = std::clamp(u, 0.0, width - 1.0);
  v = std::clamp(v, 0.0, height - 1.0);
  const int x0 = std::min(static_cast<int>(u), width - 1), y0 = std::min(static_cast<int>(v), height - 1);
  const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  const double fx = u - x0, fy = v - y0;
  auto at = [this](int x, int y) { return static_cast<double>(values[static_cast<std::size_t>(y) * width + x]); };
  const double top = (1 - fx) * at(x0, y0) + fx * at(x1, y0);
  const double bottom = (1 - fx) * at(x0, y1) + fx * at(x1, y1);
  return static_cast<float>((1 - fy) * top + fy * bottom);
}

SilhouetteDistance silhouette_distance(const Mask& mask) {
  SilhouetteDistance result;
  result.width = mask.width;
  result.height = mask.height;
  const std::vector<double> to_background = squared_distance_to(mask, false);
  const std::vector<double> to_object = squared_distance_to(mask, true);
  const double cap = mask.width + mask.height;  // stands in for "no such pixel in the image"
  result.values.resize(mask.inside.size());
  for (std::size_t i = 0; i < result.values.size(); ++i) {
    const double d = mask.inside[i] != 0 ? std::sqrt(to_background[i]) - 0.5 : -(std::sqrt(to_object[i]) - 0.5);
    result.values[i] = static_cast<float>(std::clamp(d, -cap, cap));
  }
  return result;
}

ScalarGrid carve_visual_hull(const std::vector<Camera>& cameras, const std::vector<Mask>& silhouettes,
                             const BoundingBox& box, const VisualHullOptions& options) {
  options.check();
  if (cameras.size() != silhouettes.size())
    throw InputError("visual hull: " + std::to_string(cameras.size()) + " cameras but " +
                     std::to_string(silhouettes.size()) + " silhouettes");
  if (box.is_empty() || !box.min.allFinite() || !box.max.allFinite())
    throw InputError("visual hull: the bounding box is empty or not finite");
  for (std::size_t i = 0; i < cameras.size(); ++i)
    if (silhouettes[i].width != cameras[i].width() || silhouettes[i].height != cameras[i].height())
      throw InputError("visual hull: view " + std::to_string(i) + ": the silhouette is " +
                       std::to_string(silhouettes[i].width) + "x" + std::to_string(silhouettes[i].height) +
                       " pixels, its camera's image " + std::to_string(cameras[i].width()) + "x" +
                       std::to_string(cameras[i].height()));

  std::vector<SilhouetteDistance> distances(silhouettes.size());
  parallel::parallel_for(std::size_t{0}, silhouettes.size(),
                         [&](std::size_t i) { distances[i] = silhouette_distance(silhouettes[i]); });
  std::vector<double> focal(cameras.size());
  for (std::size_t i = 0; i < cameras.size(); ++i) focal[i] = cameras[i].focal_pixels();

  ScalarGrid grid;
  const Eigen::Vector3d extent = box.size();
  grid.spacing = extent.maxCoeff() / options.resolution;
  if (!(grid.spacing > 0.0)) throw InputError("visual hull: the bounding box has no extent");
  for (int a = 0; a < 3; ++a) grid.size[a] = static_cast<int>(std::ceil(extent[a] / grid.spacing - 1e-9)) + 3;
  grid.origin = box.centre() - 0.5 * grid.spacing * Eigen::Vector3d(grid.size[0] - 1, grid.size[1] - 1, grid.size[2] - 1);
  grid.values.resize(grid.count());

  // Beyond ±3h the exact value no longer moves the iso-surface; the clamp also lets a sample stop
  // at the first views that put it far outside.
  const double band = 3.0 * grid.spacing;
  const auto min_views = static_cast<std::size_t>(options.min_views);
  parallel::parallel_for(tbb::blocked_range<int>(0, grid.size[2]), [&](const tbb::blocked_range<int>& slices) {
    for (int k = slices.begin(); k < slices.end(); ++k)
      for (int j = 0; j < grid.size[1]; ++j)
        for (int i = 0; i < grid.size[0]; ++i) {
          const Eigen::Vector3d X = grid.point(i, j, k);
          double f = box_distance(box, X);
          std::size_t seen = 0;
          for (std::size_t view = 0; view < cameras.size() && f > -band; ++view) {
            const Projection p = cameras[view].project(X);
            if (!(p.depth > 0.0) || !cameras[view].in_image(p.u, p.v)) continue;
            ++seen;
            f = std::min(f, distances[view].sample(p.u, p.v) * p.depth / focal[view]);
          }
          if (f > -band && seen < min_views) f = -band;
          grid.values[grid.index(i, j, k)] = static_cast<float>(std::clamp(f, -band, band));
        }
  });
  return grid;
}

}  // namespace mvflow
