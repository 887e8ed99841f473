// Writes rendered frames to a video file with exact per-frame timestamps, through FFmpeg's
// libraries (OpenCV's VideoWriter only knows a constant frame rate). Frames may come at
// any increasing times: dropped slots and jitter (variable frame rate) are stored as
// given, up to the container's time resolution, which StoredPtsNs() reports exactly so
// the ground truth records what a reader will see.
//
// Containers, codecs and what they store:
//   h264   libx264 in MP4 (yuv420p, preset veryfast, crf = quality, 2 B-frames always,
//          moov atom up front). Track time base 1/time_base_den: by default exact to 1 us.
//          The B-frames are on purpose: frames come out of the decoder in another
//          order than their packets, and the last 2 only when it is drained at the end
//          (OpenCV's FFmpeg backend 4.6 reads 0 ms for those; liftoff's reader does not).
//   mjpeg  Motion JPEG in AVI (full-range 4:2:0, q:v = quality). AVI counts frame slots
//          of 1/nominal_fps: each timestamp is stored rounded to the nearest slot. Dropped
//          slots survive (the muxer writes empty chunks, which readers skip, so later
//          frames keep their times; OpenCV's CAP_PROP_FRAME_COUNT counts them as frames);
//          jitter below half a slot does not.
//   ffv1   lossless FFV1 in Matroska (packed bgr0: decodes to the input pixels exactly).
//          FFmpeg's Matroska muxer stores milliseconds: timestamps round to 1 ms.
// Readers count time from the first frame (liftoff's reader and OpenCV's CAP_PROP_POS_MSEC
// subtract the stream's start; AVI stores the first frame at slot 0 whatever its time), so the
// first frame must be stored at 0: then reader times and StoredPtsNs() agree. Output is bit-exact:
// the same options and frames give the same bytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>

#include <opencv2/core/mat.hpp>

#include "liftoff/core/status.h"
#include "liftoff/synth/spec.h"

namespace liftoff::synth {

/// How to encode a video.
struct VideoWriterOptions {
  VideoCodec codec = VideoCodec::kFfv1;
  /// Frame size, px: 16 .. 4096, even for h264 and mjpeg (4:2:0 chroma).
  int width_px = 640;
  int height_px = 480;
  /// Nominal frame rate, Hz (1 .. 1000): the AVI slot rate, the key-frame interval (one
  /// key frame per nominal second, unless keyframe_interval_frames says otherwise) and the
  /// rate a reader reports as the file's fps.
  double nominal_fps = 60.0;
  /// Most frames from one key frame to the next, 0 .. 10000 (0: a nominal second; x264 may
  /// add a key frame at what it takes for a scene cut). A long interval lets H.264 hold slow
  /// motion back longer, as a camera's 250 frames do.
  int keyframe_interval_frames = 0;
  /// CRF for h264 (0 .. 51, lower is better), q:v for mjpeg (2 .. 31, lower is better);
  /// ffv1 ignores it.
  int quality = 20;
  /// Ticks per second of the h264 (MP4) track's time base, 10'000 .. 1'000'000'000. The
  /// default stores microseconds. AVI and Matroska fix their own (see above).
  int64_t time_base_den = 1'000'000;

  /// Every field in range; messages name the field and the allowed range.
  Status Validate() const;
};

/// One video file being written. Write frames in presentation order, then Close().
/// Writing goes to `<path>.partial`, renamed onto `path` by Close(): a reader never sees
/// half a video, and a writer destroyed without Close() (an error path) leaves none. Raises
/// FFmpeg's global log level to warnings (x264 chatters at info).
class VideoWriter {
 public:
  /// Creates the file (and missing parent folders). kInvalidArgument for bad options or a
  /// path whose extension is not VideoCodecExtension(codec); kUnsupported when this FFmpeg
  /// lacks the encoder or container; kIo (naming the file, with FFmpeg's reason) when the
  /// file cannot be created.
  static Result<std::unique_ptr<VideoWriter>> Open(const std::filesystem::path& path,
                                                   const VideoWriterOptions& options);

  /// Encodes one frame, 8-bit BGR (CV_8UC3) of the options' size, presented at `pts_ns`
  /// (video clock; the first frame at a time stored as 0). kInvalidArgument naming the
  /// file and frame for a wrong image, a first frame not at 0, a timestamp not after the
  /// previous one, or one that the container's resolution would store at the same time as
  /// the previous frame (the frame is skipped; the writer stays usable); kIo when encoding
  /// or writing fails (the writer keeps returning that error).
  Status Write(const cv::Mat& bgr, int64_t pts_ns);

  /// Flushes the encoder (B-frames still held), writes the trailer and index, and renames
  /// the file into place. Idempotent; returns the first error met while writing.
  Status Close();

  /// The time the container stores for a frame written at `pts_ns` (>= 0), ns: `pts_ns`
  /// rounded to the file's time base (1 us for h264, 1/nominal_fps for mjpeg, 1 ms for
  /// ffv1), rounded back to the nearest ns. Pure: usable before writing, e.g. to render
  /// each frame at the very instant that will be stored.
  int64_t StoredPtsNs(int64_t pts_ns) const;

  /// Frames accepted by Write() so far.
  int64_t frames_written() const;
  const std::filesystem::path& path() const;

  /// Without Close(), discards the unfinished video (deletes `<path>.partial`): only an
  /// explicit Close() publishes it.
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

 private:
  struct Impl;
  explicit VideoWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// Invalid inputs for the video pipeline's error tests.
/// Copies the first `keep_fraction` (0 < f < 1) of `source`'s bytes to `destination`: a
/// video cut short, as when a recording is interrupted. kInvalidArgument for the fraction,
/// kNotFound/kIo naming the file.
Status WriteTruncatedCopy(const std::filesystem::path& source,
                          const std::filesystem::path& destination, double keep_fraction);
/// Writes a small text file that no demuxer recognises to `path` (give it a video
/// extension): "not a video". kIo naming the file.
Status WriteNotAVideo(const std::filesystem::path& path);

}  // namespace liftoff::synth
