// Proof a person can check: one image per trial that shows what the analysis saw, and
// optionally the whole clip with the detections drawn on every frame.
//
// The image, top to bottom:
//   - the frames around the LED switch-on (the last dark frame, the first lit one with its
//     lit fraction, the next), cropped around the LED region and enlarged, region drawn,
//     each with its index and time;
//   - the frames around liftoff (a rest frame, the onset, the last frame below the
//     threshold, the first above it, and a later one), cropped around the foot region and
//     enlarged, with the foot region, the rest line (green), the threshold line (red) and
//     the tracked bottom of the foot (yellow) drawn; then the foot's bottom edge in the same
//     frames, enlarged until the threshold is plain to see (one square per pixel);
//   - the foot's height over the whole clip, and a close-up around liftoff: rest (0),
//     threshold, rest window, LED on, onset and liftoff with their uncertainty bars.
// The analysis pass keeps no frames, so the frames are decoded a second time; that decode
// stops right after the last frame the image needs (unless an annotated video is asked
// for, which takes every frame). It runs only when asked for.
//
// Where the lines sit in the crops: at the foot's bottom edge as the tracker located it in
// the first frame (FootTrack::foot_bottom_px), moved by the rest level (rest line), by the
// rest level and the threshold (threshold line) or by the frame's rise (tracked bottom),
// and by the frame's measured camera shake. They show what the tracker measured: a
// tracked line off the visible edge means the tracker was off.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "liftoff/core/status.h"
#include "liftoff/video/clip_analysis.h"

namespace liftoff::video {

struct VerificationOptions {
  /// PNG to write; empty: no image.
  std::filesystem::path image_path;
  /// Annotated video to write (Motion JPEG in AVI, every frame with the detections);
  /// empty: none.
  std::filesystem::path video_path;
  /// Height of each enlarged crop in the image, px (64 .. 1024).
  int crop_height_px = 220;
  /// Width of the image, px (640 .. 4096); crops are laid out to fit it.
  int image_width_px = 1400;
  /// Motion JPEG quality of the annotated video (1 .. 100).
  int video_quality = 90;

  /// Ranges, and at least one of image_path and video_path.
  Status Validate() const;
};

/// What WriteVerification did.
struct VerificationReport {
  /// Files written (empty when not asked for).
  std::filesystem::path image_path;
  std::filesystem::path video_path;
  /// Frames decoded by the second pass, and the clip's (the pass stops early for the
  /// image alone).
  int64_t frames_decoded = 0;
  int64_t clip_frames = 0;
  /// Image row of the foot's bottom edge at rest (the tracker's edge in the first frame
  /// moved by the rest level; no shake), px; NaN without a foot.
  double foot_rest_bottom_px = 0.0;
  /// "verification.png (1400x1010), 61 of 222 frames decoded".
  std::string Brief() const;
};

/// Decodes `analysis.video_path` again and writes the image and/or the annotated video.
/// Uses the analysis' regions, pulses and foot track (frames are matched by index; a clip
/// that changed since the analysis gives kInvalidArgument). Errors: the reader's; kIo when
/// a file cannot be written; kUnsupported when OpenCV cannot write Motion JPEG AVI.
Result<VerificationReport> WriteVerification(const ClipAnalysis& analysis,
                                             const VerificationOptions& options);

}  // namespace liftoff::video
