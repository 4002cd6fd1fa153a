// A rig that leaves part of the object seen only at grazing angles (two camera rings at −15° and
// +25°: below about −75° latitude a unit sphere has no view within 75° of its normal), refined
// with and without --spread-unobserved, on a textured and on a black background (where the
// default, auto, spreads). The truth is the unit sphere, so each vertex's error is | |P| − 1 |
// exactly.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <nlohmann/json.hpp>

#include "io/image_io.h"
#include "io/mesh_io.h"
#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;

struct CapErrors {
  double cap = 0.0;       // mean radial error below 75° south
  double observed = 0.0;  // ... between 45° south and 45° north
  double south = 0.0;     // ... below 55° south (issue 12's weakly seen region)
  double rest = 0.0;      // ... everywhere else
};

CapErrors cap_errors(const fs::path& mesh_file) {
  const IndexedMesh mesh = io::read_mesh(mesh_file);
  const auto sine_of = [](double degrees) { return std::sin(degrees * std::numbers::pi / 180.0); };
  double cap = 0.0, observed = 0.0, south = 0.0, rest = 0.0;
  int in_cap = 0, in_band = 0, in_south = 0, in_rest = 0;
  for (const Eigen::Vector3d& p : mesh.positions) {
    const double sine = p.y() / p.norm(), error = std::abs(p.norm() - 1.0);
    if (sine < -sine_of(75)) cap += error, ++in_cap;
    if (std::abs(sine) <= sine_of(45)) observed += error, ++in_band;
    if (sine < -sine_of(55)) south += error, ++in_south;
    else rest += error, ++in_rest;
  }
  EXPECT_GT(in_cap, 20);
  EXPECT_GT(in_band, 1000);
  return {cap / in_cap, observed / in_band, south / in_south, rest / in_rest};
}

// Renders the rig of issue 12 (the unit sphere, 24 views on rings at −15° and +25°, 2562 initial
// vertices offset by 0.04) into \p scene, with \p options added.
test::CommandResult synth_grazing_sphere(const fs::path& scene, const std::string& options = "") {
  return test::run_mvflow("synth --amplitude 0 --views 24 --width 640 --height 480 --level 6 "
                          "--init offset:0.011547 --init-vertices 2562 --elevation -15,25 " +
                          options + " -o " + scene.string());
}

// Completeness against the sampled truth: every part of the sphere is near \p mesh (at least
// \p at_least of the 20 000 samples; 1 = every one).
void expect_complete(const fs::path& mesh, const fs::path& scene, const fs::path& folder, double at_least = 1.0) {
  const fs::path json = folder / (mesh.stem().string() + "_eval.json");
  const auto eval = test::run_mvflow("eval " + mesh.string() + " " + (scene / "truth.ply").string() +
                                     " --samples 20000 --json " + json.string());
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  const nlohmann::json result = nlohmann::json::parse(test::read_text(json));
  EXPECT_GE(result.at("completeness").get<double>(), at_least) << test::read_text(json);
}

TEST(CliUnobserved, AGrazingCapFollowsTheObservedSurface) {
  const test::ScratchFolder folder;
  const fs::path scene = folder / "scene";
  // The scene of issue 12 (at 320×240 with 642 initial vertices the cap ends at 2.0× instead).
  const auto synth = synth_grazing_sphere(scene);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const auto off = test::run_mvflow("refine " + scene.string() + " -o " + (folder / "off.ply").string() +
                                    " --spread-unobserved off");
  const auto on = test::run_mvflow("refine " + scene.string() + " -o " + (folder / "on.ply").string() +
                                   " --spread-unobserved on");
  ASSERT_EQ(off.exit_code, 0) << off.output;
  ASSERT_EQ(on.exit_code, 0) << on.output;
  EXPECT_NE(on.output.find("unobserved vertices with the observed surface"), std::string::npos) << on.output;
  // Issue 12's measure: the mean error below −55° against the rest's. The premise: without a
  // spread the weakly seen region keeps several times the rest's error (measured 0.0082 against
  // 0.0014, 6.1×).
  const CapErrors without = cap_errors(folder / "off.ply");
  EXPECT_GT(without.south, 4 * without.rest);
  // With it, within 2× (measured 0.0024 against 0.0013, 1.9×), and no worse elsewhere.
  const CapErrors with = cap_errors(folder / "on.ply");
  EXPECT_LT(with.south, 2 * with.rest);
  EXPECT_LT(with.rest, 1.1 * without.rest);
  expect_complete(folder / "on.ply", scene, folder.path());
}

