// Video analysis' figures (issue 4): on the same synthetic 720p and 1080p H.264 clips, in
// one run, wall time per frame of a plain decode loop (cv::VideoCapture::read and
// CAP_PROP_POS_MSEC, nothing else: what reading a clip costs an OpenCV program) against the
// full analysis (video::AnalyzeClip: LED and foot, decoding with FFmpeg's libraries on a
// second thread and converting only the regions the detectors read to BGR), and the ratio
// (target: at most 1.2); the full analysis on one thread too, for comparison. The three run
// in turn, 15 rounds of one each: a round's ratios compare runs a second apart, and the
// medians over the rounds are the figures (blocks of 15 runs of one kind, then of the
// other, moved the 720p ratio across the target from one run of the bench to the next, as
// the machine's speed drifted). Then peak memory: a plain decode and the analysis of a 1080p
// clip and of one three times longer, each in a child process of its own, and their peak
// resident set sizes (each child's VmHWM, which starts at its exec: a forked child's
// ru_maxrss also counts the parent's pages resident at the fork, which after the timings
// above are more than either child's): the analysis' must not grow with length.
//
// The clips are rendered by synth at startup into a temporary folder (removed at exit):
// 4 s at 30 fps (the LED at 0.5 s, the foot 1 mm up near 3 s), and a 12 s 1080p clip that
// rests 8 s longer before the same ramp, for the memory figure.
//
// Run: build/bench/video_bench   (the table at the end is the figure to quote; a failed
// analysis is printed as such and exits non-zero)
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/videoio.hpp>

#include "bench_support.h"
#include "liftoff/core/status.h"
#include "liftoff/core/time.h"
#include "liftoff/stats/statistics.h"
#include "liftoff/synth/spec.h"
#include "liftoff/synth/trial_writer.h"
#include "liftoff/video/clip_analysis.h"

