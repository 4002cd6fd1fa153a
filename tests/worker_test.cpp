// The embedding worker: jobs run in order in the background, progress, cancellation (queued,
// and from another thread in the middle of an iteration), failures that do not stop the queue,
// two workers at once, destruction while a job runs. Nothing here asserts a time: latencies are
// counted in blocks or iterations, so a loaded machine cannot fail them.

#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <semaphore>
#include <thread>

#include <unistd.h>

#include "cancel_probe.h"
#include "engine/model/error.h"
#include "engine/model/scene.h"
#include "engine/worker/worker.h"
#include "io/mesh_io.h"
#include "io/scene_io.h"
#include "test_support.h"

namespace mvflow {
namespace {

namespace fs = std::filesystem;

WorkerOptions threads(int count) {
  WorkerOptions options;
  options.threads = count;
  return options;
}

// One small rendered scene for the whole suite, made by the mvflow binary.
class WorkerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // Per process: CTest runs each test of this file as its own process, possibly in parallel.
    scene_ = new fs::path(fs::temp_directory_path() / ("mvflow-worker-test-scene-" + std::to_string(::getpid())));
    fs::remove_all(*scene_);
    const std::string command = std::string(MVFLOW_BINARY) +
                                " synth --views 8 --width 160 --height 120 --level 3 --init-vertices 200 -o " +
                                scene_->string() + " > /dev/null 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*scene_);
    delete scene_;
  }
  static JobSpec job(int iterations) {
    JobSpec spec;
    spec.scene = *scene_;
    spec.options = preset("default");
    spec.options.stopping.max_iterations = iterations;
    spec.options.stopping.min_iterations = std::min(iterations, 10);
    return spec;
  }
  static fs::path* scene_;
};
fs::path* WorkerTest::scene_ = nullptr;

TEST_F(WorkerTest, RunsJobsInOrderAndReportsProgress) {
  Worker worker(threads(2));
  int seen = 0;
  JobSpec first = job(6);
  first.on_iteration = [&seen](const IterationReport&) { ++seen; };
  const auto a = worker.submit(first);
  const auto b = worker.submit(job(6));
  const JobOutcome second = worker.wait(b);
  ASSERT_TRUE(worker.try_result(a).has_value());  // a ran before b
  EXPECT_EQ(second.state, JobState::Succeeded) << second.message;
  EXPECT_EQ(second.summary.iterations.size(), 6u);
  EXPECT_GT(second.mesh.n_vertices(), 0u);
  EXPECT_EQ(seen, 6);
  EXPECT_EQ(worker.progress(a).state, JobState::Succeeded);
  EXPECT_EQ(worker.progress(b).iteration, 6);
}

// Another thread cancels the running job in the middle of its first iteration, on a scene whose
// iterations take ≥ 100 ms (0.11 s with 2 threads on the development machine, 3190 block
// kernels): the iteration does not finish, only the kernels already running then complete (at
// most 2 × threads, see Refiner.CancelFromAnotherThreadStopsTheRunningIteration), and the next
// job runs as it would on a fresh worker.
TEST_F(WorkerTest, CancelFromAnotherThreadStopsTheRunningIterationAndTheNextJobRuns) {
  test::ScratchFolder folder;
  const std::string command = std::string(MVFLOW_BINARY) +
                              " synth --views 16 --width 320 --height 240 --level 6 --init-vertices 40000 -o " +
                              (folder / "large").string() + " > /dev/null 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0);

  Worker worker(threads(2));
  std::atomic<Worker::JobId> id{0};
  test::CancelProbe probe(1000, [&] {
    while (id == 0) std::this_thread::yield();  // submit() may return after the job started
    worker.cancel(id);
  });
  JobSpec large = job(100);
  large.scene = folder / "large";
  large.on_block = probe.hook();
  int iterations = 0;
  large.on_iteration = [&](const IterationReport&) { ++iterations; };
  id = worker.submit(large);
  const JobOutcome outcome = worker.wait(id);
  probe.finish();
  std::printf("[measured] %zu blocks completed after the flag was set\n", probe.after_cancel());
  ASSERT_TRUE(probe.fired());
  EXPECT_EQ(outcome.state, JobState::Cancelled) << outcome.message;
  EXPECT_TRUE(outcome.summary.iterations.empty());
  EXPECT_EQ(iterations, 0);
  EXPECT_LE(probe.after_cancel(), 4u);

  const JobOutcome next = worker.wait(worker.submit(job(6)));
  ASSERT_EQ(next.state, JobState::Succeeded) << next.message;
  EXPECT_EQ(next.summary.iterations.size(), 6u);
  Worker fresh(threads(2));
  const JobOutcome reference = fresh.wait(fresh.submit(job(6)));
  ASSERT_EQ(reference.state, JobState::Succeeded) << reference.message;
  EXPECT_EQ(positions_of(next.mesh.topology), positions_of(reference.mesh.topology));
}

