#pragma once
// The options and the work of `mvflow hull`, shared by the program and the Python module's
// hull(): the program adds SCENE, -o and its report around them; Python gets the mesh in memory
// (nothing printed, no file round trip).

#include <CLI/CLI.hpp>
#include <cstddef>
#include <spdlog/logger.h>
#include <string>
#include <vector>

#include "stages/flow/silhouette.h"
#include "stages/hull/hull_mesh.h"

namespace mvflow::cli {

struct HullArguments {
  std::string scene;
  std::string masks;
  std::string save_masks;
  SilhouetteOptions silhouette;
  double fill_holes = 0.005;  // enclosed background regions up to this fraction of the image are filled
  std::vector<double> bbox;
  HullMeshOptions options;
  int threads = 0;
  std::vector<int> excluded_views;  // held out: neither their silhouettes nor their images are read
};

//! Registers every option of `mvflow hull` but SCENE, -o and --ascii on \p command, filling \p args
//! (which must outlive the parse).
void add_hull_options(CLI::App& command, HullArguments& args);

struct CarvedHull {
  HullMeshResult hull;
  std::size_t views = 0;  //!< the views carved with
};

//! Loads the scene, makes the silhouettes (and saves them with --save-masks) and carves the hull.
//! \throw InputError for bad input (file, line or element named), Error otherwise.
CarvedHull carve_hull(const HullArguments& args, spdlog::logger& log);

}  // namespace mvflow::cli