namespace {

using namespace liftoff;

// One rendered clip and how to analyse it.
struct BenchClip {
  std::string name;
  synth::WrittenTrial trial;
  int64_t frames = 0;
};

std::filesystem::path g_dir;
std::map<std::string, BenchClip> g_clips;
// per size, each round's ms per frame: plain decode, full analysis, on one thread
struct Rounds {
  std::vector<double> plain, full, single;
};
std::map<std::string, Rounds> g_rounds;

// The clip: `width` x `height`, 30 fps, H.264; the ramp chosen so that in a 4 s clip the
// 1 mm instant falls 1 s before the end. A longer clip rests longer before the same ramp
// (a slower ramp would leave the foot, 1 s after the 1 mm instant, under the rise a lift
// must reach, and the analysis would fail).
synth::TrialSpec BenchSpec(const std::string& id, int width_px, int height_px, double duration_s) {
  constexpr double kRampedS = 4.0;
  synth::TrialSpec spec;
  spec.id = id;
  spec.seed = 11;
  spec.duration_s = duration_s;
  spec.camera.width_px = width_px;
  spec.camera.height_px = height_px;
  spec.camera.fps = 30.0;
  spec.camera.exposure_s = 1.0 / 60.0;
  spec.camera.codec = synth::VideoCodec::kH264;
  spec.nuisance.noise_sigma = 2.0;
  spec.led.on_video_s = 0.5;
  spec.motion.bend_start_s = 0.0;
  spec.motion.bend_end_s = 0.15;
  spec.motion.ramp_start_s = 0.2 + (duration_s - kRampedS);
  spec.motion.height.liftoff_rad = 0.3;
  const double one_mm_rad = 0.3 + std::pow(0.001 / spec.motion.height.gain_m, 1.0 / 1.5);
  spec.motion.ramp_rate_rad_per_s = one_mm_rad / (kRampedS - 1.0 - 0.7);
  return spec;
}

video::ClipAnalysisOptions OptionsFor(const BenchClip& clip, int queue_frames) {
  video::ClipAnalysisOptions options;
  options.led.roi_px = video::RectFromRegion(clip.trial.truth.led_roi_px);
  options.foot.foot_roi_px = video::RectFromRegion(clip.trial.truth.foot_roi_px);
  options.foot.tape_colour = clip.trial.truth.foot;
  options.foot.px_per_mm = clip.trial.truth.px_per_mm;
  options.queue_frames = queue_frames;
  return options;
}

// wall ms per frame of a plain decode of `clip` (-1 when it read nothing)
double PlainDecodeMs(const BenchClip& clip) {
  const int64_t started_ns = MonotonicNowNs();
  cv::VideoCapture capture(clip.trial.video_path.string(), cv::CAP_FFMPEG);
  cv::Mat frame;
  double last_ms = 0.0;
  int64_t frames = 0;
  while (capture.read(frame)) {
    last_ms = capture.get(cv::CAP_PROP_POS_MSEC);
    ++frames;
  }
  benchmark::DoNotOptimize(last_ms);
  if (frames == 0) return -1;
  return 1e-6 * static_cast<double>(MonotonicNowNs() - started_ns) / static_cast<double>(frames);
}

// wall ms per frame of the full analysis of `clip`, or its error
Result<double> FullAnalysisMs(const BenchClip& clip, int queue_frames) {
  const int64_t started_ns = MonotonicNowNs();
  auto analysis = video::AnalyzeClip(clip.trial.video_path, OptionsFor(clip, queue_frames));
  if (!analysis.ok()) return analysis.status();
  if (analysis->timing.frames <= 0) return NotFoundError("the analysis read no frame");
  return 1e-6 * static_cast<double>(MonotonicNowNs() - started_ns) /
         static_cast<double>(analysis->timing.frames);
}

// one round per iteration: a plain decode, the analysis, the analysis on one thread
void BM_Rounds(benchmark::State& state, const std::string& clip_name) {
  const BenchClip& clip = g_clips.at(clip_name);
  Rounds& rounds = g_rounds[clip_name];
  for (auto _ : state) {
    const double plain = PlainDecodeMs(clip);
    const Result<double> full = FullAnalysisMs(clip, 3);
    const Result<double> single = FullAnalysisMs(clip, 0);
    if (plain < 0 || !full.ok() || !single.ok()) {
      const Status failed = plain < 0 ? NotFoundError("the plain decode read no frame")
                                      : (!full.ok() ? full.status() : single.status());
      state.SkipWithError(failed.ToString().c_str());
      rounds = {};
      return;
    }
    rounds.plain.push_back(plain);
    rounds.full.push_back(*full);
    rounds.single.push_back(*single);
  }
  state.counters["plain_ms_per_frame"] = stats::Summarize(rounds.plain).median;
  state.counters["full_ms_per_frame"] = stats::Summarize(rounds.full).median;
}

// child mode: decode one clip plainly and exit (the parent reads our peak memory)
int RunDecodeChild(const char* video) {
  cv::VideoCapture capture(video, cv::CAP_FFMPEG);
  cv::Mat frame;
  int64_t frames = 0;
  while (capture.read(frame)) ++frames;
  if (frames == 0) return 1;
  std::printf("peak_kib %ld\n", bench::OwnPeakKib());
  return 0;
}

// "x,y,w,h" as RectText below writes it
cv::Rect RectFromText(const char* text) {
  int x = 0, y = 0, width = 0, height = 0;
  std::sscanf(text, "%d,%d,%d,%d", &x, &y, &width, &height);
  return {x, y, width, height};
}

// child mode: analyse one clip and exit (the parent reads our peak memory)
int RunChild(const char* video, const char* led, const char* foot, const char* px_per_mm) {
  video::ClipAnalysisOptions options;
  options.led.roi_px = RectFromText(led);
  options.foot.foot_roi_px = RectFromText(foot);
  options.foot.px_per_mm = std::atof(px_per_mm);
  auto analysis = video::AnalyzeClip(video, options);
  if (!analysis.ok()) {
    std::fprintf(stderr, "%s\n", analysis.status().ToString().c_str());
    return 1;
  }
  std::printf("peak_kib %ld\n", bench::OwnPeakKib());
  return 0;
}

std::string RectText(const RegionPx& region) {
  return std::to_string(region.x_px) + "," + std::to_string(region.y_px) + "," +
         std::to_string(region.width_px) + "," + std::to_string(region.height_px);
}

// Peak resident memory of a child analysing `clip` (or only decoding it), KiB (-1 on
// failure).
long ChildPeakKib(const char* self, const BenchClip& clip, bool decode_only) {
  const std::string video = clip.trial.video_path.string();
  const std::string led = RectText(clip.trial.truth.led_roi_px);
  const std::string foot = RectText(clip.trial.truth.foot_roi_px);
  const std::string scale = std::to_string(clip.trial.truth.px_per_mm);
  if (decode_only) return bench::ChildReportedPeakKib({self, "--decode-child", video});
  return bench::ChildReportedPeakKib({self, "--analyse-child", video, led, foot, scale});
}

Status RenderClips() {
  const Calibration calibration = bench::ShippedCalibration();
  g_dir = std::filesystem::temp_directory_path() /
          ("liftoff-video-bench-" + std::to_string(::getpid()));
  const struct {
    std::string name;
    int width, height;
    double duration_s;
  } clips[] = {
      {"720p", 1280, 720, 4.0}, {"1080p", 1920, 1080, 4.0}, {"1080p-3x", 1920, 1080, 12.0}};
  for (const auto& wanted : clips) {
    std::fprintf(stderr, "rendering %s (%.0f s)...\n", wanted.name.c_str(), wanted.duration_s);
    auto trial = synth::WriteTrial(
        BenchSpec("bench-" + wanted.name, wanted.width, wanted.height, wanted.duration_s),
        calibration, g_dir);
    if (!trial.ok()) return trial.status();
    BenchClip clip;
    clip.name = wanted.name;
    clip.frames = static_cast<int64_t>(trial->truth.frame_times_ns.size());
    clip.trial = std::move(trial).value();
    g_clips[wanted.name] = std::move(clip);
  }
  return Status::Ok();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 6 && std::strcmp(argv[1], "--analyse-child") == 0) {
    return RunChild(argv[2], argv[3], argv[4], argv[5]);
  }
  if (argc == 3 && std::strcmp(argv[1], "--decode-child") == 0) return RunDecodeChild(argv[2]);
  const Status rendered = RenderClips();
  if (!rendered.ok()) {
    std::fprintf(stderr, "%s\n", rendered.ToString().c_str());
    return 1;
  }

