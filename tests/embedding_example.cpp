// The embedding example of the README (kept identical to it by readme_test.cpp).
#include <cstdio>

#include "engine/worker/worker.h"

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  mvflow::WorkerOptions settings;
  settings.threads = 2;
  mvflow::Worker worker(settings);  // its own thread and task arena
  mvflow::JobSpec job;
  job.scene = argv[1];
  job.options = mvflow::preset("default");
  job.options.stopping.max_iterations = 20;
  job.on_iteration = [](const mvflow::IterationReport& r) {
    std::printf("iteration %d: %zu vertices, sum g per vertex %.5f\n", r.iteration, r.vertices,
                r.sum_g_per_vertex());
  };
  const mvflow::Worker::JobId id = worker.submit(job);  // returns at once
  // ... the host goes on; from any thread: worker.progress(id), worker.cancel(id) ...
  const mvflow::JobOutcome outcome = worker.wait(id);
  if (outcome.state != mvflow::JobState::Succeeded) {
    std::printf("%s: %s\n", mvflow::to_string(outcome.state), outcome.message.c_str());
    return 1;
  }
  std::printf("%zu -> %zu vertices, sum g per vertex %.5f -> %.5f\n", outcome.summary.initial_vertices,
              outcome.summary.final_vertices, outcome.summary.initial_sum_g_per_vertex,
              outcome.summary.final_sum_g_per_vertex);
  return outcome.summary.final_sum_g_per_vertex < outcome.summary.initial_sum_g_per_vertex ? 0 : 1;
}
