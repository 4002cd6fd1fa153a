#pragma once
// A background worker for programs that embed mvflow: submit refinement jobs from any thread,
// watch their progress, cancel them, wait for or take their results. Jobs run one after another on the
// worker's own thread, inside the engine's own task arena; nothing blocks the caller except
// wait(), and no exception from a job reaches the host (a failed job reports its message).
//
// See tests/embedding_example.cpp (also in the README).

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <spdlog/logger.h>

#include "engine/refine/refine_options.h"
#include "engine/refine/refiner.h"

namespace mvflow {

//! A refinement job: the scene and the initial mesh either as files (read on the worker thread)
//! or already in memory (shared, not copied: the host may keep and read them, not change them).
struct JobSpec {
  std::filesystem::path scene;  //!< scene folder or camera file; ignored when scene_data is set
  std::filesystem::path mesh;   //!< initial mesh; empty: the scene's init.*; ignored when mesh_data is set
  //! Folder of mask files for the scene read from \p scene (io::mask_store); empty: none. An
  //! in-memory scene carries its own (Scene::masks).
  std::filesystem::path masks;
  std::shared_ptr<const Scene> scene_data;  //!< an in-memory scene (e.g. in_memory_scene())
  std::shared_ptr<const Mesh> mesh_data;    //!< an in-memory initial mesh
  RefineOptions options;
  //! Called on the worker thread after every iteration; keep it short.
  std::function<void(const IterationReport&)> on_iteration;
  //! RefineControl::on_block: after each vertex block's kernel, on the engine's threads.
  std::function<void(std::size_t block)> on_block;
};

enum class JobState { Queued, Running, Succeeded, Failed, Cancelled };
const char* to_string(JobState state);

//! What a running job does: reading its files, then the refinement's own stages.
enum class JobStage { None, Loading, Preparing, Iterating, Finishing };
const char* to_string(JobStage stage);  //!< "", "loading", "preparing", "iterating", "finishing"

struct JobProgress {
  JobState state = JobState::Queued;
  int iteration = 0;
  std::size_t vertices = 0;
  double sum_g_per_vertex = 0.0;
  JobStage stage = JobStage::None;  //!< None unless Running
};

struct JobOutcome {
  JobState state = JobState::Failed;  //!< Succeeded, Failed or Cancelled
  std::string message;                //!< why it failed
  RefineSummary summary;
  Mesh mesh;                          //!< the refined surface (Succeeded only)
};

struct WorkerOptions {
  int threads = 0;                          //!< threads of the worker's arena; 0 = all cores
  std::shared_ptr<spdlog::logger> logger;   //!< null: no log lines
};

class Worker {
 public:
  using JobId = std::uint64_t;

  explicit Worker(WorkerOptions options = WorkerOptions());
  //! Cancels the running job and every queued one, then joins the worker thread.
  ~Worker();
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  //! Queues a job; returns at once.
  JobId submit(JobSpec job);
  //! Where job \p id stands. \throw Error for an unknown id.
  JobProgress progress(JobId id) const;
  //! Asks job \p id to stop: a queued job never starts, a running one stops at its next vertex
  //! block. Returns at once; no effect on a finished job.
  void cancel(JobId id);
  //! Blocks until job \p id has finished and returns a copy of its outcome (which stays available;
  //! the copy is made outside the worker's lock).
  JobOutcome wait(JobId id);
  //! A copy of the outcome if job \p id has finished.
  std::optional<JobOutcome> try_result(JobId id) const;
  //! Blocks until job \p id has finished, moves its outcome out and forgets the job: its id is
  //! unknown afterwards (a host that takes every result keeps no finished job in memory).
  JobOutcome take(JobId id);

 private:
  struct Job;
  void run_jobs();
  void run(Job& job);
  std::shared_ptr<Job> find(JobId id) const;
  std::shared_ptr<const JobOutcome> finished(const std::shared_ptr<Job>& job);

  WorkerOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::map<JobId, std::shared_ptr<Job>> jobs_;
  std::deque<std::shared_ptr<Job>> queue_;
  JobId next_id_ = 1;
  bool stopping_ = false;
  std::thread thread_;  // last: starts after every other member exists
};

}  // namespace mvflow
