// One clip, start to end: a single pass over its frames feeds the LED detector and the foot
// tracker; then the foot's rest window is set from the LED instant and the liftoff
// instants are found. Frames are decoded on one thread and analysed on the calling thread
// through a small queue of reused buffers, so the analysis costs little more than the
// decoding, and memory stays flat in the clip's length: no frame is kept, only the foot
// tracker's 40 bytes, 8 bytes of frame time and, with an LED region, the LED's 16 bytes of
// brightness trace per frame. Method and parameters:
// docs/video.md.
//
// The rest window rule (the foot's rest height is its mean over it): by default the 0.5 s
// before the LED switches on, [LED on - 0.5 s, LED on). At the LED the test starts; before
// it nothing on the robot moves, so the window sees the foot exactly at rest, loaded as at
// the start of the test. (The simulation measures height from just before its ramp
// starts; the ramp starts seconds after the LED and the feet do not move in between unless
// the bend moves them, which a longer or later window can capture: rest_from_led_s and
// rest_to_led_s move it.) When the clip holds fewer than rest_min_frames frames in the
// window (the LED came on right after the recording began), the window is extended forward
// until it holds them, and a warning says so.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>
#include <opencv2/core.hpp>

#include "liftoff/core/manifest.h"
#include "liftoff/core/status.h"
#include "liftoff/video/foot_tracker.h"
#include "liftoff/video/led_detector.h"
#include "liftoff/video/video_reader.h"

namespace liftoff::video {

/// Which foot instant becomes the trial's liftoff.
enum class LiftoffInstant {
  /// First instant above rest by the threshold (default 1 mm): the simulation's rule.
  kThreshold,
  /// Onset of rise, the knee of the height curve.
  kOnset,
};
/// "threshold", "onset".
std::string_view LiftoffInstantName(LiftoffInstant instant);
std::optional<LiftoffInstant> ParseLiftoffInstant(std::string_view text);

struct ClipAnalysisOptions {
  /// How frames are decoded and their times checked.
  VideoReader::Options reader;
  /// The LED: ROI (empty: located automatically), thresholds, exposure. The camera's
  /// exposure, when known, belongs in both led.exposure_s and foot.exposure_s.
  LedDetector::Options led;
  /// The foot: ROI, tape colour, threshold (mm with px_per_mm, or px), reference region.
  /// An empty foot_roi_px means "LED only": no foot tracking, no liftoff (Events() is then
  /// kNotFound). rest_from_ns / rest_to_ns are ignored: the window comes from the rule below.
  FootTracker::Options foot;
  /// Rest window, s relative to the LED switch-on (the first pulse): [LED on +
  /// rest_from_led_s, LED on + rest_to_led_s). Each in [-60, 60], from < to.
  double rest_from_led_s = -0.5;
  double rest_to_led_s = 0.0;
  /// Fewest frames the rest window must hold; a window with fewer is extended forward to
  /// hold this many (1 .. 1000).
  int rest_min_frames = 5;
  /// Which foot instant is the liftoff of Events().
  LiftoffInstant liftoff = LiftoffInstant::kThreshold;
  /// Decoded frames waiting for analysis, at most (1 .. 16): the decoder runs on its own
  /// thread this far ahead. 0: decode and analyse on the calling thread, one frame at a
  /// time (slower; same results).
  int queue_frames = 3;

  /// Every part's checks; messages name the field and its allowed range.
  Status Validate() const;
};

/// Progress of AnalyzeClip: frames analysed so far and the last one's time (video clock,
/// ns). Called on the calling thread after every frame; keep it cheap.
using ClipProgress = std::function<void(int64_t frames_done, int64_t t_ns)>;

/// What one clip holds.
struct ClipAnalysis {
  /// The file, as given.
  std::filesystem::path video_path;
  /// Image size, px.
  int width_px = 0;
  int height_px = 0;
  /// Every frame's timing: drops, repairs, irregular intervals.
  FrameTimingReport timing;
  /// The LED: region, levels, every pulse (at least one).
  LedResult led;
  /// The foot's track and instants; empty when no foot region was given.
  std::optional<FootTrack> foot;
  /// Rest window used, video clock, ns ([from, to)), and how many frames it held; 0 when
  /// no foot was tracked.
  int64_t rest_from_ns = 0;
  int64_t rest_to_ns = 0;
  int64_t rest_frames = 0;
  /// Which instant is the liftoff.
  LiftoffInstant liftoff_instant = LiftoffInstant::kThreshold;
  /// Everything a person should check, from every stage ("frames: 3 dropped", "LED: dim
  /// ...", "foot: ...", "rest window: ...").
  std::vector<std::string> warnings;
  /// Wall time of the pass, s.
  double wall_seconds = 0.0;

  /// The first switch-on: the sync instant.
  const LedPulse& led_on() const { return led.pulses.front(); }
  /// The foot instant chosen as the liftoff (options' LiftoffInstant); null without a foot.
  const TimedEvent* liftoff() const;
  /// The two instants for sync: led_on_ns and its uncertainty from the first pulse,
  /// liftoff_ns and its uncertainty from liftoff(), source "video". kNotFound when no foot
  /// was tracked.
  Result<EventTimes> Events() const;
  /// "clip.mp4: LED on 0.6100 s +- 4.2 ms, liftoff 3.2860 s +- 3.1 ms (1 mm = 0.69 px),
  /// interval 2.6760 s, 222 frames, 2 warnings".
  std::string Brief() const;
  /// The `liftoff video --json` document (fields: docs/video.md, "JSON output").
  nlohmann::json ToJson() const;
};

/// Analyses the clip at `path`. Errors: options' kInvalidArgument; the reader's (kNotFound
/// no such file, kParse not a video / truncated or damaged); kInvalidArgument when a
/// region lies outside the frame, or when led.exposure_s or foot.exposure_s exceeds 1.05
/// times the clip's median frame interval (checked once the clip is read; the message
/// names the field and --exposure-ms); kNotFound when the LED never switches on or the
/// foot never lifts. Messages name the file. A lossless codec
/// (FrameTimingReport::lossless_codec) sets foot.compression_error_px to 0. `progress` may
/// be empty.
Result<ClipAnalysis> AnalyzeClip(const std::filesystem::path& path,
                                 const ClipAnalysisOptions& options,
                                 const ClipProgress& progress = {});

/// A manifest region as an OpenCV rectangle, and back.
cv::Rect RectFromRegion(const RegionPx& region);
RegionPx RegionFromRect(const cv::Rect& rect);

}  // namespace liftoff::video
