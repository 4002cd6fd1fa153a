// End-to-end quality (the engine issue's target) on reduced versions of the README's three
// synthetic scenes: `mvflow synth` renders the scene, `mvflow refine` refines its initial mesh
// (the ground truth smoothed and offset by 1 % of its diagonal) with the default preset, and
// `mvflow eval` compares both meshes with the ground truth. The refined mesh must be at least
// 50 % closer to the truth (symmetric mean distance and 90 % accuracy), lower Σg per vertex,
// closed, manifold and free of self-intersections.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "stages/flow/image_denoise.h"
#include "test_support.h"

namespace mvflow {
namespace {

struct Distances {
  double mean = 0.0;
  double accuracy = 0.0;
};

Distances evaluate(const std::filesystem::path& mesh, const std::filesystem::path& truth,
                   const std::filesystem::path& json) {
  const test::CommandResult run =
      test::run_mvflow("eval " + mesh.string() + " " + truth.string() + " --samples 50000 --json " + json.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = nlohmann::json::parse(test::read_text(json));
  return {j.at("symmetric_mean").get<double>(), j.at("accuracy").get<double>()};
}

// Renders `synth SYNTH_ARGS`, refines, evaluates; checks the target and prints the numbers.
// The refined mesh must have no intersecting face pairs.
Distances expect_refinement_halves_the_error(const std::string& name, const std::string& synth_arguments,
                                             const std::string& refine_arguments = "") {
  const test::ScratchFolder dir;
  const auto scene = dir.path() / "scene";
  const test::CommandResult synth = test::run_mvflow("synth " + synth_arguments + " -o " + scene.string());
  EXPECT_EQ(synth.exit_code, 0) << synth.output;
  if (synth.exit_code != 0) return {};
  const auto refined = dir.path() / "refined.ply";
  const auto report = dir.path() / "report.json";
  const test::CommandResult refine =
      test::run_mvflow("refine " + scene.string() + " -o " + refined.string() + " --report " + report.string() +
                       refine_arguments);
  EXPECT_EQ(refine.exit_code, 0) << refine.output;
  if (refine.exit_code != 0) return {};

  const Distances before = evaluate(scene / "init.ply", scene / "truth.ply", dir.path() / "init.json");
  const Distances after = evaluate(refined, scene / "truth.ply", dir.path() / "refined.json");
  const nlohmann::json r = nlohmann::json::parse(test::read_text(report));
  const double g_before = r.at("initial").at("sum_g_per_vertex").get<double>();
  const double g_after = r.at("final").at("sum_g_per_vertex").get<double>();
  std::printf("[measured] %s: mean %.4g -> %.4g (%.0f %%), accuracy %.4g -> %.4g (%.0f %%), Σg/vertex %.4g -> %.4g, "
              "%d -> %d vertices, %zu iterations (%s), image noise %.5f\n",
              name.c_str(), before.mean, after.mean, 100.0 * (after.mean / before.mean - 1.0), before.accuracy,
              after.accuracy, 100.0 * (after.accuracy / before.accuracy - 1.0), g_before, g_after,
              r.at("initial").at("vertices").get<int>(), r.at("final").at("vertices").get<int>(),
              r.at("iterations").size(), r.at("status").get<std::string>().c_str(),
              r.at("initial").at("image_noise").get<double>());
  EXPECT_LE(after.mean, 0.5 * before.mean);
  EXPECT_LE(after.accuracy, 0.5 * before.accuracy);
  EXPECT_LT(g_after, g_before);
  EXPECT_EQ(r.at("final").at("self_intersecting_face_pairs").get<int>(), 0);
  // Clean renders read below the noise reference even at this size, where their fine texture
  // reads most (0.0013–0.0018): the settled rule keeps the option's tolerance.
  const double image_noise = r.at("initial").at("image_noise").get<double>();
  EXPECT_GT(image_noise, 0.0);
  EXPECT_LT(image_noise, r.at("options").at("settled_noise_reference").get<double>());
  EXPECT_EQ(r.at("initial").at("settled_tolerance").get<double>(), r.at("options").at("settled_tolerance").get<double>());
  EXPECT_EQ(r.at("initial").at("denoise_sigma").get<double>(), 0.0);  // nor are they blurred
  // It ended by a stopping rule, well inside the iteration budget (issue 12: convergence).
  const std::string status = r.at("status").get<std::string>();
  EXPECT_TRUE(status == "converged" || status == "step-small" || status == "settled") << status;
  EXPECT_LE(r.at("iterations").size(), 0.75 * r.at("options").at("max_iterations").get<double>());

  const test::CommandResult info = test::run_mvflow("info " + scene.string() + " --mesh " + refined.string());
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("1 component(s), total genus 0, Euler characteristic 2, 0 boundary edge(s)"),
            std::string::npos)
      << info.output;
  EXPECT_NE(info.output.find("0 non-manifold vertex(es), 0 face(s) skipped as non-manifold"), std::string::npos)
      << info.output;
  return after;
}

// Half the README's image size keeps each scene within seconds.
const std::string kSmall = " --width 320 --height 240";

// With the default preset, and with the accurate preset (surface patches, README "Surface
// patches"): the same targets, and the accurate preset's error lower than the default's.
TEST(Quality, BumpySphere) {
  const Distances plain = expect_refinement_halves_the_error("bumpy-sphere", "--preset default" + kSmall);
  const Distances accurate = expect_refinement_halves_the_error("bumpy-sphere, --preset accurate",
                                                                "--preset default" + kSmall, " --preset accurate");
  EXPECT_LT(accurate.mean, plain.mean);
  EXPECT_LT(accurate.accuracy, plain.accuracy);
}

TEST(Quality, ConcavePeanut) { expect_refinement_halves_the_error("peanut", "--preset peanut" + kSmall); }

TEST(Quality, Bunny) {
  if (!std::filesystem::exists(std::filesystem::path(MVFLOW_SHARED_DATA) / "models" / "bunny-lowres-npm.obj"))
    GTEST_SKIP() << "the bunny model is not in " << MVFLOW_SHARED_DATA;
  // Before the untangling, a few intersecting face pairs came and went with the last bits of the
  // flow on the bunny (render seeds 1–6: 0–7 pairs of ~9 500 faces); the refined mesh must now
  // have none, like the other scenes.
  expect_refinement_halves_the_error("bunny", "--preset bunny" + kSmall);
}

// Image noise (σ = 0.01 per channel on a two-ring sphere, issue 12's t3 scene): by default the
// photographs are blurred just enough to bring their estimated noise to the reference 0.002 for
// the image patches (stages/flow/image_denoise.h), so the settled rule keeps its tolerance; with
// `--denoise off` the noise raises the tolerance by √(σ̂/0.002) instead (sessions 23–25), and with
// that rule off too the run takes longest. Measured (session 29, with far vertices on the
// half-resolution photographs as given): 50 iterations, mean 0.00142, against 61 and 0.00137 with
// --denoise off and 84 and 0.00140 with both off (session 27, with the step momentum: 50 / 0.00141,
// 56 / 0.00151, 77 / 0.00147; session 26: 50 / 0.00142, 58 / 0.00150, 74 / 0.00151). With the far
// vertices reading half-resolution copies of the blurred photographs the blurred run's mean was
// 0.00152, 10 % above --denoise off: the 2×2 average already halves the noise.
TEST(Quality, NoisyPhotographsAreBlurredAndSettleSooner) {
  const test::ScratchFolder dir;
  const auto scene = dir.path() / "scene";
  const test::CommandResult synth = test::run_mvflow(
      "synth --amplitude 0 --elevation -5,35 --views 20 --seed 5 --noise 0.01 -o " + scene.string());
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  struct Run {
    nlohmann::json report;
    double mean = 0.0;
    std::size_t iterations() const { return report.at("iterations").size(); }
    double initial(const char* key) const { return report.at("initial").at(key).get<double>(); }
  };
  const auto refine = [&](const std::string& options) {
    const auto refined = dir.path() / "refined.ply";
    const auto report = dir.path() / "report.json";
    const test::CommandResult run = test::run_mvflow("refine " + scene.string() + " -o " + refined.string() +
                                                     " --report " + report.string() + options);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    const Distances after = evaluate(refined, scene / "truth.ply", dir.path() / "eval.json");
    return Run{nlohmann::json::parse(test::read_text(report)), after.mean};
  };
  const Run blurred = refine("");
  const Run raised = refine(" --denoise off");
  const Run neither = refine(" --denoise off --settle-noise-reference 0");
  const double sigma = blurred.initial("image_noise");
  std::printf("[measured] noisy sphere: image noise %.5f, blurred with σ %.3f px: mean %.5g, %zu iterations (%s); "
              "--denoise off (settled tolerance %.5f): mean %.5g, %zu iterations (%s); both off: mean %.5g, %zu "
              "iterations (%s)\n",
              sigma, blurred.initial("denoise_sigma"), blurred.mean, blurred.iterations(),
              blurred.report.at("status").get<std::string>().c_str(), raised.initial("settled_tolerance"), raised.mean,
              raised.iterations(), raised.report.at("status").get<std::string>().c_str(), neither.mean,
              neither.iterations(), neither.report.at("status").get<std::string>().c_str());
  // The grey value's noise is σ/√3 = 0.0058 (three independent channels averaged).
  EXPECT_NEAR(sigma, 0.01 / std::sqrt(3.0), 0.0008);
  // The blur leaves the reference's noise (the gain is checked against blurred noise in
  // stages_image_noise_test), so the tolerance is the option's.
  EXPECT_NEAR(sigma * gaussian_noise_gain(blurred.initial("denoise_sigma")), 0.002, 1e-9);
  EXPECT_EQ(blurred.initial("settled_tolerance"), 0.0025);
  EXPECT_EQ(raised.initial("denoise_sigma"), 0.0);
  EXPECT_EQ(raised.initial("image_noise"), sigma);
  EXPECT_NEAR(raised.initial("settled_tolerance"), 0.0025 * std::sqrt(sigma / 0.002), 1e-12);
  EXPECT_EQ(neither.initial("settled_tolerance"), 0.0025);
  EXPECT_EQ(neither.initial("image_noise"), 0.0);  // not estimated when nothing reads it
  EXPECT_EQ(blurred.report.at("status").get<std::string>(), "settled");
  EXPECT_LT(blurred.iterations(), raised.iterations());
  EXPECT_LT(raised.iterations(), neither.iterations());
  EXPECT_LE(blurred.mean, 0.0025);
  EXPECT_LE(blurred.mean, 1.05 * raised.mean);
  EXPECT_LE(raised.mean, 1.1 * neither.mean);
}

// Issue 12's targets on its sphere rig (24 views on rings at −15° and +25°, so the cap below
// −55° is seen only at grazing angles; the initial mesh 1 % of the diagonal outside): mean
// ≤ 0.0025, acc90 ≤ 0.005, completeness 100 %, and the run ends by a stopping rule in ≤ 60
// iterations. With the default options (auto spreads the hardly observed vertices on a textured
// background, surface patches at oblique vertices, the step momentum; measured 38 iterations,
// settled, 0.00080 / 0.00175, 100 %) and with --spread-unobserved on (39, 0.00077 / 0.00164,
// 100 %; session 26: 40, 0.00081 / 0.00178 both). With session
// 23's image patches everywhere the default left one truth sample in 50 000 at 0.0355 from the mesh
// against the 0.0346 threshold (99.998 %: a vertex the grazing views left 0.05 out at −74°), so
// that was allowed then. Without any spread the cap drifts outward under the smoothing (README,
// "Weakly seen regions": 99.69 %).
TEST(Quality, TwoRingSphereSettlesWithinSixtyIterations) {
  const test::ScratchFolder dir;
  const auto scene = dir.path() / "scene";
  const test::CommandResult synth = test::run_mvflow(
      "synth --amplitude 0 --views 24 --width 640 --height 480 --level 6 --init offset:0.011547 "
      "--init-vertices 2562 --elevation -15,25 -o " + scene.string());
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  for (const std::string spread : {"", " --spread-unobserved on"}) {
    const auto refined = dir.path() / "refined.ply";
    const auto report = dir.path() / "report.json";
    const test::CommandResult refine = test::run_mvflow("refine " + scene.string() + " -o " + refined.string() +
                                                        " --report " + report.string() + spread);
    ASSERT_EQ(refine.exit_code, 0) << refine.output;
    const auto eval_json = dir.path() / "eval.json";
    const test::CommandResult eval = test::run_mvflow("eval " + refined.string() + " " +
                                                      (scene / "truth.ply").string() + " --samples 50000 --json " +
                                                      eval_json.string());
    ASSERT_EQ(eval.exit_code, 0) << eval.output;
    const nlohmann::json e = nlohmann::json::parse(test::read_text(eval_json));
    const nlohmann::json r = nlohmann::json::parse(test::read_text(report));
    const std::string status = r.at("status").get<std::string>();
    std::printf("[measured] two-ring sphere%s: mean %.5g, acc90 %.5g, completeness %.6g, %zu iterations (%s)\n",
                spread.c_str(), e.at("symmetric_mean").get<double>(), e.at("accuracy").get<double>(),
                e.at("completeness").get<double>(), r.at("iterations").size(), status.c_str());
    EXPECT_LE(e.at("symmetric_mean").get<double>(), 0.0025) << spread;
    EXPECT_LE(e.at("accuracy").get<double>(), 0.005) << spread;
    EXPECT_GE(e.at("completeness").get<double>(), 1.0) << spread;
    EXPECT_TRUE(status == "converged" || status == "settled") << status;
    EXPECT_LE(r.at("iterations").size(), 60u) << spread;
  }
}

}  // namespace
}  // namespace mvflow
