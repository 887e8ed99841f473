// Writes the sample trials in samples/trials/: eight controller logs of foot-lifting
// tests with known answers, their trial manifest, and expected.json with the exact
// rotation at liftoff of each. The README's main command tabulates them.
//
// Each trial follows the paper's procedure on the controller's clock (origin = LED on):
// bend from 0.5 s to 3.5 s, then ramp the rotating vertebra at (pi/3)/40 rad/s from
// 4 s. The foot lifts when |vertebra angle| reaches the trial's liftoff angle; the video
// instants are chosen so that the interval LED on -> liftoff lands exactly there. Seven
// logs are in liftoff's format (10 Hz with jitter, raw counts quantised through the
// calibration); one is in the 2018 format (bursts of 17 samples, ~1 s gaps, a truncated
// last line) to show the importer and the gap warnings.
//
// Usage: make_sample_trials OUTPUT_FOLDER [CALIBRATION_JSON]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"
#include "liftoff/core/json.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/random.h"
#include "liftoff/core/time.h"

namespace {

using namespace liftoff;

struct SampleTrial {
  const char* id;
  Foot foot;
  CableGroup pulled;
  RotationSense sense;
  double liftoff_rad;  // |vertebra angle| when the foot lifts
  double led_on_video_s;
  bool laika2018_format;
};

constexpr double kRampRateRadPerS = (std::numbers::pi / 3.0) / 40.0;
constexpr double kRampStartS = 4.0;
constexpr double kBendStartS = 0.5;
constexpr double kBendEndS = 3.5;
constexpr double kBendSpoolRad = 4.0;              // spool angle at the end of the bend
constexpr double kTailS = 3.0;                     // log continues this long after liftoff
constexpr double kVideoUncertaintyS = 1.0 / 60.0;  // half a frame at 30 fps, rounded up

double VertebraAngleAt(const SampleTrial& trial, double t_s) {
  const double magnitude = kRampRateRadPerS * std::max(0.0, t_s - kRampStartS);
  return trial.sense == RotationSense::kPositive ? magnitude : -magnitude;
}

double SpoolAngleAt(double t_s) {
  const double progress = std::clamp((t_s - kBendStartS) / (kBendEndS - kBendStartS), 0.0, 1.0);
  return kBendSpoolRad * progress;
}

// liftoff format: 10 Hz with +-3 ms jitter, counts quantised, LED and test events.
ControllerLog MakeLiftoffLog(const SampleTrial& trial, const Calibration& calibration, double end_s,
                             uint64_t seed) {
  SplitMix64 random(seed);
  ControllerLog log;
  log.header.calibration = calibration.name;
  log.header.source = "samples/make_sample_trials (synthetic, exact ground truth)";
  log.header.device = "synthetic controller";
  log.header.metadata["trial"] = trial.id;
  log.header.metadata["pulled_group"] = std::string(CableGroupName(trial.pulled));
  log.header.metadata["rotation"] = std::string(RotationSenseName(trial.sense));
  log.header.metadata["ramp_rate_rad_per_s"] = std::to_string(kRampRateRadPerS);
  const int64_t host_origin_ns = 1'767'225'600LL * kNanosecondsPerSecond;  // 2026-01-01
  log.events.push_back({0, host_origin_ns, LogEventKind::kLedOn, ""});
  log.events.push_back({0, host_origin_ns, LogEventKind::kTestStart, ""});
  uint32_t sequence = 0;
  for (double nominal_s = 0.0; nominal_s <= end_s; nominal_s += 0.1) {
    const double t_s = std::max(0.0, nominal_s + 0.003 * random.Symmetric());
    LogSample sample;
    sample.device_time_ns = NsFromSeconds(t_s);
    sample.host_time_ns = host_origin_ns + sample.device_time_ns + 2'000'000;  // 2 ms USB latency
    sample.sequence = sequence++;
    sample.led_on = true;
    const int64_t bend_counts = calibration.CountsFromShaftAngle(SpoolAngleAt(t_s));
    const int64_t rotate_counts = calibration.CountsFromShaftAngle(
        calibration.ShaftAngleFromVertebraAngle(VertebraAngleAt(trial, t_s)));
    sample.bend_counts = bend_counts;
    sample.rotate_counts = rotate_counts;
    sample.bend_spool_rad =
        calibration.SpoolAngleFromShaftAngle(calibration.ShaftAngleFromCounts(bend_counts));
    sample.rotate_shaft_rad = calibration.ShaftAngleFromCounts(rotate_counts);
    sample.vertebra_rad = calibration.VertebraAngleFromCounts(rotate_counts);
    log.samples.push_back(sample);
  }
  log.events.push_back({log.samples.back().device_time_ns, log.samples.back().host_time_ns,
                        LogEventKind::kTestEnd, ""});
  return log;
}

// 2018 format: bursts of 17 samples ~3.6 ms apart each second, shaft angle with two
// decimals, bare CR line ends, a truncated last line.
std::string MakeLaika2018Log(const SampleTrial& trial, const Calibration& calibration,
                             double end_s) {
  std::string text;
  char line[64];
  for (int second = 0; second <= static_cast<int>(end_s); ++second) {
    for (int k = 0; k < 17; ++k) {
      const int t_ms = second * 1000 + 4 + k * 4 - (k > 8 ? 1 : 0);
      const double shaft =
          calibration.ShaftAngleFromVertebraAngle(VertebraAngleAt(trial, t_ms * 1e-3));
      std::snprintf(line, sizeof line, "%d,%.2f,\r", t_ms, shaft);
      text += line;
    }
  }
  text += "1074.3";  // the serial capture stopped mid-line, as in the 2018 files
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::cerr << "usage: make_sample_trials OUTPUT_FOLDER [CALIBRATION_JSON]\n";
    return 2;
  }
  const std::filesystem::path folder = std::filesystem::absolute(argv[1]);
  auto calibration =
      LoadCalibration(argc == 3 ? std::filesystem::path(argv[2]) : DefaultCalibrationPath());
  if (!calibration.ok()) {
    std::cerr << calibration.status().ToString() << '\n';
    return 1;
  }
  std::filesystem::create_directories(folder / "logs");

