// The liftoff command line: every command, in the order `liftoff --help` lists them.
// apps/liftoff/main.cc runs it; tests walk it (every flag's help shows its struct's
// default).
#pragma once

#include <vector>

#include "liftoff/cli/cli11.h"

#include "liftoff/cli/flags.h"

namespace liftoff::cli {

/// Adds every command to `app` (`sim` with its three subcommands), each bound to a fresh
/// command struct; the Subcommands run them once `app` has parsed.
std::vector<Subcommand> AddCommands(CLI::App& app);

}  // namespace liftoff::cli
