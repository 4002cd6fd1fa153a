// The evaluator against analytic answers.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "engine/model/error.h"
#include "engine/model/primitives.h"
#include "stages/eval/evaluation.h"

namespace mvflow {
namespace {

EvaluationOptions few_samples(std::size_t samples = 20000) {
  EvaluationOptions options;
  options.samples = samples;
  return options;
}

double signed_volume(const IndexedMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles)
    v += m.positions[t[0]].dot(m.positions[t[1]].cross(m.positions[t[2]])) / 6.0;
  return v;
}

TEST(Primitives, IcosphereIsOutwardAndOnTheSphere) {
  const IndexedMesh sphere = make_icosphere(2.0, 3);
  EXPECT_EQ(sphere.positions.size(), 10u * 64 + 2);
  for (const auto& p : sphere.positions) EXPECT_NEAR(p.norm(), 2.0, 1e-12);
  // Outward faces give a positive signed volume, close to the sphere's.
  EXPECT_NEAR(signed_volume(sphere), 4.0 / 3.0 * std::numbers::pi * 8.0, 0.02 * 4.0 / 3.0 * std::numbers::pi * 8.0);
}

TEST(Evaluation, SamplesAreUniformByArea) {
  // Two unit squares side by side but the right one split into many more triangles: each half
  // must still get half the samples.
  IndexedMesh mesh = make_grid(1.0, 1);
  const IndexedMesh fine = make_grid(1.0, 8);
  const auto offset = static_cast<std::uint32_t>(mesh.positions.size());
  for (const auto& p : fine.positions) mesh.positions.push_back(p + Eigen::Vector3d(1, 0, 0));
  for (const auto& t : fine.triangles) mesh.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const auto samples = sample_surface(mesh, 40000, 3);
  std::size_t right = 0;
  for (const auto& s : samples) right += s.x() > 1.0;
  EXPECT_NEAR(static_cast<double>(right) / 40000, 0.5, 0.01);  // 4σ of a binomial ≈ 0.01
  EXPECT_EQ(samples, sample_surface(mesh, 40000, 3));            // deterministic
}

TEST(Evaluation, MeshAgainstItselfIsZero) {
  const IndexedMesh sphere = make_icosphere(1.0, 3);
  const EvaluationResult r = evaluate_against_truth(sphere, sphere, few_samples());
  EXPECT_LT(r.hausdorff(), 1e-12);
  EXPECT_EQ(r.completeness(), 1.0);
}

TEST(Evaluation, ConcentricSpheresAreDeltaApart) {
  // Radii 1 and 1.05. Vertices lie on the spheres, faces sag inside by at most
  // r·(1 − cos θ) with θ the largest angle from a face's vertices to its centre; the test
  // allows that sag on top of δ.
  const double delta = 0.05;
  const IndexedMesh inner = make_icosphere(1.0, 4);
  const IndexedMesh outer = make_icosphere(1.0 + delta, 4);
  double max_sag = 0;
  for (const auto& t : outer.triangles) {
    const Eigen::Vector3d centroid = (outer.positions[t[0]] + outer.positions[t[1]] + outer.positions[t[2]]) / 3;
    max_sag = std::max(max_sag, (1.0 + delta) - centroid.norm());
  }
  const EvaluationResult r = evaluate_against_truth(outer, inner, few_samples());
  EXPECT_NEAR(r.mesh_to_truth.mean, delta, max_sag);
  EXPECT_NEAR(r.truth_to_mesh.mean, delta, max_sag);
  EXPECT_NEAR(r.accuracy(), delta, max_sag);
  EXPECT_LE(r.hausdorff(), delta + max_sag);
  EXPECT_GE(r.hausdorff(), delta - max_sag);
  EXPECT_NEAR(r.truth_diagonal, 2.0 * std::sqrt(3.0), 0.01);
}

TEST(Evaluation, TranslatedPlaneIsTheTranslationLength) {
  const IndexedMesh truth = make_grid(1.0, 10);
  IndexedMesh moved = truth;
  for (auto& p : moved.positions) p.z() += 0.03;
  const EvaluationResult r = evaluate_against_truth(moved, truth, few_samples());
  EXPECT_NEAR(r.mesh_to_truth.mean, 0.03, 1e-12);
  EXPECT_NEAR(r.mesh_to_truth.max, 0.03, 1e-12);
  EXPECT_NEAR(r.accuracy(), 0.03, 1e-12);
  EXPECT_NEAR(r.symmetric_rms(), 0.03, 1e-12);
}

TEST(Evaluation, PartialMeshLosesTheRemovedAreaInCompleteness) {
  const IndexedMesh truth = make_grid(1.0, 20);
  IndexedMesh partial = truth;
  // Remove the cells with x < 0.3: 30 % of the area.
  std::vector<std::array<std::uint32_t, 3>> kept;
  for (const auto& t : truth.triangles) {
    const double x = (truth.positions[t[0]].x() + truth.positions[t[1]].x() + truth.positions[t[2]].x()) / 3;
    if (x > 0.3) kept.push_back(t);
  }
  partial.triangles = kept;
  EvaluationOptions options = few_samples(40000);
  options.completeness_threshold = 1e-6;
  const EvaluationResult r = evaluate_against_truth(partial, truth, options);
  EXPECT_NEAR(r.completeness(), 0.7, 0.01);
  EXPECT_LT(r.accuracy(), 1e-12);  // what remains lies exactly on the truth
}

TEST(Evaluation, RejectsEmptyMeshes) {
  EXPECT_THROW(evaluate_against_truth(IndexedMesh{}, make_grid(1, 1)), InputError);
  EXPECT_THROW(evaluate_against_truth(make_grid(1, 1), IndexedMesh{}), InputError);
}

}  // namespace
}  // namespace mvflow