TEST(CliUnobserved, OnABlackBackgroundTheDefaultSpreadsAnchoredAtTheRims) {
  const test::ScratchFolder folder;
  const fs::path scene = folder / "scene";
  const auto synth = synth_grazing_sphere(scene, "--background black");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const auto off = test::run_mvflow("refine " + scene.string() + " -o " + (folder / "off.ply").string() +
                                    " --spread-unobserved off");
  const auto automatic = test::run_mvflow("refine " + scene.string() + " -o " + (folder / "auto.ply").string());
  ASSERT_EQ(off.exit_code, 0) << off.output;
  ASSERT_EQ(automatic.exit_code, 0) << automatic.output;
  EXPECT_EQ(off.output.find("unobserved vertices"), std::string::npos) << off.output;
  EXPECT_NE(automatic.output.find("unobserved vertices follow the observed surface and the silhouette rims"),
            std::string::npos)
      << automatic.output;
  EXPECT_NE(automatic.output.find("unobserved vertices with the observed surface"), std::string::npos)
      << automatic.output;
  // Measured: the cap (below −75°) 0.0367 without, 0.0077 with; between ±45° 0.0010 both ways.
  const CapErrors without = cap_errors(folder / "off.ply"), with = cap_errors(folder / "auto.ply");
  EXPECT_LT(with.cap, 0.5 * without.cap);
  EXPECT_LT(with.observed, 1.25 * without.observed);
  // A few samples of the cap can end beyond the threshold: with the balloon velocity ×1.0001,
  // ×0.9999, ×1.0002, ×0.9998 this run's completeness was 1.0000 / 0.9999 / 0.9992 / 1.0000
  // without far vertices and 1.0000 / 0.9998 / 1.0000 / 0.9993 with them (session 29), 0.99975
  // as given: a knife edge either way, so the test asks 99.9 %.
  expect_complete(folder / "auto.ply", scene, folder.path(), 0.999);
  // The rim flags and the spread do not depend on the threads or the engine.
  const auto sequential = test::run_mvflow("refine " + scene.string() + " -o " + (folder / "sequential.ply").string() +
                                           " --threads 1 --engine sequential");
  ASSERT_EQ(sequential.exit_code, 0) << sequential.output;
  EXPECT_EQ(test::read_text(folder / "sequential.ply"), test::read_text(folder / "auto.ply"));
}

