// Synthetic trials' figures: render time per frame at 720p and 1080p, with the default
// nuisances and with every nuisance on, and encode time per frame for each codec at the
// same sizes, side by side (the issue asks for the render figures; the encode figures
// say where a clip's time goes).
//
// Run: build/bench/synth_bench   (time per iteration = per frame; the fps counter is
// frames per second of one core)
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "liftoff/core/time.h"
#include "liftoff/synth/scene.h"
#include "liftoff/synth/spec.h"
#include "liftoff/synth/video_writer.h"

namespace {

using namespace liftoff;
using namespace liftoff::synth;

// The paper's trial at a size; `all_nuisances` turns on every image nuisance (noise,
// 8-sample motion blur over a full-frame exposure, flicker, shake, bloom, the diagonal
// foot rising too).
TrialSpec BenchSpec(int width_px, int height_px, bool all_nuisances) {
  TrialSpec spec;
  spec.camera.width_px = width_px;
  spec.camera.height_px = height_px;
  if (all_nuisances) {
    spec.camera.exposure_s = 1.0 / spec.camera.fps;
    spec.nuisance.noise_sigma = 4.0;
    spec.nuisance.motion_blur_samples = 8;
    spec.nuisance.flicker_amplitude = 0.2;
    spec.nuisance.shake_px = 1.0;
    spec.led.bloom = 4.0;
    spec.motion.diagonal_lag_rad = 0.02;
  }
  return spec;
}

// Frame instants over the lift, where the moving feet are drawn: 0.5 s either side of
// the 1 mm instant.
std::vector<int64_t> LiftInstants(const Timeline& timeline, double fps) {
  const int64_t centre_ns = timeline.FirstVideoNsAbove(0.001).value_or(timeline.duration_ns() / 2);
  std::vector<int64_t> instants;
  for (int i = 0; i < static_cast<int>(fps); ++i) {
    instants.push_back(centre_ns - NsFromSeconds(0.5) + NsFromSeconds(i / fps));
  }
  return instants;
}

void BM_Render(benchmark::State& state, int width_px, int height_px, bool all_nuisances) {
  const TrialSpec spec = BenchSpec(width_px, height_px, all_nuisances);
  auto timeline = Timeline::Create(spec);
  auto renderer = timeline.ok() ? SceneRenderer::Create(*timeline) : timeline.status();
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().ToString().c_str());
    return;
  }
  const std::vector<int64_t> instants = LiftInstants(*timeline, spec.camera.fps);
  int64_t frame = 0;
  for (auto _ : state) {
    const size_t at = static_cast<size_t>(frame) % instants.size();
    benchmark::DoNotOptimize(renderer->RenderFrame(frame, instants[at]).data);
    ++frame;
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_Encode(benchmark::State& state, VideoCodec codec, int width_px, int height_px) {
  // one second of rendered frames (default nuisances, noise 2), encoded over and over
  TrialSpec spec = BenchSpec(width_px, height_px, false);
  spec.nuisance.noise_sigma = 2.0;
  auto timeline = Timeline::Create(spec);
  auto renderer = timeline.ok() ? SceneRenderer::Create(*timeline) : timeline.status();
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().ToString().c_str());
    return;
  }
  std::vector<cv::Mat> frames;
  const std::vector<int64_t> instants = LiftInstants(*timeline, spec.camera.fps);
  for (size_t i = 0; i < instants.size(); ++i) {
    frames.push_back(renderer->RenderFrame(static_cast<int64_t>(i), instants[i]).clone());
  }

  const auto path = std::filesystem::temp_directory_path() /
                    ("liftoff-synth-bench-" + std::to_string(::getpid()) +
                     std::string(VideoCodecExtension(codec)));
  VideoWriterOptions options;
  options.codec = codec;
  options.width_px = width_px;
  options.height_px = height_px;
  options.nominal_fps = spec.camera.fps;
  options.quality = codec == VideoCodec::kMjpeg ? 5 : 20;
  auto writer = VideoWriter::Open(path, options);
  if (!writer.ok()) {
    state.SkipWithError(writer.status().ToString().c_str());
    return;
  }
  int64_t frame = 0;
  for (auto _ : state) {
    const Status written =
        (*writer)->Write(frames[static_cast<size_t>(frame) % frames.size()],
                         NsFromSeconds(static_cast<double>(frame) / spec.camera.fps));
    if (!written.ok()) {
      state.SkipWithError(written.ToString().c_str());
      break;
    }
    ++frame;
  }
  // flushing the held frames is outside the timed loop (a few frames' work, once)
  const Status closed = (*writer)->Close();
  if (!closed.ok()) state.SkipWithError(closed.ToString().c_str());
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["bytes_per_frame"] = static_cast<double>(std::filesystem::file_size(path)) /
                                      static_cast<double>(std::max<int64_t>(frame, 1));
  std::filesystem::remove(path);
}

BENCHMARK_CAPTURE(BM_Render, 720p_default, 1280, 720, false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, 720p_all_nuisances, 1280, 720, true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, 1080p_default, 1920, 1080, false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Render, 1080p_all_nuisances, 1920, 1080, true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Encode, 720p_h264, VideoCodec::kH264, 1280, 720)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Encode, 720p_mjpeg, VideoCodec::kMjpeg, 1280, 720)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Encode, 720p_ffv1, VideoCodec::kFfv1, 1280, 720)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Encode, 1080p_h264, VideoCodec::kH264, 1920, 1080)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Encode, 1080p_mjpeg, VideoCodec::kMjpeg, 1920, 1080)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Encode, 1080p_ffv1, VideoCodec::kFfv1, 1920, 1080)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
