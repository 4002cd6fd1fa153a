// The refine options' table (tools/refine_option_table.h): every entry's flag sets the field its
// report key shows, the preset stays where no flag is given, nothing is declared twice, and a value
// out of range is refused by the stages' own checks under its flag.

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "engine/model/option_check.h"
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
      {"--far-g-ratio", {"50", 50.0}},
      {"--far-view-angle", {"45", 45.0}},
      {"--far-release", {"0.5", 0.5}},
      {"--normalize", {"on", true}},
      {"--denoise", {"off", "off"}},
      {"--denoise-reference", {"0.004", 0.004}},
      {"--surface-patch", {"on", "on"}},
      {"--surface-patch-angle", {"50", 50.0}},
      {"--surface-patch-spacing", {"3", 3.0}},
      {"--noise-floor", {"0.05", 0.05}},
      {"--drop-views", {"2", 2}},
      {"--drop-min-views", {"6", 6}},
      {"--spread-unobserved", {"on", "on"}},
      {"--observed-view-angle", {"60", 60.0}},
      {"--observed-erode", {"2", 2}},
      {"--implausible-g-ratio", {"40", 40.0}},
      {"--implausible-speed-rings", {"3", 3}},
      {"--hardly-observed", {"0.4", 0.4}},
      {"--hardly-observed-first", {"0.5", 0.5}},
      {"--spread-unmoved", {"on", "on"}},
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
      {"--settle-tolerance", {"0.006", 0.006}},
      {"--settle-noise-reference", {"0.003", 0.003}},
      {"--persistence-wait", {"2.5", 2.5}},
      {"--finest-min-iterations", {"25", 25}},
      {"--settled-wait", {"0.5", 0.5}},
      {"--run-on", {"30", 30}},
      {"--average-last", {"4", 4}},
      {"--no-remeshing", {"", false}},
      {"--refine-min-pixels", {"8", 8.0}},
      {"--refine-curvature", {"0.7", 0.7}},
      {"--untangle-rounds", {"4", 4}},
      {"--refine-min-growth", {"0.3", 0.3}},
      {"--refine-when", {"iteration", "iteration"}},
      {"--convergence", {"each-lookback", "each-lookback"}},
      {"--step", {"global", false}},
      {"--step-control", {"on", true}},
      {"--damping", {"off", false}},
      {"--momentum", {"0.25", 0.25}},
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

TEST(RefinePresets, AccurateIsTheDefaultWithSurfacePatchesAndTheFinerSettledTolerance) {
  const nlohmann::json accurate = refine_options_json(preset("accurate"), "accurate");
  const nlohmann::json plain = refine_options_json(preset("default"), "default");
  std::set<std::string> differing;
  for (const auto& [key, value] : plain.items())
    if (accurate.at(key) != value) differing.insert(key);
  EXPECT_EQ(differing, (std::set<std::string>{"preset", "photo_surface_patch", "settled_tolerance"}));
  EXPECT_EQ(accurate.at("photo_surface_patch"), "on");
  EXPECT_EQ(accurate.at("settled_tolerance"), 0.001);
  preset("accurate").check();
  EXPECT_THROW(preset("fast"), InputError);
}

// The one list the command line checks against and the error names: every name resolves to a
// valid preset, and an unknown one is refused with all of them listed.
TEST(RefinePresets, EveryListedNameResolvesAndAnUnknownOneListsThemAll) {
  EXPECT_EQ(preset_names(), (std::vector<std::string>{"default", "accurate", "thesis"}));
  for (const std::string& name : preset_names()) EXPECT_NO_THROW(preset(name).check()) << name;
  try {
    preset("fast");
    FAIL() << "an unknown preset was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown preset 'fast' (expected one of: default, accurate, thesis)"),
              std::string::npos)
        << e.what();
  }
}

// The thesis preset keeps the thesis's stopping: none of the rules added since (README, "Defaults
// and differences").
TEST(RefinePresets, TheThesisPresetStopsAsTheThesis) {
  const StoppingOptions thesis = preset("thesis").stopping;
  EXPECT_EQ(thesis.settled_tolerance, 0.0);
  EXPECT_EQ(thesis.persistence_wait, 0.0);
  EXPECT_EQ(thesis.finest_min_iterations, 0);
  EXPECT_EQ(thesis.settled_wait, 0.0);
  EXPECT_EQ(thesis.average_last, 1);
  EXPECT_EQ(thesis.max_iterations, 100);
  const StoppingOptions by_default = preset("default").stopping;
  EXPECT_EQ(by_default.finest_min_iterations, 15);
  EXPECT_EQ(by_default.average_last, 2);
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
    for (const auto& [key, value] : preset.items()) {
      if (key == entry.key) continue;
      EXPECT_EQ(after.at(key), value) << entry.flag << " also changed " << key;
    }
  }
}

