#include "capture_common.h"

#include <numbers>
#include <optional>
#include <string>

#include "liftoff/core/robot.h"

namespace liftoff::cli {
namespace {

// Set by SIGINT/SIGTERM; a lock-free atomic is safe to store from a handler.
std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void OnStopSignal(int) { g_stop_requested.store(true); }

}  // namespace

ScopedStopSignals::ScopedStopSignals(bool install) : installed_(install) {
  g_stop_requested.store(false);
  if (!installed_) return;
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = static_cast<int>(SA_RESETHAND);
  sigaction(SIGINT, &action, &old_int_);
  sigaction(SIGTERM, &action, &old_term_);
}

ScopedStopSignals::~ScopedStopSignals() {
  if (!installed_) return;
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

const std::atomic<bool>& ScopedStopSignals::stop_requested() const { return g_stop_requested; }

Result<capture::TestParameters> TestParametersFrom(const TestChoice& choice) {
  const std::optional<CableGroup> group = ParseCableGroup(choice.pulled_group);
  if (!group || (*group != CableGroup::kHR && *group != CableGroup::kHL)) {
    return InvalidArgumentError("--pulled: expected HR or HL, got \"" + choice.pulled_group + "\"");
  }
  capture::TestParameters test;
  test.pulled_group = *group;
  test.bend_target_fraction = choice.bend_percent / 100.0;
  test.ramp_amplitude_rad = choice.ramp_deg * std::numbers::pi / 180.0;
  test.ramp_duration_s = choice.ramp_s;
  const Status valid = test.Validate();
  if (!valid.ok()) {
    return InvalidArgumentError("--pulled/--bend-percent/--ramp-deg/--ramp-s: " + valid.message());
  }
  return test;
}

void AddTestFlags(Command& app, TestChoice& test) {
  app.AddOption("--pulled", test.pulled_group, "Cable group the bend pulls: HR or HL")
      ->ShowDefault();
  app.AddOption("--bend-percent", test.bend_percent,
                 "Bend each cable of the group to this percentage of its rest length")
      ->ShowDefault();
  app.AddOption("--ramp-deg", test.ramp_deg,
                 "Rotating vertebra's ramp amplitude, degrees, signed by direction")
      ->ShowDefault();
  app.AddOption("--ramp-s", test.ramp_s, "Ramp duration, seconds")->ShowDefault();
}

}  // namespace liftoff::cli
