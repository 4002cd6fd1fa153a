#pragma once
// The subcommands of the `mvflow` program. Each registers its options on the CLI11 app and
// returns the function that runs it; the function returns the process exit code.

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <spdlog/logger.h>

namespace mvflow::cli {

//! Exit codes: 0 ok, 1 bad input or failure, 2 bad usage, 130 stopped by SIGINT or SIGTERM
//! (128 + SIGINT, the shells' convention; tools/interrupt.h).
enum ExitCode : int { kOk = 0, kFailure = 1, kUsage = 2, kInterrupted = 130 };

using Runner = std::function<int(spdlog::logger& log)>;

//! `mvflow info SCENE [--mesh FILE] [--decode] [--json FILE]`
void add_info_command(CLI::App& app, Runner& runner);
//! `mvflow convert IN OUT [--ascii] [--to FORMAT]`
void add_convert_command(CLI::App& app, Runner& runner);

//! `mvflow synth [--preset NAME] [options] -o DIR`
void add_synth_command(CLI::App& app, Runner& runner);

//! `mvflow eval MESH TRUTH [--json FILE] [--samples N] [--threshold F]`
void add_eval_command(CLI::App& app, Runner& runner);

//! `mvflow slice SCENE [--mesh FILE] -o OUT.png [--axis x|y|z] [--position F]`
void add_slice_command(CLI::App& app, Runner& runner);

//! `mvflow refine SCENE --mesh FILE -o OUT [--threads N] [--report FILE.json] ...`
void add_refine_command(CLI::App& app, Runner& runner);

//! `mvflow batch LIST -o DIR [--shard i/n] [--force]`
void add_batch_command(CLI::App& app, Runner& runner);

//! `mvflow render SCENE MESH --view I -o OUT.png [--shading shaded|colour]`
void add_render_command(CLI::App& app, Runner& runner);

//! `mvflow heldout SCENE MESH --views i,j [--json FILE] [-o DIR] [--threshold T|--masks DIR] ...`
void add_heldout_command(CLI::App& app, Runner& runner);

//! `mvflow hull SCENE -o OUT [--masks DIR | --threshold T] [--dilate PX] [--bbox ...] [--vertices N]`
void add_hull_command(CLI::App& app, Runner& runner);

//! `mvflow subdivide MESH --scheme loop|modloop|butterfly [--iterations N] [--sharp-angle DEG] [--faces FILE] -o OUT`
void add_subdivide_command(CLI::App& app, Runner& runner);

//! Every subcommand above, in the order of `mvflow --help` (the program and the Python module).
void add_all_commands(CLI::App& app, Runner& runner);

}  // namespace mvflow::cli
