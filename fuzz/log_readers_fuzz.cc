// libFuzzer target for the controller log readers: arbitrary bytes as a liftoff-format
// log (read back through the file reader, bad lines tolerated) and as the 2018 Laika
// format. Whatever a reader accepts must be finite and in time order. Any crash,
// sanitizer report or broken invariant is a finding. Build and run: scripts/fuzz.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "liftoff/capture/log_loader.h"
#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"

#include "fuzz_check.h"

namespace {

// every angle finite or unmeasured (NaN), times strictly increasing; bounded in liftoff's
// format (the 2018 reader's times are bounded later, by sync)
void CheckLog(const liftoff::ControllerLog& log, bool bounded_times) {
  int64_t previous_ns = INT64_MIN;
  for (const liftoff::LogSample& sample : log.samples) {
    FUZZ_CHECK(sample.device_time_ns > previous_ns);
    FUZZ_CHECK(!bounded_times || (sample.device_time_ns >= -liftoff::kMaxLogTimeNs &&
                                  sample.device_time_ns <= liftoff::kMaxLogTimeNs));
    FUZZ_CHECK(!std::isinf(sample.vertebra_rad));
    previous_ns = sample.device_time_ns;
  }
}

const std::filesystem::path& ScratchFile() {
  static const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("liftoff-fuzz-log-" + std::to_string(getpid()));
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  {
    std::ofstream out(ScratchFile(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  liftoff::LogReadOptions options;
  options.max_bad_lines = 1'000'000;
  static const liftoff::Calibration calibration = [] {
    liftoff::Calibration c;
    c.name = "fuzz";
    c.encoder_counts_per_motor_rev = 12;
    c.gearbox_ratio = 1000;
    c.spur_gear_ratio = 4;
    return c;
  }();
  for (const liftoff::LogFormat format :
       {liftoff::LogFormat::kLiftoff, liftoff::LogFormat::kLaika2018}) {
    const auto log = liftoff::capture::LoadControllerLog(ScratchFile(), format, calibration, options);
    if (log.ok()) CheckLog(*log, format == liftoff::LogFormat::kLiftoff);
  }
  return 0;
}