// On a textured background auto spreads only the vertices that hardly had a speed at their
// resolution; `on` every vertex without one. After the finest resolution, with --spread-unmoved
// auto (off by default since session 38), only those it never gave a speed follow.
TEST(CliUnobserved, OnATexturedBackgroundTheDefaultSpreadsOnlyTheHardlyObserved) {
  const test::ScratchFolder folder;
  const fs::path scene = folder / "scene";
  const auto synth = test::run_mvflow("synth --amplitude 0 --views 12 --width 320 --height 240 --level 4 "
                                      "--init offset:0.02 --init-vertices 642 --elevation -15,25 -o " + scene.string());
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  // With the thesis's image patches: with the default's surface patches at oblique vertices a
  // crumpled band at −45…−23° of this 12-view 320×240 rig never gets a speed at the finest
  // resolution (one view left each; README, "Surface patches"), and the spread at the end takes
  // it too.
  const std::string refine = "refine " + scene.string() + " --surface-patch off";
  const auto automatic = test::run_mvflow(refine + " -o " + (folder / "auto.ply").string());
  const auto on = test::run_mvflow(refine + " -o " + (folder / "on.ply").string() +
                                   " --spread-unobserved on");
  const auto off = test::run_mvflow(refine + " -o " + (folder / "off.ply").string() +
                                    " --spread-unobserved off");
  ASSERT_EQ(automatic.exit_code, 0) << automatic.output;
  ASSERT_EQ(on.exit_code, 0) << on.output;
  ASSERT_EQ(off.exit_code, 0) << off.output;
  EXPECT_NE(automatic.output.find("hardly observed vertices follow the observed surface\n"), std::string::npos)
      << automatic.output;
  EXPECT_NE(on.output.find("unobserved vertices follow the observed surface\n"), std::string::npos) << on.output;
  EXPECT_EQ(off.output.find("follow the observed surface"), std::string::npos) << off.output;
  // Both spread before a refinement; the hardly observed are a subset of the unobserved.
  const auto moved = [](const std::string& output) {
    const std::size_t at = output.find(" unobserved vertices with the observed surface");
    if (at == std::string::npos) return -1L;
    return std::stol(output.substr(output.rfind("moved ", at) + 6));
  };
  EXPECT_GT(moved(automatic.output), 0) << automatic.output;
  EXPECT_GT(moved(on.output), 0) << on.output;
  // The cap (below −75°) ends nearer the sphere than without a spread.
  EXPECT_LT(cap_errors(folder / "auto.ply").cap, cap_errors(folder / "off.ply").cap);

  // The spread at the end (--spread-unmoved auto): one more spread than without it (the
  // default), after the last iteration, and it moves only vertices of the weakly seen parts (the
  // run is the same until then, so the vertex ids match). Measured: 388 vertices moved, none
  // within ±45°, before the step momentum; with it a dozen at 27–45° south (the crumpled band of
  // the comment above), none between the rings' ±20°. Whether the spread brings a cap nearer
  // depends on the scene: here this rig's cap below −75° 0.0091 → 0.0105; over the 32 scenes of
  // the README it costs more than it gives since session 38 (README, "Weakly seen regions").
  const auto unmoved_auto = test::run_mvflow(refine + " -o " + (folder / "unmoved_auto.ply").string() +
                                             " --spread-unmoved auto");
  ASSERT_EQ(unmoved_auto.exit_code, 0) << unmoved_auto.output;
  const auto& unmoved_off = automatic;  // the default
  const auto spreads = [](const std::string& output) {
    std::size_t count = 0;
    for (std::size_t at = output.find("unobserved vertices with the observed surface"); at != std::string::npos;
         at = output.find("unobserved vertices with the observed surface", at + 1))
      ++count;
    return count;
  };
  EXPECT_EQ(spreads(unmoved_auto.output), spreads(unmoved_off.output) + 1) << unmoved_auto.output;
  EXPECT_GT(unmoved_auto.output.rfind("unobserved vertices with the observed surface"),
            unmoved_auto.output.rfind("] iteration "))
      << unmoved_auto.output;
  EXPECT_LT(unmoved_off.output.rfind("unobserved vertices with the observed surface"),
            unmoved_off.output.rfind("] iteration "))
      << unmoved_off.output;
  const IndexedMesh at_end = io::read_mesh(folder / "unmoved_auto.ply");
  const IndexedMesh not_at_end = io::read_mesh(folder / "auto.ply");
  ASSERT_EQ(at_end.positions.size(), not_at_end.positions.size());
  std::size_t moved_at_end = 0, in_caps = 0;
  for (std::size_t v = 0; v < at_end.positions.size(); ++v) {
    const Eigen::Vector3d& p = not_at_end.positions[v];
    if (at_end.positions[v] == p) continue;
    ++moved_at_end;
    const double sine = std::abs(p.y() / p.norm());
    in_caps += sine > std::sin(std::numbers::pi / 4);
    EXPECT_GT(sine, std::sin(std::numbers::pi / 9)) << "vertex " << v << " moved at " << p.transpose();
  }
  EXPECT_GT(moved_at_end, 50u);
  EXPECT_GT(in_caps, 9 * moved_at_end / 10) << in_caps << " of " << moved_at_end;

  // The first resolution's spread takes the vertices with a speed in at most 3/4 of its
  // iterations (--hardly-observed-first), a superset of those in at most 1/4 and a subset of
  // all of them (`on`: the same set as a fraction of 1). Measured: 159, 247 and 432 vertices.
  const auto first_moved = [&](const std::string& fraction) {
    const auto r = test::run_mvflow(refine + " -o " + (folder / "first.ply").string() +
                                    " --hardly-observed-first " + fraction);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return moved(r.output);
  };
  const long quarter = first_moved("0.25"), all = first_moved("1");
  EXPECT_LT(quarter, moved(automatic.output));
  EXPECT_LT(moved(automatic.output), all);
  EXPECT_EQ(all, moved(on.output));
  // The first resolution keeps its own fraction whatever the later one, 1 (all) included.
  EXPECT_EQ(first_moved("0.25 --hardly-observed 1"), quarter);
}

