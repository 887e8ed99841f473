// `liftoff journal JOURNAL [--replay [-o LOG]]`: a capture journal shown, or its log rebuilt.
#include "liftoff/cli/capture_commands.h"

#include <memory>
#include <ostream>
#include <string>

#include "cli_common.h"
#include "liftoff/capture/journal.h"
#include "liftoff/core/output.h"

namespace liftoff::cli {

int RunJournal(const JournalCommand& command, std::ostream& out, std::ostream& err) {
  if (!command.replay) {
    if (!command.output_path.empty()) {
      return ReportError(InvalidArgumentError("--output: only with --replay"), err);
    }
    capture::JournalDumpOptions options;
    options.text = !command.hex;
    options.max_records = command.max_records;
    const Status valid = NameFlagsIn(options.Validate(), {{"--max-records", "max_records"}});
    if (!valid.ok()) return ReportError(valid, err);
    const Status dumped = capture::DumpJournal(command.journal_path, options, out);
    if (!dumped.ok()) return ReportError(dumped, err);
    return kExitOk;
  }

  // replay: the log as live capture would have written it
  if (!command.output_path.empty()) {
    const Status refused = RefuseToReplace(command.output_path, "", command.force);
    if (!refused.ok()) return ReportError(refused, err);
  }
  auto calibration = ChooseCalibration(command.calibration);
  if (!calibration.ok()) return ReportError(calibration.status(), err);
  auto replay = capture::ReplayJournal(command.journal_path, *calibration);
  if (!replay.ok()) return ReportError(replay.status(), err);
  if (replay->truncated) {
    err << "warning: " << command.journal_path.string() << ": the last record is cut off ("
        << replay->truncated_bytes << " bytes skipped: the capture stopped mid-write)\n";
  }
  out << replay->Brief() << '\n';
  if (command.output_path.empty()) return kExitOk;
  const Status written = WriteControllerLog(command.output_path, replay->log);
  if (!written.ok()) return ReportError(written, err);
  err << "wrote " << command.output_path.string() << '\n';
  return kExitOk;
}

Subcommand AddJournalCommand(Command& parent) {
  auto command = std::make_shared<JournalCommand>();
  Command* app =
      parent.AddSubcommand("journal", "Show a capture journal, or rebuild its controller log");
  app->AddOption("journal", command->journal_path, "Capture journal")->Required();
  app->AddSwitch("--replay", command->replay,
                "Rebuild the controller log with live capture's parsing");
  app->AddOption("--output,-o", command->output_path, "With --replay: log to write");
  app->AddSwitch("--force", command->force, "Overwrite an existing output file");
  app->AddSwitch("--hex", command->hex, "Dump bytes as hexadecimal");
  app->AddOption("--max-records", command->max_records, "Dump at most this many records");
  AddCalibrationFlag(*app, command->calibration);
  return RunsWith(app, command, RunJournal);
}

}  // namespace liftoff::cli
