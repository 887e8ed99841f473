#include "liftoff/cli/command_table.h"

#include <string>

#include "liftoff/cli/capture_commands.h"
#include "liftoff/cli/commands.h"
#include "liftoff/cli/report_command.h"
#include "liftoff/cli/sim_commands.h"
#include "liftoff/cli/synth_commands.h"
#include "liftoff/cli/video_commands.h"
#include "liftoff/core/version.h"

namespace liftoff::cli {

std::vector<Subcommand> AddCommands(Command& app) {
  app.RequireSubcommand();
  Command* sim = app.AddSubcommand(
      "sim", "Simulate the foot-lifting test: one run, the tension sweep, MJCF export");
  sim->RequireSubcommand();
  return {
      AddTableCommand(app),    AddReportCommand(app),       AddImport2018Command(app),
      AddSyncCommand(app),     AddLogCommand(app),          AddCalibCommand(app),
      AddCaptureCommand(app),  AddEmulateCommand(app),      AddPortsCommand(app),
      AddJournalCommand(app),  AddSynthCommand(app),        AddVideoCommand(app),
      AddSimRunCommand(*sim),  AddSimSweepCommand(*sim),    AddSimExportMjcfCommand(*sim),
  };
}

int RunLiftoff(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  return RunCommandLine("liftoff: measure robot foot-lifting tests against simulation",
                        std::string("liftoff ") + kVersion, AddCommands, argc, argv, out, err);
}

}  // namespace liftoff::cli
