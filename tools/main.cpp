// mvflow: the command-line program. Parses arguments, sets up the logger, runs one subcommand,
// and turns every error into a message and an exit code (never an abort).

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <iostream>
#include <string>

#include "engine/model/error.h"
#include "io/opencv_decoder.h"
#include "stages/flow/photo_kernel.h"
#include "tools/commands.h"

#ifndef MVFLOW_VERSION
#define MVFLOW_VERSION "unknown"
#endif

int main(int argc, char** argv) {
  using namespace mvflow::cli;
  CLI::App app{"mvflow: refines a coarse mesh of an object into a photo-consistent surface, from calibrated photographs"};
  // Built only when asked for: the decoder module's lookup reads /proc and stats files.
  app.set_version_flag("--version", [] {
    std::string kernel;
    try {
      kernel = mvflow::photo_kernel_summary();
    } catch (const mvflow::Error& e) {
      kernel = e.what();
    }
    return std::string("mvflow ") + MVFLOW_VERSION + "\nphoto kernel: " + kernel +
           "\nimages: " + mvflow::io::opencv_decoder_summary();
  });
  app.require_subcommand(1);
  app.fallthrough();
  bool verbose = false;
  std::string log_level = "info";
  app.add_flag("-v,--verbose", verbose, "Log more (same as --log-level debug)");
  app.add_option("--log-level", log_level, "Log level: trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();

  Runner runner;
  add_all_commands(app, runner);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help, version or the usage error
    return code == 0 ? kOk : kUsage;
  }

  // The program's own logger, handed to the commands (never spdlog's global default).
  auto log = spdlog::stderr_color_mt("mvflow");
  log->set_pattern("[%l] %v");
  log->set_level(verbose ? spdlog::level::debug : spdlog::level::from_str(log_level));
  try {
    const std::string kernel_used = mvflow::photo_kernel_summary();  // a bad MVFLOW_KERNEL fails here, before any work
    log->debug("photo kernel: {}", kernel_used);
    return runner(*log);
  } catch (const mvflow::Error& e) {
    log->error("{}", e.what());
  } catch (const std::exception& e) {
    log->error("internal error: {}", e.what());
  }
  return kFailure;
}
