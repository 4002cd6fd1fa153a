// tools/heldout_folds.sh as a user runs it, on the small default scene (4 views of 80×60): two
// folds of two held-out views each, the JSON it writes checked against its own per-fold entries.

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;

test::CommandResult run_folds(const std::string& arguments, const std::string& mvflow = MVFLOW_BINARY) {
  const std::string command = "MVFLOW=" + mvflow + " bash " + MVFLOW_SOURCE_DIR +
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

// Where the refined mesh matches the held-out photographs exactly, the error is zero and the PSNR
// +inf: the text says inf, and folds.json, still valid JSON, has null there and in the mean, as
// `mvflow heldout --json` has. A stand-in for mvflow answers as mvflow does for such a mesh (inf
// in its text, null in its JSON), so that no real zero error has to be made.
TEST(HeldoutFolds, ZeroErrorGivesANullPsnrNotInf) {
  const test::ScratchFolder folder;
  const fs::path stand_in = folder / "mvflow";
  test::write_text(stand_in, R"sh(#!/usr/bin/env bash
# info, hull, refine and heldout as tools/heldout_folds.sh calls them; the refined mesh scores 0.
command=$1
shift
output() { while [ $# -gt 0 ]; do case $1 in -o | --json) echo "$2"; return ;; esac; shift; done; }
case $command in
  info) echo '{"views": {"count": 4}}' > "$(output "$@")" ;;
  hull) : > "$(output "$@")" ;;
  refine) : > "$(output "$@")"; echo "refined    10 → 12 vertices" ;;
  heldout)
    if [[ $2 == *refined.ply ]]; then mae=0.00000 psnr=inf json=null; else mae=0.10000 psnr=20.00 json=20.0; fi
    printf '  all  %s %s 0.10000 0.00%%
' "$mae" "$psnr"
    printf '{"all": {"mae": %s, "psnr_db": %s}}\n' "$mae" "$json" > "$(output "$@")" ;;
esac
)sh");
  fs::permissions(stand_in, fs::perms::owner_all);
  const auto r = run_folds(kScene + " " + (folder / "folds").string() + " --folds 2", stand_in.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto json = nlohmann::json::parse(test::read_text(folder / "folds" / "folds.json"));
  EXPECT_TRUE(json["folds"][0]["refined"]["all"]["psnr_db"].is_null());
  EXPECT_TRUE(json["mean"]["refined"]["psnr_db"].is_null()) << json["mean"];
  EXPECT_EQ(json["mean"]["refined"]["mae"], 0.0);
  EXPECT_EQ(json["mean"]["hull"]["psnr_db"], 20.0);
  EXPECT_EQ(json["mean"]["mae_change_percent"], -100.0);
  EXPECT_NE(r.output.find("0.0000 inf 0.1000"), std::string::npos) << r.output;  // the mean line
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
