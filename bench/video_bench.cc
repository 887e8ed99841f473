// Video analysis' figures (issue 4): on the same synthetic 720p and 1080p H.264 clips, in
// one run, wall time per frame of a plain decode loop (cv::VideoCapture::read and
// CAP_PROP_POS_MSEC, nothing else: what reading a clip costs an OpenCV program) against the
// full analysis (video::AnalyzeClip: LED and foot, decoding with FFmpeg's libraries on a
// second thread and converting only the regions the detectors read to BGR), and the ratio
// (target: at most 1.2); the full
// analysis on one thread too, for comparison. Then peak memory: a plain decode and the
// analysis of a 1080p clip and of one three times longer, each in a child process of its
// own, and their peak resident set sizes (each child's VmHWM, which starts at its exec:
// a forked child's ru_maxrss also counts the parent's pages resident at the fork, which
// after the timings above are more than either child's): the analysis' must not grow with
// length.
//
// The clips are rendered by synth at startup into a temporary folder (removed at exit):
// 4 s at 30 fps (the LED at 0.5 s, the foot 1 mm up near 3 s), and a 12 s 1080p clip with
// a slower ramp for the memory figure.
//
// Run: build/bench/video_bench   (the table at the end is the figure to quote)
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
#include "liftoff/core/time.h"
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
// ms per frame of each benchmark, by its name
std::map<std::string, double> g_ms_per_frame;

// The clip: `width` x `height`, 30 fps, H.264; the ramp chosen so the 1 mm instant falls
// 1 s before the end.
synth::TrialSpec BenchSpec(const std::string& id, int width_px, int height_px, double duration_s) {
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
  spec.motion.ramp_start_s = 0.2;
  spec.motion.height.liftoff_rad = 0.3;
  const double one_mm_rad = 0.3 + std::pow(0.001 / spec.motion.height.gain_m, 1.0 / 1.5);
  spec.motion.ramp_rate_rad_per_s = one_mm_rad / (duration_s - 1.0 - 0.7);
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

void Record(benchmark::State& state, const std::string& name, int64_t elapsed_ns, int64_t frames) {
  const double ms = 1e-6 * static_cast<double>(elapsed_ns) / static_cast<double>(frames);
  g_ms_per_frame[name] = ms;
  state.counters["ms_per_frame"] = ms;
  state.counters["frames"] = static_cast<double>(frames);
}

// the baseline: read every frame and its time, nothing else
void BM_PlainDecode(benchmark::State& state, const std::string& clip_name) {
  const BenchClip& clip = g_clips.at(clip_name);
  int64_t frames = 0;
  const int64_t started_ns = MonotonicNowNs();
  for (auto _ : state) {
    cv::VideoCapture capture(clip.trial.video_path.string(), cv::CAP_FFMPEG);
    cv::Mat frame;
    double last_ms = 0.0;
    while (capture.read(frame)) {
      last_ms = capture.get(cv::CAP_PROP_POS_MSEC);
      ++frames;
    }
    benchmark::DoNotOptimize(last_ms);
  }
  Record(state, "plain " + clip_name, MonotonicNowNs() - started_ns, frames);
}

void BM_FullAnalysis(benchmark::State& state, const std::string& clip_name, int queue_frames) {
  const BenchClip& clip = g_clips.at(clip_name);
  const video::ClipAnalysisOptions options = OptionsFor(clip, queue_frames);
  int64_t frames = 0;
  const int64_t started_ns = MonotonicNowNs();
  for (auto _ : state) {
    auto analysis = video::AnalyzeClip(clip.trial.video_path, options);
    if (!analysis.ok()) {
      state.SkipWithError(analysis.status().ToString().c_str());
      return;
    }
    frames += analysis->timing.frames;
  }
  Record(state, (queue_frames > 0 ? "full " : "full-1thread ") + clip_name,
         MonotonicNowNs() - started_ns, frames);
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

  // plain and full side by side at each size (same clip, interleaved)
  for (const std::string size : {"720p", "1080p"}) {
    benchmark::RegisterBenchmark(("PlainDecode/" + size).c_str(), BM_PlainDecode, size)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(15);
    benchmark::RegisterBenchmark(("FullAnalysis/" + size).c_str(), BM_FullAnalysis, size, 3)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(15);
    benchmark::RegisterBenchmark(("FullAnalysisOneThread/" + size).c_str(), BM_FullAnalysis, size,
                                 0)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(15);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();

  // the figures, side by side
  std::printf("\nvideo analysis vs plain decode (H.264, 30 fps, wall time per frame):\n");
  std::printf("%-6s %10s %12s %8s %14s %8s\n", "size", "plain ms", "full ms", "ratio",
              "1 thread ms", "ratio");
  for (const std::string size : {"720p", "1080p"}) {
    const double plain = g_ms_per_frame["plain " + size];
    const double full = g_ms_per_frame["full " + size];
    const double single = g_ms_per_frame["full-1thread " + size];
    std::printf("%-6s %10.2f %12.2f %8.2f %14.2f %8.2f\n", size.c_str(), plain, full,
                plain > 0 ? full / plain : 0.0, single, plain > 0 ? single / plain : 0.0);
  }
  std::printf("\npeak memory (VmHWM of a child process, 1080p):\n");
  std::printf("%-10s %14s %14s %12s\n", "frames", "plain decode", "full analysis", "difference");
  for (const std::string name : {"1080p", "1080p-3x"}) {
    const BenchClip& clip = g_clips.at(name);
    const long decode_kib = ChildPeakKib(argv[0], clip, true);
    const long analyse_kib = ChildPeakKib(argv[0], clip, false);
    std::printf("%-10lld %10.1f MiB %10.1f MiB %8.1f MiB\n", static_cast<long long>(clip.frames),
                static_cast<double>(decode_kib) / 1024.0, static_cast<double>(analyse_kib) / 1024.0,
                static_cast<double>(analyse_kib - decode_kib) / 1024.0);
  }

  std::error_code ignored;
  std::filesystem::remove_all(g_dir, ignored);
  return 0;
}
