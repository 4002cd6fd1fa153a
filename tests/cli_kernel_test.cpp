// The photo kernel's builds as a user forces them (MVFLOW_KERNEL): the program says which build
// runs, refuses a build the CPU cannot run or does not know, and every build the CPU runs writes
// the same refined mesh, byte for byte, as the baseline.

#include <gtest/gtest.h>

#include "stages/flow/photo_kernel.h"
#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;
const fs::path kScene = fs::path(MVFLOW_TEST_DATA) / "scenes" / "default";

test::CommandResult run_with_kernel(const std::string& kernel, const std::string& arguments) {
  return test::run_mvflow_with_environment("MVFLOW_KERNEL=" + kernel, arguments);
}

TEST(CliKernel, VersionNamesTheBuildThatRuns) {
  const auto plain = test::run_mvflow("--version");
  EXPECT_EQ(plain.exit_code, 0);
  EXPECT_NE(plain.output.find(std::string("photo kernel: ") + detail::photo_kernel_builds().back().name + " (the widest"),
            std::string::npos)
      << plain.output;
  const auto forced = run_with_kernel("baseline", "--version");
  EXPECT_NE(forced.output.find("photo kernel: baseline (forced by MVFLOW_KERNEL"), std::string::npos) << forced.output;
}

TEST(CliKernel, UnknownOrUnrunnableBuildsAreRefusedBeforeAnyWork) {
  const test::ScratchFolder folder;
  const auto unknown = run_with_kernel("sse9", "refine " + kScene.string() + " -o " + (folder / "x.ply").string());
  EXPECT_EQ(unknown.exit_code, 1) << unknown.output;
  EXPECT_NE(unknown.output.find("MVFLOW_KERNEL=sse9: unknown build of the photo kernel"), std::string::npos)
      << unknown.output;
  EXPECT_FALSE(fs::exists(folder / "x.ply"));
  if (detail::photo_kernel_builds().size() < 3) {  // a CPU without AVX-512 must refuse that build
    const auto unrunnable = run_with_kernel("avx512", "info " + kScene.string());
    EXPECT_EQ(unrunnable.exit_code, 1) << unrunnable.output;
    EXPECT_NE(unrunnable.output.find("this CPU cannot run that build"), std::string::npos) << unrunnable.output;
  }
}

TEST(CliKernel, EveryBuildWritesTheBaselinesBytes) {
  const test::ScratchFolder folder;
  std::string baseline;
  for (const detail::PhotoKernelBuild& build : detail::photo_kernel_builds()) {
    const fs::path out = folder / (std::string(build.name) + ".ply");
    const auto r = run_with_kernel(build.name, "refine " + kScene.string() + " -o " + out.string() +
                                                   " --max-iterations 12 --report " + (folder / "r.json").string());
    ASSERT_EQ(r.exit_code, 0) << build.name << ": " << r.output;
    EXPECT_NE(test::read_text(folder / "r.json").find(std::string("\"photo_kernel\": \"") + build.name + "\""),
              std::string::npos);
    const std::string bytes = test::read_text(out);
    if (baseline.empty())
      baseline = bytes;
    else
      EXPECT_EQ(bytes, baseline) << build.name << " differs from the baseline";
  }
  EXPECT_FALSE(baseline.empty());
}

}  // namespace
}  // namespace mvflow
