// Pieces the live-capture commands share (`liftoff capture`, `liftoff emulate`): Ctrl-C as
// a clean stop, and the test a START command asks for.
#pragma once

#include <signal.h>

#include <atomic>

#include "liftoff/capture/emulator.h"
#include "liftoff/cli/capture_commands.h"
#include "liftoff/core/status.h"

namespace liftoff::cli {

/// SIGINT and SIGTERM set stop_requested() while in scope (when `install`); the previous
/// handlers come back at the end. SA_RESETHAND: a second Ctrl-C acts as it would without
/// us (kills). stop_requested() starts false either way.
class ScopedStopSignals {
 public:
  explicit ScopedStopSignals(bool install);
  ~ScopedStopSignals();
  ScopedStopSignals(const ScopedStopSignals&) = delete;
  ScopedStopSignals& operator=(const ScopedStopSignals&) = delete;

  /// Set by the handlers; what a capture or an emulator run watches to stop.
  const std::atomic<bool>& stop_requested() const;

 private:
  bool installed_;
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

/// TestChoice as the emulator's TestParameters (kInvalidArgument naming the flag).
Result<capture::TestParameters> TestParametersFrom(const TestChoice& choice);

/// --pulled, --bend-percent, --ramp-deg, --ramp-s, bound to `test`.
void AddTestFlags(Command& app, TestChoice& test);

}  // namespace liftoff::cli
