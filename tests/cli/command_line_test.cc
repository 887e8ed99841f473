// The command table: every flag of every command shows its struct's real default in the
// help, and giving that default changes nothing.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <regex>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "liftoff/cli/cli11.h"
#include "liftoff/cli/command_table.h"
#include "liftoff/cli/sim_commands.h"
#include "liftoff/cli/video_commands.h"
#include "liftoff/core/json.h"

namespace liftoff::cli {
namespace {

// "sim run" for the run subcommand, "table" for table
std::vector<std::string> CommandPath(const CLI::App* app) {
  std::vector<std::string> path;
  for (; app->get_parent() != nullptr; app = app->get_parent()) {
    path.insert(path.begin(), app->get_name());
  }
  return path;
}

// every option's current value (its field, read through the binding), by name
std::map<std::string, std::string> CurrentValues(CLI::App* app) {
  std::map<std::string, std::string> values;
  for (CLI::Option* option : app->get_options()) {
    option->capture_default_str();
    values[option->get_name()] = option->get_default_str();
  }
  return values;
}

TEST(CommandLine, EveryFlagsHelpShowsTheDefaultOfAFreshStruct) {
  CLI::App shown_app;
  Command shown(&shown_app);
  const std::vector<Subcommand> commands = AddCommands(shown);
  CLI::App reference_app;
  Command reference_root(&reference_app);
  std::vector<Subcommand> reference = AddCommands(reference_root);
  ASSERT_EQ(commands.size(), 15u);
  int checked = 0;
  for (size_t c = 0; c < commands.size(); ++c) {
    const std::map<std::string, std::string> defaults = CurrentValues(reference[c].app->cli_app());
    for (const CLI::Option* option : commands[c].app->cli_app()->get_options()) {
      const std::string& help_default = option->get_default_str();
      if (!option->nonpositional() || help_default.empty()) continue;
      const std::string name = option->get_name();
      EXPECT_EQ(help_default, defaults.at(name)) << name;
      // the shown default, given on the command line, leaves every field as it was
      CLI::App given_app;
      Command given_root(&given_app);
      std::vector<Subcommand> given = AddCommands(given_root);
      std::vector<std::string> arguments = CommandPath(given[c].app->cli_app());
      arguments.push_back(name + "=" + help_default);
      std::reverse(arguments.begin(), arguments.end());  // CLI11 takes them last first
      try {
        given_app.parse(arguments);
      } catch (const CLI::RequiredError&) {
        // the command's positional arguments: the flags are read before that check
      }
      EXPECT_EQ(CurrentValues(given[c].app->cli_app()), defaults) << name << "=" << help_default;
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(CommandLine, NoHelpTextTypesInANumericDefault) {
  CLI::App app;
  Command root(&app);
  const std::vector<Subcommand> commands = AddCommands(root);
  const std::regex typed_in(R"(default:? -?[0-9])");
  for (const Subcommand& command : commands) {
    for (const CLI::Option* option : command.app->cli_app()->get_options()) {
      EXPECT_FALSE(std::regex_search(option->get_description(), typed_in))
          << option->get_name() << ": " << option->get_description();
    }
  }
}

TEST(CommandLine, ExperimentFlagsShowTheExperimentsDefaultsInTheirUnits) {
  CLI::App app;
  Command root(&app);
  const std::vector<Subcommand> commands = AddCommands(root);
  const CLI::App* run = app.get_subcommand("sim")->get_subcommand("run");
  const sim::ExperimentOptions defaults;
  auto shown = [&](const std::string& flag) { return run->get_option(flag)->get_default_str(); };
  // converted by hand from the struct's SI fields
  EXPECT_EQ(shown("--ramp-deg"), FormatNumber(defaults.ramp_angle_rad * 180.0 / std::numbers::pi));
  EXPECT_EQ(shown("--ramp-deg"), "60");
  EXPECT_EQ(shown("--threshold-mm"), FormatNumber(defaults.liftoff_threshold_m * 1000.0));
  EXPECT_EQ(shown("--ground-clearance-mm"), FormatNumber(defaults.ground_clearance_m * 1000.0));
  EXPECT_EQ(shown("--dt"), FormatNumber(defaults.engine.time_step_s));
  EXPECT_EQ(shown("--bend-fraction"), FormatNumber(defaults.bend_fraction));
  EXPECT_EQ(shown("--solver-iterations"), std::to_string(defaults.engine.solver_iterations));
  EXPECT_EQ(shown("--pretension-ratios"), "0.006,0.015,0.052,0.004");
  // unset optionals: the model file's, no default shown
  EXPECT_EQ(shown("--friction"), "");
  EXPECT_EQ(shown("--attachment"), "");
  // every experiment flag is on each sim command and the report
  for (const FieldFlag<sim::ExperimentOptions>& flag : ExperimentFlags()) {
    for (const char* command : {"run", "sweep", "export-mjcf"}) {
      EXPECT_NO_THROW(app.get_subcommand("sim")->get_subcommand(command)->get_option(flag.flag))
          << command << " " << flag.flag;
    }
    EXPECT_NO_THROW(app.get_subcommand("report")->get_option(flag.flag)) << flag.flag;
  }
}

TEST(ClipFlags, BindEachFlagToItsField) {
  video::ClipAnalysisOptions options;
  CLI::App app;
  Command root(&app);
  AddClipFlags(root, options);
  AddFlags(root, ClipInstantFlags(), options);
  std::vector<std::string> arguments = {"--led-roi",
                                        "563,45,26,27",
                                        "--foot-roi",
                                        "300,520,160,120",
                                        "--foot",
                                        "C",
                                        "--px-per-mm",
                                        "1.5",
                                        "--threshold-px",
                                        "2.5",
                                        "--exposure-ms",
                                        "8",
                                        "--rest-window=-1,0.25",
                                        "--liftoff",
                                        "onset"};
  std::reverse(arguments.begin(), arguments.end());
  app.parse(arguments);
  auto checked = CheckedClipOptions(options);
  ASSERT_TRUE(checked.ok()) << checked.status().ToString();
  EXPECT_EQ(checked->led.roi_px, cv::Rect(563, 45, 26, 27));
  EXPECT_EQ(checked->foot.foot_roi_px, cv::Rect(300, 520, 160, 120));
  EXPECT_EQ(checked->foot.tape_colour, Foot::kC);
  EXPECT_EQ(checked->foot.px_per_mm, 1.5);
  EXPECT_EQ(checked->foot.threshold_px, 2.5);
  EXPECT_DOUBLE_EQ(checked->led.exposure_s, 0.008);
  EXPECT_DOUBLE_EQ(checked->foot.exposure_s, 0.008) << "the camera's exposure, for the foot too";
  EXPECT_EQ(checked->rest_from_led_s, -1.0);
  EXPECT_EQ(checked->rest_to_led_s, 0.25);
  EXPECT_EQ(checked->liftoff, video::LiftoffInstant::kOnset);
  // written back as they were given
  std::string described = DescribeChanged(ClipFlags(), options);
  EXPECT_EQ(described,
            "--led-roi 563,45,26,27 --foot-roi 300,520,160,120 --foot C --px-per-mm 1.5 "
            "--threshold-px 2.5 --exposure-ms 8");
  EXPECT_EQ(DescribeChanged(ClipInstantFlags(), options), "--rest-window=-1,0.25 --liftoff onset");
  // --threshold-mm (excluded by --threshold-px above)
  video::ClipAnalysisOptions in_mm;
  CLI::App mm_app;
  Command mm_root(&mm_app);
  AddClipFlags(mm_root, in_mm);
  mm_app.parse(std::vector<std::string>{"2.5", "--threshold-mm"});
  EXPECT_EQ(in_mm.foot.threshold_mm, 2.5);
  EXPECT_EQ(in_mm.foot.threshold_px, std::nullopt);
}

// A bad value: the parse or the check names the flag.
TEST(ClipFlags, ABadValueNamesItsFlag) {
  const auto error = [](std::vector<std::string> arguments) -> std::string {
    video::ClipAnalysisOptions options;
    CLI::App app;
    Command root(&app);
    AddClipFlags(root, options);
    AddFlags(root, ClipInstantFlags(), options);
    std::reverse(arguments.begin(), arguments.end());
    try {
      app.parse(arguments);
    } catch (const FlagError& failure) {
      return failure.status().message();
    } catch (const CLI::ParseError& failure) {
      return failure.what();
    }
    auto checked = CheckedClipOptions(options);
    return checked.ok() ? "" : checked.status().message();
  };
  for (const char* bad : {"1,2,3", "1,2,3,4,5", "1,2,0,4", "-1,2,3,4", "a,b,c,d", "1,2,3,4 "}) {
    EXPECT_THAT(error({"--foot-roi", bad}), ::testing::HasSubstr("--foot-roi: expected x,y,w,h"))
        << bad;
  }
  EXPECT_THAT(error({"--foot", "E"}), ::testing::HasSubstr("--foot: expected A, B, C or D"));
  EXPECT_THAT(error({"--liftoff", "soon"}),
              ::testing::HasSubstr("--liftoff: expected threshold or onset"));
  EXPECT_THAT(error({"--px-per-mm", "-1"}), ::testing::HasSubstr("--px-per-mm: expected"));
  EXPECT_THAT(
      error({"--exposure-ms", "2000"}),
      ::testing::HasSubstr("--exposure-ms: led: exposure_s: expected 0 (unknown) .. 1 s, got 2"));
  EXPECT_THAT(error({"--rest-window=0.5,0"}),
              ::testing::HasSubstr("--rest-window: rest_to_led_s: expected more than"));
  EXPECT_THAT(error({"--rest-window=-70,0"}),
              ::testing::HasSubstr("--rest-window: rest_from_led_s: expected"));
  for (const char* bad : {"--rest-window=1", "--rest-window=a,0", "--rest-window=1;2",
                          "--rest-window=0,", "--rest-window=0,1,2", "--rest-window=nan,0"}) {
    EXPECT_THAT(error({bad}), ::testing::HasSubstr("--rest-window: expected FROM,TO in seconds"))
        << bad;
  }
  EXPECT_THAT(error({"--threshold-mm", "1", "--threshold-px", "2"}),
              ::testing::HasSubstr("excludes"));
}

// The clip flags' defaults are the options' own: no flag given, no field changed.
TEST(ClipFlags, NoFlagGivenLeavesEveryOptionAtItsDefault) {
  video::ClipAnalysisOptions options;
  CLI::App app;
  Command root(&app);
  AddClipFlags(root, options);
  AddFlags(root, ClipInstantFlags(), options);
  app.parse(std::vector<std::string>{});
  auto checked = CheckedClipOptions(options);
  ASSERT_TRUE(checked.ok()) << checked.status().ToString();
  const video::ClipAnalysisOptions defaults;
  EXPECT_EQ(checked->led.roi_px, defaults.led.roi_px);
  EXPECT_EQ(checked->led.exposure_s, defaults.led.exposure_s);
  EXPECT_EQ(checked->foot.foot_roi_px, defaults.foot.foot_roi_px);
  EXPECT_EQ(checked->foot.tape_colour, defaults.foot.tape_colour);
  EXPECT_EQ(checked->foot.px_per_mm, defaults.foot.px_per_mm);
  EXPECT_EQ(checked->foot.threshold_mm, defaults.foot.threshold_mm);
  EXPECT_EQ(checked->foot.threshold_px, defaults.foot.threshold_px);
  EXPECT_EQ(checked->foot.exposure_s, defaults.foot.exposure_s);
  EXPECT_EQ(checked->rest_from_led_s, defaults.rest_from_led_s);
  EXPECT_EQ(checked->rest_to_led_s, defaults.rest_to_led_s);
  EXPECT_EQ(checked->liftoff, defaults.liftoff);
  EXPECT_EQ(DescribeChanged(ClipFlags(), options), "");
  EXPECT_EQ(DescribeChanged(ClipInstantFlags(), options), "");
}

}  // namespace
}  // namespace liftoff::cli
