// liftoff: the command line. Each command is a file of src/cli/ (its flags bound to its
// options struct, its Run function); liftoff/cli/command_table.h lists them.
#include <iostream>
#include <string>
#include <vector>

#include "liftoff/cli/cli11.h"

#include "liftoff/cli/command_table.h"
#include "liftoff/core/version.h"

int main(int argc, char** argv) {
  CLI::App app{"liftoff: measure robot foot-lifting tests against simulation"};
  app.set_version_flag("--version", std::string("liftoff ") + liftoff::kVersion);
  const std::vector<liftoff::cli::Subcommand> commands = liftoff::cli::AddCommands(app);
  return liftoff::cli::RunCommandLine(app, commands, argc, argv, std::cout, std::cerr);
}
