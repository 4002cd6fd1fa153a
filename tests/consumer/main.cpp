// A host program built against an installed mvflow (tests/consumer/CMakeLists.txt): renders a
// small synthetic scene in memory, refines its initial mesh for a few iterations on the worker,
// writes the result as PLY and reads it back. Prints one line and exits 0 when every step worked.
#include <cstdio>
#include <filesystem>
#include <memory>

#include <mvflow/engine/model/mesh_stats.h>
#include <mvflow/engine/worker/worker.h>
#include <mvflow/io/mesh_io.h>
#include <mvflow/stages/synth/synth_scene.h>

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  mvflow::BuiltinShapeOptions shape;
  shape.level = 4;
  mvflow::SynthOptions synth;
  synth.rig.views = 8;
  synth.rig.width = 160;
  synth.rig.height = 120;
  synth.init.vertices = 300;
  const mvflow::SynthScene scene =
      mvflow::make_synth_scene(mvflow::make_builtin_object("bumpy-sphere", shape), nullptr, synth);

  mvflow::WorkerOptions settings;
  settings.threads = 2;
  mvflow::Worker worker(settings);
  mvflow::JobSpec job;
  job.scene_data = std::make_shared<const mvflow::Scene>(
      mvflow::in_memory_scene(scene.views, scene.images, scene.bounding_box));
  job.mesh_data = std::make_shared<const mvflow::Mesh>(mvflow::build_mesh(scene.initial, "init"));
  job.options = mvflow::preset("default");
  job.options.stopping.max_iterations = 10;  // the least the stopping rules accept
  const mvflow::JobOutcome outcome = worker.take(worker.submit(job));
  if (outcome.state != mvflow::JobState::Succeeded) {
    std::printf("%s: %s\n", mvflow::to_string(outcome.state), outcome.message.c_str());
    return 1;
  }

  const std::filesystem::path file = std::filesystem::path(argv[1]) / "refined.ply";
  mvflow::io::write_mesh(file, mvflow::to_indexed(outcome.mesh));
  const mvflow::MeshStats stats = mvflow::compute_mesh_stats(mvflow::io::load_mesh(file));
  std::printf("mvflow %s: %zu iterations, %zu vertices read back, closed %d, mean edge %.4f\n",
              MVFLOW_PACKAGE_VERSION, outcome.summary.iterations.size(), stats.vertices,
              stats.is_closed() ? 1 : 0, stats.mean_edge);
  return stats.vertices == outcome.mesh.n_vertices() && stats.is_closed() && stats.mean_edge > 0 ? 0 : 1;
}
