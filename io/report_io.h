#pragma once
// The JSON report of a refinement (SPEC §7): inputs, options, and per iteration the vertices,
// faces, Σg, Σg/vertex, Δt, max|F|, the stopping test and the time of every stage.

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "engine/model/refine_report.h"

namespace mvflow::io {

//! The report as JSON. \p inputs and \p options are copied in as given (the caller knows them).
nlohmann::json report_to_json(const RefineSummary& summary, const nlohmann::json& inputs, const nlohmann::json& options);

//! Writes report_to_json through a temporary file.
void write_report(const std::filesystem::path& file, const RefineSummary& summary, const nlohmann::json& inputs,
                  const nlohmann::json& options);

}  // namespace mvflow::io