TEST_F(WorkerTest, CancelWhileQueuedNeverStarts) {
  Worker worker(threads(1));
  const auto running = worker.submit(job(30));
  const auto queued = worker.submit(job(30));
  worker.cancel(queued);
  const JobOutcome outcome = worker.wait(queued);
  EXPECT_EQ(outcome.state, JobState::Cancelled);
  EXPECT_TRUE(outcome.summary.iterations.empty());
  EXPECT_EQ(worker.wait(running).state, JobState::Succeeded);
}

TEST_F(WorkerTest, BadJobFailsAndTheNextStillRuns) {
  Worker worker;
  JobSpec bad = job(6);
  bad.scene = "/nonexistent/scene";
  const auto failing = worker.submit(bad);
  const auto good = worker.submit(job(6));
  const JobOutcome failed = worker.wait(failing);
  EXPECT_EQ(failed.state, JobState::Failed);
  EXPECT_NE(failed.message.find("/nonexistent/scene"), std::string::npos) << failed.message;
  EXPECT_EQ(worker.wait(good).state, JobState::Succeeded);
}

TEST_F(WorkerTest, TwoWorkersAtOnceGiveTheSameBits) {
  Worker left(threads(1)), right(threads(1));
  const auto a = left.submit(job(6));
  const auto b = right.submit(job(6));
  const JobOutcome x = left.wait(a), y = right.wait(b);
  ASSERT_EQ(x.state, JobState::Succeeded);
  ASSERT_EQ(y.state, JobState::Succeeded);
  EXPECT_EQ(positions_of(x.mesh.topology), positions_of(y.mesh.topology));
}

// The scene and mesh a host already holds: the photographs' pixels copied into a scene with no
// file behind it (in_memory_scene), the initial mesh read by the host. Same bits as the job that
// reads the files, and the job's paths are not read.
TEST_F(WorkerTest, InMemorySceneAndMeshGiveTheSameBitsAsFiles) {
  const Scene loaded = io::load_scene(*scene_);
  ASSERT_TRUE(loaded.mesh_file.has_value());
  std::vector<View> views;
  std::vector<Image> images;
  for (std::size_t i = 0; i < loaded.views.size(); ++i) {
    views.push_back(loaded.views[i]);
    images.push_back(loaded.image(i));
  }
  JobSpec in_memory = job(6);
  in_memory.scene = "/nonexistent/scene";
  in_memory.mesh = "/nonexistent/mesh.ply";
  in_memory.scene_data = std::make_shared<const Scene>(in_memory_scene(views, images, loaded.bounding_box));
  in_memory.mesh_data = std::make_shared<const Mesh>(io::load_mesh(*loaded.mesh_file));

  Worker worker(threads(2));
  const JobOutcome from_memory = worker.take(worker.submit(in_memory));
  const JobOutcome from_files = worker.take(worker.submit(job(6)));
  ASSERT_EQ(from_memory.state, JobState::Succeeded) << from_memory.message;
  ASSERT_EQ(from_files.state, JobState::Succeeded) << from_files.message;
  EXPECT_EQ(from_memory.summary.iterations.size(), 6u);
  EXPECT_EQ(positions_of(from_memory.mesh.topology), positions_of(from_files.mesh.topology));
}