// `refine --masks`: silhouettes from files instead of thresholded photographs, so a textured
// background gets the rim fit and the anchored spread too (`synth --masks` writes the truth's).
TEST(CliUnobserved, MaskFilesBringTheRimsToATexturedBackground) {
  const test::ScratchFolder folder;
  const fs::path scene = folder / "scene";
  const auto synth = synth_grazing_sphere(scene, "--masks");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string masks = (scene / "masks").string();
  // Against no spread at all: the default spreads the hardly observed vertices on a textured
  // background too (OnATexturedBackgroundTheDefaultSpreadsOnlyTheHardlyObserved).
  const auto plain = test::run_mvflow("refine " + scene.string() + " -o " + (folder / "plain.ply").string() +
                                      " --spread-unobserved off");
  const auto masked =
      test::run_mvflow("refine " + scene.string() + " --masks " + masks + " -o " + (folder / "masked.ply").string());
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  ASSERT_EQ(masked.exit_code, 0) << masked.output;
  EXPECT_EQ(plain.output.find("fitting the rims"), std::string::npos) << plain.output;
  EXPECT_NE(masked.output.find("fitting the rims to the silhouettes of the mask images"), std::string::npos)
      << masked.output;
  EXPECT_NE(masked.output.find("unobserved vertices follow the observed surface and the silhouette rims"),
            std::string::npos)
      << masked.output;
  // Measured (session 42): the cap (below −75°) starts at 0.0391 and ends at 0.0028 with the masks;
  // without them and the spread only smoothing moves it, so its error depends on how long the
  // finest resolution runs: 0.0095 in 64 iterations (a settled stop waits while the observed
  // surface still creeps), 0.0166 in 40 without that wait. Between ±45° 0.0008 both ways.
  const CapErrors start = cap_errors(scene / "init.ply");
  const CapErrors without = cap_errors(folder / "plain.ply"), with = cap_errors(folder / "masked.ply");
  EXPECT_LT(with.cap, 0.1 * start.cap);
  EXPECT_LT(with.cap, 0.5 * without.cap);
  EXPECT_LT(with.observed, 1.3 * without.observed);
  expect_complete(folder / "masked.ply", scene, folder.path());

  // Bad mask folders stop the run with the file named, before anything is written.
  const fs::path out = folder / "out.ply";
  test::write_text(out, "keep");
  fs::remove(scene / "masks" / "view_007.png");
  auto r = test::run_mvflow("refine " + scene.string() + " --masks " + masks + " -o " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("view_007.png: no mask for view 7 (view_007.png)"), std::string::npos) << r.output;
  io::write_png(scene / "masks" / "view_007.png", Image(64, 48));
  r = test::run_mvflow("refine " + scene.string() + " --masks " + masks + " -o " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("view_007.png: the mask is 64x48 pixels, but view 7 (view_007.png) is 640x480"),
            std::string::npos)
      << r.output;
  r = test::run_mvflow("refine " + scene.string() + " --masks " + (folder / "none").string() + " -o " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("the mask folder does not exist"), std::string::npos) << r.output;
  EXPECT_EQ(test::read_text(out), "keep");
}

}  // namespace
}  // namespace mvflow
