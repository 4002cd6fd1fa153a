// Real photographs end to end: one fold of the Middlebury dino (SPEC §8): the visual
// hull carved without four held-out views (`mvflow hull`'s defaults: no dilation), refined without
// them, and both scored on them. The refinement must lower the held-out-view error by at least
// 10 % against the hull's. The README reports the full four-fold runs on both sets
// (tools/heldout_folds.sh).

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "test_support.h"

namespace mvflow {
namespace {

struct HeldoutScore {
  double mae = 0.0;
  double psnr = 0.0;
  double silhouette = 0.0;
};

HeldoutScore score(const std::string& scene, const std::filesystem::path& mesh, const std::string& views,
                   const std::filesystem::path& json) {
  const test::CommandResult run =
      test::run_mvflow("heldout " + scene + " " + mesh.string() + " --views " + views + " --json " + json.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json all = nlohmann::json::parse(test::read_text(json)).at("all");
  return {all.at("mae").get<double>(), all.at("psnr_db").get<double>(),
          all.at("silhouette_disagreement").get<double>()};
}

TEST(RealData, RefiningTheDinoHullLowersItsHeldOutViewError) {
  const std::filesystem::path scene = std::filesystem::path(MVFLOW_SHARED_DATA) / "dinoSparseRing";
  if (!std::filesystem::exists(scene)) GTEST_SKIP() << "the Middlebury dino is not in " << MVFLOW_SHARED_DATA;
  const test::ScratchFolder dir;
  const std::string held_out = "0,4,8,12";
  const auto hull = dir / "hull.ply";
  const auto refined = dir / "refined.ply";
  const test::CommandResult carve =
      test::run_mvflow("hull " + scene.string() + " -o " + hull.string() + " --exclude-views " + held_out);
  ASSERT_EQ(carve.exit_code, 0) << carve.output;
  const test::CommandResult refine = test::run_mvflow("refine " + scene.string() + " --mesh " + hull.string() +
                                                      " --exclude-views " + held_out + " -o " + refined.string());
  ASSERT_EQ(refine.exit_code, 0) << refine.output;

  const HeldoutScore before = score(scene.string(), hull, held_out, dir / "hull.json");
  const HeldoutScore after = score(scene.string(), refined, held_out, dir / "refined.json");
  std::printf("[measured] dino, views %s held out: MAE %.4f -> %.4f, PSNR %.2f -> %.2f dB, silhouette %.4f -> %.4f\n",
              held_out.c_str(), before.mae, after.mae, before.psnr, after.psnr, before.silhouette, after.silhouette);
  // Measured: MAE 0.0998 -> 0.0817, PSNR 14.56 -> 14.96 dB, silhouette 0.116 -> 0.119 (the
  // hull is exact at the silhouettes of the views it was carved from; the rims of the refined
  // surface are not, README "Real photographs").
  EXPECT_LT(after.mae, 0.9 * before.mae);
  EXPECT_GT(after.psnr, before.psnr);
}

}  // namespace
}  // namespace mvflow
