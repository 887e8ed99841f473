// `liftoff video`: one clip's LED switch-on and foot liftoff, with proof (verification
// image, annotated video); `liftoff sync` (its instants from the command line or a clip's
// analysis, with the same clip flags); and the video parts of `liftoff table` (progress while
// trials' videos are analysed, a verification image per analysed trial). Same shape as commands.h:
// an Add function binds flags to each struct; each Run function writes results to `out`, progress
// and diagnostics to `err`, and returns the process exit code (ExitCodeFor; docs/cli.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "liftoff/cli/commands.h"
#include "liftoff/cli/progress_line.h"
#include "liftoff/core/status.h"
#include "liftoff/sync/trial_analysis.h"
#include "liftoff/video/clip_analysis.h"

namespace liftoff::cli {

/// `liftoff video CLIP`: the clip's frame timing, LED switch-on and (with a foot region)
/// liftoff; text, or the analysis as JSON (docs/video.md, "JSON output").
struct VideoCommand {
  std::filesystem::path video_path;
  /// The clip analysis' options as the flags give them (CheckedClipOptions checks them).
  video::ClipAnalysisOptions clip;
  /// Verification image (PNG) and annotated video (MJPG AVI) to write; empty: none.
  std::filesystem::path verify_path;
  std::filesystem::path annotate_path;
  bool json = false;
  /// Progress on stderr: "auto" (live on a terminal, else a line every 5 s), "live",
  /// "lines" or "off".
  std::string progress = "auto";
};
int RunVideo(const VideoCommand& command, std::ostream& out, std::ostream& err);

/// The clip analysis' flags (`video`, `sync --video`), bound to video::ClipAnalysisOptions:
/// regions, foot, scale, threshold and exposure (--exposure-ms writes led.exposure_s;
/// CheckedClipOptions gives the foot the same).
const std::vector<FieldFlag<video::ClipAnalysisOptions>>& ClipFlags();
/// `liftoff video`'s further clip flags: the rest window and which instant is the liftoff.
const std::vector<FieldFlag<video::ClipAnalysisOptions>>& ClipInstantFlags();
/// ClipFlags bound to `clip` on `app` (--threshold-px excluding --threshold-mm); returned so
/// a mode flag can require them.
std::vector<Flag*> AddClipFlags(Command& app, video::ClipAnalysisOptions& clip);
/// The options as the flags left them, the camera's exposure given to the foot too, checked
/// by Validate(); kInvalidArgument naming the flag.
Result<video::ClipAnalysisOptions> CheckedClipOptions(video::ClipAnalysisOptions options);

/// `liftoff sync LOG --led-on S --liftoff S` or `liftoff sync LOG --video CLIP ...`: one
/// lookup, the rotation at liftoff. The two video instants come either from the command
/// line or from the clip's analysis (exactly one of the two).
struct SyncCommand {
  std::filesystem::path log_path;
  /// "auto", "liftoff", "laika-2018".
  std::string log_format = "auto";
  CalibrationChoice calibration;
  LookupChoice lookup;
  /// Video instants, seconds from the video's start (both, or neither with video_path).
  std::optional<double> led_on_s;
  std::optional<double> liftoff_s;
  /// Half-width of each instant's timing uncertainty, seconds (with led_on_s/liftoff_s).
  double uncertainty_s = 0.0;
  /// The clip whose analysis gives the instants and their uncertainties; needs
  /// clip.foot.foot_roi_px.
  std::filesystem::path video_path;
  /// The clip analysis' options as the flags give them (CheckedClipOptions checks them).
  video::ClipAnalysisOptions clip;
  /// With video_path: verification image (PNG) to write; empty: none.
  std::filesystem::path verify_path;
  /// With video_path: progress on stderr, "auto", "live", "lines" or "off" (as `liftoff
  /// video`).
  std::string progress = "auto";
  bool json = false;
};
int RunSync(const SyncCommand& command, std::ostream& out, std::ostream& err);

/// The progress of long video analyses on a ProgressLine: frames, video time and rate.
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
  explicit VideoProgress(ProgressLine line);
  ProgressLine line_;
  std::string label_;
  int64_t started_ns_ = 0;
};

/// AnalyzeClip showing its progress on `progress` (labelled with the clip's file name);
/// the progress line is ended before returning.
Result<video::ClipAnalysis> AnalyzeClipShowingProgress(const std::filesystem::path& path,
                                                       const video::ClipAnalysisOptions& options,
                                                       VideoProgress& progress);

/// File stems for trial ids, in order: each id made a safe file name (anything but letters,
/// digits, '.', '_' and '-' becomes '_'; a leading '.' too; an empty id is "trial"), and
/// unique even where the file system ignores case: a stem that would clash with an earlier
/// one gets "-2", "-3", ... ("a/1" and "a_1" become "a_1" and "a_1-2").
std::vector<std::string> TrialFileStems(const std::vector<std::string>& trial_ids);

/// What WriteTrialVerifications wrote.
struct TrialVerifications {
  /// Per outcome, in order: the image written, or empty (no video analysis, or it failed).
  std::vector<std::filesystem::path> image_paths;
  /// Per outcome: why its image failed (OK when written or not asked for).
  std::vector<Status> errors;
  /// One line per image written (VerificationReport::Brief()).
  std::vector<std::string> written;
  /// The first error (OK when none); the other images are still written.
  Status first_failure;
};

/// Writes `dir`/<stem>.png for every trial of `analysis` whose times came from its video
/// (failed ones included, when their video analysis got through), `stems` one per outcome
/// (TrialFileStems of their ids). Each error goes to `err` as it happens.
TrialVerifications WriteTrialVerifications(const sync::ManifestAnalysis& analysis,
                                           const std::vector<std::string>& stems,
                                           const std::filesystem::path& dir, std::ostream& err);

/// The command added to the command line `parent` (flags bound to its struct).
Subcommand AddVideoCommand(Command& parent);
Subcommand AddSyncCommand(Command& parent);

}  // namespace liftoff::cli
