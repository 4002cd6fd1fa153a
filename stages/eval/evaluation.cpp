#include "stages/eval/evaluation.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "engine/model/bounding_box.h"
#include "engine/model/error.h"
#include "engine/model/option_check.h"
#include "engine/model/parallel.h"
#include "engine/model/surface_query.h"

namespace mvflow {

namespace {

// Uniform double in [0,1) from 53 random bits: the same numbers on every platform, unlike
// std::uniform_real_distribution whose algorithm the standard leaves open.
double unit_random(std::mt19937_64& random) { return static_cast<double>(random() >> 11) * 0x1.0p-53; }

DirectedDistances summarize(std::vector<double> distances, double fraction, double threshold) {
  DirectedDistances d;
  if (distances.empty()) return d;
  // Sums in sample order: deterministic whatever the thread count that filled the vector.
  double sum = 0.0, sum_squares = 0.0;
  std::size_t within = 0;
  for (double x : distances) {
    sum += x;
    sum_squares += x * x;
    within += x <= threshold;
  }
  const auto n = static_cast<double>(distances.size());
  d.mean = sum / n;
  d.rms = std::sqrt(sum_squares / n);
  d.within_threshold = static_cast<double>(within) / n;
  const auto rank = std::min(distances.size() - 1, static_cast<std::size_t>(std::ceil(fraction * n)) - 1);
  std::nth_element(distances.begin(), distances.begin() + static_cast<std::ptrdiff_t>(rank), distances.end());
  d.quantile = distances[rank];
  d.max = *std::max_element(distances.begin(), distances.end());
  return d;
}

std::vector<double> distances_to(const std::vector<Eigen::Vector3d>& points, const SurfaceQuery& surface) {
  std::vector<double> distances(points.size());
  parallel::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 1024), [&](const auto& range) {
    for (std::size_t i = range.begin(); i < range.end(); ++i) distances[i] = surface.closest_point(points[i]).distance;
  });
  return distances;
}

BoundingBox bounding_box_of(const IndexedMesh& mesh) {
  BoundingBox box;
  for (const auto& p : mesh.positions) box.extend(p);
  return box;
}

}  // namespace

void EvaluationOptions::check() const {
  require_option(samples > 0, "samples", samples, "> 0");
  require_option(accuracy_fraction > 0 && accuracy_fraction <= 1, "accuracy_fraction", accuracy_fraction, "(0, 1]");
  require_option(completeness_threshold >= 0, "completeness_threshold", completeness_threshold, ">= 0");
}

double EvaluationResult::symmetric_rms() const {
  return std::sqrt(0.5 * (mesh_to_truth.rms * mesh_to_truth.rms + truth_to_mesh.rms * truth_to_mesh.rms));
}

std::vector<Eigen::Vector3d> sample_surface(const IndexedMesh& mesh, std::size_t count, std::uint64_t seed) {
  std::vector<double> cumulative_area;
  cumulative_area.reserve(mesh.triangles.size());
  double total = 0.0;
  for (const auto& t : mesh.triangles) {
    const auto &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative_area.push_back(total);
  }
  if (!(total > 0) || !std::isfinite(total)) throw InputError("cannot sample a surface with no area");
  std::mt19937_64 random(seed);
  std::vector<Eigen::Vector3d> samples;
  samples.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double target = unit_random(random) * total;
    const auto face = std::min<std::size_t>(
        static_cast<std::size_t>(std::upper_bound(cumulative_area.begin(), cumulative_area.end(), target) -
                                 cumulative_area.begin()),
        mesh.triangles.size() - 1);
    // Uniform point in a triangle: fold the unit square onto it.
    double r1 = unit_random(random), r2 = unit_random(random);
    if (r1 + r2 > 1) {
      r1 = 1 - r1;
      r2 = 1 - r2;
    }
    const auto& t = mesh.triangles[face];
    const auto &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
    samples.push_back(a + r1 * (b - a) + r2 * (c - a));
  }
  return samples;
}

EvaluationResult evaluate_against_truth(const IndexedMesh& mesh, const IndexedMesh& truth,
                                        const EvaluationOptions& options) {
  options.check();
  if (mesh.triangles.empty()) throw InputError("the mesh to evaluate has no triangles");
  if (truth.triangles.empty()) throw InputError("the ground-truth mesh has no triangles");
  EvaluationResult result;
  result.truth_diagonal = bounding_box_of(truth).diagonal();
  result.threshold = options.completeness_threshold * result.truth_diagonal;

  const SurfaceQuery truth_surface(truth);
  const SurfaceQuery mesh_surface(mesh);
  // Different seeds for the two sample sets so that identical meshes are not sampled identically.
  const auto mesh_samples = sample_surface(mesh, options.samples, options.seed);
  const auto truth_samples = sample_surface(truth, options.samples, options.seed + 1);
  result.mesh_to_truth =
      summarize(distances_to(mesh_samples, truth_surface), options.accuracy_fraction, result.threshold);
  result.truth_to_mesh =
      summarize(distances_to(truth_samples, mesh_surface), options.accuracy_fraction, result.threshold);
  return result;
}

}  // namespace mvflow
