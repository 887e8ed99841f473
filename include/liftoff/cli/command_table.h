// The liftoff command line: every command, in the order `liftoff --help` lists them.
// apps/liftoff/main.cc runs it; tests walk it (every flag's help shows its struct's
// default).
#pragma once

#include <ostream>
#include <vector>

#include "liftoff/cli/flags.h"

namespace liftoff::cli {

/// Adds every command to `app` (`sim` with its three subcommands), each bound to a fresh
/// command struct; the Subcommands run them once `app` has parsed.
std::vector<Subcommand> AddCommands(Command& app);

/// The liftoff command line: parses `argv`, runs the command chosen, returns its exit code.
int RunLiftoff(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace liftoff::cli
