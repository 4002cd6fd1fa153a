// `mvflow hull` as a user runs it: the mesh it writes, mask files, and bad input; `mvflow synth`'s
// hull start and mask files.

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <numbers>
#include <regex>

#include "io/image_io.h"
#include "stages/flow/silhouette.h"
#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;
using test::CommandResult;
using test::run_mvflow;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

//! A sphere on a black background, 16 views of 320×240, rendered once for the whole suite.
class CliHull : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One folder per process: CTest may run the tests of this suite in parallel processes.
    scene_ = new fs::path(fs::temp_directory_path() / ("mvflow-CliHull-scene-" + std::to_string(getpid())));
    fs::remove_all(*scene_);
    const CommandResult r = run_mvflow("synth --background black --amplitude 0 --level 4 --views 16 --width 320 "
                                       "--height 240 --init-vertices 100 -o " + scene_->string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() {
    std::error_code ignored;
    fs::remove_all(*scene_, ignored);
    delete scene_;
  }
  static std::string scene() { return scene_->string(); }

 private:
  static fs::path* scene_;
};

fs::path* CliHull::scene_ = nullptr;

TEST_F(CliHull, WritesAClosedManifoldMeshOfAboutTheRequestedSize) {
  test::ScratchFolder folder;
  const std::string out = (folder / "hull.ply").string();
  const CommandResult r = run_mvflow("hull " + scene() + " --threshold 0.005 --vertices 1200 -o " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "1 components, genus 0, closed, manifold")) << r.output;
  std::smatch count;
  ASSERT_TRUE(std::regex_search(r.output, count, std::regex("mesh +([0-9]+) vertices"))) << r.output;
  EXPECT_NEAR(std::stod(count[1]), 1200.0, 120.0) << r.output;
  const CommandResult info = run_mvflow("info " + scene() + " --mesh " + out);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(contains(info.output, "1 component(s), total genus 0, Euler characteristic 2, 0 boundary edge(s)"))
      << info.output;
  EXPECT_TRUE(contains(info.output, "0 non-manifold vertex(es)")) << info.output;
}

TEST_F(CliHull, ExcludedViewsCarveNothingSoTheHullOnlyGrows) {
  // Fewer views carve less: the hull of 12 views contains the hull of 16, so its volume is larger.
  // With the ring rig, the views left out are the only ones seeing some flanks head on.
  test::ScratchFolder folder;
  auto volume_of = [&](const std::string& extra) {
    const CommandResult r = run_mvflow("hull " + scene() + " --threshold 0.005 --vertices 800 -o " +
                                       (folder / "hull.ply").string() + extra);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    std::smatch volume;
    EXPECT_TRUE(std::regex_search(r.output, volume, std::regex("volume +([0-9.eE+-]+)"))) << r.output;
    return volume.size() > 1 ? std::stod(volume[1]) : 0.0;
  };
  const double all = volume_of("");
  const double without_four = volume_of(" --exclude-views 0,4,8,12");
  std::printf("[measured] hull volume %.5f with every view, %.5f without views 0,4,8,12\n", all, without_four);
  EXPECT_GT(without_four, all);
}

TEST_F(CliHull, MaskFilesGiveTheSameMeshAsTheThresholdTheyCameFrom) {
  test::ScratchFolder folder;
  const std::string masks = (folder / "masks").string();
  CommandResult r = run_mvflow("hull " + scene() + " --threshold 0.005 --vertices 500 --save-masks " + masks + " -o " +
                               (folder / "a.ply").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(folder / "masks" / "view_000.png"));
  r = run_mvflow("hull " + scene() + " --masks " + masks + " --vertices 500 -o " + (folder / "b.ply").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(test::read_text(folder / "a.ply"), test::read_text(folder / "b.ply"));
  // Matched by stem, any image extension in any case.
  fs::rename(folder / "masks" / "view_005.png", folder / "masks" / "view_005.PNG");
  r = run_mvflow("hull " + scene() + " --masks " + masks + " --vertices 500 -o " + (folder / "c.ply").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(test::read_text(folder / "a.ply"), test::read_text(folder / "c.ply"));
}

TEST_F(CliHull, BadInputNamesTheFileAndLeavesTheOutputAlone) {
  test::ScratchFolder folder;
  const fs::path out = folder / "out.ply";
  test::write_text(out, "keep");
  const std::string tail = " --vertices 300 -o " + out.string();

  CommandResult r = run_mvflow("hull " + scene() + " --masks " + (folder / "none").string() + tail);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "none: the mask folder does not exist")) << r.output;

  // A missing mask, then one of the wrong size.
  const fs::path masks = folder / "masks";
  ASSERT_EQ(run_mvflow("hull " + scene() + " --threshold 0.005 --save-masks " + masks.string() + " --vertices 300 -o " +
                       (folder / "first.ply").string())
                .exit_code,
            0);
  fs::remove(masks / "view_003.png");
  r = run_mvflow("hull " + scene() + " --masks " + masks.string() + tail);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "view_003.png: no mask for view 3 (view_003.png); expected an image named view_003")) << r.output;
  io::write_png(masks / "view_003.png", Image(32, 24));
  r = run_mvflow("hull " + scene() + " --masks " + masks.string() + tail);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "view_003.png: the mask is 32x24 pixels, but view 3 (view_003.png) is 320x240"))
      << r.output;
  // Two masks for one view.
  test::write_text(masks / "view_003.pgm", "P2");
  r = run_mvflow("hull " + scene() + " --masks " + masks.string() + tail);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "several masks for view 3")) << r.output;

  // An empty hull: a box where the object is not.
  r = run_mvflow("hull " + scene() + " --threshold 0.005 --bbox 5 5 5 6 6 6" + tail);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "the visual hull is empty")) << r.output;
  r = run_mvflow("hull " + scene() + " --bbox 1 1 1 0 2 2" + tail);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "--bbox")) << r.output;
  r = run_mvflow("hull " + scene() + " -o " + (folder / "out.xyz").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  r = run_mvflow("hull " + scene() + " --threshold 0.005 --exclude-views 3,16" + tail);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "excluded view 16 does not exist (the scene has 16 views, 0..15)")) << r.output;

  // Usage errors.
  EXPECT_EQ(run_mvflow("hull " + scene() + " --masks " + masks.string() + " --threshold 0.1" + tail).exit_code, 2);
  EXPECT_EQ(run_mvflow("hull " + scene() + " --bbox 1 2 3" + tail).exit_code, 2);
  EXPECT_EQ(run_mvflow("hull " + scene() + " --threshold 1.5" + tail).exit_code, 2);
  EXPECT_EQ(run_mvflow("hull " + scene()).exit_code, 2);

  EXPECT_EQ(test::read_text(out), "keep");
}

