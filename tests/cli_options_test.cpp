// The refine options' table (tools/refine_option_table.h): every entry's flag sets the field its
// report key shows, the preset stays where no flag is given, and nothing is declared twice.

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "tools/refine_option_table.h"

namespace mvflow::cli {
namespace {

// For every flag: what a user types after it ("" for a switch) and what the report must then show.
// A new table entry fails EveryEntryIsCovered until it is added here.
const std::map<std::string, std::pair<std::string, nlohmann::json>>& cases() {
  static const std::map<std::string, std::pair<std::string, nlohmann::json>> c = {
      {"--engine", {"sequential", "sequential"}},
      {"--block-size", {"37", 37}},
      {"--velocity", {"0.25", 0.25}},
      {"--cfl", {"0.5", 0.5}},
      {"--speed-quantile", {"0.75", 0.75}},
      {"--patch", {"3", 7}},
      {"--sg-k", {"6", 6}},
      {"--sg-order", {"3", 3}},
      {"--curvature-area", {"barycentric", "barycentric"}},
      {"--max-view-angle", {"70", 70.0}},
      {"--max-views", {"5", 5}},
      {"--preferred-view-angle", {"50", 50.0}},
      {"--min-views", {"4", 4}},
      {"--image-levels", {"2", 2}},
      {"--normalize", {"on", true}},
      {"--noise-floor", {"0.05", 0.05}},
      {"--drop-views", {"2", 2}},
      {"--drop-min-views", {"6", 6}},
      {"--spread-unobserved", {"on", true}},
      {"--observed-view-angle", {"60", 60.0}},
      {"--observed-erode", {"2", 2}},
      {"--fill-unobserved", {"on", true}},
      {"--weak-view-angle", {"60", 60.0}},
      {"--fit-silhouettes", {"on", "on"}},
      {"--rim-angle", {"12", 12.0}},
      {"--rim-dead-zone", {"1.5", 1.5}},
      {"--rim-step", {"0.3", 0.3}},
      {"--smoothing", {"0.2", 0.2}},
      {"--smoothing-steps", {"3", 3}},
      {"--taubin-pass-band", {"0.05", 0.05}},
      {"--regularization", {"0.25", 0.25}},
      {"--regularization-steps", {"2", 2}},
      {"--epsilon", {"1.5", 1.5}},
      {"--min-iterations", {"12", 12}},
      {"--max-iterations", {"77", 77}},
      {"--step-tolerance", {"0.004", 0.004}},
      {"--no-remeshing", {"", false}},
      {"--refine-min-pixels", {"8", 8.0}},
      {"--refine-curvature", {"0.7", 0.7}},
      {"--untangle-rounds", {"4", 4}},
      {"--refine-min-growth", {"0.3", 0.3}},
      {"--refine-when", {"iteration", "iteration"}},
      {"--convergence", {"each-lookback", "each-lookback"}},
      {"--step", {"global", false}},
      {"--step-control", {"on", true}},
      {"--keep-inside-silhouettes", {"", true}},
      {"--silhouette-threshold", {"0.3", 0.3}},
      {"--silhouette-dilate", {"5", 5}},
      {"--no-adaptive", {"", false}},
      {"--exclude-views", {"1,4", nlohmann::json::array({1, 4})}},
  };
  return c;
}

// Parses `refine FLAG [VALUE]` as the program does and returns the report's options.
nlohmann::json options_after(const std::vector<std::string>& arguments) {
  CLI::App command;
  add_refine_options(command);
  std::vector<std::string> reversed(arguments.rbegin(), arguments.rend());  // CLI11 takes them reversed
  command.parse(reversed);
  return refine_options_json(resolve_refine_options("default", command), "default");
}

TEST(RefineOptionTable, FlagsAndReportKeysAreDeclaredOnce) {
  std::set<std::string> flags, keys;
  for (const RefineOptionEntry& entry : refine_option_table()) {
    EXPECT_TRUE(flags.insert(entry.flag).second) << entry.flag;
    EXPECT_TRUE(keys.insert(entry.key).second) << entry.key;
  }
  const nlohmann::json json = refine_options_json(default_preset(), "default");
  EXPECT_EQ(json.size(), keys.size() + 1);  // and "preset"
}

TEST(RefineOptionTable, EveryEntryIsCovered) {
  EXPECT_EQ(cases().size(), refine_option_table().size());
  for (const RefineOptionEntry& entry : refine_option_table())
    EXPECT_TRUE(cases().count(entry.flag)) << entry.flag << " has no case in this test";
}

TEST(RefineOptionTable, EachFlagSetsItsOwnFieldAndNothingElse) {
  const nlohmann::json preset = options_after({});
  EXPECT_EQ(preset, refine_options_json(default_preset(), "default"));  // no flag: the preset
  for (const RefineOptionEntry& entry : refine_option_table()) {
    const auto& [argument, expected] = cases().at(entry.flag);
    std::vector<std::string> arguments = {entry.flag};
    if (!argument.empty()) arguments.push_back(argument);
    const nlohmann::json after = options_after(arguments);
    EXPECT_NE(preset.at(entry.key), expected) << entry.flag << ": the case must differ from the default";
    EXPECT_EQ(after.at(entry.key), expected) << entry.flag;
    for (const auto& [key, value] : preset.items())
      if (key != entry.key) EXPECT_EQ(after.at(key), value) << entry.flag << " also changed " << key;
  }
}

TEST(RefineOptionTable, BadValuesAreRefusedByTheFlagsChecks) {
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"--engine", "fast"}, {"--patch", "9"}, {"--min-views", "1"}, {"--normalize", "yes"},
        {"--image-levels", "5"}, {"--block-size", "0"}, {"--observed-erode", "-1"}}) {
    EXPECT_THROW(options_after(bad), CLI::ParseError) << bad[0] << " " << bad[1];
  }
}

}  // namespace
}  // namespace mvflow::cli