  // plain and full in turn at each size (same clip), 15 rounds
  for (const std::string size : {"720p", "1080p"}) {
    benchmark::RegisterBenchmark(("Rounds/" + size).c_str(), BM_Rounds, size)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(15);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();

  // the figures: medians over the rounds, and each round's ratio's range
  int exit_code = 0;
  std::printf("\nvideo analysis vs plain decode (H.264, 30 fps, wall ms per frame; medians of "
              "15 rounds):\n");
  std::printf("%-6s %9s %8s %7s %13s %9s %7s %13s\n", "size", "plain ms", "full ms", "ratio",
              "ratio range", "1 thr ms", "ratio", "ratio range");
  for (const std::string size : {"720p", "1080p"}) {
    const Rounds& rounds = g_rounds[size];
    if (rounds.plain.empty()) {
      std::printf("%-6s failed: its rounds stopped with an error (above)\n", size.c_str());
      exit_code = 1;
      continue;
    }
    std::vector<double> full_ratio, single_ratio;
    for (size_t i = 0; i < rounds.plain.size(); ++i) {
      full_ratio.push_back(rounds.full[i] / rounds.plain[i]);
      single_ratio.push_back(rounds.single[i] / rounds.plain[i]);
    }
    const stats::Summary full = stats::Summarize(full_ratio);
    const stats::Summary single = stats::Summarize(single_ratio);
    std::printf("%-6s %9.2f %8.2f %7.2f %6.2f-%-6.2f %9.2f %7.2f %6.2f-%-6.2f\n", size.c_str(),
                stats::Summarize(rounds.plain).median, stats::Summarize(rounds.full).median,
                full.median, full.min, full.max, stats::Summarize(rounds.single).median,
                single.median, single.min, single.max);
  }
  std::printf("\npeak memory (VmHWM of a child process, 1080p):\n");
  std::printf("%-10s %14s %14s %12s\n", "frames", "plain decode", "full analysis", "difference");
  for (const std::string name : {"1080p", "1080p-3x"}) {
    const BenchClip& clip = g_clips.at(name);
    const long decode_kib = ChildPeakKib(argv[0], clip, true);
    const long analyse_kib = ChildPeakKib(argv[0], clip, false);
    if (decode_kib < 0 || analyse_kib < 0) {
      std::printf("%-10lld failed: the %s child reported no peak memory\n",
                  static_cast<long long>(clip.frames), decode_kib < 0 ? "decode" : "analysis");
      exit_code = 1;
      continue;
    }
    std::printf("%-10lld %10.1f MiB %10.1f MiB %8.1f MiB\n", static_cast<long long>(clip.frames),
                static_cast<double>(decode_kib) / 1024.0, static_cast<double>(analyse_kib) / 1024.0,
                static_cast<double>(analyse_kib - decode_kib) / 1024.0);
  }

  std::error_code ignored;
  std::filesystem::remove_all(g_dir, ignored);
  return exit_code;
}
