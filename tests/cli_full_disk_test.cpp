// A full disk while `mvflow` writes: on a 64 KiB tmpfs filled up to its last kilobyte, every kind
// of output (mesh, JSON report, PNG) fails with a clear error, exit 1, and leaves the previous
// file of that name untouched and no temporary file behind; the per-vertex dumps stop with a
// warning instead. Needs root (mount); skipped otherwise.

#include <gtest/gtest.h>

#include <sys/mount.h>

#include <fstream>

#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;
const fs::path kScene = fs::path(MVFLOW_TEST_DATA) / "scenes" / "default";

class FullDisk : public ::testing::Test {
 protected:
  void SetUp() override {
    disk_ = scratch_ / "disk";
    fs::create_directories(disk_);
    if (mount("tmpfs", disk_.c_str(), "tmpfs", 0, "size=64k") != 0)
      GTEST_SKIP() << "cannot mount a tmpfs here (needs root): " << std::strerror(errno);
    mounted_ = true;
    for (const char* name : {"out.ply", "out.obj", "out.off", "out.stl", "report.json", "view.png"})
      test::write_text(disk_ / name, std::string("old ") + name + "\n");
    // Fill it to its last kilobyte (less than a page): no new file with content fits.
    std::ofstream filler(disk_ / "filler", std::ios::binary);
    const std::string block(1024, 'x');
    while (filler.write(block.data(), static_cast<std::streamsize>(block.size())) && filler.flush()) {
    }
    filler.close();
    const auto capacity = fs::space(disk_).capacity;
    fs::resize_file(disk_ / "filler", capacity - 1024);
    ASSERT_LE(fs::space(disk_).available, 2048u);
  }
  void TearDown() override {
    if (mounted_) umount(disk_.c_str());
  }

  // DISK/NAME, which holds "old NAME" (written before the disk was filled).
  fs::path old_file(const std::string& name) {
    EXPECT_EQ(test::read_text(disk_ / name), "old " + name + "\n");
    return disk_ / name;
  }
  // The command fails naming \p file; the old content is intact; nothing else appeared.
  void expect_failed_and_intact(const test::CommandResult& r, const fs::path& file) {
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find(file.filename().string()), std::string::npos) << r.output;
    EXPECT_EQ(test::read_text(file), "old " + file.filename().string() + "\n");
    std::size_t files = 0;
    for (const auto& entry : fs::directory_iterator(disk_)) ++files, (void)entry;
    EXPECT_EQ(files, 7u) << "a temporary file was left behind";
  }

  test::ScratchFolder scratch_;
  fs::path disk_;
  bool mounted_ = false;
};

TEST_F(FullDisk, MeshOutputsFailAndKeepTheOldFile) {
  const fs::path mesh = kScene / "init.off";
  for (const char* name : {"out.ply", "out.obj", "out.off", "out.stl"}) {
    const fs::path target = old_file(name);
    // A refined mesh of the test scene (~4 KB as PLY) does not fit in the last kilobyte.
    const auto r = test::run_mvflow("refine " + kScene.string() + " -o " + target.string() + " --ascii");
    expect_failed_and_intact(r, target);
  }
}

TEST_F(FullDisk, ReportAndImageOutputsFailAndKeepTheOldFile) {
  const fs::path report = old_file("report.json");
  const auto refine = test::run_mvflow("refine " + kScene.string() + " -o " + (scratch_ / "refined.ply").string() +
                                       " --report " + report.string());
  expect_failed_and_intact(refine, report);
  const fs::path png = old_file("view.png");
  const auto render = test::run_mvflow("render " + kScene.string() + " " + (kScene / "init.off").string() +
                                       " --view 0 -o " + png.string());
  expect_failed_and_intact(render, png);
}

TEST_F(FullDisk, PerVertexDumpsStopWithAWarningAndTheRunGoesOn) {
  // The dumps are a diagnostic: on a full disk they stop, the refined mesh is still written.
  const fs::path scene = scratch_ / "scene", dumps = disk_ / "dumps";
  ASSERT_EQ(test::run_mvflow("synth --views 8 --width 160 --height 120 --level 3 --init-vertices 200 -o " +
                             scene.string())
                .exit_code,
            0);
  const auto r = test::run_mvflow("refine " + scene.string() + " -o " + (scratch_ / "refined.ply").string() +
                                  " --max-iterations 6 --min-iterations 6 --dump-fields " + dumps.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("iteration_0001.ply"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no more per-vertex dumps after iteration 0"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(scratch_ / "refined.ply"));
  EXPECT_TRUE(fs::is_empty(dumps)) << "a dump or a temporary file was left behind";
}

}  // namespace
}  // namespace mvflow
