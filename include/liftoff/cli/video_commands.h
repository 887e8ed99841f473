// `liftoff video`: one clip's LED switch-on and foot liftoff, with proof (verification
// image, annotated video); and the video parts of `liftoff table` (progress while trials'
// videos are analysed, a verification image per analysed trial). Same shape as
// commands.h: apps/liftoff/main.cc maps flags onto these structs; each Run function
// writes results to `out`, progress and diagnostics to `err`, and returns the process
// exit code (ExitCodeFor; docs/cli.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>

#include "liftoff/cli/commands.h"
#include "liftoff/core/status.h"
#include "liftoff/sync/trial_analysis.h"

namespace liftoff::cli {

/// `liftoff video CLIP`: the clip's frame timing, LED switch-on and (with a foot region)
/// liftoff; text, or the analysis as JSON (docs/video.md, "JSON output").
struct VideoCommand {
  std::filesystem::path video_path;
  /// Regions "x,y,w,h", px. LED: empty = locate automatically. Foot: empty = LED only.
  std::string led_roi;
  std::string foot_roi;
  /// The foot whose tape colour to track (A, B, C, D); empty: edges only.
  std::string foot;
  /// Image scale at the foot, px per mm; 0: estimated from the foot's width.
  double px_per_mm = 0.0;
  /// Liftoff threshold above rest: mm (with the scale), or px when threshold_px is given
  /// (> 0; then threshold_mm is ignored).
  double threshold_mm = 1.0;
  std::optional<double> threshold_px;
  /// Camera exposure per frame, ms (> 0, at most 1.05 frame intervals); 0: unknown (the
  /// LED allows any exposure up to the frame interval, the foot takes half of it).
  double exposure_ms = 0.0;
  /// Rest window "FROM,TO", s relative to the LED switch-on.
  std::string rest_window = "-0.5,0";
  /// Which foot instant is the liftoff: "threshold" or "onset".
  std::string liftoff = "threshold";
  /// Verification image (PNG) and annotated video (MJPG AVI) to write; empty: none.
  std::filesystem::path verify_path;
  std::filesystem::path annotate_path;
  bool json = false;
  /// Progress on stderr: "auto" (live on a terminal, else a line every 5 s), "live",
  /// "lines" or "off".
  std::string progress = "auto";
};
int RunVideo(const VideoCommand& command, std::ostream& out, std::ostream& err);

/// A progress line on `err` for long video analyses: rewritten in place ("live"), one line
/// every 5 s of wall time ("lines"), or nothing ("off"); "auto" is live when `err` is the
/// process' standard error and a terminal, else lines.
class VideoProgress {
 public:
  /// kInvalidArgument "--progress: expected auto, live, lines or off, got ..." for another
  /// mode.
  static Result<VideoProgress> Create(std::string_view mode, std::ostream& err);
  /// Reports `frames_done` frames of `label` analysed, the last at `t_ns` (video clock).
  void Show(std::string_view label, int64_t frames_done, int64_t t_ns);
  /// Ends a live line (call before printing anything else).
  void Done();

 private:
  VideoProgress(std::ostream& err, bool live, bool off);
  std::ostream* err_;
  bool live_ = false;
  bool off_ = false;
  std::string label_;
  int64_t started_ns_ = 0;
  int64_t last_shown_ns_ = 0;
  size_t last_width_ = 0;
};

/// Writes `dir`/<trial id>.png for every trial of `analysis` whose times came from its
/// video (failed ones included, when their video analysis got through); one line per file
/// on `err`. Returns the first error; the other images are still written.
Status WriteTrialVerifications(const sync::ManifestAnalysis& analysis,
                               const std::filesystem::path& dir, std::ostream& err);

}  // namespace liftoff::cli
