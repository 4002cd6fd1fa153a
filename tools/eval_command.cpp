// `mvflow eval MESH TRUTH`: accuracy and completeness of a mesh against a ground truth.

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "io/atomic_write.h"
#include "io/mesh_io.h"
#include "stages/eval/evaluation.h"
#include "tools/commands.h"

namespace mvflow::cli {

namespace {

struct EvalArguments {
  std::string mesh;
  std::string truth;
  std::string json;
  EvaluationOptions options;
};

nlohmann::json directed_json(const DirectedDistances& d, double diagonal) {
  return {{"mean", d.mean},         {"rms", d.rms},
          {"max", d.max},           {"quantile", d.quantile},
          {"within_threshold", d.within_threshold},
          {"relative", {{"mean", d.mean / diagonal}, {"rms", d.rms / diagonal}, {"max", d.max / diagonal},
                        {"quantile", d.quantile / diagonal}}}};
}

int run_eval(const EvalArguments& args, spdlog::logger& log) {
  if (!args.json.empty()) io::check_writable(args.json);  // before the sampling, not after it
  const IndexedMesh mesh = io::read_mesh(args.mesh);
  const IndexedMesh truth = io::read_mesh(args.truth);
  const EvaluationResult r = evaluate_against_truth(mesh, truth, args.options);
  const double diagonal = r.truth_diagonal;
  const auto percent = [diagonal](double x) { return 100.0 * x / diagonal; };

  fmt::print("mesh   {}\ntruth  {} (bounding-box diagonal {:.6g})\n", args.mesh, args.truth, diagonal);
  fmt::print("{:<34} {:>14} {:>12}\n", "measure", "absolute", "% of diag");
  const auto row = [&](const std::string& name, double value) {
    fmt::print("{:<34} {:>14.6g} {:>12.5f}\n", name, value, percent(value));
  };
  row(fmt::format("accuracy ({:g} % of mesh samples)", 100 * args.options.accuracy_fraction), r.accuracy());
  fmt::print("{:<34} {:>14.4f} {:>12}\n",
             fmt::format("completeness (within {:.3g})", r.threshold), r.completeness(), "fraction");
  row("mean  mesh → truth", r.mesh_to_truth.mean);
  row("mean  truth → mesh", r.truth_to_mesh.mean);
  row("mean  symmetric", r.symmetric_mean());
  row("RMS   mesh → truth", r.mesh_to_truth.rms);
  row("RMS   truth → mesh", r.truth_to_mesh.rms);
  row("RMS   symmetric", r.symmetric_rms());
  row("max   mesh → truth", r.mesh_to_truth.max);
  row("max   truth → mesh", r.truth_to_mesh.max);
  row("Hausdorff", r.hausdorff());

  if (!args.json.empty()) {
    const nlohmann::json report = {
        {"mesh", args.mesh},
        {"truth", args.truth},
        {"samples", args.options.samples},
        {"seed", args.options.seed},
        {"truth_bounding_box_diagonal", diagonal},
        {"accuracy_fraction", args.options.accuracy_fraction},
        {"accuracy", r.accuracy()},
        {"accuracy_relative", r.accuracy() / diagonal},
        {"completeness_threshold", r.threshold},
        {"completeness_threshold_relative", args.options.completeness_threshold},
        {"completeness", r.completeness()},
        {"symmetric_mean", r.symmetric_mean()},
        {"symmetric_rms", r.symmetric_rms()},
        {"hausdorff", r.hausdorff()},
        {"mesh_to_truth", directed_json(r.mesh_to_truth, diagonal)},
        {"truth_to_mesh", directed_json(r.truth_to_mesh, diagonal)}};
    io::write_atomically(args.json, false, [&](std::ostream& out) { out << report.dump(2) << '\n'; });
    log.info("wrote {}", args.json);
  }
  return kOk;
}

}  // namespace

void add_eval_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<EvalArguments>();
  CLI::App* command = app.add_subcommand("eval", "Accuracy and completeness of a mesh against a ground-truth mesh");
  command->add_option("mesh", args->mesh, "Mesh to evaluate")->required();
  command->add_option("truth", args->truth, "Ground-truth mesh")->required();
  command->add_option("--json", args->json, "Also write the measures as JSON to this file");
  command->add_option("--samples", args->options.samples, "Surface samples per mesh (uniform by area)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--threshold", args->options.completeness_threshold,
                      "Completeness threshold, relative to the truth's bounding-box diagonal")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command->add_option("--accuracy-fraction", args->options.accuracy_fraction,
                      "Accuracy is the distance within which this fraction of mesh samples lie")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  command->add_option("--seed", args->options.seed, "Sampling seed")->capture_default_str();
  command->callback([args, &runner] { runner = [args](spdlog::logger& log) { return run_eval(*args, log); }; });
}

}  // namespace mvflow::cli