// `mvflow synth --init hull`: the visual hull of the truth's exact silhouettes (ray cast, so the
// textured background does not matter). Measured: 404 vertices, symmetric mean distance 0.0088
// to the truth (radius 1) with 8 views of 160x120.
TEST(CliSynth, InitHullIsAClosedMeshCloseToTheTruth) {
  test::ScratchFolder folder;
  const std::string scene = (folder / "scene").string();
  CommandResult r = run_mvflow("synth --views 8 --width 160 --height 120 --level 3 --init hull --init-vertices 400 -o " + scene);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_mvflow("info " + scene + " --mesh " + scene + "/init.ply");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "1 component(s), total genus 0, Euler characteristic 2, 0 boundary edge(s)")) << r.output;
  r = run_mvflow("eval " + scene + "/init.ply " + scene + "/truth.ply --samples 20000");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::smatch mean;
  ASSERT_TRUE(std::regex_search(r.output, mean, std::regex("mean  symmetric +([0-9.e+-]+)"))) << r.output;
  EXPECT_LT(std::stod(mean[1]), 0.02) << r.output;
  EXPECT_EQ(run_mvflow("synth --init hull:2 -o " + scene).exit_code, 2);
}

// `mvflow synth --masks`: the truth's exact silhouettes. A unit sphere seen from distance 3 by a
// camera aimed at its centre has a disc of radius f·tan(asin(1/3)) pixels for its outline: 48.99
// pixels at 160×120 with the 60° field of view (f = 80 / tan 30°), 7540 pixels of area.
TEST(CliSynth, MasksAreTheTruthsExactSilhouettes) {
  test::ScratchFolder folder;
  const fs::path scene = folder / "scene";
  CommandResult r = run_mvflow("synth --amplitude 0 --views 4 --width 160 --height 120 --level 5 --masks -o " +
                               scene.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const double f = 80.0 / std::tan(30.0 * std::numbers::pi / 180.0);
  const double radius = f * std::tan(std::asin(1.0 / 3.0));
  for (const char* name : {"view_000.png", "view_003.png"}) {
    const Mask mask = mask_from_image(io::read_image(scene / "masks" / name));
    ASSERT_EQ(mask.width, 160);
    ASSERT_EQ(mask.height, 120);
    // Inscribed triangles make the polyhedron's outline a little smaller than the sphere's.
    EXPECT_NEAR(static_cast<double>(mask.count()), std::numbers::pi * radius * radius, 0.01 * 7540.0) << name;
    // Pixels well inside or well outside the disc are object or background.
    for (int y = 0; y < 120; ++y)
      for (int x = 0; x < 160; ++x) {
        const double d = std::hypot(x - 79.5, y - 59.5);
        if (d < radius - 1.5) {
          EXPECT_TRUE(mask.at(x, y)) << name << " " << x << "," << y;
        } else if (d > radius + 1.5) {
          EXPECT_FALSE(mask.at(x, y)) << name << " " << x << "," << y;
        }
      }
  }
  // Without the flag there are none.
  r = run_mvflow("synth --amplitude 0 --views 4 --width 160 --height 120 --level 3 -o " + (folder / "plain").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(folder / "plain" / "masks"));
}

}  // namespace
}  // namespace mvflow
