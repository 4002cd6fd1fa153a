#include "engine/worker/worker.h"

#include <atomic>

#include "engine/model/error.h"
#include "io/mesh_io.h"
#include "io/scene_io.h"

namespace mvflow {

struct Worker::Job {
  JobId id = 0;
  JobSpec spec;
  std::atomic<bool> cancel{false};
  JobProgress progress;  // guarded by Worker::mutex_
  // Set once, under Worker::mutex_, and never changed after: readers copy it outside the lock.
  std::shared_ptr<const JobOutcome> outcome;
  bool taken = false;  // guarded by Worker::mutex_: take() has removed the outcome
};

namespace {

JobStage job_stage(RefineStage stage) {
  switch (stage) {
    case RefineStage::Preparing: return JobStage::Preparing;
    case RefineStage::Iterating: return JobStage::Iterating;
    case RefineStage::Finishing: return JobStage::Finishing;
  }
  return JobStage::None;
}

}  // namespace

const char* to_string(JobStage stage) {
  switch (stage) {
    case JobStage::None: return "";
    case JobStage::Loading: return "loading";
    case JobStage::Preparing: return "preparing";
    case JobStage::Iterating: return "iterating";
    case JobStage::Finishing: return "finishing";
  }
  return "?";
}

const char* to_string(JobState state) {
  switch (state) {
    case JobState::Queued: return "queued";
    case JobState::Running: return "running";
    case JobState::Succeeded: return "succeeded";
    case JobState::Failed: return "failed";
    case JobState::Cancelled: return "cancelled";
  }
  return "?";
}

Worker::Worker(WorkerOptions options) : options_(std::move(options)), thread_([this] { run_jobs(); }) {}

Worker::~Worker() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    for (auto& [id, job] : jobs_) job->cancel = true;
  }
  changed_.notify_all();
  thread_.join();
}

Worker::JobId Worker::submit(JobSpec spec) {
  auto job = std::make_shared<Job>();
  job->spec = std::move(spec);
  {
    std::lock_guard lock(mutex_);
    job->id = next_id_++;
    jobs_.emplace(job->id, job);
    queue_.push_back(job);
  }
  changed_.notify_all();
  return job->id;
}

std::shared_ptr<Worker::Job> Worker::find(JobId id) const {
  const auto found = jobs_.find(id);
  MVFLOW_CHECK(found != jobs_.end(), "unknown job id " + std::to_string(id));
  return found->second;
}

JobProgress Worker::progress(JobId id) const {
  std::lock_guard lock(mutex_);
  return find(id)->progress;
}

void Worker::cancel(JobId id) {
  std::lock_guard lock(mutex_);
  find(id)->cancel = true;
}

std::shared_ptr<const JobOutcome> Worker::finished(const std::shared_ptr<Job>& job) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return job->outcome != nullptr || job->taken; });
  MVFLOW_CHECK(!job->taken, "job " + std::to_string(job->id) + " was taken by another thread");
  return job->outcome;
}

JobOutcome Worker::wait(JobId id) {
  std::shared_ptr<Job> job;
  {
    std::lock_guard lock(mutex_);
    job = find(id);
  }
  return *finished(job);  // copied outside the lock
}

std::optional<JobOutcome> Worker::try_result(JobId id) const {
  std::shared_ptr<const JobOutcome> outcome;
  {
    std::lock_guard lock(mutex_);
    outcome = find(id)->outcome;
  }
  if (!outcome) return std::nullopt;
  return *outcome;
}

JobOutcome Worker::take(JobId id) {
  std::shared_ptr<Job> job;
  {
    std::lock_guard lock(mutex_);
    job = find(id);
  }
  std::shared_ptr<const JobOutcome> outcome = finished(job);
  {
    std::lock_guard lock(mutex_);
    if (job->taken) outcome.reset();  // another take() was first
    job->taken = true;
    job->outcome.reset();
    jobs_.erase(id);  // from now on nobody can reach the outcome but the holders of a copy
  }
  // Sole owner: move it out (it was made non-const, only handed out as const). A wait() or
  // try_result() still copying it on another thread keeps it shared: copy then.
  changed_.notify_all();  // a wait() on this job now fails instead of waiting forever
  MVFLOW_CHECK(outcome != nullptr, "job " + std::to_string(id) + " was taken by another thread");
  if (outcome.use_count() == 1) return std::move(const_cast<JobOutcome&>(*outcome));
  return *outcome;
}

void Worker::run_jobs() {
  for (;;) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, nothing left
      job = queue_.front();
      queue_.pop_front();
      if (job->cancel) {  // cancelled while queued (or the worker is shutting down)
        job->progress.state = JobState::Cancelled;
        job->outcome =
            std::make_shared<JobOutcome>(JobOutcome{JobState::Cancelled, "cancelled before it started", {}, {}});
        changed_.notify_all();
        continue;
      }
      job->progress.state = JobState::Running;
      job->progress.stage = JobStage::Loading;
    }
    run(*job);
    changed_.notify_all();
  }
}

void Worker::run(Job& job) {
  JobOutcome outcome;
  try {
    const std::shared_ptr<const Scene> scene =
        job.spec.scene_data ? job.spec.scene_data
                            : std::make_shared<const Scene>(io::load_scene(job.spec.scene, {.mask_folder = job.spec.masks}));
    std::shared_ptr<const Mesh> initial = job.spec.mesh_data;
    if (!initial) {
      std::filesystem::path mesh_file = job.spec.mesh;
      if (mesh_file.empty() && scene->mesh_file) mesh_file = *scene->mesh_file;
      if (mesh_file.empty()) throw InputError(job.spec.scene, 0, "no initial mesh given and no init.* in the scene");
      initial = std::make_shared<const Mesh>(io::load_mesh(mesh_file));
    }

    RefineControl control;
    control.threads = options_.threads;
    control.logger = options_.logger;
    control.cancel = &job.cancel;
    control.on_iteration = job.spec.on_iteration;
    control.on_block = job.spec.on_block;
    control.on_progress = [this, &job](const RefineProgress& p) {
      std::lock_guard lock(mutex_);
      job.progress.iteration = p.iteration;
      job.progress.vertices = p.vertices;
      job.progress.sum_g_per_vertex = p.sum_g_per_vertex;
      job.progress.stage = job_stage(p.stage);
    };
    RefineResult result = refine_mesh(*scene, *initial, job.spec.options, control);
    outcome.summary = std::move(result.summary);
    outcome.message = outcome.summary.message;
    outcome.state = outcome.summary.status == RefineStatus::Failed      ? JobState::Failed
                    : outcome.summary.status == RefineStatus::Cancelled ? JobState::Cancelled
                                                                         : JobState::Succeeded;
    if (outcome.state == JobState::Succeeded) outcome.mesh = std::move(result.mesh);
  } catch (const std::exception& e) {
    outcome.state = job.cancel ? JobState::Cancelled : JobState::Failed;
    outcome.message = e.what();
  }
  if (options_.logger && outcome.state == JobState::Failed)
    options_.logger->error("job {}: {}", job.id, outcome.message);
  std::lock_guard lock(mutex_);
  job.progress.state = outcome.state;
  job.progress.stage = JobStage::None;
  job.outcome = std::make_shared<JobOutcome>(std::move(outcome));  // not const: take() may move it
}

}  // namespace mvflow
