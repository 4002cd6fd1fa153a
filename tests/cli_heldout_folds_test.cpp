// tools/heldout_folds.sh as a user runs it, on the small default scene (4 views of 80×60): two
// folds of two held-out views each, the JSON it writes checked against its own per-fold entries.

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;

test::CommandResult run_folds(const std::string& arguments) {
  const std::string command = "MVFLOW=" + std::string(MVFLOW_BINARY) + " bash " + MVFLOW_SOURCE_DIR +
                              "/tools/heldout_folds.sh " + arguments + " 2>&1";
  test::CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) result.output += buffer;
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

const std::string kScene = (fs::path(MVFLOW_TEST_DATA) / "scenes" / "default").string();

TEST(HeldoutFolds, WritesEveryFoldAndTheirMeansAsJson) {
  const test::ScratchFolder folder;
  const auto r = run_folds(kScene + " " + (folder / "folds").string() +
                           " --folds 2 -- --max-iterations 10 --no-adaptive");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto json = nlohmann::json::parse(test::read_text(folder / "folds" / "folds.json"));
  ASSERT_EQ(json["folds"].size(), 2u);
  EXPECT_EQ(json["folds_count"], 2);
  EXPECT_EQ(json["hull_dilate"], 0);  // the hull command's default
  double hull = 0, refined = 0;
  int worse = 0;
  for (int f = 0; f < 2; ++f) {
    const auto& fold = json["folds"][f];
    EXPECT_EQ(fold["fold"], f);
    EXPECT_EQ(fold["held_out_views"], (std::vector<int>{f, f + 2}));
    // Each fold carries both meshes' own `mvflow heldout` summaries, per view and pooled.
    EXPECT_EQ(fold["hull"]["inputs"]["held_out_views"], fold["held_out_views"]);
    ASSERT_EQ(fold["refined"]["views"].size(), 2u);
    hull += fold["hull"]["all"]["mae"].get<double>() / 2;
    refined += fold["refined"]["all"]["mae"].get<double>() / 2;
    worse += fold["refined"]["all"]["mae"].get<double>() > fold["hull"]["all"]["mae"].get<double>();
  }
  // The means are the folds' (to the printed precision), the change is theirs.
  EXPECT_NEAR(json["mean"]["hull"]["mae"].get<double>(), hull, 1e-5);
  EXPECT_NEAR(json["mean"]["refined"]["mae"].get<double>(), refined, 1e-5);
  EXPECT_NEAR(json["mean"]["mae_change_percent"].get<double>(), 100 * (refined - hull) / hull, 0.02);
  EXPECT_EQ(json["mean"]["folds_refined_worse"], worse);
  EXPECT_NE(r.output.find("refined vs hull: MAE"), std::string::npos) << r.output;
}

TEST(HeldoutFolds, RefusesFoldCountsThatLeaveNoViewOrHoldNoneOut) {
  const test::ScratchFolder folder;
  for (const char* folds : {"1", "5", "x"}) {
    const auto r = run_folds(kScene + " " + (folder / "f").string() + " --folds " + folds);
    EXPECT_EQ(r.exit_code, 2) << folds << ": " << r.output;
    EXPECT_NE(r.output.find("--folds must be a whole number from 2 to the scene's 4 views"), std::string::npos)
        << r.output;
  }
}

}  // namespace
}  // namespace mvflow
