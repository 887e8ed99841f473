// CLI11, the command-line parser, for src/cli/flags.cc (the only source file that uses it;
// the command files go through liftoff/cli/flags.h) and the tests that walk its options.
// GCC 12 at -O2 reports a "potential null pointer dereference" inside CLI11's own string
// splitting (used by Option::delimiter) once it is inlined into our code; the warning is
// about a std::vector growing in CLI::detail::split, not about anything that can be null,
// so it is silenced for CLI11's headers only.
#pragma once

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnull-dereference"
#endif
#include <CLI/CLI.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
