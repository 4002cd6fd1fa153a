// `mvflow batch LIST -o DIR`: many refinements one after another, each into its own folder,
// resumable (complete outputs are skipped), robust (a failing scene is reported and the batch
// goes on), and shardable across machines (`--shard i/n`).

#include <algorithm>
#include <filesystem>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "engine/model/error.h"
#include "engine/refine/refiner.h"
#include "io/atomic_write.h"
#include "io/mesh_io.h"
#include "io/report_io.h"
#include "io/scene_io.h"
#include "io/text_reader.h"
#include "tools/commands.h"
#include "tools/interrupt.h"

namespace mvflow::cli {

namespace {

namespace fs = std::filesystem;

struct BatchArguments {
  std::string list;
  std::string output = "batch-out";
  std::string shard = "0/1";
  std::string preset = "default";
  int threads = 0;
  int max_iterations = 0;
  std::string masks;  // each scene's mask folder, relative to the scene folder; empty: none
  bool force = false;
};

struct BatchItem {
  fs::path scene;
  fs::path mesh;      // empty: the scene's init.*
  std::string name;   // output folder name
};

// A manifest: one scene per line, `SCENE [MESH]`, '#' comments, paths relative to the manifest.
// A folder: every subfolder that holds a scene.
std::vector<BatchItem> read_items(const fs::path& list) {
  std::vector<BatchItem> items;
  if (fs::is_directory(list)) {
    for (const auto& entry : fs::directory_iterator(list)) {
      if (!entry.is_directory()) continue;
      try {
        io::locate_scene(entry.path());
      } catch (const Error&) {
        continue;  // not a scene folder
      }
      items.push_back({entry.path(), {}, entry.path().filename().string()});
    }
  } else {
    io::TextReader reader(list);
    const fs::path base = list.parent_path();
    while (reader.next_content_line()) {
      const auto tokens = io::split_whitespace(reader.line());
      if (tokens.size() > 2) reader.fail("expected `SCENE [MESH]`, got " + std::to_string(tokens.size()) + " fields");
      BatchItem item;
      item.scene = base / fs::path(std::string(tokens[0]));
      if (tokens.size() == 2) item.mesh = base / fs::path(std::string(tokens[1]));
      item.name = fs::path(std::string(tokens[0])).lexically_normal().relative_path().string();
      std::replace(item.name.begin(), item.name.end(), '/', '_');
      items.push_back(item);
    }
  }
  std::sort(items.begin(), items.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  for (std::size_t i = 1; i < items.size(); ++i)
    if (items[i].name == items[i - 1].name)
      throw InputError(list, 0, "two scenes would share the output folder '" + items[i].name + "'");
  return items;
}

std::pair<int, int> parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  int index = -1, count = 0;
  try {
    if (slash != std::string::npos) {
      index = std::stoi(text.substr(0, slash));
      count = std::stoi(text.substr(slash + 1));
    }
  } catch (const std::exception&) {
    count = 0;
  }
  if (count < 1 || index < 0 || index >= count)
    throw InputError("--shard expects i/n with 0 <= i < n (e.g. 3/10), got '" + text + "'");
  return {index, count};
}

bool is_complete(const fs::path& folder) {
  return fs::is_regular_file(folder / "refined.ply") && fs::is_regular_file(folder / "report.json");
}

struct Row {
  std::string name;
  std::string status;
  std::size_t iterations = 0;
  std::size_t vertices = 0;
  double g_before = 0.0, g_after = 0.0, seconds = 0.0;
  std::string message;
};

Row refine_one(const BatchItem& item, const fs::path& folder, const RefineOptions& options, const BatchArguments& args,
               spdlog::logger& log) {
  Row row{item.name, "failed", 0, 0, 0, 0, 0, ""};
  try {
    const Scene scene = io::load_scene(
        item.scene, {.mask_folder = args.masks.empty() ? fs::path() : io::locate_scene(item.scene).folder / args.masks});
    fs::path mesh_file = item.mesh;
    if (mesh_file.empty() && scene.mesh_file) mesh_file = *scene.mesh_file;
    if (mesh_file.empty()) throw InputError(item.scene, 0, "no initial mesh (give it in the list or put init.ply in the scene)");
    const Mesh initial = io::load_mesh(mesh_file);
    RefineControl control;
    control.threads = args.threads;
    control.cancel = &interrupt_requested();
    // With -v, one line per iteration names the scene: a scene's progress is visible (and a test
    // knows the refinement is under way) without the info-level lines of every scene.
    control.on_iteration = [&](const IterationReport& r) {
      log.debug("{}: iteration {:3d}  vertices {:7d}  {}", item.name, r.iteration, r.vertices, r.stop);
    };
    const RefineResult result = refine_mesh(scene, initial, options, control);
    const RefineSummary& s = result.summary;
    row.iterations = s.iterations.size();
    row.vertices = s.final_vertices;
    row.g_before = s.initial_sum_g_per_vertex;
    row.g_after = s.final_sum_g_per_vertex;
    row.seconds = s.seconds;
    if (s.status == RefineStatus::Failed) throw Error(s.message);
    if (s.status == RefineStatus::Cancelled) {  // nothing written: the next batch redoes this scene
      row.status = "interrupted";
      return row;
    }
    fs::create_directories(folder);
    io::write_mesh(folder / "refined.ply", to_indexed(result.mesh));
    // The report last: its presence marks the folder complete.
    io::write_report(folder / "report.json", s, {{"scene", item.scene.string()}, {"mesh", mesh_file.string()}},
                     {{"preset", args.preset}, {"max_iterations", options.stopping.max_iterations}});
    row.status = to_string(s.status);
  } catch (const std::exception& e) {
    row.message = e.what();
    log.error("{}: {}", item.name, e.what());
  }
  return row;
}

int run_batch(const BatchArguments& args, spdlog::logger& log) {
  install_interrupt_handlers();
  const auto [shard, shards] = parse_shard(args.shard);
  RefineOptions options = preset(args.preset);
  if (args.max_iterations > 0) {
    options.stopping.max_iterations = args.max_iterations;
    options.stopping.min_iterations = std::min(options.stopping.min_iterations, args.max_iterations);
  }
  options.check();
  const std::vector<BatchItem> items = read_items(args.list);
  io::prepare_output_folder(args.output);  // before the first scene's work, not after it
  std::vector<Row> rows;
  int failed = 0;
  for (std::size_t k = 0; k < items.size(); ++k) {
    if (static_cast<int>(k % static_cast<std::size_t>(shards)) != shard) continue;  // another shard's
    const BatchItem& item = items[k];
    const fs::path folder = fs::path(args.output) / item.name;
    if (!args.force && is_complete(folder)) {
      rows.push_back({item.name, "skipped (complete)", 0, 0, 0, 0, 0, ""});
      continue;
    }
    if (interrupt_requested()) break;
    log.info("[{}/{}] {}", k + 1, items.size(), item.scene.string());
    rows.push_back(refine_one(item, folder, options, args, log));
    failed += rows.back().status == "failed";
    if (interrupt_requested()) break;  // this scene's work is not saved; the rest are not started
  }
  fmt::print("{:<28} {:<20} {:>6} {:>9} {:>12} {:>12} {:>8}\n", "scene", "status", "iter", "vertices", "g/vertex in",
             "g/vertex out", "seconds");
  for (const Row& r : rows)
    fmt::print("{:<28} {:<20} {:>6} {:>9} {:>12.5g} {:>12.5g} {:>8.2f}{}\n", r.name, r.status, r.iterations, r.vertices,
               r.g_before, r.g_after, r.seconds, r.message.empty() ? "" : "  " + r.message);
  fmt::print("{} scene(s) in shard {}/{}: {} failed\n", rows.size(), shard, shards, failed);
  if (interrupt_requested()) {
    log.warn("interrupted: the scenes not marked complete are redone by the next batch");
    return kInterrupted;
  }
  return failed > 0 ? kFailure : kOk;
}

}  // namespace

void add_batch_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<BatchArguments>();
  CLI::App* c = app.add_subcommand("batch", "Refine many scenes one after another (resumable, shardable)");
  c->add_option("list", args->list,
                "A folder of scene folders, or a text file with one `SCENE [MESH]` per line (# comments; paths "
                "relative to the file)")
      ->required();
  c->add_option("-o,--output", args->output, "Output root: DIR/NAME/refined.ply and report.json per scene")
      ->capture_default_str();
  c->add_option("--shard", args->shard, "Run only shard i of n (scenes in sorted order, k mod n == i)")
      ->check(CLI::Validator(
          [](std::string& text) {
            try {
              parse_shard(text);
              return std::string();
            } catch (const Error& e) {
              return std::string(e.what());
            }
          },
          "i/n"))
      ->capture_default_str();
  c->add_option("--preset", args->preset, "default, accurate or thesis (as refine's)")
      ->check(CLI::IsMember(preset_names()))
      ->capture_default_str();
  c->add_option("--threads", args->threads, "Threads per refinement (0 = all cores)")->capture_default_str();
  c->add_option("--masks", args->masks,
                "Each scene's mask folder, relative to the scene folder (e.g. masks): as refine --masks");
  // The stopping rules compare the last `lookback` iterations with one before them, so no budget
  // below lookback + 1 can be met (lookback is 5 in every preset).
  const int smallest = StoppingOptions{}.lookback + 1;
  c->add_option("--max-iterations", args->max_iterations,
                "Override the preset's iteration limit (0 = keep, else >= " + std::to_string(smallest) + ")")
      ->check(CLI::Validator(
          [smallest](const std::string& text) -> std::string {
            const int value = std::stoi(text);
            if (value == 0 || value >= smallest) return {};
            return "expected 0 (keep the preset's) or >= " + std::to_string(smallest) +
                   " (the stopping rules' lookback + 1), got " + text;
          },
          "0 or >= " + std::to_string(smallest)));
  c->add_flag("--force", args->force, "Refine scenes whose outputs are already complete");
  c->callback([args, &runner] { runner = [args](spdlog::logger& log) { return run_batch(*args, log); }; });
}

}  // namespace mvflow::cli
