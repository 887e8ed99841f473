#include "liftoff/cli/command_table.h"

#include "liftoff/cli/capture_commands.h"
#include "liftoff/cli/commands.h"
#include "liftoff/cli/report_command.h"
#include "liftoff/cli/sim_commands.h"
#include "liftoff/cli/synth_commands.h"
#include "liftoff/cli/video_commands.h"

namespace liftoff::cli {

std::vector<Subcommand> AddCommands(CLI::App& app) {
  app.require_subcommand(1);
  CLI::App* sim = app.add_subcommand(
      "sim", "Simulate the foot-lifting test: one run, the tension sweep, MJCF export");
  sim->require_subcommand(1);
  return {
      AddTableCommand(app),    AddReportCommand(app),       AddImport2018Command(app),
      AddSyncCommand(app),     AddLogCommand(app),          AddCalibCommand(app),
      AddCaptureCommand(app),  AddEmulateCommand(app),      AddPortsCommand(app),
      AddJournalCommand(app),  AddSynthCommand(app),        AddVideoCommand(app),
      AddSimRunCommand(*sim),  AddSimSweepCommand(*sim),    AddSimExportMjcfCommand(*sim),
  };
}

}  // namespace liftoff::cli