TEST(RefineOptionTable, BadValuesAreRefusedByTheFlagsChecks) {
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"--engine", "fast"}, {"--patch", "9"}, {"--min-views", "1"}, {"--normalize", "yes"},
        {"--image-levels", "5"}, {"--block-size", "0"}, {"--observed-erode", "-1"}, {"--implausible-g-ratio", "1"}, {"--implausible-speed-rings", "17"}, {"--hardly-observed", "1.5"},
        {"--hardly-observed-first", "-0.1"}, {"--settle-noise-reference", "-0.001"}, {"--persistence-wait", "-1"}, {"--finest-min-iterations", "-1"}, {"--settled-wait", "-1"}, {"--run-on", "-1"}, {"--run-on", "1000001"},
        {"--average-last", "0"}, {"--average-last", "12"},
        {"--denoise", "on"}, {"--denoise-reference", "0"}, {"--momentum", "1"},
        {"--far-g-ratio", "0.5"}, {"--far-view-angle", "0"}, {"--far-release", "2"}}) {
    EXPECT_THROW(options_after(bad), CLI::ParseError) << bad[0] << " " << bad[1];
  }
}

// The message a refused command line gives ("" if it is accepted).
std::string refusal(const std::vector<std::string>& arguments) {
  try {
    options_after(arguments);
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return "";
}

TEST(RefineOptionTable, AValueOutOfRangeIsRefusedNamingTheFlagTheFieldTheValueAndTheValidValues) {
  EXPECT_EQ(refusal({"--cfl", "20"}), "--cfl: option cfl = 20 is out of range: expected (0, 10]");
  EXPECT_EQ(refusal({"--smoothing", "1.5"}),
            "--smoothing: option smoothing.lambda_dt = 1.5 is out of range: expected (0, 1)");
  EXPECT_EQ(refusal({"--max-view-angle", "200"}),
            "--max-view-angle: option visibility.max_angle_degrees = 200 is out of range: expected (0, 90]");
  EXPECT_EQ(refusal({"--patch", "9"}), "--patch: option photo.photo.half_patch = 9 is out of range: expected [1, 7]");
  EXPECT_EQ(refusal({"--max-iterations", "5"}),
            "--max-iterations: option stopping.max_iterations = 5 is out of range: expected >= min_iterations (10)");
}

TEST(RefineOptionTable, RangesAreCheckedOnceEveryFlagIsApplied) {
  // λ·dt = 0.95 needs a Taubin pass band below the default's (μ < 1); with 0 it is valid.
  EXPECT_EQ(refusal({"--smoothing", "0.95", "--taubin-pass-band", "0"}), "");
  EXPECT_EQ(refusal({"--smoothing", "0.95"}).rfind("--taubin-pass-band: option smoothing.taubin_pass_band = 0.1", 0), 0u);
  EXPECT_EQ(refusal({"--min-iterations", "300", "--max-iterations", "400"}), "");
  // A choice refused only in combination: named by its own flag too.
  EXPECT_EQ(refusal({"--surface-patch", "on", "--normalize", "on"}),
            "--surface-patch: option photo.photo.surface_patch = on is out of range: expected off or oblique when "
            "normalize is on");
  EXPECT_EQ(refusal({"--surface-patch", "on"}), "");
}

TEST(RefineOptionTable, HelpQuotesTheValidValuesOfTheStagesChecks) {
  CLI::App command;
  add_refine_options(command);
  EXPECT_NE(command.get_option("--cfl")->get_description().find("(valid: (0, 10])"), std::string::npos);
  EXPECT_NE(command.get_option("--patch")->get_description().find("(valid: [1, 7])"), std::string::npos);
  EXPECT_NE(command.get_option("--sg-k")->get_description().find("(valid: an even number >= 2)"), std::string::npos);
  for (const RefineOptionEntry& entry : refine_option_table()) {
    if (!entry.members.empty() && entry.flag != "--exclude-views") {
      EXPECT_NE(command.get_option(entry.flag)->get_description().find("(valid: "), std::string::npos) << entry.flag;
    }
  }
}

TEST(RefineOptions, CheckNamesTheFirstFieldOutOfRangeByItsPath) {
  RefineOptions options = default_preset();
  EXPECT_NO_THROW(options.check());
  options.smoothing.lambda_dt = 2;
  try {
    options.check();
    FAIL() << "smoothing.lambda_dt = 2 was accepted";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "smoothing.lambda_dt");
    EXPECT_EQ(e.value(), "2");
    EXPECT_EQ(e.expected(), "(0, 1)");
    EXPECT_STREQ(e.what(), "option smoothing.lambda_dt = 2 is out of range: expected (0, 1)");
  }
  options = default_preset();
  options.visibility.half_patch = 3;  // the photo patch stays 2
  EXPECT_THROW(options.check(), OptionError);
  options = default_preset();
  options.excluded_views = {2, -1};
  EXPECT_THROW(options.check(), InputError);  // OptionError is an InputError
}

}  // namespace
}  // namespace mvflow::cli
