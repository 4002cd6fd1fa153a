#pragma once
// The thesis-sized suite of mvflow_bench: four synthetic scenes sized like the thesis's
// reconstructions (tables 5.1–5.4: vertices after the initial refinement, photographs, and the
// deformation steps to the final result; 5-megapixel images like its camera), refined with the
// thesis preset for exactly the thesis's number of steps, timed end to end without rendering
// (the thesis's times exclude nothing but are dominated by the flow), beside table 5.5.

#include <string>
#include <vector>

#include "perf/bench_table.h"

namespace mvflow::perf {

//! One row of the thesis's tables 5.1–5.5.
struct ThesisModel {
  std::string name;
  std::size_t initial_vertices;  //!< after the initial refinement (row (n)/(j))
  std::size_t final_vertices;    //!< the final result
  int views;                     //!< photographs
  int steps;                     //!< deformation steps to the final result
  double seconds;                //!< total time, table 5.5 (Pentium III 600 MHz)
  double gradient_seconds;       //!< time of ∇g, table 5.5
};

//! Bag, Nefertiti, frog, clown.
const std::vector<ThesisModel>& thesis_models();

struct ThesisSuiteSettings {
  std::vector<int> threads{1, 2};
  int width = 2592;   //!< the thesis's 5-megapixel camera
  int height = 1944;
  std::vector<std::string> models;  //!< names to run; empty: all four
};

//! One row per model and thread count. \throw Error when a refinement fails, or (when
//! \p validate) when Σg per vertex does not fall or the thread counts disagree bit for bit.
std::vector<Row> run_thesis_suite(const ThesisSuiteSettings& settings, bool validate);

}  // namespace mvflow::perf
