// Sequential decoding with true per-frame timestamps, through FFmpeg's libraries (decoded
// and converted to BGR as OpenCV's FFmpeg backend does, whose times and container figures
// it also reports). Nominal frame rate and the container's frame count are never trusted
// (both lie for variable-frame-rate files): each frame's time is the decoder's
// presentation time, checked; a time that is missing or does not increase is extrapolated
// from the median interval and marked (Frame::t_repaired). Dropped and irregular frames are
// reported in FrameTimingReport. Memory stays flat: one frame buffer, a few dozen intervals and a
// fixed histogram.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "liftoff/core/status.h"
#include "liftoff/video/frame.h"

namespace liftoff::video {

/// One frame whose interval to its predecessor is not the usual one.
struct TimingIrregularity {
  enum class Kind {
    kDropped,    ///< interval about n >= 2 usual intervals: n - 1 frames missing
    kIrregular,  ///< interval off the usual one by more than the tolerance, not a drop
    kRepaired,   ///< timestamp unreadable (0 or not increasing) and extrapolated
  };
  Kind kind = Kind::kIrregular;
  /// The frame (Frame::index) and its time, ns.
  int64_t frame_index = 0;
  int64_t t_ns = 0;
  /// Interval from the previous frame, ns.
  int64_t interval_ns = 0;
  /// kDropped: estimated number of missing frames.
  int64_t missing_frames = 0;
};

/// What the timestamps of a whole clip looked like.
struct FrameTimingReport {
  int64_t frames = 0;    ///< frames decoded
  int64_t first_ns = 0;  ///< first frame's time, ns
  int64_t last_ns = 0;   ///< last frame's time, ns
  /// The usual interval: the median of all read (not repaired) intervals, ns; exact for a
  /// constant rate, else within 0.3 % (a fixed histogram keeps memory flat).
  int64_t median_interval_ns = 0;
  /// Frame rate, Hz: (frames - 1 + dropped_frames) / (last_ns - first_ns), the frames
  /// over the span of their times. Unlike 1 / median_interval_ns it is not biased by
  /// timestamps rounded to 1 ms (MKV at 60 fps: 17, 17, 16 ms, median 17 ms = 58.8 fps).
  /// 0 with fewer than two frames.
  double fps = 0.0;
  double container_fps = 0.0;    ///< what the container claims (not used), Hz
  int64_t container_frames = 0;  ///< what the container claims (not used)
  /// The codec's FourCC as the backend reports it ("FFV1", "avc1", "h264", "MJPG"; empty
  /// when unknown), and whether it is a lossless codec (FFV1, HuffYUV, UtVideo, PNG, raw).
  /// Lossy codecs update slow sub-pixel motion in steps (see FootTracker::Options).
  std::string codec_fourcc;
  bool lossless_codec = false;
  int64_t dropped_frames = 0;   ///< sum of missing_frames
  int64_t repaired_frames = 0;  ///< frames with t_repaired
  /// Every irregular, dropped or repaired frame, in order (at most max_listed; the counts
  /// above are complete).
  std::vector<TimingIrregularity> irregularities;
  int64_t irregular_frames = 0;  ///< count of kIrregular (complete)
  /// Errors FFmpeg's demuxer and decoder logged while reading (they are caught, not
  /// printed): damage the decoder concealed, or that ended the stream. The first one's text.
  int64_t decoder_errors = 0;
  std::string first_decoder_error;
  /// Key frames among the decoded frames (Frame::keyframe), and whether the file's packets
  /// said which they are (when not, every frame counts as a key frame).
  int64_t keyframes = 0;
  bool keyframes_known = false;
  /// "1432 frames at 60.00 fps, 16.667 ms median interval, 3 dropped, 2 repaired, 0 irregular"
  /// (", 2 decoder errors" appended when there were any).
  std::string Brief() const;
};

/// Decodes a video file frame by frame.
class VideoReader {
 public:
  struct Options {
    /// An interval differing from the median by more than this fraction of it is
    /// irregular; one near n medians (n >= 2, within the fraction) is n - 1 drops. (0, 1).
    double irregular_tolerance_frac = 0.25;
    /// Intervals used to estimate the usual interval on the fly before the whole clip is
    /// known, >= 3: each interval is judged against the median of the window centred on it
    /// (so a rate that changes midway is followed), and a repair extrapolates by the
    /// median of the last ones.
    int median_window_frames = 31;
    /// Most irregularities listed in the report (counts stay complete); >= 0.
    int max_listed = 1000;
    /// The decoder's threads (0 .. 64; 0: the machine's cores, at most 16). Decoded frames
    /// are the same whatever the count; lower it when several clips decode at once.
    int decoder_threads = 0;

    Status Validate() const;
  };

  /// Opens `path`. kNotFound when it does not exist; kParse "not a video" when no decoder
  /// accepts it, or "truncated or damaged" when it looks like a video container (a known
  /// file signature) but cannot be opened or yields no frame. Messages name the file.
  static Result<VideoReader> Open(const std::filesystem::path& path, const Options& options);
  static Result<VideoReader> Open(const std::filesystem::path& path) {
    return Open(path, Options{});
  }

  VideoReader(VideoReader&&) noexcept;
  VideoReader& operator=(VideoReader&&) noexcept;
  ~VideoReader();

  /// Decodes the next frame into `frame` (its bgr buffer is reused). Returns false at the
  /// end of the stream. kParse "truncated or damaged" naming the file and the last frame
  /// when the stream ends short of what the container lists, both in frames and in time:
  /// by a tenth, or by two frames when FFmpeg reported errors. The frames already returned
  /// stay valid. FFmpeg's and OpenCV's own messages are caught while the reader works
  /// (the first error goes into the message and FrameTimingReport), never printed.
  Result<bool> Next(Frame& frame);

  /// From the next frame on, converts only these regions of each picture to BGR (at least
  /// their pixels, equal to a whole conversion's); the rest of Frame::bgr is unspecified.
  /// Empty (the default): whole pictures. Converting a picture to BGR costs more than
  /// decoding it at 720p, and a detector reads a few regions.
  void ConvertOnly(std::vector<cv::Rect> regions_px);

  /// Image size, px.
  int width_px() const;
  int height_px() const;
  /// The file.
  const std::filesystem::path& path() const;
  /// Timing so far (complete once Next returned false).
  const FrameTimingReport& timing() const;

 private:
  struct Impl;
  explicit VideoReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace liftoff::video
