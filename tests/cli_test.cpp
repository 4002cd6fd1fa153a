// The `mvflow` program as a user runs it: exit codes, output, and error messages.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <regex>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_support.h"
#include "vertex_fields_reader.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;
const fs::path kDefaultScene = fs::path(MVFLOW_TEST_DATA) / "scenes" / "default";

using test::CommandResult;

CommandResult run(const std::string& arguments) { return test::run_mvflow(arguments); }

TEST(Cli, VersionAndHelpExitZero) {
  EXPECT_EQ(run("--version").exit_code, 0);
  const CommandResult help = run("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("info"), std::string::npos);
  EXPECT_EQ(run("info --help").exit_code, 0);
  EXPECT_EQ(run("convert --help").exit_code, 0);
}

TEST(Cli, BadUsageExitsTwo) {
  EXPECT_EQ(run("").exit_code, 2);
  EXPECT_EQ(run("no-such-command").exit_code, 2);
  EXPECT_EQ(run("info").exit_code, 2);
  EXPECT_EQ(run("--log-level loud info x").exit_code, 2);
}

TEST(Cli, SliceRefusesAnOptionOutOfRangeUnderItsFlag) {
  // The range is the photo options' check()'s (as refine's), refused before the scene is read.
  const CommandResult spacing = run("slice " + kDefaultScene.string() + " -o unused.png --surface-patch on --surface-patch-spacing 20");
  EXPECT_EQ(spacing.exit_code, 2) << spacing.output;
  EXPECT_NE(spacing.output.find("--surface-patch-spacing: option surface_patch_spacing = 20 is out of range: expected (0, 8]"),
            std::string::npos)
      << spacing.output;
  EXPECT_FALSE(fs::exists("unused.png"));
}

TEST(Cli, InfoDescribesTheDefaultScene) {
  test::ScratchFolder folder;
  const CommandResult r = run("info " + kDefaultScene.string() + " --json " + (folder / "info.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("cameras    4 (middlebury"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("4 × 80x60"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("6 vertices, 8 faces, 12 edges"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("total genus 0"), std::string::npos) << r.output;
  const std::string json = test::read_text(folder / "info.json");
  EXPECT_NE(json.find("\"coverage\""), std::string::npos);
  // The 4 ring cameras all see the box centre.
  EXPECT_NE(r.output.find("   4   4   4"), std::string::npos) << r.output;
}

TEST(Cli, BadInputExitsOneNamingTheFile) {
  test::ScratchFolder folder;
  test::write_text(folder / "broken_par.txt", "2\nview.png 1 0 0 0 1 0 0 0 1\n");
  const CommandResult r = run("info " + (folder / "broken_par.txt").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("broken_par.txt:2"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("terminate"), std::string::npos) << r.output;
}

TEST(Cli, RefineChecksItsOutputsBeforeAnyWork) {
  test::ScratchFolder folder;
  const std::string scene = kDefaultScene.string();
  struct Case {
    std::string arguments, expected;
  };
  const Case cases[] = {
      {"-o " + (folder / "missing" / "x.ply").string(), "does not exist"},
      {"-o " + (folder / "x.ply").string() + " --report " + (folder / "missing" / "r.json").string(), "r.json"},
      {"-o " + folder.path().string(), "it is a folder"},
  };
  for (const Case& c : cases) {
    const CommandResult r = run("refine " + scene + " " + c.arguments);
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("refining"), std::string::npos) << "the refinement started: " << r.output;
  }
  EXPECT_FALSE(fs::exists(folder / "x.ply"));
  EXPECT_TRUE(fs::is_empty(folder.path()));  // no probe file left behind
}

TEST(Cli, EveryCommandChecksItsOutputsBeforeAnyWork) {
  // A regular file where a folder is expected: no user (root included) can create folders under it.
  test::ScratchFolder folder;
  const fs::path blocker = folder / "file";
  test::write_text(blocker, "not a folder\n");
  const std::string scene = kDefaultScene.string(), mesh = (kDefaultScene / "init.off").string();
  test::write_text(folder / "list.txt", scene + "\n");
  struct Case {
    std::string arguments, expected, work_started;
  };
  const Case cases[] = {
      {"hull " + scene + " -o " + (blocker / "x.ply").string(), "does not exist", "grid "},
      {"hull " + scene + " -o " + (folder / "h.ply").string() + " --save-masks " + (blocker / "masks").string(),
       "cannot be created as the output folder", "grid "},
      {"batch " + (folder / "list.txt").string() + " -o " + (blocker / "out").string(),
       "cannot be created as the output folder", "[1/"},
      {"synth --level 1 --views 2 --width 16 --height 12 -o " + (blocker / "scene").string(),
       "cannot be created as the output folder", "rendered"},
      {"refine " + scene + " -o " + (folder / "r.ply").string() + " --dump-fields " + (blocker / "fields").string(),
       "cannot be created as the output folder", "refining"},
      {"eval " + mesh + " " + mesh + " --json " + (blocker / "e.json").string(), "does not exist", "accuracy"},
      {"heldout " + scene + " " + mesh + " --views 0 --json " + (blocker / "h.json").string(), "does not exist",
       "scoring"},
      {"heldout " + scene + " " + mesh + " --views 0 -o " + (blocker / "h").string(),
       "cannot be created as the output folder", "scoring"},
  };
  for (const Case& c : cases) {
    const CommandResult r = run(c.arguments);
    EXPECT_EQ(r.exit_code, 1) << c.arguments << "\n" << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.arguments << "\n" << r.output;
    EXPECT_NE(r.output.find(blocker.string()), std::string::npos) << "the error names the location: " << r.output;
    EXPECT_EQ(r.output.find(c.work_started), std::string::npos) << "the work started: " << r.output;
  }
  EXPECT_FALSE(fs::exists(folder / "h.ply"));
  EXPECT_FALSE(fs::exists(folder / "r.ply"));
}

TEST(Cli, RefineDumpsEachIterationsVertexFields) {
  test::ScratchFolder folder;
  const fs::path scene = folder / "scene", dumps = folder / "fields" / "run";  // created, parents too
  const std::string synth = "synth --views 8 --width 160 --height 120 --level 3 --init-vertices 200 -o ";
  ASSERT_EQ(run(synth + scene.string()).exit_code, 0);
  const CommandResult r = run("refine " + scene.string() + " -o " + (folder / "r.ply").string() + " --report " +
                              (folder / "r.json").string() + " --max-iterations 6 --min-iterations 6 --dump-fields " +
                              dumps.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string report = test::read_text(folder / "r.json");
  // One file per iteration the report lists, named by iteration, and nothing else.
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dumps)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  std::vector<std::string> expected;
  for (int k = 1; k <= 6; ++k) expected.push_back("iteration_000" + std::to_string(k) + ".ply");
  EXPECT_EQ(names, expected);
  // The last one's vertices with g are those the report counts for its iteration ("defined_g"),
  // and its surface has the report's vertex count.
  const test::VertexFieldsDump last = test::read_vertex_fields_dump(dumps / "iteration_0006.ply");
  EXPECT_EQ(last.comments.at("iteration"), "6");
  std::size_t with_g = 0;
  for (std::size_t v = 0; v < last.rows.size(); ++v) with_g += !std::isnan(last.value(v, "g"));
  const nlohmann::json iteration6 = nlohmann::json::parse(report).at("iterations").at(5);
  EXPECT_EQ(iteration6.at("iteration"), 6);
  EXPECT_EQ(with_g, iteration6.at("defined_g").get<std::size_t>());
  EXPECT_EQ(last.rows.size(), iteration6.at("vertices").get<std::size_t>());
  EXPECT_GT(with_g, 0u);

  // A folder that holds another run's dumps is refused before any work.
  const CommandResult again = run("refine " + scene.string() + " -o " + (folder / "r2.ply").string() +
                                  " --max-iterations 6 --min-iterations 6 --dump-fields " + dumps.string());
  EXPECT_EQ(again.exit_code, 1) << again.output;
  EXPECT_NE(again.output.find("holds per-vertex dumps of another run"), std::string::npos) << again.output;
  EXPECT_EQ(again.output.find("refining"), std::string::npos) << again.output;
  EXPECT_FALSE(fs::exists(folder / "r2.ply"));
}

TEST(Cli, NonManifoldMeshIsReportedNotFatal) {
  test::ScratchFolder folder;
  // Three triangles on the edge (0,1).
  test::write_text(folder / "fan.off", "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n");
  const CommandResult r = run("info " + kDefaultScene.string() + " --mesh " + (folder / "fan.off").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("1 face(s) skipped as non-manifold"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("fan.off: 1 face(s) would make the mesh non-manifold"), std::string::npos) << r.output;
}

TEST(Cli, BadMeshExitsOneNamingFileAndLine) {
  test::ScratchFolder folder;
  test::write_text(folder / "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n");
  const CommandResult r = run("info " + kDefaultScene.string() + " --mesh " + (folder / "bad.obj").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("bad.obj:3"), std::string::npos) << r.output;
  // Converting it fails too, and leaves an existing output untouched.
  test::write_text(folder / "out.ply", "keep");
  EXPECT_EQ(run("convert " + (folder / "bad.obj").string() + " " + (folder / "out.ply").string()).exit_code, 1);
  EXPECT_EQ(test::read_text(folder / "out.ply"), "keep");
}

TEST(Cli, ConvertMeshAndCamerasRoundTrip) {
  test::ScratchFolder folder;
  const auto ply = folder / "init.ply";
  CommandResult r = run("convert " + (kDefaultScene / "init.off").string() + " " + ply.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run("info " + kDefaultScene.string() + " --mesh " + ply.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("6 vertices, 8 faces"), std::string::npos) << r.output;

  // Middlebury → COLMAP needs image sizes, which convert reads from the images.
  r = run("convert " + kDefaultScene.string() + " " + (folder / "colmap").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(folder / "colmap" / "cameras.txt"));
  EXPECT_NE(test::read_text(folder / "colmap" / "cameras.txt").find(" 80 60 "), std::string::npos);
}

TEST(Cli, BatchContinuesPastFailuresSkipsCompleteAndShards) {
  test::ScratchFolder folder;
  for (const char* name : {"a", "b"}) {
    const CommandResult r = run("synth --views 6 --width 120 --height 90 --level 3 --init-vertices 120 -o " +
                                (folder / name).string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  test::write_text(folder / "list.txt", "# two scenes and a missing one\na\nmissing\nb\n");
  const std::string batch = "batch " + (folder / "list.txt").string() + " -o " + (folder / "out").string() +
                            " --max-iterations 6 --threads 2";
  CommandResult r = run(batch);
  EXPECT_EQ(r.exit_code, 1) << r.output;  // one scene failed
  EXPECT_TRUE(fs::exists(folder / "out" / "a" / "refined.ply"));
  EXPECT_TRUE(fs::exists(folder / "out" / "b" / "report.json"));  // the batch went on past "missing"
  EXPECT_NE(r.output.find("3 scene(s) in shard 0/1: 1 failed"), std::string::npos) << r.output;

  // Run again: complete scenes are skipped.
  r = run(batch);
  EXPECT_NE(r.output.find("a                            skipped (complete)"), std::string::npos) << r.output;

  // Shards split the sorted list (a, b, missing) by index mod n.
  test::write_text(folder / "good.txt", "a\nb\n");
  r = run("batch " + (folder / "good.txt").string() + " -o " + (folder / "sharded").string() +
          " --max-iterations 6 --shard 1/2");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(folder / "sharded" / "a"));
  EXPECT_TRUE(fs::exists(folder / "sharded" / "b" / "refined.ply"));
  EXPECT_EQ(run("batch " + (folder / "good.txt").string() + " --shard 2/2").exit_code, 2);  // usage
  // A budget the stopping rules cannot work in is refused before any scene, naming the bound.
  r = run("batch " + (folder / "good.txt").string() + " -o " + (folder / "small").string() + " --max-iterations 4");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(">= 6"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(folder / "small"));
}

TEST(Cli, BatchMasksAreEachScenesOwnAsInRefine) {
  test::ScratchFolder folder;
  for (const char* name : {"a", "b"}) {
    const CommandResult r = run("synth --views 6 --width 120 --height 90 --level 3 --init-vertices 120 --masks -o " +
                                (folder / name).string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  test::write_text(folder / "list.txt", "a\nb\n");
  CommandResult r = run("batch " + (folder / "list.txt").string() + " -o " + (folder / "out").string() +
                        " --max-iterations 6 --masks masks");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The same bits as refine with the scene's mask folder.
  r = run("refine " + (folder / "b").string() + " --masks " + (folder / "b" / "masks").string() +
          " --max-iterations 6 --min-iterations 6 -o " + (folder / "b.ply").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(test::read_text(folder / "out" / "b" / "refined.ply"), test::read_text(folder / "b.ply"));
  r = run("refine " + (folder / "b").string() + " --max-iterations 6 --min-iterations 6 -o " + (folder / "plain.ply").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(test::read_text(folder / "plain.ply"), test::read_text(folder / "b.ply"));  // the masks mattered
  // A scene without its masks fails alone, naming the file.
  fs::remove_all(folder / "a" / "masks");
  r = run("batch " + (folder / "list.txt").string() + " -o " + (folder / "again").string() +
          " --max-iterations 6 --masks masks");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("the mask folder does not exist"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(folder / "again" / "b" / "refined.ply"));
}

// Far vertices read half-resolution photographs, which need every image at least 16 × 16: on
// smaller ones the default run goes on without them instead of failing. The same rig at 16 × 16
// flags far vertices at a low ratio, so the count in the report can be nonzero.
TEST(Cli, ImagesTooSmallToHalveRunWithoutFarVertices) {
  test::ScratchFolder folder;
  const auto far_vertices_reported = [&](const std::string& name, const std::string& size) {
    const fs::path scene = folder / name;
    const CommandResult synth = run("synth --views 8 --level 3 " + size + " -o " + scene.string());
    EXPECT_EQ(synth.exit_code, 0) << synth.output;
    const CommandResult refine = run("refine " + scene.string() + " -o " + (scene / "out.ply").string() + " --report " +
                                     (scene / "report.json").string() + " --far-g-ratio 3");
    EXPECT_EQ(refine.exit_code, 0) << refine.output;
    const std::string report = test::read_text(scene / "report.json");
    const std::regex field("\"far_vertices\": *([0-9]+)");
    std::size_t iterations = 0, far = 0;
    for (auto m = std::sregex_iterator(report.begin(), report.end(), field); m != std::sregex_iterator(); ++m) {
      ++iterations;
      far += std::stoul((*m)[1].str());
    }
    EXPECT_GT(iterations, 10u) << size;
    return far;
  };
  EXPECT_EQ(far_vertices_reported("small", "--width 14 --height 12"), 0u);
  EXPECT_GT(far_vertices_reported("halvable", "--width 16 --height 16"), 0u);
}

}  // namespace
}  // namespace mvflow
