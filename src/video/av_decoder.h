// FFmpeg's demuxer and decoder for one file's video stream, used directly (private to the
// video module).
//
// It decodes as OpenCV's FFmpeg backend does (the first video stream, frame and slice
// threads, the picture converted to BGR by swscale with SWS_BICUBIC, turned upright by the
// stream's display matrix) and reports what that backend reports (its times, rate, frame
// count and FourCC), with one addition that is the reason it exists: the conversion to BGR
// can be limited to the regions a detector reads. At 720p the conversion of a whole
// picture costs more than decoding it, and the detectors read a few regions of it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "liftoff/core/status.h"

namespace liftoff::video::internal {

/// What the container says about the stream (none of it trusted for timing).
struct StreamFacts {
  /// The frame rate FFmpeg guesses from the container, Hz (OpenCV's CAP_PROP_FPS).
  double fps = 0.0;
  /// The frames the container lists, or its duration times `fps` when it lists none
  /// (OpenCV's CAP_PROP_FRAME_COUNT).
  int64_t frames = 0;
  /// The codec's tag, else its four-letter name ("avc1", "MJPG", "FFV1"; OpenCV's
  /// CAP_PROP_FOURCC as text); empty when neither is printable.
  std::string fourcc;
  /// The upright picture's size, px.
  int width_px = 0;
  int height_px = 0;
  /// Clockwise turn that makes the stored picture upright, degrees (0, 90, 180, 270).
  int rotation_deg = 0;
};

class AvDecoder {
 public:
  /// Opens `path`'s first video stream. kParse with the reason ("FFmpeg cannot open it",
  /// "no video stream", "no decoder for hevc") when it cannot; the caller names the file.
  /// `threads`: the decoder's frame and slice threads; 0: the machine's cores (at most 16).
  static Result<std::unique_ptr<AvDecoder>> Open(const std::string& path, int threads = 0);
  ~AvDecoder();
  AvDecoder(const AvDecoder&) = delete;
  AvDecoder& operator=(const AvDecoder&) = delete;

  const StreamFacts& facts() const;

  /// Decodes the next frame in presentation order: true, or false at the end of the
  /// stream (or at a read error, which the caller judges by what the container listed).
  /// Packets the decoder rejects are skipped, as OpenCV does (FFmpeg logs why).
  bool Next();

  /// The current frame's presentation time, ms from the stream's start time (NaN when the
  /// frame carries none).
  double position_ms() const;

  /// Converts the current frame into `bgr` (made height x width CV_8UC3 when it is not):
  /// the whole picture when `regions_px` is empty, else at least the pixels inside each
  /// region (clipped to the picture; widened to whole 16-pixel columns and chroma
  /// samples), their values equal to a whole conversion's; pixels outside the regions are
  /// unspecified. Regions are converted alone only in planar formats (H.264's and MJPEG's
  /// YUV) and unrotated streams, and only while the first such frame's regions equal its
  /// whole conversion (checked once); otherwise the whole picture is converted.
  void ToBgr(const std::vector<cv::Rect>& regions_px, cv::Mat& bgr);

 private:
  struct Impl;
  explicit AvDecoder(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace liftoff::video::internal
