// `mvflow heldout` as a user runs it, on the small default scene (4 views of 80×60, an octahedron).

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "io/image_io.h"
#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;
const fs::path kDefaultScene = fs::path(MVFLOW_TEST_DATA) / "scenes" / "default";

std::string scene_and_mesh() {
  return kDefaultScene.string() + " " + (kDefaultScene / "init.off").string();
}

TEST(CliHeldout, WritesPanelsAndSummary) {
  test::ScratchFolder folder;
  const auto r =
      test::run_mvflow("heldout " + scene_and_mesh() + " --views 1,3 -o " + (folder / "out").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* name : {"heldout_001.png", "heldout_003.png"}) {
    const Image panel = io::read_image(folder / "out" / name);
    EXPECT_EQ(panel.width(), 3 * 80) << name;
    EXPECT_EQ(panel.height(), 60) << name;
  }
  const auto json = nlohmann::json::parse(test::read_text(folder / "out" / "heldout.json"));
  EXPECT_EQ(json["inputs"]["held_out_views"], (std::vector<int>{1, 3}));
  EXPECT_EQ(json["inputs"]["colouring_views"], (std::vector<int>{0, 2}));
  ASSERT_EQ(json["views"].size(), 2u);
  EXPECT_EQ(json["views"][0]["view"], 1);
  EXPECT_EQ(json["options"]["real_silhouette"]["threshold"], 0.19);
  EXPECT_EQ(json["options"]["supersample"], 2);
  // The summary line prints the pooled MAE of the JSON, a colour error on [0, 1].
  ASSERT_TRUE(json["all"]["mae"].is_number()) << json.dump();
  const double mae = json["all"]["mae"].get<double>();
  EXPECT_GT(mae, 0.0);
  EXPECT_LT(mae, 1.0);
  EXPECT_NE(r.output.find("  all  "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(fmt::format("{:>9.5f}", mae)), std::string::npos) << r.output;
  // The pooled values are the per-view pixel counts added up.
  EXPECT_EQ(json["all"]["union_pixels"].get<std::size_t>(),
            json["views"][0]["union_pixels"].get<std::size_t>() +
                json["views"][1]["union_pixels"].get<std::size_t>());
}

TEST(CliHeldout, BadViewExitsOneNamingItAndTheCount) {
  const auto r = test::run_mvflow("heldout " + scene_and_mesh() + " --views 1,4");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("held-out view 4 does not exist (the scene has 4 views"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("default_par.txt"), std::string::npos) << r.output;
}

TEST(CliHeldout, UsageErrorsExitTwo) {
  EXPECT_EQ(test::run_mvflow("heldout " + scene_and_mesh()).exit_code, 2);  // no --views
  EXPECT_EQ(test::run_mvflow("heldout " + scene_and_mesh() + " --views 1 --background 0.1,0.2").exit_code, 2);
  EXPECT_EQ(test::run_mvflow("heldout " + scene_and_mesh() + " --views 1 --threshold 0.1 --masks " +
                             kDefaultScene.string())
                .exit_code,
            2);
}

TEST(CliHeldout, MasksFolderIsMatchedByImageName) {
  test::ScratchFolder folder;
  // The photographs themselves as masks: every non-black pixel is object.
  const auto r = test::run_mvflow("heldout " + scene_and_mesh() + " --views 2 --masks " +
                                  kDefaultScene.string() + " --json " + (folder / "h.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto json = nlohmann::json::parse(test::read_text(folder / "h.json"));
  EXPECT_EQ(json["options"]["real_silhouette"]["source"], "masks");
  // An empty folder has no mask for the view: exit 1 naming the image.
  fs::create_directories(folder / "empty");
  const auto missing =
      test::run_mvflow("heldout " + scene_and_mesh() + " --views 2 --masks " + (folder / "empty").string());
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("no mask for view 2 (view02.png)"), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace mvflow