  // two trials per foot; which group and sense lift which foot follows paper Table II
  const std::vector<SampleTrial> trials = {
      {"A1", Foot::kA, CableGroup::kHR, RotationSense::kPositive, 0.450, 2.217, false},
      {"A2", Foot::kA, CableGroup::kHR, RotationSense::kPositive, 0.470, 1.803, false},
      {"B1", Foot::kB, CableGroup::kHR, RotationSense::kNegative, 0.580, 3.050, false},
      {"B2", Foot::kB, CableGroup::kHR, RotationSense::kNegative, 0.595, 2.640, false},
      {"C1", Foot::kC, CableGroup::kHL, RotationSense::kPositive, 0.520, 1.377, false},
      {"C2", Foot::kC, CableGroup::kHL, RotationSense::kPositive, 0.535, 2.905, false},
      {"D1", Foot::kD, CableGroup::kHL, RotationSense::kNegative, 0.415, 4.112, false},
      {"D2", Foot::kD, CableGroup::kHL, RotationSense::kNegative, 0.430, 2.520, true},
  };

  TrialManifest manifest;
  manifest.base_dir = folder;
  manifest.description =
      "Sample trials with known answers (samples/make_sample_trials.cc); expected.json holds them";
  nlohmann::json expected = {{"calibration", calibration->name},
                             {"ramp_rate_rad_per_s", kRampRateRadPerS},
                             {"trials", nlohmann::json::object()}};
  uint64_t seed = 2018;
  for (const SampleTrial& trial : trials) {
    // the video instants: LED on as given, liftoff when the ramp reaches the angle,
    // rounded to the millisecond as a person would write them down
    const double interval_s = kRampStartS + trial.liftoff_rad / kRampRateRadPerS;
    const int64_t led_on_ns = NsFromSeconds(trial.led_on_video_s);
    const int64_t liftoff_ns =
        NsFromSeconds(std::round((trial.led_on_video_s + interval_s) * 1e3) / 1e3);
    const double exact_interval_s = SecondsFromNs(liftoff_ns - led_on_ns);
    const double true_liftoff_rad = std::abs(VertebraAngleAt(trial, exact_interval_s));
    const double end_s = exact_interval_s + kTailS;

    TrialRecord record;
    record.id = trial.id;
    record.foot = trial.foot;
    record.test_number = trial.id[1] - '0';
    record.pulled_group = trial.pulled;
    record.rotation = trial.sense;
    record.times = EventTimes{led_on_ns, liftoff_ns, NsFromSeconds(kVideoUncertaintyS),
                              NsFromSeconds(kVideoUncertaintyS), "synthetic (exact)"};
    if (trial.laika2018_format) {
      record.log_path = folder / "logs" / (std::string(trial.id) + "-2018-format.txt");
      record.log_format = LogFormat::kLaika2018;
      std::ofstream(record.log_path, std::ios::binary)
          << MakeLaika2018Log(trial, *calibration, end_s);
      record.notes = "2018 serial format: bursts each second, so the lookup falls in a gap";
    } else {
      record.log_path = folder / "logs" / (std::string(trial.id) + ".csv");
      record.log_format = LogFormat::kLiftoff;
      const Status written =
          WriteControllerLog(record.log_path, MakeLiftoffLog(trial, *calibration, end_s, seed++));
      if (!written.ok()) {
        std::cerr << written.ToString() << '\n';
        return 1;
      }
    }
    manifest.trials.push_back(record);
    expected["trials"][trial.id] = {{"foot", FootName(trial.foot)},
                                    {"liftoff_rad", true_liftoff_rad},
                                    {"interval_s", exact_interval_s}};
  }
  if (Status status = WriteManifest(folder / "manifest.json", manifest); !status.ok()) {
    std::cerr << status.ToString() << '\n';
    return 1;
  }
  if (Status status = WriteJsonFile(folder / "expected.json", expected); !status.ok()) {
    std::cerr << status.ToString() << '\n';
    return 1;
  }
  std::cout << "wrote " << trials.size() << " sample trials to " << folder.string() << '\n';
  return 0;
}