// take() hands the outcome over and forgets the job; wait() and try_result() keep it.
TEST_F(WorkerTest, TakeMovesTheOutcomeOutAndForgetsTheJob) {
  Worker worker(threads(2));
  const auto kept = worker.submit(job(6));
  const auto taken = worker.submit(job(6));
  const JobOutcome copy = worker.wait(kept);
  const JobOutcome outcome = worker.take(taken);
  ASSERT_EQ(outcome.state, JobState::Succeeded) << outcome.message;
  EXPECT_EQ(positions_of(outcome.mesh.topology), positions_of(copy.mesh.topology));  // same job, same bits
  EXPECT_THROW(worker.progress(taken), Error);
  EXPECT_THROW(worker.try_result(taken), Error);
  EXPECT_THROW(worker.take(taken), Error);
  ASSERT_TRUE(worker.try_result(kept).has_value());
  EXPECT_EQ(worker.try_result(kept)->mesh.n_vertices(), copy.mesh.n_vertices());
  EXPECT_EQ(worker.progress(kept).state, JobState::Succeeded);
}

// The stage a host sees while the job runs, and none once it has finished.
TEST_F(WorkerTest, ProgressStageIsAnEnum) {
  Worker worker(threads(2));
  std::atomic<Worker::JobId> id{0};
  std::vector<JobStage> seen;
  JobSpec spec = job(6);
  spec.on_iteration = [&](const IterationReport&) {
    while (id == 0) std::this_thread::yield();
    seen.push_back(worker.progress(id).stage);  // the worker thread, outside the worker's lock
  };
  id = worker.submit(spec);
  const JobOutcome outcome = worker.wait(id);
  ASSERT_EQ(outcome.state, JobState::Succeeded) << outcome.message;
  ASSERT_EQ(seen.size(), 6u);
  for (const JobStage stage : seen) EXPECT_EQ(stage, JobStage::Iterating) << to_string(stage);
  EXPECT_EQ(worker.progress(id).stage, JobStage::None);
  EXPECT_STREQ(to_string(JobStage::Loading), "loading");
}

// The destructor cancels the running job and the queued one, then joins (it must not hang or
// crash). Counted, not timed: the first job cannot end on its own before kIterations iterations
// (its minimum too), and the worker is destroyed once that job has reported its first one, so a
// destructor that waited for the jobs instead would let the first reach kIterations and the second
// start.
TEST_F(WorkerTest, DestructionWhileRunningCancelsAndJoins) {
  constexpr int kIterations = 1000;
  std::atomic<int> first_iterations{0};
  std::atomic<std::size_t> second_blocks{0};
  std::binary_semaphore running{0};
  {
    Worker worker(threads(2));
    JobSpec first = job(kIterations);
    first.options.stopping.min_iterations = kIterations;
    first.on_iteration = [&](const IterationReport&) {
      if (++first_iterations == 1) running.release();
    };
    JobSpec second = job(6);
    second.on_block = [&](std::size_t) { ++second_blocks; };
    worker.submit(first);
    worker.submit(second);
    running.acquire();
  }
  std::printf("[measured] the first job ran %d iteration(s)\n", first_iterations.load());
  EXPECT_GE(first_iterations, 1);
  EXPECT_LT(first_iterations, kIterations);
  EXPECT_EQ(second_blocks, 0u);
}

TEST(Readme, ContainsTheEmbeddingExampleVerbatim) {
  const std::string readme = test::read_text(fs::path(MVFLOW_SOURCE_DIR) / "README.md");
  const std::string example = test::read_text(fs::path(MVFLOW_SOURCE_DIR) / "tests" / "embedding_example.cpp");
  const auto body = example.substr(example.find("#include <cstdio>"));
  EXPECT_NE(readme.find(body), std::string::npos) << "README must show tests/embedding_example.cpp from #include <cstdio> on";
}

}  // namespace
}  // namespace mvflow
