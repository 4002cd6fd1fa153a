// SIGINT and SIGTERM during `mvflow refine` and `mvflow batch`, as a user's Ctrl-C or a cluster's
// kill sends them: the command stops within a few blocks, writes nothing half-done and exits 130;
// an interrupted or killed batch is resumed by the next one.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "test_support.h"

extern char** environ;

namespace mvflow {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// `mvflow ARGUMENTS...` running in the background, its stdout and stderr going to a log file.
class Running {
 public:
  Running(const std::vector<std::string>& arguments, const fs::path& log) : log_(log) {
    std::vector<std::string> all = {MVFLOW_BINARY};
    all.insert(all.end(), arguments.begin(), arguments.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    const int error = posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    EXPECT_EQ(error, 0);
  }
  ~Running() {
    if (!waited_) kill(pid_, SIGKILL), wait();
  }

  // Waits (up to a minute) until the log contains \p text.
  bool wait_for(const std::string& text) const {
    for (const auto end = Clock::now() + std::chrono::seconds(60); Clock::now() < end;) {
      if (test::read_text(log_).find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  void signal(int number) const { kill(pid_, number); }
  // The exit code, or −signal when a signal ended the process.
  int wait() {
    int status = 0;
    waitpid(pid_, &status, 0);
    waited_ = true;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
  }
  std::string log() const { return test::read_text(log_); }

 private:
  fs::path log_;
  pid_t pid_ = 0;
  bool waited_ = false;
};

// The last iteration a refine log reports ("iteration   7  vertices ..."), 0 for none.
int last_iteration(const std::string& log) {
  int last = 0;
  for (std::size_t at = log.find("iteration "); at != std::string::npos; at = log.find("iteration ", at + 1))
    last = std::max(last, std::atoi(log.c_str() + at + 10));
  return last;
}

// Renders the default synthetic scene (~2 s to refine) into \p folder.
fs::path make_scene(const fs::path& folder) {
  const auto r = test::run_mvflow("synth -o " + folder.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return folder;
}

// Counted, not timed: the refinement cannot end on its own before kIterations iterations (its
// minimum too), so one that ignored the signal, or noticed it only at the end, reaches them.
TEST(CliInterrupt, RefineStopsWithinBlocksAndWritesNothing) {
  constexpr int kIterations = 300;
  const std::string iterations = std::to_string(kIterations);
  const test::ScratchFolder scratch;
  const fs::path scene = make_scene(scratch / "scene");
  for (const int number : {SIGINT, SIGTERM}) {
    const fs::path folder = scratch / ("run" + std::to_string(number));
    fs::create_directories(folder);
    const fs::path out = folder / "refined.ply", report = folder / "report.json";
    Running run({"refine", scene.string(), "-o", out.string(), "--report", report.string(), "--min-iterations",
                 iterations, "--max-iterations", iterations},
                folder / "log.txt");
    ASSERT_TRUE(run.wait_for("iteration   3 ")) << run.log();
    const auto sent = Clock::now();
    run.signal(number);
    const int code = run.wait();
    const double latency = std::chrono::duration<double>(Clock::now() - sent).count();
    EXPECT_EQ(code, 130) << run.log();
    EXPECT_NE(run.log().find("nothing written"), std::string::npos) << run.log();
    EXPECT_LT(last_iteration(run.log()), kIterations) << run.log();
    std::printf("signal %d: stopped %.3f s after it was sent, after iteration %d\n", number, latency,
                last_iteration(run.log()));
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(report));
    for (const auto& entry : fs::directory_iterator(folder))  // no temporary file left
      EXPECT_EQ(entry.path().filename(), "log.txt");
  }
}

TEST(CliInterrupt, BatchStopsAndTheNextBatchRedoesTheInterruptedOrKilledScene) {
  const test::ScratchFolder folder;
  const fs::path scenes = folder / "scenes", out = folder / "out";
  make_scene(scenes / "a");
  fs::copy(scenes / "a", scenes / "b", fs::copy_options::recursive);
  for (const int number : {SIGINT, SIGKILL}) {
    fs::remove_all(out);
    {
      // -v: batch logs each iteration of a scene at debug level, named by the scene.
      Running run({"-v", "batch", scenes.string(), "-o", out.string()}, folder / "log.txt");
      ASSERT_TRUE(run.wait_for("[1/2]")) << run.log();
      // Into scene a's refinement, however slow the machine: its first iteration is done, so the
      // signal cannot land while the scene loads (the scene takes ~2 s alone; a signal that came
      // after it finished would let [2/2] start, which fails below).
      ASSERT_TRUE(run.wait_for("a: iteration   1 ")) << run.log();
      run.signal(number);
      const int code = run.wait();
      EXPECT_EQ(code, number == SIGINT ? 130 : -SIGKILL) << run.log();
      if (number == SIGINT) {
        EXPECT_NE(run.log().find("interrupted"), std::string::npos) << run.log();
        EXPECT_EQ(run.log().find("[2/2]"), std::string::npos) << "the next scene was started: " << run.log();
      }
      EXPECT_FALSE(fs::exists(out / "a" / "report.json"));  // the mark of a complete scene
      EXPECT_FALSE(fs::exists(out / "a" / "refined.ply"));
    }
    const auto resumed = test::run_mvflow("batch " + scenes.string() + " -o " + out.string());
    EXPECT_EQ(resumed.exit_code, 0) << resumed.output;
    EXPECT_NE(resumed.output.find("[1/2]"), std::string::npos) << "scene a is redone: " << resumed.output;
    for (const char* name : {"a", "b"}) {
      EXPECT_TRUE(fs::exists(out / name / "refined.ply")) << name;
      EXPECT_TRUE(fs::exists(out / name / "report.json")) << name;
    }
  }
}

}  // namespace
}  // namespace mvflow
