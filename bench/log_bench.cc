// Reading controller logs and looking angles up in them: the costs behind `liftoff table`.
// Figures: lines/s for liftoff's format and the 2018 format (a 1 kHz, 10-minute capture is
// 600,000 lines), and the time of one lookup in a long log.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <benchmark/benchmark.h>

#include "liftoff/capture/laika2018.h"
#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"
#include "liftoff/sync/lookup.h"

#include "bench_support.h"

namespace {

using namespace liftoff;

// A 1 kHz log of `samples` samples: counts, shaft and vertebra angles on a ramp.
ControllerLog MakeLog(int64_t samples) {
  const Calibration calibration = bench::ShippedCalibration();
  ControllerLog log;
  log.header.calibration = calibration.name;
  log.samples.reserve(static_cast<size_t>(samples));
  for (int64_t i = 0; i < samples; ++i) {
    LogSample sample;
    sample.device_time_ns = i * 1'000'000;
    sample.host_time_ns = 1'700'000'000'000'000'000 + sample.device_time_ns;
    sample.sequence = static_cast<uint32_t>(i);
    sample.led_on = true;
    sample.rotate_counts = i / 3;
    sample.bend_counts = 4000;
    sample.rotate_shaft_rad = calibration.ShaftAngleFromCounts(*sample.rotate_counts);
    sample.vertebra_rad = calibration.VertebraAngleFromCounts(*sample.rotate_counts);
    sample.bend_spool_rad = calibration.ShaftAngleFromCounts(4000);
    log.samples.push_back(sample);
  }
  return log;
}

std::filesystem::path TempPath(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("liftoff-bench-" + name);
}

void BM_ReadLiftoffLog(benchmark::State& state) {
  const auto path = TempPath("liftoff.csv");
  if (!WriteControllerLog(path, MakeLog(state.range(0))).ok()) state.SkipWithError("write failed");
  for (auto _ : state) {
    auto log = ReadControllerLog(path);
    if (!log.ok()) state.SkipWithError(log.status().ToString().c_str());
    benchmark::DoNotOptimize(log);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetBytesProcessed(state.iterations() *
                          static_cast<int64_t>(std::filesystem::file_size(path)));
  std::filesystem::remove(path);
}
BENCHMARK(BM_ReadLiftoffLog)->Arg(600'000)->Unit(benchmark::kMillisecond);

void BM_ImportLaika2018Log(benchmark::State& state) {
  const auto path = TempPath("laika2018.txt");
  {
    std::ofstream out(path, std::ios::binary);
    char line[64];
    for (int64_t i = 0; i < state.range(0); ++i) {
      std::snprintf(line, sizeof line, "%lld,%.2f,\r", static_cast<long long>(i),
                    static_cast<double>(i) * 1e-4);
      out << line;
    }
  }
  const Calibration calibration = bench::ShippedCalibration();
  for (auto _ : state) {
    auto log = capture::ImportLaika2018Log(path, calibration);
    if (!log.ok()) state.SkipWithError(log.status().ToString().c_str());
    benchmark::DoNotOptimize(log);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  std::filesystem::remove(path);
}
BENCHMARK(BM_ImportLaika2018Log)->Arg(600'000)->Unit(benchmark::kMillisecond);

void BM_LookupInLongLog(benchmark::State& state) {
  const ControllerLog log = MakeLog(state.range(0));
  sync::LookupOptions options;
  int64_t query_ns = 0;
  const int64_t span_ns = log.LastSampleNs();
  for (auto _ : state) {
    query_ns = (query_ns + 7'777'777) % span_ns;
    auto lookup = sync::LookupVertebraAngle(log, query_ns, 20'000'000, options);
    benchmark::DoNotOptimize(lookup);
  }
}
BENCHMARK(BM_LookupInLongLog)->Arg(600'000);

}  // namespace

BENCHMARK_MAIN();
