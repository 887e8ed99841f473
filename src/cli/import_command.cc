// `liftoff import-2018`: a 2018 Laika folder as a trial manifest.
#include "liftoff/cli/commands.h"

#include <memory>
#include <ostream>

#include "cli_common.h"
#include "liftoff/capture/laika2018.h"
#include "liftoff/core/output.h"

namespace liftoff::cli {
// ---------------------------------------------------------------------------------------
// liftoff import-2018

int RunImport2018(const Import2018Command& command, std::ostream& out, std::ostream& err) {
  if (command.output_path.empty()) {
    return ReportError(InvalidArgumentError("--output: name the manifest file to write"), err);
  }
  auto imported = capture::ImportLaika2018Folder(command.folder, command.output_path);
  if (!imported.ok()) return ReportError(imported.status(), err);
  // never onto the folder's own files, --force or not
  std::vector<NamedPath> inputs = TrialInputs(imported->manifest);
  inputs.push_back({"FOLDER's times", command.folder / capture::kLaika2018TimesCsv});
  if (const int refused =
          RefuseToOverwriteInputs({{"--output", command.output_path}}, inputs, err);
      refused != kExitOk) {
    return refused;
  }
  if (const Status refused = RefuseToReplace(command.output_path, "", command.force);
      !refused.ok()) {
    return ReportError(refused, err);
  }
  for (const std::string& warning : imported->warnings) err << "warning: " << warning << '\n';
  const Status written = WriteManifest(command.output_path, imported->manifest);
  if (!written.ok()) return ReportError(written, err);
  out << "wrote " << command.output_path.string() << ": " << imported->manifest.trials.size()
      << " trials from " << command.folder.string() << '\n';
  return kExitOk;
}

Subcommand AddImport2018Command(Command& parent) {
  auto command = std::make_shared<Import2018Command>();
  Command* app = parent.AddSubcommand(
      "import-2018", "Turn a 2018 Laika folder (logs + video times CSV) into a trial manifest");
  app->AddOption("folder", command->folder, "Folder with TestN*.txt and the times CSV")
      ->Required();
  app->AddOption("--output,-o", command->output_path, "Manifest to write")->Required();
  app->AddSwitch("--force", command->force, "Overwrite an existing manifest");
  return RunsWith(app, command, RunImport2018);
}

}  // namespace liftoff::cli
