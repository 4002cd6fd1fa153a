#pragma once
// Every option of `mvflow refine` that sets a RefineOptions field, declared once: its flag, its
// key in the report's "options", the field it sets (and the field's name in RefineOptions::check's
// errors) and its help. Registration on the command line, --help, applying what the user gave over
// the preset, validation and the report all walk this one table, so a flag cannot be registered
// under one name and read under another. The valid values are not written here: they are the
// stages' own check()s, which --help and a refused flag quote.

#include <CLI/CLI.hpp>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/refine/refine_options.h"

namespace mvflow::cli {

struct RefineOptionEntry {
  std::string flag;  //!< e.g. "--cfl"
  std::string key;   //!< e.g. "cfl" in the report's "options"
  //! The fields it sets as RefineOptions::check names them ("smoothing.lambda_dt"), so that a value
  //! out of range is reported under the flag; empty for most choices (CLI11 checks those), but
  //! not for a choice that check() can refuse in combination with another option.
  std::vector<std::string> members;
  //! Registers the flag on \p command with its help, for --help its valid values and the default
  //! preset's value.
  std::function<CLI::Option*(CLI::App& command)> add;
  //! Sets the field of \p target from what the user gave (called only when the flag was given).
  std::function<void(const CLI::Option& given, RefineOptions& target)> apply;
  //! The field's value in \p options, as the report writes it.
  std::function<nlohmann::json(const RefineOptions& options)> value;
};

//! The table, in the order of `mvflow refine --help`.
const std::vector<RefineOptionEntry>& refine_option_table();

//! Registers every entry's flag on \p command.
void add_refine_options(CLI::App& command);

//! The preset \p preset_name with every option the user gave on \p command applied, checked by
//! RefineOptions::check. \throw CLI::ValidationError naming the flag of the first value out of
//! range, the field, the value and the valid values.
RefineOptions resolve_refine_options(const std::string& preset_name, const CLI::App& command);

//! {"preset": NAME, KEY: value...} for every entry.
nlohmann::json refine_options_json(const RefineOptions& options, const std::string& preset_name);

}  // namespace mvflow::cli
